//! The analysis: zones, every figure of `specula analyze`, the thesis's claims. Rows go back
//! as the CLI's JSON, which `specula/__init__.py` parses.

use pyo3::prelude::*;
use specula::analysis::{analyze_all, Precision, DEFAULT_EXPONENTS};
use specula::claims::{claim_exponents, ClaimOptions};
use specula::zones::{bloom_angle, bloom_cos, epicentre_angle, epicentre_cos};
use specula::{Exponent, LobeKind};

use crate::arrays::{self, count};
use crate::errors::{guarded, value_error};
use crate::options::{exponent, lobe_kind};

/// `value` as JSON text.
pub fn json(value: &impl serde::Serialize) -> PyResult<String> {
    serde_json::to_string(value).map_err(|e| value_error(e.to_string()))
}

/// The zones of ``t^n`` (SPEC section 3): where the epicentre (``t^n >= 1/2``) and the bloom
/// (``t^n >= 1/256``) end, as cosines and angles (radians).
#[pyfunction]
pub fn zones_json(n: f64) -> PyResult<String> {
    guarded(|| {
        let n = exponent(n)?;
        json(&serde_json::json!({
            "n": n.get(),
            "epicentre_cos": epicentre_cos(n),
            "bloom_cos": bloom_cos(n),
            "epicentre_angle": epicentre_angle(n),
            "bloom_angle": bloom_angle(n),
        }))
    })
}

/// Every figure of ``specula analyze`` for lobes x exponents (its defaults where ``None``),
/// as its JSON rows.
#[pyfunction]
#[pyo3(signature = (lobes = None, exponents = None, precision = "f64"))]
pub fn analyze_json(
    py: Python<'_>,
    lobes: Option<Vec<String>>,
    exponents: Option<Vec<f64>>,
    precision: &str,
) -> PyResult<String> {
    guarded(|| {
        let precision = Precision::parse(precision).map_err(value_error)?;
        let kinds = match lobes {
            None => LobeKind::ALL.to_vec(),
            Some(texts) => texts
                .iter()
                .map(|text| lobe_kind(text))
                .collect::<PyResult<Vec<LobeKind>>>()?,
        };
        let exponents: Vec<Exponent> = match exponents {
            None => DEFAULT_EXPONENTS
                .iter()
                .map(|&n| Exponent::new(n))
                .collect(),
            Some(values) => values.into_iter().map(exponent).collect::<PyResult<_>>()?,
        };
        specula_decide::check_lobes(&kinds, &exponents).map_err(value_error)?;
        json(&py.detach(|| analyze_all(&kinds, &exponents, precision, &|| {})))
    })
}

/// The thesis's accuracy and energy claims with their verdicts, as ``specula claims
/// --format json`` (without the hardware claim, which synthesizes); each option the CLI's
/// default where ``None``.
#[pyfunction]
#[pyo3(signature = (
    exponent_steps = None,
    samples_per_zone = None,
    reciprocity_pairs = None,
    seed = None
))]
pub fn claims_json(
    py: Python<'_>,
    exponent_steps: Option<i64>,
    samples_per_zone: Option<i64>,
    reciprocity_pairs: Option<i64>,
    seed: Option<i64>,
) -> PyResult<String> {
    guarded(|| {
        let defaults = ClaimOptions::default();
        let options = ClaimOptions {
            exponents: match exponent_steps {
                None => defaults.exponents,
                Some(steps) => claim_exponents(count("exponent_steps", steps, 1, 200)?),
            },
            samples_per_zone: samples_per_zone.map_or(Ok(defaults.samples_per_zone), |s| {
                count("samples_per_zone", s, 2, 1_000_001)
            })?,
            reciprocity_pairs: reciprocity_pairs.map_or(Ok(defaults.reciprocity_pairs), |p| {
                count("reciprocity_pairs", p, 1, 10_000_000)
            })?,
            seed: seed.map_or(Ok(defaults.seed), arrays::seed)?,
        };
        json(&py.detach(|| specula_decide::analyses::claims(&options)))
    })
}
