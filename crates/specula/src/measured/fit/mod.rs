//! Fitting the classic model to a measured material, for every lobe, and GGX beside them.
//!
//! The model is `f(wo, wi) = kd / pi + K lobe(t)` per RGB channel, `t` the lobe's cosine in
//! either geometry and `K = ks N(n)`: because `ks` is free, every normalisation describes
//! the same set of functions, so one fit per lobe and geometry serves them all, and each
//! normalisation's `ks` is `K / N(n)` ([`Fit::ks`]). `n` is one per material
//! ([`Sharing::Shared`], what a renderer's material has) or one per channel. The baseline
//! is GGX: `kd / pi + K D(h) G2(wo, wi) / (4 cos(theta_o) cos(theta_i))`, Trowbridge-Reitz
//! with Smith's height-correlated masking, `alpha` in place of `n` and no Fresnel term (the
//! lobes have none either; `K` plays a constant `F0`).
//!
//! **The microfacet model** ([`microfacet_families`]) puts each lobe where GGX's `D` is: `kd /
//! pi + K D_lobe(h) G2(wo, wi) / (4 cos(theta_o) cos(theta_i))`, with the lobe's own
//! normalisation and masking ([`crate::microfacet`]), `n` its parameter; Beckmann's
//! distribution stands beside GGX. Fitted exactly as the classic model is.
//!
//! **Error**, in the spirit of Ngan, Durand and Matusik (2005): the material and the model
//! are compared as `f cos(theta_i)`, the radiance a unit irradiance reflects, at the
//! [`comparison_pairs`] (half/difference angles, weighted by solid angle, grazing pairs
//! beyond 80 degrees dropped), after a **cube root**, which compresses a highlight's range
//! roughly as lightness does (CIE `L*` goes as `Y^(1/3)`), so that neither the peak alone
//! nor the diffuse floor alone decides the fit:
//! `E = sqrt( sum_j w_j sum_c (cbrt(y_jc cos_j) - cbrt(m_jc cos_j))^2 / 3 )`, weights summing
//! to 1. [`Fit::error`] is that `E`; the per-channel figures split it.
//!
//! **Optimiser.** For a given `n` the best `(kd, K)` of a channel is a two-parameter
//! problem that is linear but for the cube root: it starts from the weighted linear least
//! squares that linearises the root at the data and takes projected Gauss-Newton steps
//! (`kd, K >= 0`). Over `n` the error is not convex (a lobe can fit the sheen or the peak),
//! so `ln n` is first scanned on a grid of [`GRID_POINTS`] over `[1, 1000]`, then refined by
//! Brent's method (the `argmin` crate) between the best grid point's neighbours: a global
//! start, then a local polish. The same procedure fits GGX's `ln alpha` over
//! `[ALPHA_RANGE]`. Everything is deterministic, so a fit is reproducible to the last bit.

mod channel;
mod observations;
pub mod verdict;

use channel::Prepared;

use core::f64::consts::FRAC_1_PI;

use argmin::core::{CostFunction, Executor};
use argmin::solver::brent::BrentOpt;
use glam::DVec3;
use rayon::prelude::*;
use serde::Serialize;

pub use observations::{comparison_pairs, Observations, GRID, MAX_ELEVATION_DEGREES};

use crate::analysis::albedo::specular_albedo_per_unit;
use crate::microfacet::energy::directional_albedo;
use crate::microfacet::Distribution;
use crate::{Exponent, Geometry, Lobe, LobeKind, Normalisation};

/// Points of the global scan over `ln n` (or `ln alpha`).
pub const GRID_POINTS: usize = 24;

/// GGX's `alpha` range searched.
pub const ALPHA_RANGE: [f64; 2] = [0.002, 1.0];

/// The specular term's family.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
#[serde(tag = "family", rename_all = "kebab-case")]
pub enum Specular {
    /// One of specula's lobes in one geometry.
    Lobe {
        /// The lobe.
        #[serde(serialize_with = "serialize_kind")]
        kind: LobeKind,
        /// Phong or Blinn.
        geometry: Geometry,
    },
    /// The GGX microfacet model.
    Ggx,
    /// One of specula's lobes as the normal distribution of a microfacet model,
    /// `D G2 / (4 cos_o cos_i)` ([`crate::microfacet`]), `n` its parameter.
    Microfacet {
        /// The lobe.
        #[serde(serialize_with = "serialize_kind")]
        kind: LobeKind,
    },
    /// Beckmann's distribution in the same microfacet model, `alpha` its parameter.
    Beckmann,
}

