//! What a microfacet model loses to single scattering, as Kulla and Conty (2017) plot it: the
//! directional albedo `E(mu) = int f(wo, wi) cos theta_i dwi` of the BRDF with Fresnel 1 (the
//! rest is light the masking stops, which real surfaces scatter again), and its cosine-weighted
//! average `E_avg = 2 int_0^1 E(mu) mu dmu`.

use core::f64::consts::{FRAC_PI_2, TAU};

use super::{fresnel_schlick, Distribution};
use crate::quadrature::integrate_pieces;

/// Azimuths of the inner, periodic trapezoid rule over the half vector.
const AZIMUTHS: usize = 64;

/// The 8-point Gauss-Legendre rule on `[-1, 1]`: the positive nodes and their weights (the
/// rule is symmetric), mapped to `[0, 1]` for the average over `mu`.
const GAUSS_LEGENDRE: [(f64, f64); 4] = [
    (0.183_434_642_495_649_8, 0.362_683_783_378_362),
    (0.525_532_409_916_329, 0.313_706_645_877_887_3),
    (0.796_666_477_413_626_7, 0.222_381_034_453_374_5),
    (0.960_289_856_497_536_3, 0.101_228_536_290_376_3),
];

/// `E(mu)` of `distribution`'s BRDF with Fresnel 1 at `cos_o = mu`, integrated over the half
/// vector (`dwi = 4 |wo . h| dh`): `int D(h) G2(wo, wi) (wo . h) / cos_o dh` where `wi`, the
/// reflection of `wo` about `h`, is above the horizon.
#[must_use]
pub fn directional_albedo(distribution: &Distribution, cos_o: f64) -> f64 {
    directional_albedo_with_fresnel(distribution, cos_o, 1.0)
}

/// [`directional_albedo`] with Schlick's Fresnel of `f0` inside the integral.
#[must_use]
pub fn directional_albedo_with_fresnel(distribution: &Distribution, cos_o: f64, f0: f64) -> f64 {
    let width = distribution.width();
    let cos_o = cos_o.clamp(1e-6, 1.0);
    let sin_o = (1.0 - cos_o * cos_o).sqrt();
    let ring = |theta: f64| {
        let (s, c) = theta.sin_cos();
        let seen: f64 = (0..AZIMUTHS)
            .map(|k| {
                let cos_phi = (TAU * k as f64 / AZIMUTHS as f64).cos();
                // `wo . h` and the reflected direction's height from `h`'s angles (`wo` lies
                // in the xz plane).
                let cos = sin_o * s * cos_phi + cos_o * c;
                let wi_z = 2.0 * cos * c - cos_o;
                if cos <= 0.0 || wi_z <= 0.0 {
                    0.0
                } else {
                    distribution.g2(cos_o, wi_z) * cos * fresnel_schlick(f0, cos)
                }
            })
            .sum();
        distribution.d(c) * s * seen * TAU / AZIMUTHS as f64 / cos_o
    };
    let mut points: Vec<f64> = (0..12)
        .map(|k| width * 0.25 * 2f64.powi(k))
        .filter(|p| *p < FRAC_PI_2)
        .collect();
    points.extend([0.0, FRAC_PI_2]);
    integrate_pieces(ring, &points, 1e-7)
}

/// `E_avg = 2 int_0^1 E(mu) mu dmu` (8-point Gauss-Legendre over `mu`).
#[must_use]
pub fn average_albedo(distribution: &Distribution) -> f64 {
    GAUSS_LEGENDRE
        .iter()
        .flat_map(|&(x, w)| [(0.5 - 0.5 * x, 0.5 * w), (0.5 + 0.5 * x, 0.5 * w)])
        .map(|(mu, weight)| 2.0 * weight * mu * directional_albedo(distribution, mu))
        .sum()
}
