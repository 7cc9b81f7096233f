//! The two classic distributions in closed form: Beckmann's and GGX's (Trowbridge-Reitz)
//! normal distribution, Smith's `Lambda` for each, and the sampling of `D cos theta_h` by
//! inversion; and Walter et al.'s rational approximation of Beckmann's `Lambda`, the check of a
//! lobe's tabulated masking (its `pow` lobe is Walter's Phong distribution).

use core::f64::consts::PI;

/// Beckmann's `D` at `cos theta_h` for roughness `alpha`.
#[must_use]
pub fn beckmann_d(alpha: f64, cos_theta: f64) -> f64 {
    if cos_theta <= 0.0 {
        return 0.0;
    }
    let c2 = cos_theta * cos_theta;
    let tan2 = (1.0 - c2).max(0.0) / c2;
    (-tan2 / (alpha * alpha)).exp() / (PI * alpha * alpha * c2 * c2)
}

/// Beckmann's Smith `Lambda` at a direction of cosine `cos_theta`, exact:
/// `(erf(a) - 1) / 2 + exp(-a^2) / (2 a sqrt(pi))` with `a = 1 / (alpha tan theta)`.
#[must_use]
pub fn beckmann_lambda(alpha: f64, cos_theta: f64) -> f64 {
    let Some(a) = inverse_slope(alpha, cos_theta) else {
        return f64::INFINITY;
    };
    if a.is_infinite() {
        return 0.0;
    }
    // erf(a) - 1 = -erfc(a), written so that no cancellation loses the small difference.
    (0.5 * ((-a * a).exp() / (a * PI.sqrt()) - libm::erfc(a))).max(0.0)
}

/// Walter et al.'s (2007) rational approximation of Beckmann's `Lambda`, in
/// `a = 1 / (alpha tan theta)`: `(1 - 1.259 a + 0.396 a^2) / (3.535 a + 2.181 a^2)` below
/// `a = 1.6`, 0 above. For the Phong distribution of exponent `n`, `alpha = sqrt(2 / (n + 2))`.
#[must_use]
pub fn walter_lambda(alpha: f64, cos_theta: f64) -> f64 {
    let Some(a) = inverse_slope(alpha, cos_theta) else {
        return f64::INFINITY;
    };
    if a >= 1.6 {
        0.0
    } else {
        (1.0 - 1.259 * a + 0.396 * a * a) / (3.535 * a + 2.181 * a * a)
    }
}

/// GGX's `D` at `cos theta_h` for roughness `alpha`.
#[must_use]
pub fn ggx_d(alpha: f64, cos_theta: f64) -> f64 {
    if cos_theta <= 0.0 {
        return 0.0;
    }
    let a2 = alpha * alpha;
    let c2 = cos_theta * cos_theta;
    let denominator = c2 * (a2 - 1.0) + 1.0;
    a2 / (PI * denominator * denominator)
}

/// GGX's Smith `Lambda`: `(sqrt(1 + alpha^2 tan^2 theta) - 1) / 2`.
#[must_use]
pub fn ggx_lambda(alpha: f64, cos_theta: f64) -> f64 {
    if cos_theta <= 0.0 {
        return f64::INFINITY;
    }
    let c2 = cos_theta * cos_theta;
    let tan2 = (1.0 - c2).max(0.0) / c2;
    0.5 * ((1.0 + alpha * alpha * tan2).sqrt() - 1.0)
}

/// `cos theta_h` drawn with density `D cos theta_h` over the hemisphere of normals (its
/// azimuth is uniform), for Beckmann: `tan^2 theta = -alpha^2 ln(1 - u)`.
#[must_use]
pub fn beckmann_sample_cos(alpha: f64, u: f64) -> f64 {
    let tan2 = -alpha * alpha * (-u).ln_1p();
    1.0 / (1.0 + tan2).sqrt()
}

/// As [`beckmann_sample_cos`], for GGX: `tan^2 theta = alpha^2 u / (1 - u)`.
#[must_use]
pub fn ggx_sample_cos(alpha: f64, u: f64) -> f64 {
    let tan2 = alpha * alpha * u / (1.0 - u);
    1.0 / (1.0 + tan2).sqrt()
}

/// `1 / (alpha tan theta)`: infinite along the normal, `None` at or below the horizon.
fn inverse_slope(alpha: f64, cos_theta: f64) -> Option<f64> {
    if cos_theta <= 0.0 {
        return None;
    }
    let sin_theta = (1.0 - cos_theta * cos_theta).max(0.0).sqrt();
    Some(if sin_theta == 0.0 {
        f64::INFINITY
    } else {
        cos_theta / (alpha * sin_theta)
    })
}
