//! The verdict on a material: which lobe to ship.
//!
//! A renderer's material has one `n`, so candidates are the shared-`n` fits. In the classic
//! model the reference is `pow`'s better fit of the two geometries; a lobe *meets* when its
//! fit error is within `margin` of it (`E <= (1 + margin) E_pow`), and the verdict is the
//! meeting lobe with the highest rate on the target, the rate given by the caller (a cost
//! model, a benchmark): the core decides, the face measures. `pow` meets by definition, so
//! wherever the target can run it there is a verdict. In the microfacet model the candidates
//! are the lobes as distributions and the reference is GGX's fit, the distribution engines
//! ship: a lobe meets within `margin` of GGX, and where none does there is no verdict.

use serde::Serialize;

use super::{Fit, Normals, Sharing, Specular};

/// GGX's family in the microfacet model, the reference there.
const GGX_DISTRIBUTION: Specular = Specular::Microfacet {
    normals: Normals::Ggx,
};
use crate::LobeKind;

/// Which model's fits a verdict ranks.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum Model {
    /// `kd / pi + K lobe(t)`, against `pow`'s fit.
    Classic,
    /// `kd / pi + K F D G2 / (4 cos_o cos_i)` with each lobe as `D`, against GGX's fit in
    /// the same model.
    Microfacet,
}

/// One candidate's standing.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Standing {
    /// Its index in the fits given.
    pub fit: usize,
    /// `E / E_pow`: pow's fit in the same geometry and sharing (for GGX, pow's better
    /// geometry with the same sharing; for a distribution, pow's distribution).
    pub relative_to_pow: f64,
    /// `E / E_ggx` (GGX's fit with the same sharing, in the same model: with Fresnel for a
    /// microfacet family).
    pub relative_to_ggx: f64,
    /// The target's rate at the fitted `n` (higher is cheaper); `None` where it cannot run.
    pub rate: Option<f64>,
    /// Within the margin of pow's best fit.
    pub meets: bool,
}

/// The ranking of a material's fits on one target.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Verdict {
    /// The margin allowed over the reference's error, as a fraction.
    pub margin: f64,
    /// The reference's shared-`n` error (pow's best, or GGX's in the microfacet model).
    pub reference_error: f64,
    /// Every fit's standing, in the fits' order.
    pub standings: Vec<Standing>,
    /// The index (in the fits) of the cheapest meeting shared-`n` lobe; where none meets,
    /// the candidate with a rate whose fit is closest to the reference's.
    pub chosen: usize,
    /// Whether the chosen lobe meets (always in the classic model, where pow meets itself).
    pub within_margin: bool,
}

/// The best error among `fits` matching `pick`, or NaN where none does.
fn best_error(fits: &[Fit], pick: impl Fn(&Fit) -> bool) -> f64 {
    fits.iter()
        .filter(|f| pick(f))
        .map(|f| f.error)
        .min_by(f64::total_cmp)
        .unwrap_or(f64::NAN)
}

/// Ranks `fits` (as [`super::fit_all`] returns them, pow among the lobes) with `rates[i]`
/// the rate of `fits[i]` on the target (read for shared-`n` lobes only; `None` where the
/// target cannot run it). `None` when the reference's shared fit is missing or no candidate
/// has a rate.
#[must_use]
pub fn verdict(fits: &[Fit], margin: f64, rates: &[Option<f64>]) -> Option<Verdict> {
    verdict_of(Model::Classic, fits, margin, rates)
}

/// [`verdict`] for `model`'s candidates and reference (see the module page).
#[must_use]
pub fn verdict_of(
    model: Model,
    fits: &[Fit],
    margin: f64,
    rates: &[Option<f64>],
) -> Option<Verdict> {
    let is_pow = |f: &Fit| match model {
        Model::Classic => matches!(
            f.specular,
            Specular::Lobe {
                kind: LobeKind::Pow,
                ..
            }
        ),
        Model::Microfacet => {
            f.specular
                == Specular::Microfacet {
                    normals: Normals::Lobe(LobeKind::Pow),
                }
        }
    };
    let is_candidate = |f: &Fit| match model {
        Model::Classic => matches!(f.specular, Specular::Lobe { .. }),
        Model::Microfacet => matches!(
            f.specular,
            Specular::Microfacet {
                normals: Normals::Lobe(_)
            }
        ),
    };
    let is_reference = |f: &Fit| match model {
        Model::Classic => is_pow(f),
        Model::Microfacet => f.specular == GGX_DISTRIBUTION,
    };
    let reference_error = best_error(fits, |f| is_reference(f) && f.sharing == Sharing::Shared);
    if !reference_error.is_finite() {
        return None;
    }
    let standings: Vec<Standing> = fits
        .iter()
        .enumerate()
        .map(|(index, fit)| {
            // A classic lobe against pow in its geometry; a distribution, GGX and Beckmann
            // against the model's pow.
            let pow = best_error(fits, |f| {
                f.sharing == fit.sharing
                    && match (fit.specular, f.specular) {
                        (
                            Specular::Lobe { geometry: a, .. },
                            Specular::Lobe {
                                kind: LobeKind::Pow,
                                geometry: b,
                            },
                        ) => a == b,
                        (Specular::Lobe { .. }, _) => false,
                        _ => is_pow(f),
                    }
            });
            // GGX in the fit's own model: with Fresnel for the microfacet families.
            let ggx_family = if fit.specular.has_fresnel() {
                GGX_DISTRIBUTION
            } else {
                Specular::Ggx
            };
            let ggx = best_error(fits, |f| {
                f.specular == ggx_family && f.sharing == fit.sharing
            });
            let candidate = fit.sharing == Sharing::Shared && is_candidate(fit);
            let rate = if candidate {
                rates.get(index).copied().flatten()
            } else {
                None
            };
            Standing {
                fit: index,
                relative_to_pow: fit.error / pow,
                relative_to_ggx: fit.error / ggx,
                rate,
                meets: candidate && rate.is_some() && fit.error <= (1.0 + margin) * reference_error,
            }
        })
        .collect();
    // Errors closer than a millionth of each other are one error (the optimiser converges no
    // closer): between them the lobe listed first, in the registry's order, is chosen.
    let more_accurate = |a: &Standing, b: &Standing| {
        let (ea, eb) = (fits[a.fit].error, fits[b.fit].error);
        if (ea - eb).abs() <= 1e-6 * ea.max(eb) {
            b.fit.cmp(&a.fit)
        } else {
            eb.total_cmp(&ea)
        }
    };
    let cheapest_meeting = standings.iter().filter(|s| s.meets).max_by(|a, b| {
        let (ra, rb) = (a.rate.unwrap_or(0.0), b.rate.unwrap_or(0.0));
        ra.total_cmp(&rb).then_with(|| more_accurate(a, b))
    });
    let closest = || {
        standings
            .iter()
            .filter(|s| s.rate.is_some())
            .max_by(|a, b| more_accurate(a, b))
    };
    let within_margin = cheapest_meeting.is_some();
    let chosen = cheapest_meeting.or_else(closest)?.fit;
    Some(Verdict {
        margin,
        reference_error,
        standings,
        chosen,
        within_margin,
    })
}
