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
//! **The microfacet model** ([`microfacet_families`]) puts each lobe where GGX's `D` is,
//! with Schlick's Fresnel: `kd / pi + K F(wo.h) D_lobe(h) G2(wo, wi) / (4 cos(theta_o)
//! cos(theta_i))`, `F = F0 + (1 - F0) (1 - wo.h)^5`, with the lobe's own normalisation and
//! masking ([`crate::microfacet`]), `n` its parameter; Beckmann's and GGX's distributions
//! stand beside them, in the same model. `K F` is linear in `K F0` and `K (1 - F0)`, so the
//! Fresnel term adds a third linear coefficient, not a search dimension ([`Fit::f0`]).
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
//! **Optimiser.** For a given `n` the best `(kd, K)` of a channel (with Fresnel, `(kd, K F0,
//! K (1 - F0))`) is a problem that is linear but for the cube root: it starts from the
//! weighted linear least squares that linearises the root at the data and takes projected
//! Gauss-Newton steps (every coefficient `>= 0`, so `F0` lies in `[0, 1]`). Over `n` the
//! error is not convex (a lobe can fit the sheen or the peak), so `ln n` is first scanned on a
//! grid of [`GRID_POINTS`] over `[1, 1000]`, then refined by
//! Brent's method (the `argmin` crate) between the best grid point's neighbours: a global
//! start, then a local polish. The same procedure fits GGX's `ln alpha` over
//! `[ALPHA_RANGE]`. Everything is deterministic, so a fit is reproducible to the last bit.

mod channel;
mod observations;
mod search;
mod sums;
pub mod verdict;

use channel::Prepared;
pub use search::fit;
use search::fit_family;

use core::f64::consts::FRAC_1_PI;

use glam::DVec3;
use rayon::prelude::*;
use serde::Serialize;

pub use observations::{comparison_pairs, Observations, GRID, MAX_ELEVATION_DEGREES};

use crate::analysis::albedo::specular_albedo_per_unit;
use crate::microfacet::energy::directional_albedo_with_fresnel;
use crate::microfacet::{fresnel_schlick, Distribution};
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
    /// GGX in the classic model's comparison: `D G2 / (4 cos_o cos_i)` without Fresnel, `K`
    /// a constant `F0`, as the lobes have no Fresnel term either.
    Ggx,
    /// The microfacet model, `D G2 F / (4 cos_o cos_i)` with Schlick's Fresnel, its `F0`
    /// fitted ([`crate::microfacet`]).
    Microfacet {
        /// The distribution of normals.
        normals: Normals,
    },
}

/// The normal distribution of a [`Specular::Microfacet`] family.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Normals {
    /// One of specula's lobes, `n` its parameter.
    Lobe(LobeKind),
    /// Beckmann's, `alpha` its parameter.
    Beckmann,
    /// GGX's (Trowbridge and Reitz's), `alpha` its parameter.
    Ggx,
}

impl Normals {
    /// The lobe's id, `beckmann` or `ggx`.
    #[must_use]
    pub fn id(self) -> String {
        match self {
            Normals::Lobe(kind) => kind.to_string(),
            Normals::Beckmann => "beckmann".into(),
            Normals::Ggx => "ggx".into(),
        }
    }
}

impl Serialize for Normals {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        s.serialize_str(&self.id())
    }
}

fn serialize_kind<S: serde::Serializer>(kind: &LobeKind, s: S) -> Result<S::Ok, S::Error> {
    s.serialize_str(&kind.to_string())
}

impl Specular {
    /// A short name: `pow/phong`, `ggx`, `pow/microfacet`, `ggx/microfacet`.
    #[must_use]
    pub fn label(self) -> String {
        match self {
            Specular::Lobe { kind, geometry } => format!("{kind}/{}", geometry.id()),
            Specular::Ggx => "ggx".into(),
            Specular::Microfacet { normals } => format!("{}/microfacet", normals.id()),
        }
    }

    /// The lobe of a classic family or a lobe's distribution (`None` for Beckmann and GGX).
    #[must_use]
    pub fn kind(self) -> Option<LobeKind> {
        match self {
            Specular::Lobe { kind, .. }
            | Specular::Microfacet {
                normals: Normals::Lobe(kind),
            } => Some(kind),
            Specular::Ggx | Specular::Microfacet { .. } => None,
        }
    }

    /// Whether the shape parameter is a roughness `alpha` (else an exponent `n`).
    #[must_use]
    pub fn takes_alpha(self) -> bool {
        matches!(
            self,
            Specular::Ggx
                | Specular::Microfacet {
                    normals: Normals::Beckmann | Normals::Ggx
                }
        )
    }

