//! Where a material is compared with a model: a fixed set of direction pairs, each with its
//! share of the solid-angle measure, and the material's `f cos(theta_i)` there.
//!
//! The pairs are midpoints of a grid in Rusinkiewicz's half/difference angles
//! `(theta_h, theta_d, phi_d)`, with `theta_h = (pi / 2) u^2` for `u` uniform (as MERL
//! tabulates it): a highlight a few degrees wide still gets dozens of samples, which a grid
//! uniform in the two directions would miss. Each pair's weight is its cell's measure in
//! `dwi dwo = 4 cos(theta_d) sin(theta_h) sin(theta_d) dtheta_h dphi_h dtheta_d dphi_d`
//! (`phi_h` is integrated out: the materials are isotropic), so a weighted sum is an
//! integral over pairs of directions. `phi_d` covers `[0, pi]`, a whole period of an
//! isotropic BRDF's mirror symmetry. Pairs with either direction beyond
//! [`MAX_ELEVATION_DEGREES`] are dropped, as Ngan et al. (2005) drop grazing data: the
//! measurements there are least reliable and a renderer's cosine makes them matter least.

use core::f64::consts::{FRAC_PI_2, PI};

use glam::DVec3;
use rayon::prelude::*;

use crate::Rgb;

/// The largest elevation of either direction kept, degrees.
pub const MAX_ELEVATION_DEGREES: f64 = 80.0;

/// Grid resolution in `theta_h`, `theta_d` and `phi_d`.
pub const GRID: [usize; 3] = [48, 24, 24];

/// A material's values at the comparison directions.
#[derive(Clone, Debug)]
pub struct Observations {
    /// The viewer's directions (local frame).
    pub wo: Vec<DVec3>,
    /// The light's directions.
    pub wi: Vec<DVec3>,
    /// Each pair's share of the measure; they sum to 1.
    pub weight: Vec<f64>,
    /// The material's `f(wo, wi) cos(theta_i)`, per channel.
    pub value: Vec<Rgb>,
}

/// The comparison pairs `(wo, wi, weight)`, weights summing to 1 (see the module page).
#[must_use]
pub fn comparison_pairs() -> Vec<(DVec3, DVec3, f64)> {
    let [nh, nd, nphi] = GRID;
    let cos_limit = MAX_ELEVATION_DEGREES.to_radians().cos();
    let mut pairs = Vec::with_capacity(nh * nd * nphi);
    for ih in 0..nh {
        let u = (ih as f64 + 0.5) / nh as f64;
        let theta_h = FRAC_PI_2 * u * u;
        let d_theta_h = PI * u / nh as f64;
        let h = DVec3::new(theta_h.sin(), 0.0, theta_h.cos());
        for id in 0..nd {
            let theta_d = FRAC_PI_2 * (id as f64 + 0.5) / nd as f64;
            let d_theta_d = FRAC_PI_2 / nd as f64;
            for iphi in 0..nphi {
                let phi_d = PI * (iphi as f64 + 0.5) / nphi as f64;
                let d_phi_d = PI / nphi as f64;
                // The difference vector about the half vector, rotated so its pole is h.
                let d = DVec3::new(
                    theta_d.sin() * phi_d.cos(),
                    theta_d.sin() * phi_d.sin(),
                    theta_d.cos(),
                );
                let (s, c) = theta_h.sin_cos();
                let wi = DVec3::new(c * d.x + s * d.z, d.y, -s * d.x + c * d.z);
                let wo = 2.0 * h.dot(wi) * h - wi;
                if wi.z < cos_limit || wo.z < cos_limit {
                    continue;
                }
                let weight = 4.0
                    * theta_d.cos()
                    * theta_h.sin()
                    * theta_d.sin()
                    * d_theta_h
                    * d_theta_d
                    * d_phi_d;
                pairs.push((wo, wi, weight));
            }
        }
    }
    let total: f64 = pairs.iter().map(|p| p.2).sum();
    pairs.iter_mut().for_each(|p| p.2 /= total);
    pairs
}

impl Observations {
    /// The material `f_cos(wo, wi)` (its `f cos(theta_i)`) at [`comparison_pairs`].
    pub fn of(f_cos: impl Fn(DVec3, DVec3) -> Rgb + Sync) -> Self {
        let pairs = comparison_pairs();
        let value = pairs.par_iter().map(|&(wo, wi, _)| f_cos(wo, wi)).collect();
        Self {
            wo: pairs.iter().map(|p| p.0).collect(),
            wi: pairs.iter().map(|p| p.1).collect(),
            weight: pairs.iter().map(|p| p.2).collect(),
            value,
        }
    }

    /// How many pairs.
    #[must_use]
    pub fn len(&self) -> usize {
        self.weight.len()
    }

    /// Whether there are none.
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.weight.is_empty()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The weights are a measure on pairs of directions: the weighted mean of
    /// `cos(theta_i) cos(theta_o)` equals its mean over the kept region computed a second
    /// way, on a fine grid in the two directions' own elevations.
    #[test]
    fn weighted_sums_integrate_over_direction_pairs() {
        let pairs = comparison_pairs();
        let by_pairs: f64 = pairs.iter().map(|(wo, wi, w)| w * wo.z * wi.z).sum();
        let limit = MAX_ELEVATION_DEGREES.to_radians();
        let m = 400;
        let (mut numerator, mut denominator) = (0.0, 0.0);
        for i in 0..m {
            let theta_i = limit * (i as f64 + 0.5) / m as f64;
            for o in 0..m {
                let theta_o = limit * (o as f64 + 0.5) / m as f64;
                let measure = theta_i.sin() * theta_o.sin();
                numerator += measure * theta_i.cos() * theta_o.cos();
                denominator += measure;
            }
        }
        let by_grid = numerator / denominator;
        assert!((by_pairs - by_grid).abs() < 2e-3, "{by_pairs} vs {by_grid}");
        assert!(pairs
            .iter()
            .all(|(wo, wi, _)| (wo.length() - 1.0).abs() < 1e-12
                && (wi.length() - 1.0).abs() < 1e-12));
    }
}
