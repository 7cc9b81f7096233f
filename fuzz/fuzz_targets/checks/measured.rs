//! The measured-material target's check, also run by `crates/render/tests/fuzz_regressions.rs`
//! on the seeds and every crash input kept in `fuzz/regressions/`.

use glam::DVec3;
use specula::measured::MeasuredBrdf;

/// The reader must answer any bytes with a material or an error, never a panic; a material it
/// accepts answers every evaluation, density and draw with finite numbers.
pub fn check_measured(data: &[u8]) {
    let Ok(material) = MeasuredBrdf::from_bytes(data) else {
        return;
    };
    let direction = |theta: f64, phi: f64| {
        DVec3::new(
            theta.sin() * phi.cos(),
            theta.sin() * phi.sin(),
            theta.cos(),
        )
    };
    for (theta_o, theta_i, phi) in [
        (0.0, 0.0, 0.0),
        (0.3, 0.3, core::f64::consts::PI),
        (1.2, 0.1, 1.0),
        (1.55, 1.5, 0.2),
    ] {
        let (wo, wi) = (direction(theta_o, 0.0), direction(theta_i, phi));
        assert!(material.f_cos(wo, wi).is_finite() && material.f(wo, wi).is_finite());
        assert!(material.pdf(wo, wi).is_finite());
        for u in [[0.0, 0.0], [0.5, 0.5], [0.999, 0.001], [1.0, 1.0]] {
            if let Some(drawn) = material.sample(wo, u) {
                assert!(drawn.f.is_finite() && drawn.pdf.is_finite() && drawn.wi.is_finite());
            }
        }
    }
}