    /// Whether the family has Schlick's Fresnel term with a fitted `F0`.
    #[must_use]
    pub fn has_fresnel(self) -> bool {
        matches!(self, Specular::Microfacet { .. })
    }

    /// This family's specular shape at `parameter`: a lobe in its geometry, or a
    /// distribution of normals.
    #[must_use]
    pub fn shape(self, parameter: f64) -> Shape {
        self.shape_for(parameter, Stage::Answer)
    }

    /// [`Specular::shape`], its lobe distributions' tables made as `stage` needs them.
    fn shape_for(self, parameter: f64, stage: Stage) -> Shape {
        let exponent = Exponent::clamped(parameter);
        match self {
            Specular::Lobe { kind, geometry } => Shape::Lobe {
                lobe: Lobe::new(kind, exponent),
                geometry,
            },
            Specular::Ggx
            | Specular::Microfacet {
                normals: Normals::Ggx,
            } => Shape::Microfacet(Distribution::Ggx { alpha: parameter }),
            Specular::Microfacet {
                normals: Normals::Beckmann,
            } => Shape::Microfacet(Distribution::Beckmann { alpha: parameter }),
            Specular::Microfacet {
                normals: Normals::Lobe(kind),
            } => Shape::Microfacet(Distribution::lobe_within(kind, exponent, stage.tolerance())),
        }
    }

    /// The searched range of the shape parameter's logarithm.
    fn log_range(self) -> [f64; 2] {
        if self.takes_alpha() {
            ALPHA_RANGE.map(f64::ln)
        } else {
            [Exponent::MIN.ln(), Exponent::MAX.ln()]
        }
    }

    /// The specular term's columns per unit coefficient at every observation (without the
    /// cosine): the lobe, or `D G2 / (4 cos_o cos_i)`; with Fresnel, that term and the same
    /// times Schlick's `(1 - wo.h)^5`, the model being `K F0 M + K (1 - F0) M S`.
    fn columns(self, parameter: f64, observations: &Prepared, stage: Stage) -> Vec<Vec<f64>> {
        let distribution = match self.shape_for(parameter, stage) {
            Shape::Lobe { lobe, geometry } => {
                let t = match geometry {
                    Geometry::Phong => &observations.t_phong,
                    Geometry::Blinn => &observations.t_blinn,
                };
                return vec![t.iter().map(|&t| lobe.eval(t)).collect()];
            }
            Shape::Microfacet(distribution) => distribution,
        };
        // microfacet_specular's terms, each pair's part of them made once (`Prepared`).
        let term: Vec<f64> = observations
            .microfacet
            .iter()
            .map(|pair| {
                if pair.above {
                    distribution.d(pair.cos_h) * distribution.g2_at(&pair.wo, &pair.wi)
                        / pair.four_cosines
                } else {
                    0.0
                }
            })
            .collect();
        if !self.has_fresnel() {
            return vec![term];
        }
        let schlick = observations
            .microfacet
            .iter()
            .zip(&term)
            .map(|(pair, m)| m * pair.schlick)
            .collect();
        vec![term, schlick]
    }
}

/// What a fit evaluates a family for: comparing parameters in its search, or the answer at
/// the parameter found.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Stage {
    /// The lobe distributions' `Lambda` tables to `1e-6`, where [`Distribution::lobe`]'s
    /// are to `1e-8`: near one another the profile over `ln n` is the same to about `1e-7`
    /// of the error (every bundled material's fits agree with the exact tables' to 4e-7), and
    /// the tables, 45 % of a microfacet fit's time, take a third less.
    Search,
    /// The exact tables: the reported error and coefficients are the answer's own.
    Answer,
}

/// The search's `Lambda` tables' tolerance ([`Stage::Search`]).
const SEARCH_TOLERANCE: f64 = 1e-6;

impl Stage {
    fn tolerance(self) -> f64 {
        match self {
            Stage::Search => SEARCH_TOLERANCE,
            Stage::Answer => crate::microfacet::tabulated::TOLERANCE,
        }
    }
}

/// A family's specular shape at one parameter.
#[derive(Clone, Debug)]
pub enum Shape {
    /// A lobe of the cosine `t` in a geometry.
    Lobe {
        /// The lobe at its `n`.
        lobe: Lobe,
        /// Phong or Blinn.
        geometry: Geometry,
    },
    /// A distribution of normals in the microfacet model.
    Microfacet(Distribution),
}

