//! Helmholtz reciprocity: `f(wo, wi) = f(wi, wo)`, checked over random direction pairs.
//!
//! The random numbers come from the caller's generator (never drawn inside a model), so a run
//! is reproducible from its seed.

use core::f64::consts::TAU;

use glam::DVec3;
use rand::{Rng, RngExt};

use crate::Rgb;

/// The worst asymmetry found: `max |f(a, b) - f(b, a)| / max(|f(a, b)|, |f(b, a)|)` over
/// `pairs` pairs of directions drawn uniformly on the upper hemisphere (per channel).
pub fn max_reciprocity_error(
    f: impl Fn(DVec3, DVec3) -> Rgb,
    pairs: usize,
    rng: &mut impl Rng,
) -> f64 {
    (0..pairs)
        .map(|_| {
            let (a, b) = (uniform_hemisphere(rng), uniform_hemisphere(rng));
            let (forward, backward) = (f(a, b), f(b, a));
            let scale = forward.abs().max(backward.abs());
            let difference = (forward - backward).abs();
            (0..3)
                .filter(|&c| scale[c] > 0.0)
                .map(|c| difference[c] / scale[c])
                .fold(0.0, f64::max)
        })
        .fold(0.0, f64::max)
}

/// A direction uniformly distributed on the upper hemisphere (`z > 0`).
pub fn uniform_hemisphere(rng: &mut impl Rng) -> DVec3 {
    let z: f64 = 1.0 - rng.random::<f64>(); // (0, 1]
    let phi = TAU * rng.random::<f64>();
    let r = (1.0 - z * z).max(0.0).sqrt();
    DVec3::new(r * phi.cos(), r * phi.sin(), z)
}
