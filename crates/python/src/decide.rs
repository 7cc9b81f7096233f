//! The decision and the report: `specula recommend`'s rows, `specula design`'s answer, one
//! lobe's cost on a target, and the report, each one call into `specula-decide` or
//! `specula-report`.

use std::path::PathBuf;
use std::str::FromStr;

use indicatif::ProgressBar;
use pyo3::prelude::*;
use specula::LobeKind;
use specula_decide::design::{default_whole_error, design, Bounds, DesignRequest};
use specula_decide::{
    lobe_rate, parse_exponent_range, parse_exponents, rate_unit, recommend, Request, Target, Zone,
};

use crate::errors::{guarded, value_error};
use crate::lobe::Lobe;
use crate::options::lobe_kind;

fn lobes(texts: &[String]) -> PyResult<Vec<LobeKind>> {
    texts.iter().map(|text| lobe_kind(text)).collect()
}

/// `specula recommend --format json`'s rows (every candidate ranked on `target`) and the
/// note the CLI prints on standard error, if any.
#[pyfunction]
#[pyo3(signature = (target, n, max_error, zone, energy_conserving, extra_lobes, gpu=None))]
#[allow(clippy::too_many_arguments)] // one per keyword of `specula.recommend`
pub fn recommend_json(
    py: Python<'_>,
    target: &str,
    n: &str,
    max_error: f64,
    zone: &str,
    energy_conserving: bool,
    extra_lobes: Vec<String>,
    gpu: Option<&str>,
) -> PyResult<String> {
    guarded(|| {
        let request = Request {
            target: Target::from_str(target).map_err(value_error)?,
            gpu: gpu
                .map(specula::gpus::Gpu::parse)
                .transpose()
                .map_err(value_error)?,
            exponents: parse_exponents(n).map_err(value_error)?,
            max_error,
            zone: Zone::from_str(zone).map_err(value_error)?,
            energy_conserving,
            lobes: specula_decide::candidates(&lobes(&extra_lobes)?),
        };
        let answer = py
            .detach(|| recommend(&request, &ProgressBar::hidden()))
            .map_err(value_error)?;
        let reply = serde_json::json!({
            "note": answer.note,
            "basis": answer.basis,
            "candidates": answer.candidates,
        });
        Ok(reply.to_string())
    })
}

/// `specula design --format json`'s answer (every designed lobe, the built-ins beside them,
/// the verdict), with the cheapest designed lobe's file text as `toml` (or `null`).
#[pyfunction]
#[pyo3(signature = (
    target,
    n,
    max_error,
    max_whole_error,
    energy_tolerance,
    no_transcendentals,
    extra_lobes
))]
#[allow(clippy::too_many_arguments)] // one per keyword of `specula.design`
pub fn design_json(
    py: Python<'_>,
    target: &str,
    n: &str,
    max_error: f64,
    max_whole_error: Option<f64>,
    energy_tolerance: Option<f64>,
    no_transcendentals: bool,
    extra_lobes: Vec<String>,
) -> PyResult<String> {
    guarded(|| {
        let ends = parse_exponent_range(n, 1).map_err(value_error)?;
        let target = Target::from_str(target).map_err(value_error)?;
        let request = DesignRequest {
            target,
            gpu: None,
            range: (ends[0], ends[ends.len() - 1]),
            bounds: Bounds {
                epicentre: max_error,
                whole: max_whole_error.unwrap_or_else(|| default_whole_error(max_error)),
                energy: energy_tolerance,
            },
            no_transcendentals,
            also: lobes(&extra_lobes)?,
            max_operations: specula_decide::design::grammar::default_max_operations(target),
        };
        let answer = py
            .detach(|| design(&request, &ProgressBar::hidden()))
            .map_err(value_error)?;
        let toml = answer
            .best()
            .map(|best| specula_render::lobe_file::lobe_file_text(&best.definition(), &[]));
        let mut reply = serde_json::to_value(&answer).map_err(|e| value_error(e.to_string()))?;
        reply["toml"] = serde_json::json!(toml);
        Ok(reply.to_string())
    })
}

/// One lobe's cost figure on `target` (higher is cheaper) and its unit.
#[pyfunction]
pub fn cost_json(py: Python<'_>, target: &str, lobe: &Lobe) -> PyResult<String> {
    guarded(|| {
        let target = Target::from_str(target).map_err(value_error)?;
        if target == Target::Fpga {
            return Err(value_error(
                "an FPGA cost depends on the accuracy asked for (it sets the datapath's word \
                 length): use recommend(\"fpga\", n, max_error), whose rows name the datapath \
                 and its cost; valid targets here: cpu, gpu-nvidia, gpu-amd",
            ));
        }
        let core = *lobe.core();
        let rate = py
            .detach(|| lobe_rate(target, &core))
            .map_err(value_error)?;
        Ok(serde_json::json!({ "rate": rate, "unit": rate_unit(target) }).to_string())
    })
}

/// Writes the report to `out`; returns the page's path.
#[pyfunction]
#[pyo3(signature = (out, quick, bench, extra_lobes, materials))]
pub fn report(
    py: Python<'_>,
    out: PathBuf,
    quick: bool,
    bench: bool,
    extra_lobes: Vec<String>,
    materials: Option<PathBuf>,
) -> PyResult<String> {
    guarded(|| {
        let options = specula_report::Options {
            out,
            quick,
            bench,
            lobes: lobes(&extra_lobes)?,
            materials,
            synthesize: true,
        };
        let summary = py
            .detach(|| specula_report::write_report_then_synthesize(&options, &|_| {}))
            .map_err(value_error)?;
        Ok(summary.page.display().to_string())
    })
}
