//! The GGX roughness fitted to each lobe: GGX is a normalised distribution, the fit lies in
//! (0, 1) and narrows as `n` grows, and for Blinn's `pow` it lands near
//! the classic Beckmann correspondence `alpha = sqrt(2 / (n + 2))` (Walter et al. 2007),
//! which GGX's longer tail pulls lower.

use specula::fit::{ggx, microfacet};
use specula::quadrature::integrate;
use specula::{Geometry, Lobe, LobeKind};

#[test]
fn ggx_is_a_normalised_distribution_of_normals() {
    for alpha in [0.02, 0.1, 0.5, 1.0] {
        let total = integrate(
            |theta: f64| {
                ggx(alpha, theta.cos()) * theta.cos() * theta.sin() * core::f64::consts::TAU
            },
            0.0,
            core::f64::consts::FRAC_PI_2,
            1e-12,
        );
        assert!((total - 1.0).abs() < 1e-8, "alpha {alpha}: {total}");
    }
}

#[test]
fn the_fit_is_inside_the_range_and_narrows_with_n() {
    for kind in LobeKind::ALL {
        for geometry in Geometry::ALL {
            let mut previous = f64::INFINITY;
            for n in [8.0, 64.0, 512.0] {
                let lobe = Lobe::try_new(kind, n).unwrap();
                let fit = microfacet(&lobe, geometry);
                assert!(fit.alpha > 0.0 && fit.alpha < 1.0, "{kind} {n}: {fit:?}");
                assert!(
                    fit.relative_error.is_finite() && fit.relative_error < 1.0,
                    "{kind} {n}: {fit:?}"
                );
                assert!(
                    fit.alpha < previous,
                    "{kind} {geometry:?}: alpha grows with n"
                );
                previous = fit.alpha;
            }
        }
    }
}

#[test]
fn blinn_pow_lands_near_the_beckmann_correspondence() {
    for n in [16.0, 64.0, 256.0] {
        let fit = microfacet(&Lobe::try_new(LobeKind::Pow, n).unwrap(), Geometry::Blinn);
        let beckmann = (2.0 / (n + 2.0)).sqrt();
        assert!(
            fit.alpha > 0.5 * beckmann && fit.alpha < beckmann,
            "n = {n}: alpha {} against Beckmann's {beckmann}",
            fit.alpha
        );
    }
}
