//! Properties every lobe and BRDF must have, over random inputs (SPEC sections 1 and 6).
//! The same suite runs on the `f64` reference and the `f32` fast path.

use glam::DVec3;
use proptest::prelude::*;
use specula::analysis::max_directional_albedo;
use specula::{Brdf, Exponent, Geometry, Lobe, LobeKind, Normalisation, Rgb};

fn any_lobe() -> impl Strategy<Value = LobeKind> {
    prop_oneof![
        proptest::sample::select(LobeKind::ALL.to_vec()),
        (0u8..=10).prop_map(|v| LobeKind::CosQuad { v }),
    ]
}

fn any_exponent() -> impl Strategy<Value = Exponent> {
    prop_oneof![1.0f64..=1000.0, (0.0f64..=3.0).prop_map(|e| 10f64.powf(e))].prop_map(Exponent::new)
}

fn unit_upper(x: f64, y: f64, z: f64) -> Option<DVec3> {
    let v = DVec3::new(x, y, z.abs());
    (v.length() > 1e-3 && v.z > 1e-6).then(|| v.normalize())
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(2000))]

    #[test]
    fn lobe_is_finite_within_unit_range_and_zero_for_nonpositive_cosine(
        kind in any_lobe(), n in any_exponent(), t in -1.0f64..=1.0,
    ) {
        let lobe = Lobe::new(kind, n);
        let value = lobe.eval(t);
        prop_assert!(value.is_finite() && (0.0..=1.0).contains(&value), "{kind} n={n} t={t}: \
            {value}");
        let value32 = lobe.eval(t as f32);
        prop_assert!(value32.is_finite() && (0.0..=1.0).contains(&value32));
        if t <= 0.0 {
            prop_assert_eq!(value, 0.0);
            prop_assert_eq!(value32, 0.0);
        }
    }

    #[test]
    fn f32_path_tracks_f64(kind in any_lobe(), n in any_exponent(), t in 0.0f32..=1.0) {
        let lobe = Lobe::new(kind, n);
        let (fast, reference) = (f64::from(lobe.eval(t)), lobe.eval(f64::from(t)));
        prop_assert!((fast - reference).abs() <= lobe.f32_tolerance(),
            "{kind} n={n} t={t}: f32 {fast} vs f64 {reference}");
    }

    #[test]
    fn angle_and_cosine_inputs_agree(
        kind in any_lobe(),
        n in any_exponent(),
        g in 0.0f64..(core::f64::consts::FRAC_PI_2 - 1e-9),
    ) {
        let lobe = Lobe::new(kind, n);
        prop_assert!((lobe.eval_angle(g) - lobe.eval(g.cos())).abs() < 1e-9);
    }

    #[test]
    fn every_brdf_is_reciprocal(
        kind in any_lobe(), n in any_exponent(),
        geometry in proptest::sample::select(Geometry::ALL.to_vec()),
        normalisation in proptest::sample::select(Normalisation::ALL.to_vec()),
        a in (-1.0f64..1.0, -1.0f64..1.0, 0.0f64..1.0),
        b in (-1.0f64..1.0, -1.0f64..1.0, 0.0f64..1.0),
    ) {
        let (Some(wo), Some(wi)) = (unit_upper(a.0, a.1, a.2), unit_upper(b.0, b.1, b.2)) else {
            return Ok(());
        };
        let (kd, ks) = (Rgb::splat(0.3), Rgb::new(0.7, 0.5, 0.2));
        let brdf = Brdf::new(kd, ks, Lobe::new(kind, n), geometry, normalisation);
        let (forward, backward) = (brdf.f(wo, wi), brdf.f(wi, wo));
        let scale = forward.max_element().max(1.0);
        prop_assert!((forward - backward).abs().max_element() <= 1e-12 * scale);
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(24))]

    /// White furnace: the `lobe`-normalised BRDF (Phong geometry, kd = 0, ks = 1) reflects at
    /// most what it receives, from every outgoing direction.
    #[test]
    fn lobe_normalised_brdf_passes_the_white_furnace(kind in any_lobe(), n in any_exponent()) {
        let lobe = Lobe::new(kind, n);
        let brdf = Brdf::new(Rgb::ZERO, Rgb::ONE, lobe, Geometry::Phong, Normalisation::Lobe);
        let (theta, albedo) = max_directional_albedo(&brdf);
        prop_assert!(albedo <= 1.0 + 1e-3, "{kind} n={n}: albedo {albedo} at {theta} rad");
    }
}