fn serialize_kind<S: serde::Serializer>(kind: &LobeKind, s: S) -> Result<S::Ok, S::Error> {
    s.serialize_str(&kind.to_string())
}

impl Specular {
    /// A short name: `pow/phong`, `ggx`.
    #[must_use]
    pub fn label(self) -> String {
        match self {
            Specular::Lobe { kind, geometry } => format!("{kind}/{}", geometry.id()),
            Specular::Ggx => "ggx".into(),
            Specular::Microfacet { kind } => format!("{kind}/microfacet"),
            Specular::Beckmann => "beckmann".into(),
        }
    }

    /// The lobe of a classic or microfacet family (`None` for Beckmann and GGX).
    #[must_use]
    pub fn kind(self) -> Option<LobeKind> {
        match self {
            Specular::Lobe { kind, .. } | Specular::Microfacet { kind } => Some(kind),
            Specular::Ggx | Specular::Beckmann => None,
        }
    }

    /// Whether the shape parameter is a roughness `alpha` (else an exponent `n`).
    #[must_use]
    pub fn takes_alpha(self) -> bool {
        matches!(self, Specular::Ggx | Specular::Beckmann)
    }

    /// The microfacet distribution of this family at `parameter` (`None` for the classic
    /// lobes, which are no distribution of normals).
    #[must_use]
    pub fn distribution(self, parameter: f64) -> Option<Distribution> {
        match self {
            Specular::Lobe { .. } => None,
            Specular::Ggx => Some(Distribution::Ggx { alpha: parameter }),
            Specular::Beckmann => Some(Distribution::Beckmann { alpha: parameter }),
            Specular::Microfacet { kind } => {
                Some(Distribution::lobe(kind, Exponent::clamped(parameter)))
            }
        }
    }

    /// The searched range of the shape parameter's logarithm.
    fn log_range(self) -> [f64; 2] {
        match self {
            Specular::Lobe { .. } | Specular::Microfacet { .. } => {
                [Exponent::MIN.ln(), Exponent::MAX.ln()]
            }
            Specular::Ggx | Specular::Beckmann => ALPHA_RANGE.map(f64::ln),
        }
    }

    /// The specular term per unit `K` at every observation (without the cosine).
    fn values(self, parameter: f64, observations: &Prepared) -> Vec<f64> {
        match self {
            Specular::Lobe { kind, geometry } => {
                let lobe = Lobe::new(kind, Exponent::clamped(parameter));
                let t = match geometry {
                    Geometry::Phong => &observations.t_phong,
                    Geometry::Blinn => &observations.t_blinn,
                };
                t.iter().map(|&t| lobe.eval(t)).collect()
            }
            Specular::Ggx | Specular::Microfacet { .. } | Specular::Beckmann => self
                .distribution(parameter)
                .map_or_else(Vec::new, |distribution| {
                    observations
                        .pairs
                        .iter()
                        .map(|&(wo, wi)| microfacet_specular(&distribution, wo, wi))
                        .collect()
                }),
        }
    }
}

/// A distribution's `D G2 / (4 cos_o cos_i)`, no Fresnel (the fit's `K` plays a constant
/// `F0`).
#[must_use]
pub fn microfacet_specular(distribution: &Distribution, wo: DVec3, wi: DVec3) -> f64 {
    if wo.z <= 0.0 || wi.z <= 0.0 {
        return 0.0;
    }
    let h = (wo + wi).normalize();
    distribution.d(h.z) * distribution.g2(wo.z, wi.z) / (4.0 * wo.z * wi.z)
}

/// One `n` per material, or one per channel.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum Sharing {
    /// One `n` for the three channels.
    Shared,
    /// Each channel its own `n`.
    PerChannel,
}

