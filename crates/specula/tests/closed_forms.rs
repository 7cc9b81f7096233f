//! Lobes, normalisations and albedos against closed forms derived by hand.

use core::f64::consts::{FRAC_PI_2, PI};

use specula::analysis::{directional_albedo, energy_ratio};
use specula::lobe::thesis_coefficients;
use specula::normalisation::{lobe_constant, lobe_integral};
use specula::{Brdf, Exponent, Geometry, Lobe, LobeKind, Normalisation, Rgb};

fn lobe(kind: LobeKind, n: f64) -> Lobe {
    Lobe::new(kind, Exponent::new(n))
}

#[test]
fn schlick_at_n_one_is_the_cosine() {
    let schlick = lobe(LobeKind::Schlick, 1.0);
    for i in 1..=100 {
        let t = f64::from(i) / 100.0;
        assert!((schlick.eval(t) - t).abs() < 1e-15, "t = {t}");
    }
}

#[test]
fn schlick_mod_is_schlick_below_eight_and_has_power_a_above() {
    for n in [1.0, 3.0, 7.5] {
        for t in [0.1, 0.5, 0.97] {
            assert_eq!(
                lobe(LobeKind::SchlickMod, n).eval(t),
                lobe(LobeKind::Schlick, n).eval(t)
            );
        }
    }
    // n = 100: a = 2^(6 - 2) = 16.
    let t: f64 = 0.93;
    let expected = t.powi(16) / (100.0 * (1.0 - t) + t);
    assert!((lobe(LobeKind::SchlickMod, 100.0).eval(t) - expected).abs() < 1e-15);
}

#[test]
fn logexp_is_exact_at_y_zero_and_minus_one_and_vanishes_at_minus_three() {
    for n in [1.0, 7.0, 64.0, 999.0] {
        let logexp = lobe(LobeKind::LogExp, n);
        assert_eq!(logexp.eval(1.0), 1.0);
        let y_minus_one = (-1.0 / n).exp2(); // t with n log2 t = -1
        assert!((logexp.eval(y_minus_one) - 0.5).abs() < 1e-13, "n = {n}");
        let y_minus_three = (-3.0 / n).exp2();
        assert!(logexp.eval(y_minus_three).abs() < 1e-13);
        assert_eq!(logexp.eval((-3.5 / n).exp2()), 0.0);
    }
}

#[test]
fn logexp_rr_is_exact_at_every_integer_y() {
    let rr = lobe(LobeKind::LogExpRr, 37.0);
    for k in 0..20 {
        let t = (-f64::from(k) / 37.0).exp2();
        let expected = (-f64::from(k)).exp2();
        assert!(
            (rr.eval(t) - expected).abs() <= 1e-13 * expected,
            "y = -{k}"
        );
    }
}

#[test]
fn cosquad_at_n_equal_two_to_the_v_is_t_to_the_n() {
    // a = (2^v + 1)/(2^v + 1) = 1, so the base is t.
    for v in [2u8, 4, 6] {
        let n = f64::from(1u32 << v);
        let k = lobe(LobeKind::CosQuad { v }, n);
        for t in [0.2f64, 0.8, 0.999] {
            assert!((k.eval(t) - t.powf(n)).abs() < 1e-14);
        }
    }
}

/// `int_0^1 (a (t - 1) + 1)^(2^v) dt = 1 / ((2^v + 1) a) = 1 / (n + 1)` when the support
/// `t >= (a - 1)/a` lies inside `[0, 1]`, i.e. `n >= 2^v`.
#[test]
fn cosquad_integrates_to_one_over_n_plus_one_when_n_is_at_least_two_to_the_v() {
    for v in [3u8, 4, 5] {
        for n in [f64::from(1u32 << v), 40.0, 333.3, 1000.0] {
            let k = lobe(LobeKind::CosQuad { v }, n);
            assert!(
                (lobe_integral(&k) * (n + 1.0) - 1.0).abs() < 1e-10,
                "v = {v}, n = {n}"
            );
            // A second method: a midpoint rule in t, written here.
            let steps = 400_000;
            let midpoint: f64 = (0..steps)
                .map(|i| k.eval((f64::from(i) + 0.5) / f64::from(steps)))
                .sum::<f64>()
                / f64::from(steps);
            assert!(
                (midpoint * (n + 1.0) - 1.0).abs() < 1e-5,
                "v = {v}, n = {n}: {midpoint}"
            );
        }
    }
    // Below 2^v the lobe reaches past the horizon and is cut there: less energy.
    assert!(energy_ratio(&lobe(LobeKind::CosQuad { v: 4 }, 4.0)) < 0.999);
}

