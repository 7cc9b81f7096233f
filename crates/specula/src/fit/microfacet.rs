//! The GGX roughness that best stands in for a lobe: what a renderer whose only glossy
//! closures are microfacet models (Blender Cycles' OSL, MaterialX's OSL and MDL back ends)
//! is given in place of the lobe.
//!
//! A lobe read as a distribution of normals is `D(h) = lobe(cos theta_h) / Z`, normalised so
//! that `int D cos theta_h dw = 1`, as a microfacet distribution must be. For the Blinn
//! geometry that is the lobe itself; for Phong, whose lobe is about the mirror direction, it
//! is the lobe at `t = cos 2 theta_h`, exact at normal incidence (`wo = n`, where the mirror
//! angle is twice the half angle). The fit minimises the relative L2 distance
//! `int (D_ggx - D)^2 cos theta dw / int D^2 cos theta dw` over `alpha` by golden-section
//! search on `ln alpha`, and reports its square root.

use core::f64::consts::{FRAC_PI_2, TAU};

use crate::{Geometry, Lobe};

/// A GGX roughness fitted to a lobe.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct MicrofacetFit {
    /// GGX's `alpha` (the square of an artist's "roughness").
    pub alpha: f64,
    /// The relative L2 distance between the two distributions at that `alpha`.
    pub relative_error: f64,
}

/// GGX's (Trowbridge-Reitz) normal distribution at `cos theta`: the microfacet model's.
pub use crate::microfacet::closed::ggx_d as ggx;

/// The GGX `alpha` closest to `lobe` in `geometry` (see the module page).
#[must_use]
pub fn microfacet(lobe: &Lobe, geometry: Geometry) -> MicrofacetFit {
    let shape = |theta: f64| match geometry {
        Geometry::Blinn => lobe.eval(theta.cos()),
        Geometry::Phong => lobe.eval((2.0 * theta).cos()),
    };
    // Breakpoints on the lobe's own scale, where the integrands change fastest.
    let width = match geometry {
        Geometry::Blinn => (2.0 / (lobe.exponent().get() + 2.0)).sqrt(),
        Geometry::Phong => 0.5 * (2.0 / (lobe.exponent().get() + 2.0)).sqrt(),
    };
    let mut points: Vec<f64> = (0..12)
        .map(|k| width * 0.25 * 2f64.powi(k))
        .filter(|p| *p < FRAC_PI_2)
        .collect();
    points.extend([0.0, FRAC_PI_2]);
    points.sort_by(f64::total_cmp);
    // Composite Simpson, 64 panels per piece, with the lobe tabulated once: the search then
    // only evaluates GGX.
    const PANELS: usize = 64;
    let mut nodes = Vec::new();
    for piece in points.windows(2) {
        let step = (piece[1] - piece[0]) / PANELS as f64;
        for k in 0..=PANELS {
            let simpson = if k == 0 || k == PANELS {
                1.0
            } else if k % 2 == 1 {
                4.0
            } else {
                2.0
            };
            let theta = piece[0] + step * k as f64;
            let measure = simpson * step / 3.0 * theta.cos() * theta.sin() * TAU;
            nodes.push((theta.cos(), measure, shape(theta)));
        }
    }
    let normaliser: f64 = nodes.iter().map(|(_, w, d)| w * d).sum();
    let energy: f64 = nodes
        .iter()
        .map(|(_, w, d)| w * (d / normaliser).powi(2))
        .sum();
    let distance = |alpha: f64| {
        nodes
            .iter()
            .map(|(c, w, d)| w * (ggx(alpha, *c) - d / normaliser).powi(2))
            .sum::<f64>()
            / energy
    };
    let (mut low, mut high) = (1e-4f64.ln(), 0.0f64);
    let golden = 0.5 * (5f64.sqrt() - 1.0);
    let mut left = high - golden * (high - low);
    let mut right = low + golden * (high - low);
    let (mut at_left, mut at_right) = (distance(left.exp()), distance(right.exp()));
    for _ in 0..60 {
        if at_left < at_right {
            high = right;
            right = left;
            at_right = at_left;
            left = high - golden * (high - low);
            at_left = distance(left.exp());
        } else {
            low = left;
            left = right;
            at_left = at_right;
            right = low + golden * (high - low);
            at_right = distance(right.exp());
        }
    }
    let alpha = (0.5 * (low + high)).exp();
    MicrofacetFit {
        alpha,
        relative_error: distance(alpha).sqrt(),
    }
}
