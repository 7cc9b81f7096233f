//! A request's query: its parameters, each read at most once and checked against its valid
//! values, and the one-line JSON refusal ([`ApiError`]) when one is not.

use std::collections::HashMap;

use axum::extract::rejection::QueryRejection;
use axum::extract::Query;
use axum::http::StatusCode;
use axum::response::{IntoResponse, Response};
use axum::Json;
use serde::Serialize;
use specula::formula::MAX_SOURCE_BYTES;
use specula::{Exponent, Geometry, LobeKind, Normalisation};
use specula_render::IlluminationModel;

/// A request the server cannot serve, and why.
#[derive(Debug, Serialize)]
pub struct ApiError {
    #[serde(skip)]
    status: StatusCode,
    /// What went wrong, in a sentence.
    error: String,
    /// The offending parameter, if one.
    #[serde(skip_serializing_if = "Option::is_none")]
    parameter: Option<String>,
    /// Its valid values or range.
    #[serde(skip_serializing_if = "Option::is_none")]
    valid: Option<String>,
}

impl ApiError {
    pub(crate) fn bad(parameter: &str, error: String, valid: String) -> Self {
        Self {
            status: StatusCode::BAD_REQUEST,
            error,
            parameter: Some(parameter.to_owned()),
            valid: Some(valid),
        }
    }

    pub(crate) fn not_found(error: String, valid: String) -> Self {
        Self {
            status: StatusCode::NOT_FOUND,
            error,
            parameter: None,
            valid: Some(valid),
        }
    }

    pub(crate) fn unavailable(error: String) -> Self {
        Self {
            status: StatusCode::SERVICE_UNAVAILABLE,
            error,
            parameter: None,
            valid: None,
        }
    }

    /// A newer request for the same view came while this one waited ([`crate::supersede`]).
    pub(crate) fn superseded() -> Self {
        Self {
            status: StatusCode::CONFLICT,
            error: "superseded by a newer request for the same view".to_owned(),
            parameter: None,
            valid: None,
        }
    }

    pub(crate) fn internal(error: String) -> Self {
        Self {
            status: StatusCode::INTERNAL_SERVER_ERROR,
            error,
            parameter: None,
            valid: None,
        }
    }
}

impl IntoResponse for ApiError {
    fn into_response(self) -> Response {
        (self.status, Json(&self)).into_response()
    }
}

impl From<ApiError> for Response {
    fn from(error: ApiError) -> Self {
        error.into_response()
    }
}

/// The query string as key-value pairs, or a JSON 400 when it is not well-formed.
pub(crate) type QueryPairs = Result<Query<Vec<(String, String)>>, QueryRejection>;

pub(crate) fn pairs(query: QueryPairs) -> Result<Vec<(String, String)>, ApiError> {
    query.map(|Query(pairs)| pairs).map_err(|e| ApiError {
        status: StatusCode::BAD_REQUEST,
        error: format!("the query string is malformed: {e}"),
        parameter: None,
        valid: Some("key=value pairs joined by &, percent-encoded".into()),
    })
}

/// A request's query parameters, each read at most once.
pub(crate) struct Params {
    values: HashMap<String, String>,
}

impl Params {
    /// The query, refusing any parameter outside `known`.
    pub(crate) fn new(query: Vec<(String, String)>, known: &[&str]) -> Result<Self, ApiError> {
        let mut values = HashMap::new();
        for (key, value) in query {
            if !known.contains(&key.as_str()) {
                return Err(ApiError::bad(
                    &key,
                    format!("unknown parameter `{key}`"),
                    known.join(", "),
                ));
            }
            if values.insert(key.clone(), value).is_some() {
                return Err(ApiError::bad(
                    &key,
                    format!("`{key}` is given twice"),
                    "one value".into(),
                ));
            }
        }
        Ok(Self { values })
    }

    pub(crate) fn text(&self, name: &str) -> Option<&str> {
        self.values.get(name).map(String::as_str)
    }

    /// A choice from `all` by id, or `default`.
    pub(crate) fn choice<T: Copy>(
        &self,
        name: &str,
        all: &[T],
        id: fn(T) -> &'static str,
        default: T,
    ) -> Result<T, ApiError> {
        let Some(text) = self.text(name) else {
            return Ok(default);
        };
        all.iter().copied().find(|&v| id(v) == text).ok_or_else(|| {
            let valid = all.iter().map(|&v| id(v)).collect::<Vec<_>>().join(", ");
            ApiError::bad(name, format!("unknown {name} `{text}`"), valid)
        })
    }

