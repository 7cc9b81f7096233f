//! The JSON API: parameters parsed with the library's registries, every refusal a 400 with a
//! JSON body naming the parameter and its valid range or choices.
//!
//! Every `lobe` is a built-in id (`cosquad:v=2`) or, as on the command line, `=FORMULA`: a
//! formula of `t` and `n` (`lobe==exp2(n * (t - 1) * 1.4427)`, percent-encoded). A formula is
//! refused with a 400 whose `error` is the library's one-line message (the position and the
//! problem) when it does not parse, when it is longer than
//! [`MAX_SOURCE_BYTES`](specula::formula::MAX_SOURCE_BYTES) (before any work), or when
//! [`Lobe::checked`] finds it outside `[0, 1]` at the request's `n`.
//!
//! - `GET /api/models`: the lobes, geometries, normalisations, shadings, objects and limits,
//!   and the formula language's functions and length limit (the page's text box);
//! - `GET /api/evaluate?lobe&n&geometry&normalisation&theta_in`: every plot's data;
//! - `GET /api/analyze?lobe&n`: the error, energy and albedo figures (`specula analyze`'s),
//!   and `costs`, the lobe's cost on every target the server's cost model knows;
//! - `GET /api/render?object&lobe&n&geometry&normalisation&shading&model&light_theta&light_phi&size`:
//!   a PNG from the CPU renderer;
//! - `GET /api/volume?volume&view&lobe&n&geometry&normalisation&size`: a volume (a built-in
//!   one, or a real scan while its file is installed) ray marched on the CPU, as a PNG;
//! - `GET /api/environment?lobe&n&geometry&normalisation&size&spp`: the environment scene lit
//!   by the procedural sky (Monte Carlo, CPU), as a PNG;
//! - `GET /api/materials`, `GET /api/fits?material`, `GET /api/material-render?material&fit&size&spp`:
//!   the measured materials of the `--data` folder, by name (`measured.rs`).

use std::collections::HashMap;
use std::sync::Arc;

use axum::extract::rejection::QueryRejection;
use axum::extract::{Query, State};
use axum::http::{header, StatusCode};
use axum::response::{IntoResponse, Response};
use axum::Json;
use serde::Serialize;
use serde_json::json;
use specula::analysis::{analyze, Precision};
use specula::formula::MAX_SOURCE_BYTES;
use specula::{Exponent, Geometry, Lobe, LobeKind, Normalisation};
use specula_render::volume::raymarch::View;
use specula_render::{IlluminationModel, Shading};

use super::explorer::{curves, render_png, Object, RenderRequest};
use super::guard::{Hosts, Limiter};
use specula_render::volume::phantom::BuiltIn;

use super::environment::{
    environment_png, EnvironmentRequest, MAX_ENVIRONMENT_SIZE, MAX_ENVIRONMENT_SPP,
};
use super::measured::Materials;
use super::volume::{volume_png, Choice, VolumeRequest, MAX_VOLUME_SIZE};

/// The largest render side, in pixels.
pub const MAX_RENDER_SIZE: u32 = 1024;

/// A lobe's cost on one target, as the explorer shows it beside its errors.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct TargetCost {
    /// The target's id (`cpu`, `gpu-nvidia`, ...).
    pub target: String,
    /// The figure.
    pub value: f64,
    /// What it counts.
    pub unit: String,
}

/// The costs of a prepared lobe on every target the server knows. The binary supplies the
/// GPU models (they need the shader compiler, which this crate does not depend on); the
/// default knows the CPU's counted SIMD instructions only.
pub type CostModel = Arc<dyn Fn(&Lobe) -> Result<Vec<TargetCost>, String> + Send + Sync>;

/// The CPU's cost: the instructions the lobe's SIMD kernel executes per vector of 8.
#[must_use]
pub fn cpu_cost(lobe: &Lobe) -> TargetCost {
    TargetCost {
        target: "cpu".into(),
        value: f64::from(lobe.batch_instructions().total()),
        unit: "SIMD instructions per 8 evaluations (counted; fewer is cheaper)".into(),
    }
}

