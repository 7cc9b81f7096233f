//! Directional albedo `rho(wo) = int f(wo, wi) cos(theta_i) dwi` (the white-furnace test).
//!
//! The diffuse term contributes `kd` exactly. The specular term is reduced to a 1-D integral
//! over the lobe's polar angle by integrating each ring of the lobe around its axis in closed
//! form: for a ring the integrand is linear (Phong) or a product of two linear functions
//! (Blinn) in `cos(phi)`, clipped where it goes negative, so the clipped ring integral is
//! elementary. The remaining integral is adaptive Gauss-Kronrod. No Monte Carlo noise enters
//! the figure; tests check it against brute-force integration and the closed forms at normal
//! incidence.

use core::f64::consts::{FRAC_PI_2, PI};

use crate::quadrature::integrate_pieces;
use crate::{zones, Brdf, Geometry, Lobe, Rgb};

/// `rho` for the outgoing direction at polar angle `theta_o` (the BRDF is isotropic).
#[must_use]
pub fn directional_albedo(brdf: &Brdf, theta_o: f64) -> Rgb {
    let specular = brdf.normalisation_constant()
        * specular_albedo_per_unit(brdf.lobe(), brdf.geometry(), theta_o);
    brdf.kd + brdf.ks * specular
}

/// `int lobe(t) cos(theta_i) dwi` over the upper hemisphere, for `wo` at `theta_o`.
#[must_use]
pub fn specular_albedo_per_unit(lobe: &Lobe, geometry: Geometry, theta_o: f64) -> f64 {
    let theta_o = theta_o.clamp(0.0, FRAC_PI_2);
    let n = lobe.exponent();
    let mut points = vec![
        0.0,
        zones::epicentre_angle(n),
        zones::bloom_angle(n),
        FRAC_PI_2,
    ];
    if let Some(quadratic) = lobe.angle_quadratic() {
        points.push(quadratic.cutoff());
    }
    // The bit tricks' kinks: placed to 1e-12 rad, well inside this tolerance's reach.
    points.extend(lobe.kinks().into_iter().map(f64::acos));
    let tolerance = 1e-11;
    match geometry {
        Geometry::Phong => {
            points.push(FRAC_PI_2 - theta_o);
            integrate_pieces(
                |g| lobe.eval_angle(g) * g.sin() * phong_ring(g, theta_o),
                &points,
                tolerance,
            )
        }
        Geometry::Blinn => {
            4.0 * integrate_pieces(
                |theta_h| lobe.eval_angle(theta_h) * theta_h.sin() * blinn_ring(theta_h, theta_o),
                &points,
                tolerance,
            )
        }
    }
}

/// `int_0^{2 pi} max(0, cos(theta_i)) dphi` over the ring at angle `g` around the mirror
/// direction of `wo`: `cos(theta_i) = cos g cos(theta_o) + sin g sin(theta_o) cos(phi)`.
fn phong_ring(g: f64, theta_o: f64) -> f64 {
    let a = g.cos() * theta_o.cos();
    let b = g.sin() * theta_o.sin();
    clipped_linear_ring(a, b)
}

/// `int_0^{2 pi} max(0, a + b cos(phi)) dphi` for `b >= 0`.
fn clipped_linear_ring(a: f64, b: f64) -> f64 {
    if a >= b {
        2.0 * PI * a
    } else if a <= -b {
        0.0
    } else {
        let phi = (-a / b).acos();
        2.0 * (a * phi + b * phi.sin())
    }
}

/// `int_0^{2 pi} (wo.h) cos(theta_i) dphi` over the ring of half vectors at `theta_h`, where
/// both factors are positive (`wi = 2 (wo.h) h - wo` above the horizon, `h` facing `wo`).
fn blinn_ring(theta_h: f64, theta_o: f64) -> f64 {
    let (sin_h, cos_h) = theta_h.sin_cos();
    let (sin_o, cos_o) = theta_o.sin_cos();
    // wo.h = gamma + delta cos(phi); cos(theta_i) = alpha + beta cos(phi).
    let (gamma, delta) = (cos_o * cos_h, sin_o * sin_h);
    let (alpha, beta) = (2.0 * cos_h * gamma - cos_o, 2.0 * cos_h * delta);
    let (from_a, to_a) = positive_phi_range(alpha, beta);
    let (from_b, to_b) = positive_phi_range(gamma, delta);
    let (from, to) = (from_a.max(from_b), to_a.min(to_b));
    if from >= to {
        return 0.0;
    }
    // Antiderivative of (alpha + beta c)(gamma + delta c), c = cos(phi).
    let primitive = |phi: f64| {
        alpha * gamma * phi
            + (alpha * delta + beta * gamma) * phi.sin()
            + beta * delta * (0.5 * phi + 0.25 * (2.0 * phi).sin())
    };
    2.0 * (primitive(to) - primitive(from))
}

/// The sub-interval of `[0, pi]` where `a + b cos(phi) > 0` (cos is decreasing there, so it is
/// one interval touching an end).
fn positive_phi_range(a: f64, b: f64) -> (f64, f64) {
    if b == 0.0 {
        return if a > 0.0 { (0.0, PI) } else { (0.0, 0.0) };
    }
    let crossing = (-a / b).clamp(-1.0, 1.0).acos();
    if b > 0.0 {
        (0.0, crossing)
    } else {
        (crossing, PI)
    }
}

/// The largest directional albedo over outgoing angles (per channel maximum of the
/// luminance-free sum, i.e. of `kd + ks * specular` with the largest `ks`), and the angle
/// where it occurs, in radians.
///
/// A 1-degree scan of `theta_o` in `[0, 90)` refined by golden-section search around the best.
#[must_use]
pub fn max_directional_albedo(brdf: &Brdf) -> (f64, f64) {
    let albedo = |theta: f64| directional_albedo(brdf, theta).max_element();
    let step = 1f64.to_radians();
    let last = FRAC_PI_2 - 1e-6;
    let best = (0..=90)
        .map(|i| (i as f64 * step).min(last))
        .map(|theta| (theta, albedo(theta)))
        .fold((0.0, f64::NEG_INFINITY), |best, sample| {
            if sample.1 > best.1 {
                sample
            } else {
                best
            }
        });
    let (mut a, mut b) = ((best.0 - step).max(0.0), (best.0 + step).min(last));
    let ratio = 0.5 * (5f64.sqrt() - 1.0);
    for _ in 0..40 {
        let (x1, x2) = (b - ratio * (b - a), a + ratio * (b - a));
        if albedo(x1) > albedo(x2) {
            b = x2;
        } else {
            a = x1;
        }
    }
    let refined = 0.5 * (a + b);
    let refined_value = albedo(refined);
    if refined_value > best.1 {
        (refined, refined_value)
    } else {
        best
    }
}
