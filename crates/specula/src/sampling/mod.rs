//! Importance sampling of the specular term, in pbrt's vocabulary: [`SpecularSampler::sample`]
//! turns two uniform numbers (passed in, never drawn here) into a direction `wi` with its
//! density and the BRDF's value, and [`SpecularSampler::pdf`] gives the density of any `wi`.
//!
//! Each lobe is a distribution of its cosine ([`CosineDistribution`]); the two geometries
//! place it:
//! - **Phong**: `wi` is drawn about the mirror direction `r = (-wo.x, -wo.y, wo.z)` with
//!   `t = r.wi`, so the solid-angle density is `lobe(t) / (2 pi L)`;
//! - **Blinn**: the half vector `h` is drawn about the normal with `t = h.z`, and `wi` is
//!   `wo` mirrored about it; the density of `wi` is that of `h` times the Jacobian
//!   `1 / (4 wo.h)`.
//!
//! A draw below the horizon (or, for Blinn, with `wo.h <= 0`) returns `None`: the lobe's mass
//! there is lost, so the density integrates to the probability of a draw and to less than 1
//! when the lobe reaches below the surface. The estimator `value cos(theta_i) / pdf` then
//! averages to the specular term's directional albedo.
//!
//! Conventions are the library's: local frame with `z` the normal, unit `wo` towards the
//! viewer, `wi` towards the light. [`chi2`] holds the statistical tests every lobe passes.

mod alias;
pub mod chi2;
mod cosine;
mod distribution;
mod table32;

pub use alias::{AliasTable, GroupedAliasTable};
pub use cosine::{CosineDistribution, TABLE_BINS};
pub use distribution::{power_heuristic, Distribution1D, Distribution2D, Draw1D, Draw2D};
pub use table32::CosineTable32;

use core::f64::consts::TAU;

use glam::DVec3;

use crate::lobe::Warp;
use crate::{Geometry, Lobe, Normalisation};

/// One sampled direction.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Sample {
    /// The direction towards the light, unit length, above the surface.
    pub wi: DVec3,
    /// Its density with respect to solid angle.
    pub pdf: f64,
    /// The specular BRDF term there, `N(n) lobe(t)` (per unit `ks`).
    pub value: f64,
    /// Newton iterations spent drawing the cosine (0 for closed forms and tables).
    pub iterations: u32,
}

/// The specular term of a BRDF, prepared for sampling.
#[derive(Clone, Debug)]
pub struct SpecularSampler {
    cosine: CosineDistribution,
    geometry: Geometry,
    scale: f64,
}

/// A uniform number (counter-based, so a draw is the same on any thread and in any order) in
/// `[0, 1)` for draw `index`, dimension `dimension` of stream `seed` ([`random_bits`], 53
/// bits kept).
#[must_use]
pub fn uniform(seed: u64, index: u64, dimension: u64) -> f64 {
    (random_bits(seed, index, dimension) >> 11) as f64 * (1.0 / (1u64 << 53) as f64)
}

/// 64 random bits for draw `index`, dimension `dimension` of stream `seed`: SplitMix64's
/// finaliser over the three, counter-based like [`uniform`] (a renderer working in `f32`
/// takes two 32-bit numbers from each).
#[must_use]
#[inline]
pub fn random_bits(seed: u64, index: u64, dimension: u64) -> u64 {
    let mut z = seed
        .wrapping_mul(0x9E37_79B9_7F4A_7C15)
        .wrapping_add(index.wrapping_mul(0xD1B5_4A32_D192_ED03))
        .wrapping_add(dimension.wrapping_mul(0x8CB9_2BA7_2F3D_8DD7));
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}

/// The sum of `weights`, or `None` when there are none, one is negative or not finite, or
/// the sum is not: what a table drawing in proportion to them refuses.
fn weights_total(weights: &[f64]) -> Option<f64> {
    if weights.is_empty() || weights.iter().any(|w| !w.is_finite() || *w < 0.0) {
        return None;
    }
    let total: f64 = weights.iter().sum();
    total.is_finite().then_some(total)
}

/// A uniform `f32` in `[0, 1)` from the top 24 of 32 random bits.
#[must_use]
#[inline]
pub fn unit_f32(bits: u32) -> f32 {
    (bits >> 8) as f32 * (1.0 / (1u32 << 24) as f32)
}