/// A fitted model.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Fit {
    /// The specular family.
    pub specular: Specular,
    /// How `n` is shared.
    pub sharing: Sharing,
    /// `n` (or GGX's `alpha`) per channel; equal when shared.
    pub parameter: [f64; 3],
    /// Diffuse reflectance per channel.
    pub kd: [f64; 3],
    /// `K = ks N(n)`, the specular scale of the peak-1 lobe, per channel.
    pub k: [f64; 3],
    /// The fit error `E` (see the module page).
    pub error: f64,
    /// Each channel's share, `sqrt(sum_j w_j r_jc^2)`.
    pub channel_error: [f64; 3],
}

impl Fit {
    /// Whether a channel's `n` (or `alpha`) sits at an end of the range searched: the
    /// material would have it further out, and the figure is the range's, not the
    /// material's.
    #[must_use]
    pub fn at_range_end(&self) -> bool {
        let [low, high] = self.specular.log_range();
        self.parameter
            .iter()
            .any(|p| (p.ln() - low).abs() < 1e-6 || (p.ln() - high).abs() < 1e-6)
    }

    /// `ks` per channel under `normalisation` (`K / N(n)`); `None` for GGX.
    #[must_use]
    pub fn ks(&self, normalisation: Normalisation) -> Option<[f64; 3]> {
        let Specular::Lobe { kind, .. } = self.specular else {
            return None;
        };
        Some(core::array::from_fn(|c| {
            let lobe = Lobe::new(kind, Exponent::clamped(self.parameter[c]));
            self.k[c] / normalisation.constant_for(&lobe)
        }))
    }

    /// The fitted model's albedo at normal incidence per channel (`kd` plus the specular
    /// term's hemispherical integral): above 1 the fit creates energy.
    #[must_use]
    pub fn albedo_at_normal(&self) -> [f64; 3] {
        core::array::from_fn(|c| {
            let specular = match self.specular {
                Specular::Lobe { kind, geometry } => {
                    let lobe = Lobe::new(kind, Exponent::clamped(self.parameter[c]));
                    specular_albedo_per_unit(&lobe, geometry, 0.0)
                }
                Specular::Ggx | Specular::Microfacet { .. } | Specular::Beckmann => self
                    .specular
                    .distribution(self.parameter[c])
                    .map_or(0.0, |d| directional_albedo(&d, 1.0)),
            };
            self.kd[c] + self.k[c] * specular
        })
    }

    /// The fitted model prepared for evaluation: each channel's lobe made once, so that
    /// evaluating it (per pixel, per plotted point) prepares nothing.
    #[must_use]
    pub fn prepare(&self) -> FittedModel {
        FittedModel {
            kd: DVec3::from_array(self.kd),
            k: DVec3::from_array(self.k),
            shape: match self.specular {
                Specular::Lobe { kind, geometry } => FittedShape::Lobe {
                    lobes: Box::new(
                        self.parameter
                            .map(|n| Lobe::new(kind, Exponent::clamped(n))),
                    ),
                    geometry,
                },
                Specular::Ggx | Specular::Microfacet { .. } | Specular::Beckmann => {
                    FittedShape::Microfacet(Box::new(self.parameter.map(|p| {
                        self.specular
                            .distribution(p)
                            .unwrap_or(Distribution::Ggx { alpha: p })
                    })))
                }
            },
        }
    }
}

/// A [`Fit`] ready to evaluate: `f = kd / pi + K spec(wo, wi)` per channel.
#[derive(Clone, Debug)]
pub struct FittedModel {
    kd: DVec3,
    k: DVec3,
    shape: FittedShape,
}

/// The specular term's prepared form, per channel.
#[derive(Clone, Debug)]
enum FittedShape {
    Lobe {
        lobes: Box<[Lobe; 3]>,
        geometry: Geometry,
    },
    /// A distribution per channel (GGX's, Beckmann's, a lobe's).
    Microfacet(Box<[Distribution; 3]>),
}