/// What the handlers share.
#[derive(Clone)]
pub struct AppState {
    computations: Limiter,
    pub(crate) costs: CostModel,
    pub(crate) designer: Option<crate::design::DesignModel>,
    hosts: Hosts,
    pub(crate) materials: Arc<Materials>,
}

impl AppState {
    /// The state with `costs` as the cost model.
    #[must_use]
    pub fn with_costs(costs: CostModel) -> Self {
        Self {
            computations: Limiter::default(),
            costs,
            designer: None,
            hosts: Hosts::default(),
            materials: Arc::new(Materials::none()),
        }
    }

    /// The state offering `materials` (the `--data` folder's; by default none).
    #[must_use]
    pub fn with_materials(self, materials: Materials) -> Self {
        Self {
            materials: Arc::new(materials),
            ..self
        }
    }

    /// The state answering `/api/design` with `designer`.
    #[must_use]
    pub fn with_designer(self, designer: crate::design::DesignModel) -> Self {
        Self {
            designer: Some(designer),
            ..self
        }
    }

    /// The state answering only to `hosts` (the default: loopback names, any port).
    #[must_use]
    pub fn answering(self, hosts: Hosts) -> Self {
        Self { hosts, ..self }
    }

    /// The host names it answers to.
    #[must_use]
    pub fn hosts(&self) -> Hosts {
        self.hosts.clone()
    }
}