/// `(n+1)/(2 pi) int_{hemisphere} cos^n(g) dw = 1`, here by a midpoint rule in `(g, phi)`.
#[test]
fn pow_normalised_by_n_plus_one_over_two_pi_integrates_to_one() {
    for n in [1.0, 10.0, 120.0] {
        let pow = lobe(LobeKind::Pow, n);
        let analytic = (n + 1.0) / (2.0 * PI);
        assert!((Normalisation::Lobe.analytic(Exponent::new(n)) - analytic).abs() < 1e-15);
        assert!((lobe_constant(&pow) / analytic - 1.0).abs() < 1e-10);
        let (rings, sectors) = (20_000, 8);
        let dg = FRAC_PI_2 / f64::from(rings);
        let dphi = 2.0 * PI / f64::from(sectors);
        let integral: f64 = (0..rings)
            .map(|i| {
                let g = (f64::from(i) + 0.5) * dg;
                pow.eval(g.cos()) * g.sin() * dg * dphi * f64::from(sectors)
            })
            .sum();
        assert!(
            (analytic * integral - 1.0).abs() < 1e-6,
            "n = {n}: {}",
            analytic * integral
        );
    }
}

/// At normal incidence the Phong lobe is centred on the normal:
/// `rho = (n+1)/(2 pi) * 2 pi int cos^n g cos g sin g dg = (n+1)/(n+2)`.
#[test]
fn phong_albedo_at_normal_incidence_is_n_plus_one_over_n_plus_two() {
    for n in [1.0, 5.0, 64.0, 1000.0] {
        let brdf = Brdf::new(
            Rgb::ZERO,
            Rgb::ONE,
            lobe(LobeKind::Pow, n),
            Geometry::Phong,
            Normalisation::Lobe,
        );
        let rho = directional_albedo(&brdf, 0.0).x;
        assert!((rho - (n + 1.0) / (n + 2.0)).abs() < 1e-9, "n = {n}: {rho}");
    }
}

/// The exact Blinn normalisation makes `int (N.H)^n (N.L) dw_L = 1` at normal incidence:
/// `8 pi int_0^{pi/4} cos^(n+1) cos(2 theta) sin = 8 pi (n + 2^(-n/2)) / ((n+2)(n+4))`.
#[test]
fn blinn_normalisation_gives_unit_albedo_at_normal_incidence() {
    for n in [1.0, 3.0, 50.0, 900.0] {
        let brdf = Brdf::new(
            Rgb::ZERO,
            Rgb::ONE,
            lobe(LobeKind::Pow, n),
            Geometry::Blinn,
            Normalisation::Blinn,
        );
        assert!(
            (directional_albedo(&brdf, 0.0).x - 1.0).abs() < 1e-9,
            "n = {n}"
        );
    }
}

#[test]
fn diffuse_albedo_is_kd() {
    let brdf = Brdf::new(
        Rgb::new(0.2, 0.5, 0.7),
        Rgb::ZERO,
        lobe(LobeKind::Pow, 10.0),
        Geometry::Phong,
        Normalisation::None,
    );
    for theta in [0.0, 0.7, 1.4] {
        assert!((directional_albedo(&brdf, theta) - Rgb::new(0.2, 0.5, 0.7)).length() < 1e-15);
    }
}

#[test]
fn cheb2_thesis_uses_the_slide_coefficients() {
    let [c, b, a] = thesis_coefficients(Exponent::new(100.0));
    assert_eq!(c, 1.0);
    assert!((a - (-0.272 * 100.0 - 0.16)).abs() < 1e-12);
    assert!((b - (-0.005 * 100.0 - 0.7)).abs() < 1e-12);
    let g: f64 = 0.02;
    let expected = 1.0 + b * g + a * g * g;
    assert!((lobe(LobeKind::Cheb2Thesis, 100.0).eval_angle(g) - expected).abs() < 1e-15);
}

/// `cheb2`'s coefficients are the thesis's closed-form conversion of a 3-node Chebyshev
/// series of `cos^n` over the epicentre, recomputed here from the slide's formulas.
#[test]
fn cheb2_coefficients_follow_the_thesis_formulas() {
    for n in [2.0, 30.0, 700.0] {
        let f = |x: f64| x.cos().powf(n);
        let (lo, hi) = (0.0, (-1.0 / n).exp2().acos());
        let (tm, tp) = ((hi - lo) / 2.0, (hi + lo) / 2.0);
        let c: Vec<f64> = (0..3)
            .map(|j| {
                (1..=3)
                    .map(|k| {
                        let theta = PI * (f64::from(k) - 0.5) / 3.0;
                        f(theta.cos() * tm + tp) * (f64::from(j) * theta).cos()
                    })
                    .sum::<f64>()
                    * 2.0
                    / 3.0
            })
            .collect();
        let a = 2.0 * c[2] / (tm * tm);
        let b = (c[1] * tm - 4.0 * c[2] * tp) / (tm * tm);
        let cc = (2.0 * c[2] * tp * tp - c[1] * tp * tm) / (tm * tm) + c[0] / 2.0 - c[2];
        let got = lobe(LobeKind::Cheb2, n)
            .angle_quadratic()
            .map(|q| q.coeffs());
        let [gc, gb, ga] = got.expect("cheb2 is a quadratic in the angle");
        for (x, y) in [(gc, cc), (gb, b), (ga, a)] {
            assert!(
                (x - y).abs() <= 1e-9 * y.abs().max(1.0),
                "n = {n}: {x} vs {y}"
            );
        }
    }
}
