//! Measuring a lobe against `t^n`: errors per zone, energy, albedo, reciprocity, cost.
//!
//! [`analyze`] gathers every figure of SPEC section 4 and the white-furnace maximum of
//! section 6 for one lobe at one `n`; the submodules expose each measurement on its own.

pub mod accuracy;
pub mod albedo;
pub mod reciprocity;
pub mod shape;

use glam::DVec3;
use serde::Serialize;

pub use accuracy::{
    error_figures, error_figures_on, ErrorFigures, Evaluator, Precision, ZoneSamples,
    DEFAULT_SAMPLES_PER_ZONE,
};
pub use albedo::{directional_albedo, max_directional_albedo, specular_albedo_per_unit};
pub use reciprocity::max_reciprocity_error;
pub use shape::{shape, Shape};

use crate::normalisation::{lobe_constant, lobe_integral};
use crate::ops::OpCounts;
use crate::{Brdf, Exponent, Geometry, Lobe, LobeKind, Normalisation};

/// Every figure for one lobe at one `n` (the rows of `specula analyze`).
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct LobeReport {
    /// The lobe (id with parameters).
    pub lobe: LobeKind,
    /// The exponent.
    pub n: f64,
    /// The evaluator of the error figures (`f64`, `f32`, `gpu`).
    pub precision: &'static str,
    /// Error figures, flattened into the report.
    #[serde(flatten)]
    pub errors: ErrorFigures,
    /// `int_0^{pi/2} lobe(cos g) sin g dg / (1/(n+1))`: 1 means energy-matched to `t^n`.
    pub energy_ratio: f64,
    /// Whether the energy's integral met its tolerance (a formula whose `f64` values carry
    /// cancellation noise may not, within the quadrature's budget: the figure is then its
    /// estimate).
    pub energy_converged: bool,
    /// The constant that makes this lobe integrate to 1 (`lobe` normalisation, numeric).
    pub lobe_norm_numeric: f64,
    /// `(n+1)/(2 pi)`, the analytic constant of `t^n`, for comparison.
    pub lobe_norm_analytic: f64,
    /// The largest directional albedo of the `lobe`-normalised BRDF, `kd = 0`, `ks = 1`,
    /// Phong geometry (at most 1 for an energy-conserving model).
    pub max_albedo: f64,
    /// The outgoing polar angle (degrees) of that maximum.
    pub max_albedo_theta_deg: f64,
    /// Operations of one evaluation from a cosine.
    pub ops: OpCounts,
}

/// All figures for `kind` at `n`, with the error figures evaluated by `evaluator`.
#[must_use]
pub fn analyze(kind: LobeKind, n: Exponent, evaluator: &mut dyn Evaluator) -> LobeReport {
    let lobe = Lobe::new(kind, n);
    let brdf = Brdf::new(
        DVec3::ZERO,
        DVec3::ONE,
        lobe,
        Geometry::Phong,
        Normalisation::Lobe,
    );
    let (theta, max_albedo) = max_directional_albedo(&brdf);
    let energy = crate::normalisation::lobe_integral_estimate(&lobe);
    LobeReport {
        lobe: kind,
        n: n.get(),
        precision: evaluator.name(),
        errors: error_figures(&lobe, evaluator, DEFAULT_SAMPLES_PER_ZONE),
        energy_ratio: energy.value * (n.get() + 1.0),
        energy_converged: energy.converged,
        lobe_norm_numeric: lobe_constant(&lobe),
        lobe_norm_analytic: Normalisation::Lobe.analytic(n),
        max_albedo,
        max_albedo_theta_deg: theta.to_degrees(),
        ops: lobe.ops(),
    }
}

/// [`analyze`] for every lobe at every exponent (lobes outer, exponents inner), in parallel,
/// with the error figures in `precision` (the rows of `specula analyze`); `on_each` is called
/// as each row is done.
#[must_use]
pub fn analyze_all(
    kinds: &[LobeKind],
    exponents: &[Exponent],
    precision: Precision,
    on_each: &(dyn Fn() + Sync),
) -> Vec<LobeReport> {
    use rayon::prelude::*;
    let jobs: Vec<(LobeKind, Exponent)> = kinds
        .iter()
        .flat_map(|&kind| exponents.iter().map(move |&n| (kind, n)))
        .collect();
    jobs.par_iter()
        .map(|&(kind, n)| {
            let report = analyze(kind, n, &mut { precision });
            on_each();
            report
        })
        .collect()
}

/// The lobe's energy relative to `t^n`: `(n + 1) int_0^{pi/2} lobe(cos g) sin g dg`.
#[must_use]
pub fn energy_ratio(lobe: &Lobe) -> f64 {
    lobe_integral(lobe) * (lobe.exponent().get() + 1.0)
}

/// The exponents `specula analyze` uses by default.
pub const DEFAULT_EXPONENTS: [f64; 11] = [
    1.0, 2.0, 4.0, 8.0, 16.0, 32.0, 64.0, 128.0, 256.0, 512.0, 1000.0,
];