    /// A finite number in `range`, or `default`.
    pub(crate) fn number(
        &self,
        name: &str,
        range: core::ops::RangeInclusive<f64>,
        default: f64,
    ) -> Result<f64, ApiError> {
        let Some(text) = self.text(name) else {
            return Ok(default);
        };
        let valid = format!("a number in [{}, {}]", range.start(), range.end());
        match text.trim().parse::<f64>() {
            Ok(value) if value.is_finite() && range.contains(&value) => Ok(value),
            Ok(value) => Err(ApiError::bad(
                name,
                format!("{name} = {value} is out of range"),
                valid,
            )),
            Err(_) => Err(ApiError::bad(
                name,
                format!("{name} = `{text}` is not a number"),
                valid,
            )),
        }
    }

    /// The lobe: an id, with parameters (`cosquad:v=2`), or `=FORMULA`.
    pub(crate) fn lobe(&self) -> Result<LobeKind, ApiError> {
        let text = self.text("lobe").unwrap_or("pow");
        if let Some(formula) = text.trim_start().strip_prefix('=') {
            // Refused before the text is copied or read: the parser's own limit, said here.
            if formula.len() > MAX_SOURCE_BYTES {
                return Err(bad_lobe(format!(
                    "the formula is {} bytes long; the limit is {MAX_SOURCE_BYTES}",
                    formula.len()
                )));
            }
        }
        LobeKind::parse(text).map_err(|error| match error {
            // The position and the problem, in a line; the lobe's name is the server's
            // numbering (`formula-7`), not the user's, so it is left out.
            specula::Error::Formula { message, .. } => bad_lobe(message),
            specula::Error::InvalidLobeParameter { .. } => bad_lobe(error.to_string()),
            _ => bad_lobe(format!("unknown lobe `{}`", specula::excerpt(text))),
        })
    }

    /// The illumination model (`classic` unless named).
    pub(crate) fn model(&self) -> Result<IlluminationModel, ApiError> {
        self.choice(
            "model",
            &IlluminationModel::ALL,
            IlluminationModel::id,
            IlluminationModel::Classic,
        )
    }

    /// The light's polar angle from the camera's axis (`light_theta`, 0 to 89 degrees, 30 by
    /// default) and its azimuth (`light_phi`, -180 to 180, 45), in radians.
    pub(crate) fn light(&self) -> Result<(f64, f64), ApiError> {
        let theta = self.number("light_theta", 0.0..=89.0, 30.0)?;
        let phi = self.number("light_phi", -180.0..=180.0, 45.0)?;
        Ok((theta.to_radians(), phi.to_radians()))
    }

    pub(crate) fn exponent(&self) -> Result<Exponent, ApiError> {
        let n = self.number("n", 1.0..=1000.0, 64.0)?;
        Exponent::try_new(n)
            .map_err(|e| ApiError::bad("n", e.to_string(), "a number in [1, 1000]".into()))
    }

    pub(crate) fn geometry(&self) -> Result<Geometry, ApiError> {
        self.choice("geometry", &Geometry::ALL, Geometry::id, Geometry::Blinn)
    }

    pub(crate) fn normalisation(&self, default: Normalisation) -> Result<Normalisation, ApiError> {
        self.choice(
            "normalisation",
            &Normalisation::ALL,
            Normalisation::id,
            default,
        )
    }
}

/// A refused `lobe`: `error` and the valid forms.
pub(crate) fn bad_lobe(error: String) -> ApiError {
    ApiError::bad(
        "lobe",
        error,
        format!(
            "{}, with parameters as ID:NAME=VALUE (cosquad:v=2), or =FORMULA: a formula of t and n",
            LobeKind::valid_ids()
        ),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A formula over the parser's limit (which HTTP's address limit already keeps out) is
    /// refused by its length alone, at once, without echoing it.
    #[test]
    fn an_oversize_formula_is_refused_by_its_length() {
        let text = format!("={}", "t+".repeat(1 << 19));
        let params = Params::new(vec![("lobe".into(), text)], &["lobe"]).expect("known");
        let started = std::time::Instant::now();
        let error = params.lobe().expect_err("too long");
        assert!(started.elapsed() < std::time::Duration::from_millis(100));
        assert_eq!(error.status, StatusCode::BAD_REQUEST);
        assert_eq!(
            error.error,
            format!(
                "the formula is {} bytes long; the limit is {MAX_SOURCE_BYTES}",
                1 << 20
            )
        );
    }
}