/// The mirror direction of `wo` about the normal: the Phong lobe's axis.
#[must_use]
pub fn mirror(wo: DVec3) -> DVec3 {
    DVec3::new(-wo.x, -wo.y, wo.z)
}

/// `v` mirrored about the unit vector `axis`.
fn reflect(v: DVec3, axis: DVec3) -> DVec3 {
    2.0 * v.dot(axis) * axis - v
}

/// The unit vector at cosine `t` and azimuth `phi` about the unit `axis`.
fn about(axis: DVec3, t: f64, phi: f64) -> DVec3 {
    let (b1, b2) = axis.any_orthonormal_pair();
    let sine = (1.0 - t * t).max(0.0).sqrt();
    let (s, c) = phi.sin_cos();
    (t * axis + sine * (c * b1 + s * b2)).normalize()
}

impl SpecularSampler {
    /// Prepares `lobe` with `geometry`; `normalisation` scales the value (not the density).
    #[must_use]
    pub fn new(lobe: Lobe, geometry: Geometry, normalisation: Normalisation) -> Self {
        Self {
            scale: normalisation.constant_for(&lobe),
            cosine: CosineDistribution::new(lobe),
            geometry,
        }
    }

    /// The lobe.
    #[must_use]
    pub fn lobe(&self) -> &Lobe {
        self.cosine.lobe()
    }

    /// The geometry.
    #[must_use]
    pub fn geometry(&self) -> Geometry {
        self.geometry
    }

    /// How the cosine is drawn.
    #[must_use]
    pub fn warp(&self) -> Warp {
        self.cosine.warp()
    }

    /// The distribution of the lobe's cosine.
    #[must_use]
    pub fn cosine(&self) -> &CosineDistribution {
        &self.cosine
    }

    /// The axis the lobe is drawn about for `wo`: the mirror direction (Phong) or the normal
    /// (Blinn's half vector).
    #[must_use]
    pub fn axis(&self, wo: DVec3) -> DVec3 {
        match self.geometry {
            Geometry::Phong => mirror(wo),
            Geometry::Blinn => DVec3::Z,
        }
    }

    /// The specular term `N(n) lobe(t)` for `wo` and `wi` above the surface, else 0.
    #[must_use]
    pub fn value(&self, wo: DVec3, wi: DVec3) -> f64 {
        if wo.z <= 0.0 || wi.z <= 0.0 {
            return 0.0;
        }
        self.scale * self.lobe().eval(self.geometry.cos_lobe_local(wo, wi))
    }

    /// A direction for the uniform numbers `u` (each in `[0, 1)`), or `None` when the draw
    /// falls below the horizon or `wo` is not above the surface.
    #[must_use]
    pub fn sample(&self, wo: DVec3, u: [f64; 2]) -> Option<Sample> {
        if wo.z <= 0.0 {
            return None;
        }
        let drawn = self.cosine.sample(u[0]);
        let t = drawn.x;
        let phi = TAU * u[1];
        let around = self.cosine.density(t) / TAU;
        let (wi, pdf) = match self.geometry {
            Geometry::Phong => (about(self.axis(wo), t, phi), around),
            Geometry::Blinn => {
                let h = about(DVec3::Z, t, phi);
                let cosine = wo.dot(h);
                if cosine <= 0.0 {
                    return None;
                }
                (reflect(wo, h).normalize(), around / (4.0 * cosine))
            }
        };
        if wi.z <= 0.0 || pdf <= 0.0 {
            return None;
        }
        Some(Sample {
            wi,
            pdf,
            value: self.value(wo, wi),
            iterations: drawn.iterations,
        })
    }

    /// The density of `wi` given `wo`, with respect to solid angle.
    #[must_use]
    pub fn pdf(&self, wo: DVec3, wi: DVec3) -> f64 {
        if wo.z <= 0.0 || wi.z <= 0.0 {
            return 0.0;
        }
        match self.geometry {
            Geometry::Phong => self.cosine.density(self.axis(wo).dot(wi)) / TAU,
            Geometry::Blinn => {
                let sum = wo + wi;
                if sum.length_squared() == 0.0 {
                    return 0.0;
                }
                let h = sum.normalize();
                let cosine = wo.dot(h);
                if cosine <= 0.0 {
                    return 0.0;
                }
                self.cosine.density(h.z) / TAU / (4.0 * cosine)
            }
        }
    }
}
