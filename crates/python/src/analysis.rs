//! The analysis: zones, every figure of `specula analyze`, the thesis's claims. Rows go back
//! as the CLI's JSON, which `specula/__init__.py` parses.

use pyo3::prelude::*;
use rayon::prelude::*;
use specula::analysis::{analyze, LobeReport, Precision};
use specula::claims::{claim_exponents, evaluate_all, ClaimOptions};
use specula::zones::{bloom_angle, bloom_cos, epicentre_angle, epicentre_cos};
use specula::LobeKind;

use crate::errors::{guarded, value_error};
use crate::lobe::exponent;

fn json(value: &impl serde::Serialize) -> PyResult<String> {
    serde_json::to_string(value).map_err(|e| value_error(e.to_string()))
}

/// The zones of ``t^n`` (SPEC section 3): where the epicentre (``t^n >= 1/2``) and the bloom
/// (``t^n >= 1/256``) end, as cosines and angles (radians).
#[pyfunction]
pub fn zones_json(n: f64) -> PyResult<String> {
    let n = exponent(n)?;
    json(&serde_json::json!({
        "n": n.get(),
        "epicentre_cos": epicentre_cos(n),
        "bloom_cos": bloom_cos(n),
        "epicentre_angle": epicentre_angle(n),
        "bloom_angle": bloom_angle(n),
    }))
}

/// Every figure of ``specula analyze`` for lobes x exponents, as its JSON rows.
#[pyfunction]
#[pyo3(signature = (lobes, exponents, precision = "f64"))]
pub fn analyze_json(
    py: Python<'_>,
    lobes: Vec<String>,
    exponents: Vec<f64>,
    precision: &str,
) -> PyResult<String> {
    let precision = match precision {
        "f64" => Precision::F64,
        "f32" => Precision::F32,
        "simd" => Precision::F32Simd,
        other => {
            return Err(value_error(format!(
                "unknown precision '{other}'; valid precisions: f64, f32, simd"
            )))
        }
    };
    let kinds = lobes
        .iter()
        .map(|text| {
            let lobe = specula_render::lobe_file::parse_lobe(text, None).map_err(value_error)?;
            Ok(lobe)
        })
        .collect::<PyResult<Vec<LobeKind>>>()?;
    let exponents = exponents
        .into_iter()
        .map(exponent)
        .collect::<PyResult<Vec<_>>>()?;
    for &kind in &kinds {
        for &n in &exponents {
            specula::Lobe::checked(kind, n).map_err(|e| value_error(e.to_string()))?;
        }
    }
    let jobs: Vec<_> = kinds
        .iter()
        .flat_map(|&kind| exponents.iter().map(move |&n| (kind, n)))
        .collect();
    guarded(|| {
        let reports: Vec<LobeReport> = py.detach(|| {
            jobs.par_iter()
                .map(|&(kind, n)| analyze(kind, n, &mut { precision }))
                .collect()
        });
        json(&reports)
    })
}

/// The thesis's accuracy and energy claims with their verdicts, as ``specula claims
/// --format json`` (without the hardware claim, which synthesizes).
#[pyfunction]
#[pyo3(signature = (exponent_steps = 48, samples_per_zone = 100_001, reciprocity_pairs = 100_000, seed = 0x5eed_5bec))]
pub fn claims_json(
    py: Python<'_>,
    exponent_steps: usize,
    samples_per_zone: usize,
    reciprocity_pairs: usize,
    seed: u64,
) -> PyResult<String> {
    if !(1..=1000).contains(&exponent_steps)
        || !(2..=10_000_000).contains(&samples_per_zone)
        || !(1..=100_000_000).contains(&reciprocity_pairs)
    {
        return Err(value_error(format!(
            "claims: exponent_steps {exponent_steps} (1 to 1000), samples_per_zone \
             {samples_per_zone} (2 to 10000000) or reciprocity_pairs {reciprocity_pairs} \
             (1 to 100000000) is out of range"
        )));
    }
    let options = ClaimOptions {
        exponents: claim_exponents(exponent_steps),
        samples_per_zone,
        reciprocity_pairs,
        seed,
    };
    guarded(|| json(&py.detach(|| evaluate_all(&options))))
}