/// A distribution's `D G2 / (4 cos_o cos_i)`, without Fresnel.
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
    /// `K = ks N(n)`, the specular scale of the peak-1 lobe, per channel (a microfacet
    /// family's `ks`, its Fresnel factor's scale).
    pub k: [f64; 3],
    /// Schlick's `F0` per channel, in the microfacet model (`None` in the classic one).
    pub f0: Option<[f64; 3]>,
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
            let specular = match self.specular.shape(self.parameter[c]) {
                Shape::Lobe { lobe, geometry } => specular_albedo_per_unit(&lobe, geometry, 0.0),
                Shape::Microfacet(d) => {
                    directional_albedo_with_fresnel(&d, 1.0, self.f0.map_or(1.0, |f0| f0[c]))
                }
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
            f0: self.f0.map(DVec3::from_array),
            shapes: Box::new(self.shapes()),
        }
    }

    /// Each channel's shape; channels sharing a parameter share one (a lobe's distribution
    /// builds its tables once, not per channel).
    fn shapes(&self) -> [Shape; 3] {
        let first = self.specular.shape(self.parameter[0]);
        self.parameter.map(|p| {
            if p == self.parameter[0] {
                first.clone()
            } else {
                self.specular.shape(p)
            }
        })
    }
}

/// A [`Fit`] ready to evaluate: `f = kd / pi + K spec(wo, wi)` per channel, the specular
/// term times Schlick's Fresnel where the fit has an `F0`.
#[derive(Clone, Debug)]
pub struct FittedModel {
    kd: DVec3,
    k: DVec3,
    f0: Option<DVec3>,
    /// Each channel's shape.
    shapes: Box<[Shape; 3]>,
}

impl FittedModel {
    /// The first channel's specular shape (what a renderer draws its directions from).
    #[must_use]
    pub fn first_shape(&self) -> &Shape {
        &self.shapes[0]
    }

    /// The specular term per unit `K`, per channel (without the cosine), Fresnel included.
    #[must_use]
    pub fn specular(&self, wo: DVec3, wi: DVec3) -> DVec3 {
        let fresnel = self.f0.map_or(DVec3::ONE, |f0| {
            let cos = wo.dot((wo + wi).normalize());
            f0.to_array().map(|f0| fresnel_schlick(f0, cos)).into()
        });
        let value = |shape: &Shape| match shape {
            Shape::Lobe { lobe, geometry } => lobe.eval(geometry.cos_lobe_local(wo, wi)),
            Shape::Microfacet(distribution) => microfacet_specular(distribution, wo, wi),
        };
        fresnel * DVec3::from_array(self.shapes.each_ref().map(value))
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
        .map(|&kind| Normals::Lobe(kind))
        .chain([Normals::Beckmann, Normals::Ggx])
        .map(|normals| Specular::Microfacet { normals })
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
    fit_families_counted(observations, families).0
}

/// [`fit_families`] and the observation evaluations it made: every pass of the solver over
/// the observations counts them all, which the benches divide by the time taken and hold
/// against [`evaluation_peak`].
#[must_use]
pub fn fit_families_counted(observations: &Observations, families: &[Specular]) -> (Vec<Fit>, u64) {
    let prepared = Prepared::new(observations);
    let fits = families
        .par_iter()
        .flat_map_iter(|&specular| fit_family(&prepared, specular))
        .collect();
    (fits, prepared.evaluations.into_inner())
}

/// The observation evaluations per second one thread reaches in the solver's two passes
/// when it does nothing else (the cost with its cube roots, then the Gauss-Newton sums, over
/// every observation at `pow`'s Phong rows for `n = 64`), for about `seconds`: the most a fit
/// could make of this machine's vector units, against which its own rate is read.
#[must_use]
pub fn evaluation_peak(observations: &Observations, seconds: f64) -> f64 {
    let prepared = Prepared::new(observations);
    let specular = Specular::Lobe {
        kind: LobeKind::Pow,
        geometry: Geometry::Phong,
    };
    let rows = prepared.rows(&specular.columns(64.0, &prepared, Stage::Answer));
    let mut roots = vec![0.0; observations.weight.len()];
    let x = [0.05, 0.5, 0.0];
    let start = std::time::Instant::now();
    while start.elapsed().as_secs_f64() < seconds {
        for _ in 0..16 {
            core::hint::black_box(prepared.cost(0, &rows, core::hint::black_box(&x), &mut roots));
            core::hint::black_box(prepared.step(0, &rows, &roots));
        }
    }
    prepared.evaluations.into_inner() as f64 / start.elapsed().as_secs_f64()
}