impl FittedModel {
    /// The specular term per unit `K`, per channel (without the cosine).
    #[must_use]
    pub fn specular(&self, wo: DVec3, wi: DVec3) -> DVec3 {
        match &self.shape {
            FittedShape::Lobe { lobes, geometry } => {
                let t = geometry.cos_lobe_local(wo, wi);
                DVec3::new(lobes[0].eval(t), lobes[1].eval(t), lobes[2].eval(t))
            }
            FittedShape::Microfacet(distributions) => DVec3::new(
                microfacet_specular(&distributions[0], wo, wi),
                microfacet_specular(&distributions[1], wo, wi),
                microfacet_specular(&distributions[2], wo, wi),
            ),
        }
    }

    /// `f(wo, wi)` per channel; zero when either direction is at or below the horizon.
    #[must_use]
    pub fn f(&self, wo: DVec3, wi: DVec3) -> DVec3 {
        if wo.z <= 0.0 || wi.z <= 0.0 {
            return DVec3::ZERO;
        }
        self.kd * FRAC_1_PI + self.k * self.specular(wo, wi)
    }

    /// `f(wo, wi) cos(theta_i)`.
    #[must_use]
    pub fn f_cos(&self, wo: DVec3, wi: DVec3) -> DVec3 {
        self.f(wo, wi) * wi.z.max(0.0)
    }
}

/// One shape parameter's profile: its best error over `(kd, K)` for some channels.
struct Profile<'p, 'a> {
    prepared: &'p Prepared<'a>,
    specular: Specular,
    channels: &'p [usize],
}

impl Profile<'_, '_> {
    fn solve(&self, log_parameter: f64) -> (Vec<([f64; 2], f64)>, f64) {
        let values = self.specular.values(log_parameter.exp(), self.prepared);
        let solutions: Vec<([f64; 2], f64)> = self
            .channels
            .iter()
            .map(|&c| self.prepared.solve_channel(c, &values))
            .collect();
        let total = solutions.iter().map(|s| s.1).sum();
        (solutions, total)
    }
}

impl CostFunction for Profile<'_, '_> {
    type Param = f64;
    type Output = f64;

    fn cost(&self, log_parameter: &f64) -> Result<f64, argmin::core::Error> {
        Ok(self.solve(*log_parameter).1)
    }
}

/// The scan of one family over the grid of log-parameters: per point, each channel's best
/// cost (the shared fit sums them, a per-channel fit takes its own).
fn scan(prepared: &Prepared, specular: Specular) -> (Vec<f64>, Vec<[f64; 3]>) {
    let [low, high] = specular.log_range();
    let grid: Vec<f64> = (0..GRID_POINTS)
        .map(|i| low + (high - low) * i as f64 / (GRID_POINTS - 1) as f64)
        .collect();
    let costs = grid
        .iter()
        .map(|&p| {
            let values = specular.values(p.exp(), prepared);
            core::array::from_fn(|c| prepared.solve_channel(c, &values).1)
        })
        .collect();
    (grid, costs)
}

/// The best log-parameter of `profile`: the scan's best point for its channels, then Brent
/// between that point's neighbours.
fn minimise(profile: &Profile, grid: &[f64], costs: &[[f64; 3]]) -> f64 {
    let total = |i: usize| profile.channels.iter().map(|&c| costs[i][c]).sum::<f64>();
    let best = (0..grid.len())
        .min_by(|&a, &b| total(a).total_cmp(&total(b)))
        .unwrap_or(0);
    let (a, b) = (
        grid[best.saturating_sub(1)],
        grid[(best + 1).min(grid.len() - 1)],
    );
    let polished = Executor::new(
        Profile { ..*profile },
        BrentOpt::new(a, b).set_tolerance(1e-8, 1e-5),
    )
    .configure(|state| state.max_iters(60))
    .run()
    .ok()
    .and_then(|result| {
        let state = result.state();
        state.best_param.map(|p| (p, state.best_cost))
    });
    match polished {
        Some((p, cost)) if cost <= total(best) => p,
        _ => grid[best],
    }
}

/// Fits `specular` to the observations with `n` shared or per channel.
#[must_use]
pub fn fit(observations: &Observations, specular: Specular, sharing: Sharing) -> Fit {
    let [shared, per_channel] = fit_family(&Prepared::new(observations), specular);
    match sharing {
        Sharing::Shared => shared,
        Sharing::PerChannel => per_channel,
    }
}

