//! The analysis code's figures against independent computations written here: a dense
//! brute-force scan for the error figures, a 2-D midpoint rule for the albedo, and the
//! structure of each formula for the operation counts.

use core::f64::consts::{FRAC_PI_2, PI};

use glam::DVec3;
use specula::analysis::{
    directional_albedo, energy_ratio, error_figures, Precision, DEFAULT_SAMPLES_PER_ZONE,
};
use specula::{Brdf, Exponent, Geometry, Lobe, LobeKind, Normalisation, Rgb};

/// Max errors by a dense uniform scan of `[0, pi/2]`, zones classified by the reference value.
fn brute_force(lobe: &Lobe, samples: usize) -> [f64; 4] {
    let n = lobe.exponent().get();
    let mut figures = [0.0f64; 4]; // epicentre rel, epicentre abs, bloom abs, tail abs
    for i in 0..=samples {
        let g = FRAC_PI_2 * i as f64 / samples as f64;
        let reference = g.cos().powf(n);
        let error = (lobe.eval(g.cos()) - reference).abs();
        if reference >= 0.5 {
            figures[0] = figures[0].max(error / reference);
            figures[1] = figures[1].max(error);
        } else if reference >= 1.0 / 256.0 {
            figures[2] = figures[2].max(error);
        } else {
            figures[3] = figures[3].max(error);
        }
    }
    figures
}

#[test]
fn error_figures_agree_with_a_brute_force_scan() {
    for kind in LobeKind::ALL {
        for n in [3.0, 50.0, 600.0] {
            let lobe = Lobe::new(kind, Exponent::new(n));
            let analysed = error_figures(&lobe, &mut Precision::F64, DEFAULT_SAMPLES_PER_ZONE);
            // The narrowest epicentre (n = 600) is 0.048 rad: 4e6 samples put ~120k in it.
            let scanned = brute_force(&lobe, 4_000_000);
            let pairs = [
                (analysed.epicentre_max_rel, scanned[0]),
                (analysed.epicentre_max_abs, scanned[1]),
                (analysed.bloom_max_abs, scanned[2]),
                (analysed.tail_max_abs, scanned[3]),
            ];
            for (zone, (a, b)) in pairs.into_iter().enumerate() {
                // Two different sample sets find the same maximum to within their spacing.
                assert!(
                    (a - b).abs() <= 2e-3 * a.max(b) + 1e-15,
                    "{kind} n={n} figure {zone}: analysis {a} vs scan {b}"
                );
            }
        }
    }
}

#[test]
fn energy_ratio_agrees_with_a_midpoint_rule_in_the_cosine() {
    for kind in LobeKind::ALL {
        for n in [2.0, 40.0, 900.0] {
            let lobe = Lobe::new(kind, Exponent::new(n));
            let steps = 2_000_000;
            let midpoint: f64 = (0..steps)
                .map(|i| lobe.eval((f64::from(i) + 0.5) / f64::from(steps)))
                .sum::<f64>()
                / f64::from(steps);
            let expected = midpoint * (n + 1.0);
            let got = energy_ratio(&lobe);
            assert!(
                (got - expected).abs() < 2e-4 * expected,
                "{kind} n={n}: {got} vs {expected}"
            );
        }
    }
}

/// `rho(wo) = int f(wo, wi) cos(theta_i) dwi` by a midpoint rule over the hemisphere in
/// `(cos theta, phi)` (uniform in solid angle).
fn albedo_by_grid(brdf: &Brdf, theta_o: f64, cells: u32) -> f64 {
    let wo = DVec3::new(theta_o.sin(), 0.0, theta_o.cos());
    let mut sum = 0.0;
    for i in 0..cells {
        let z = (f64::from(i) + 0.5) / f64::from(cells);
        let r = (1.0 - z * z).sqrt();
        for j in 0..cells {
            let phi = 2.0 * PI * (f64::from(j) + 0.5) / f64::from(cells);
            let wi = DVec3::new(r * phi.cos(), r * phi.sin(), z);
            sum += brdf.f(wo, wi).x * z;
        }
    }
    sum * 2.0 * PI / f64::from(cells * cells)
}

#[test]
fn directional_albedo_agrees_with_brute_force_integration() {
    for geometry in Geometry::ALL {
        for kind in [
            LobeKind::Pow,
            LobeKind::Schlick,
            LobeKind::Cheb2,
            LobeKind::CosQuad { v: 4 },
        ] {
            for n in [2.0, 12.0] {
                let lobe = Lobe::new(kind, Exponent::new(n));
                let brdf = Brdf::new(
                    Rgb::splat(0.1),
                    Rgb::ONE,
                    lobe,
                    geometry,
                    Normalisation::Lobe,
                );
                for theta_o in [0.0, 0.6, 1.2, 1.5] {
                    let fast = directional_albedo(&brdf, theta_o).x;
                    let slow = albedo_by_grid(&brdf, theta_o, 1500);
                    assert!(
                        (fast - slow).abs() < 2e-3,
                        "{kind} {geometry:?} n={n} theta={theta_o}: {fast} vs {slow}"
                    );
                }
            }
        }
    }
}

/// The operation counts reflect each formula's structure (SPEC section 8).
#[test]
fn operation_counts_follow_the_formulas() {
    let ops = |kind: LobeKind, n: f64| Lobe::new(kind, Exponent::new(n)).ops();
    // schlick: one multiply, two adds, one divide.
    let schlick = ops(LobeKind::Schlick, 100.0);
    assert_eq!(
        (schlick.mul, schlick.add, schlick.div, schlick.square),
        (1, 2, 1, 0)
    );
    // schlick-mod adds log2(a) squarings: a = 2^(floor(log2 n) - 2).
    for (n, squarings) in [(4.0, 0), (8.0, 1), (100.0, 4), (1000.0, 7)] {
        assert_eq!(ops(LobeKind::SchlickMod, n).square, squarings, "n = {n}");
    }
    // cosquad: v squarings, one multiply by a.
    for v in [0u8, 4, 9] {
        let k = ops(LobeKind::CosQuad { v }, 100.0);
        assert_eq!((k.square, k.mul), (u32::from(v), 1));
    }
    // logexp: the log2 unit twice, no exponential.
    let logexp = ops(LobeKind::LogExp, 100.0);
    assert_eq!((logexp.log2, logexp.exp2, logexp.pow), (2, 0, 0));
    // The quadratics: Horner (two multiplies, two adds) after one acos.
    for kind in [LobeKind::Cheb2, LobeKind::Cheb2Thesis, LobeKind::Minimax2] {
        let q = ops(kind, 100.0);
        assert_eq!((q.mul, q.add, q.acos), (2, 2, 1), "{kind}");
    }
    assert_eq!(ops(LobeKind::Pow, 100.0).pow, 1);
}