impl Default for AppState {
    fn default() -> Self {
        Self::with_costs(Arc::new(|lobe: &Lobe| Ok(vec![cpu_cost(lobe)])))
    }
}

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

    pub(crate) fn unavailable(error: String) -> Self {
        Self {
            status: StatusCode::SERVICE_UNAVAILABLE,
            error,
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
    fn choice<T: Copy>(
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
    fn lobe(&self) -> Result<LobeKind, ApiError> {
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

    fn exponent(&self) -> Result<Exponent, ApiError> {
        let n = self.number("n", 1.0..=1000.0, 64.0)?;
        Exponent::try_new(n)
            .map_err(|e| ApiError::bad("n", e.to_string(), "a number in [1, 1000]".into()))
    }

    fn geometry(&self) -> Result<Geometry, ApiError> {
        self.choice("geometry", &Geometry::ALL, Geometry::id, Geometry::Blinn)
    }

    fn normalisation(&self, default: Normalisation) -> Result<Normalisation, ApiError> {
        self.choice(
            "normalisation",
            &Normalisation::ALL,
            Normalisation::id,
            default,
        )
    }
}

/// A refused `lobe`: `error` and the valid forms.
fn bad_lobe(error: String) -> ApiError {
    ApiError::bad(
        "lobe",
        error,
        format!(
            "{}, with parameters as ID:NAME=VALUE (cosquad:v=2), or =FORMULA: a formula of t and n",
            LobeKind::valid_ids()
        ),
    )
}

/// `kind` prepared for `n`, refusing a formula whose values leave `[0, 1]` there or are not
/// finite ([`Lobe::checked`]). Run inside [`compute`]: a long formula's check takes a tenth of
/// a second.
fn checked(kind: LobeKind, n: Exponent) -> Result<Lobe, ApiError> {
    Lobe::checked(kind, n).map_err(|error| match error {
        specula::Error::Formula { message, .. } => bad_lobe(message),
        error => bad_lobe(error.to_string()),
    })
}

/// Runs `work` on the blocking pool once a worker is free, or answers the full queue's 503; a
/// panic inside becomes a 500, never a dropped server.
pub(crate) async fn compute<T: Send + 'static>(
    state: &AppState,
    work: impl FnOnce() -> T + Send + 'static,
) -> Result<T, Response> {
    let _turn = state.computations.turn().await?;
    tokio::task::spawn_blocking(work)
        .await
        .map_err(|e| ApiError::internal(format!("the computation failed: {e}")).into())
}

/// [`compute`] for a request's lobe: `work` is given the lobe once [`checked`] accepts it, in
/// the same turn.
async fn compute_with<T: Send + 'static>(
    state: &AppState,
    kind: LobeKind,
    n: Exponent,
    work: impl FnOnce(Lobe) -> T + Send + 'static,
) -> Result<T, Response> {
    compute(state, move || checked(kind, n).map(work))
        .await?
        .map_err(Response::from)
}

/// Any other path.
pub async fn not_found() -> ApiError {
    ApiError {
        status: StatusCode::NOT_FOUND,
        error: "no such page or endpoint".into(),
        parameter: None,
        valid: Some(
            "/, /api/models, /api/evaluate, /api/analyze, /api/render, /api/volume, /api/environment, /api/materials, /api/fits, /api/material-render, /api/design"
                .into(),
        ),
    }
}

pub async fn models() -> impl IntoResponse {
    let lobes: Vec<_> = LobeKind::ALL
        .iter()
        .map(|kind| {
            let info = kind.info();
            let style = kind.line_style();
            let params: Vec<_> = info
                .params
                .iter()
                .map(|p| {
                    json!({
                        "name": p.name,
                        "description": p.description,
                        "default": p.default,
                        "min": p.min,
                        "max": p.max,
                    })
                })
                .collect();
            json!({
                "id": kind.id(),
                "summary": info.summary,
                "formula": info.formula,
                "colour": style.hex(),
                "dashed": style.dashed,
                "params": params,
            })
        })
        .collect();
    Json(json!({
        "lobes": lobes,
        "geometries": Geometry::ALL.map(Geometry::id),
        "normalisations": Normalisation::ALL.map(Normalisation::id),
        "shadings": Shading::ALL.map(Shading::id),
        "models": IlluminationModel::ALL.map(IlluminationModel::id),
        "objects": Object::ALL.map(Object::id),
        "n": [1.0, 1000.0],
        "max_render_size": MAX_RENDER_SIZE,
        // The built-in volumes, then the real scans whose files are installed.
        "volumes": Choice::available().into_iter().map(Choice::id).collect::<Vec<_>>(),
        "views": View::STANDARD.map(View::id),
        "max_volume_size": MAX_VOLUME_SIZE,
        "max_environment_size": MAX_ENVIRONMENT_SIZE,
        "max_environment_spp": MAX_ENVIRONMENT_SPP,
        // The text box's language and limit (a formula is sent as `lobe==FORMULA`).
        "formula": {
            "max_bytes": MAX_SOURCE_BYTES,
            "functions": specula::formula::FUNCTIONS.map(|(_, signature)| signature),
        },
    }))
}

pub async fn evaluate(
    State(state): State<AppState>,
    query: QueryPairs,
) -> Result<Response, Response> {
    let params = Params::new(
        pairs(query)?,
        &["lobe", "n", "geometry", "normalisation", "theta_in"],
    )?;
    let (kind, n) = (params.lobe()?, params.exponent()?);
    let (geometry, normalisation) = (
        params.geometry()?,
        params.normalisation(Normalisation::Lobe)?,
    );
    let theta_in = params.number("theta_in", 0.0..=89.0, 30.0)?.to_radians();
    let data = compute_with(&state, kind, n, move |_| {
        curves(kind, n, geometry, normalisation, theta_in)
    })
    .await?;
    Ok(Json(data).into_response())
}

pub async fn analyze_lobe(
    State(state): State<AppState>,
    query: QueryPairs,
) -> Result<Response, Response> {
    let params = Params::new(pairs(query)?, &["lobe", "n"])?;
    let (kind, n) = (params.lobe()?, params.exponent()?);
    let costs = state.costs.clone();
    let (report, costs) = compute_with(&state, kind, n, move |lobe| {
        (analyze(kind, n, &mut Precision::F64), costs(&lobe))
    })
    .await?;
    let costs = costs.map_err(ApiError::internal)?;
    let mut body = serde_json::to_value(report).map_err(|e| ApiError::internal(e.to_string()))?;
    body["costs"] = json!(costs);
    Ok(Json(body).into_response())
}

pub async fn render(
    State(state): State<AppState>,
    query: QueryPairs,
) -> Result<Response, Response> {
    let params = Params::new(
        pairs(query)?,
        &[
            "object",
            "lobe",
            "n",
            "geometry",
            "normalisation",
            "shading",
            "model",
            "light_theta",
            "light_phi",
            "size",
        ],
    )?;
    let (kind, n) = (params.lobe()?, params.exponent()?);
    let request = RenderRequest {
        object: params.choice("object", &Object::ALL, Object::id, Object::Sphere)?,
        kind,
        n,
        geometry: params.geometry()?,
        normalisation: params.normalisation(Normalisation::None)?,
        shading: params.choice("shading", &Shading::ALL, Shading::id, Shading::Phong)?,
        model: params.choice(
            "model",
            &IlluminationModel::ALL,
            IlluminationModel::id,
            IlluminationModel::Classic,
        )?,
        light_theta: params.number("light_theta", 0.0..=89.0, 30.0)?.to_radians(),
        light_phi: params
            .number("light_phi", -180.0..=180.0, 45.0)?
            .to_radians(),
        size: params.number("size", 16.0..=f64::from(MAX_RENDER_SIZE), 512.0)? as u32,
    };
    let encoded = compute_with(&state, kind, n, move |_| render_png(&request)).await?;
    Ok(png(encoded.map_err(ApiError::internal)?))
}

pub async fn volume(
    State(state): State<AppState>,
    query: QueryPairs,
) -> Result<Response, Response> {
    let params = Params::new(
        pairs(query)?,
        &[
            "volume",
            "view",
            "lobe",
            "n",
            "geometry",
            "normalisation",
            "size",
        ],
    )?;
    let (kind, n) = (params.lobe()?, params.exponent()?);
    let request = VolumeRequest {
        volume: params.choice(
            "volume",
            &Choice::available(),
            Choice::id,
            Choice::BuiltIn(BuiltIn::SheppLogan),
        )?,
        view: params.choice("view", &View::STANDARD, View::id, View::Anterior)?,
        kind,
        n,
        geometry: params.geometry()?,
        normalisation: params.normalisation(Normalisation::ThesisPhong)?,
        size: params.number("size", 16.0..=f64::from(MAX_VOLUME_SIZE), 256.0)? as u32,
    };
    let encoded = compute_with(&state, kind, n, move |_| volume_png(&request)).await?;
    Ok(png(encoded.map_err(ApiError::internal)?))
}

pub async fn environment(
    State(state): State<AppState>,
    query: QueryPairs,
) -> Result<Response, Response> {
    let params = Params::new(
        pairs(query)?,
        &["lobe", "n", "geometry", "normalisation", "size", "spp"],
    )?;
    let (kind, n) = (params.lobe()?, params.exponent()?);
    let request = EnvironmentRequest {
        kind,
        n,
        geometry: params.geometry()?,
        normalisation: params.normalisation(Normalisation::Lobe)?,
        size: params.number("size", 16.0..=f64::from(MAX_ENVIRONMENT_SIZE), 384.0)? as u32,
        spp: params.number("spp", 1.0..=f64::from(MAX_ENVIRONMENT_SPP), 16.0)? as u32,
    };
    let encoded = compute_with(&state, kind, n, move |_| environment_png(&request)).await?;
    Ok(png(encoded.map_err(ApiError::internal)?))
}

/// The encoded image as a PNG response.
pub(crate) fn png(encoded: Vec<u8>) -> Response {
    (
        [
            (header::CONTENT_TYPE, "image/png"),
            (header::CACHE_CONTROL, "no-store"),
        ],
        encoded,
    )
        .into_response()
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