/// Both fits of one family, from one scan.
fn fit_family(prepared: &Prepared, specular: Specular) -> [Fit; 2] {
    let (grid, costs) = scan(prepared, specular);
    let fit = |sharing, parameter: [f64; 3], solutions: [([f64; 2], f64); 3]| {
        let channel_error = solutions.map(|(_, cost)| cost.sqrt());
        Fit {
            specular,
            sharing,
            parameter: parameter.map(f64::exp),
            kd: solutions.map(|([kd, _], _)| kd),
            k: solutions.map(|([_, k], _)| k),
            error: (channel_error.iter().map(|e| e * e).sum::<f64>() / 3.0).sqrt(),
            channel_error,
        }
    };
    let profile = |channels| Profile {
        prepared,
        specular,
        channels,
    };
    let all = profile(&[0, 1, 2]);
    let shared = minimise(&all, &grid, &costs);
    let at_shared = all.solve(shared).0;
    let shared_solutions = [at_shared[0], at_shared[1], at_shared[2]];
    // Each channel from its own scan, or from the shared optimum where that is better (a
    // second start: a channel's scan can bracket another basin than the sum's).
    let mut parameter = [shared; 3];
    let mut solutions = shared_solutions;
    for (c, channel) in [[0], [1], [2]].iter().enumerate() {
        let own = profile(channel);
        let best = minimise(&own, &grid, &costs);
        let (solved, cost) = own.solve(best);
        if cost < solutions[c].1 {
            (parameter[c], solutions[c]) = (best, solved[0]);
        }
    }
    [
        fit(Sharing::Shared, [shared; 3], shared_solutions),
        fit(Sharing::PerChannel, parameter, solutions),
    ]
}

/// The plane of incidence seen from elevation `theta_o` (radians): `count` light directions
/// at signed elevations evenly spaced over `(-90, 90)` degrees, as `(elevation, wo, wi)`,
/// with `wo = (sin theta_o, 0, cos theta_o)`, so the mirror direction is at `-theta_o`. The
/// polar plots of a material against its fits are drawn along it.
#[must_use]
pub fn plane_of_incidence(theta_o: f64, count: usize) -> Vec<(f64, DVec3, DVec3)> {
    let wo = DVec3::new(theta_o.sin(), 0.0, theta_o.cos());
    (0..count)
        .map(|i| {
            let elevation = core::f64::consts::PI * ((i as f64 + 0.5) / count as f64 - 0.5);
            (
                elevation,
                wo,
                DVec3::new(elevation.sin(), 0.0, elevation.cos()),
            )
        })
        .collect()
}

/// The viewing elevations of the polar plots, degrees.
pub const POLAR_ANGLES_DEGREES: [f64; 3] = [0.0, 30.0, 60.0];

/// The families [`fit_all`] fits, in its order: each of `kinds` in Phong then Blinn, then
/// GGX.
#[must_use]
pub fn families(kinds: &[LobeKind]) -> Vec<Specular> {
    kinds
        .iter()
        .flat_map(|&kind| Geometry::ALL.map(|geometry| Specular::Lobe { kind, geometry }))
        .chain([Specular::Ggx])
        .collect()
}

/// The families of the microfacet model: each of `kinds` as a normal distribution, then
/// Beckmann's and GGX's.
#[must_use]
pub fn microfacet_families(kinds: &[LobeKind]) -> Vec<Specular> {
    kinds
        .iter()
        .map(|&kind| Specular::Microfacet { kind })
        .chain([Specular::Beckmann, Specular::Ggx])
        .collect()
}

/// Every family in `kinds` in both geometries, and GGX, each shared and per channel, fitted
/// in parallel; in that order (lobes in `kinds`' order, Phong before Blinn, shared first).
#[must_use]
pub fn fit_all(observations: &Observations, kinds: &[LobeKind]) -> Vec<Fit> {
    fit_families(observations, &families(kinds))
}

/// Each of `families`, shared and per channel, fitted in parallel, in that order.
#[must_use]
pub fn fit_families(observations: &Observations, families: &[Specular]) -> Vec<Fit> {
    let prepared = Prepared::new(observations);
    families
        .par_iter()
        .flat_map_iter(|&specular| fit_family(&prepared, specular))
        .collect()
}
