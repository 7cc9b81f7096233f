//! What a lobe costs on each target the server knows, as the explorer shows it beside the
//! lobe's errors (`/api/analyze`) and beside a measured material's fits (`measured.rs`).

use std::sync::Arc;

use serde::Serialize;
use specula::Lobe;

/// A lobe's rate on one target, as a cost model gives it: higher is better.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct TargetRate {
    /// The target's id (`cpu`, `gpu-nvidia`, ...).
    pub target: String,
    /// The rate (evaluations per instruction, per clock, ...): higher is better.
    pub value: f64,
    /// What it counts.
    pub unit: String,
}

/// A lobe's cost on one target, as the explorer shows it beside its errors: its rate and that
/// rate over pow's at the same `n` (one direction on every target: higher is better).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct TargetCost {
    /// The model's rate.
    #[serde(flatten)]
    pub rate: TargetRate,
    /// The rate over pow's on the same target at the same `n`: pow's throughput times this.
    pub versus_pow: f64,
}

/// The rates of a prepared lobe on every target the server knows. The binary supplies the
/// GPU models (they need the shader compiler, which this crate does not depend on); the
/// default knows the CPU's counted SIMD instructions only.
pub type CostModel = Arc<dyn Fn(&Lobe) -> Result<Vec<TargetRate>, String> + Send + Sync>;

/// The CPU's counted rate: evaluations per instruction of the lobe's SIMD kernel (8 per
/// vector), counted, not timed ("CPU, counted", as the report's cost section names it; the
/// timed rates are "CPU, measured", `specula recommend --target cpu`'s).
#[must_use]
pub fn cpu_cost(lobe: &Lobe) -> TargetRate {
    TargetRate {
        target: "cpu".into(),
        value: 8.0 / f64::from(lobe.batch_instructions().total().max(1)),
        unit: "CPU, counted: evaluations per SIMD instruction (not timed; higher is better)".into(),
    }
}

/// `lobe`'s costs by `model`, each with its rate over pow's at the same `n`.
pub(crate) fn costs_versus_pow(model: &CostModel, lobe: &Lobe) -> Result<Vec<TargetCost>, String> {
    let pow = model(&Lobe::new(specula::LobeKind::Pow, lobe.exponent()))?;
    model(lobe)?
        .into_iter()
        .map(|rate| {
            let reference = pow
                .iter()
                .find(|p| p.target == rate.target)
                .ok_or_else(|| format!("the cost model has no rate for pow on {}", rate.target))?;
            Ok(TargetCost {
                versus_pow: rate.value / reference.value,
                rate,
            })
        })
        .collect()
}
