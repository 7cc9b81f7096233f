//! What `/api/design` (`api.rs`) asks for: a lobe designed for a GPU family, a range of `n`
//! and an epicentre bound (`specula design`'s answer as JSON). The search lives in
//! `specula-decide`, above this crate, so the server is handed it ([`DesignModel`]) by the
//! command that starts it; a server without one says so.

use std::sync::Arc;

use crate::query::{ApiError, Params};

/// What a design request asks for.
#[derive(Clone, Debug, PartialEq)]
pub struct DesignQuery {
    /// `gpu-nvidia`, `gpu-amd` or `gpu-intel`.
    pub target: String,
    /// The range of `n`, its ends.
    pub range: (f64, f64),
    /// The epicentre's largest relative error, as a fraction.
    pub max_error: f64,
}

/// The search: `specula design --format json`'s answer for a query, or a one-line refusal.
pub type DesignModel = Arc<dyn Fn(&DesignQuery) -> Result<serde_json::Value, String> + Send + Sync>;

/// The targets the explorer designs for: the GPUs, costed from their compilers' code (the
/// CPU's costs are timed, tens of seconds a design, so `specula design --target cpu` is for a
/// quiet machine).
pub const DESIGN_TARGETS: [&str; 3] = ["gpu-nvidia", "gpu-amd", "gpu-intel"];

/// The request's design query, refused with the parameter at fault.
pub(crate) fn query(params: &Params) -> Result<DesignQuery, ApiError> {
    let target = params.text("target").unwrap_or(DESIGN_TARGETS[0]);
    if !DESIGN_TARGETS.contains(&target) {
        return Err(ApiError::bad(
            "target",
            format!(
                "the explorer cannot design for `{}`",
                specula::excerpt(target)
            ),
            format!(
                "{} (for cpu, run specula design --target cpu: its costs are timed)",
                DESIGN_TARGETS.join(", ")
            ),
        ));
    }
    let low = params.number("low", 1.0..=1000.0, 8.0)?;
    let high = params.number("high", 1.0..=1000.0, 512.0)?;
    if low > high {
        return Err(ApiError::bad(
            "high",
            format!("the range of n is empty ({low} to {high})"),
            format!("a number in [{low}, 1000]"),
        ));
    }
    let percent = params.number("max_error", 1e-6..=100.0, 0.1)?;
    Ok(DesignQuery {
        target: target.to_owned(),
        range: (low, high),
        max_error: percent / 100.0,
    })
}
