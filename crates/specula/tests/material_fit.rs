//! The material fit recovers models it is given: observations made by the core's `Brdf`
//! (a second implementation of the classic model) or by a GGX written out here are fitted
//! back to their own parameters, with an error at rounding level; channels with different
//! exponents are told apart by the per-channel fit and not by the shared one; and the
//! verdict picks the cheapest lobe within the margin.

#![allow(clippy::needless_range_loop)]

use core::f64::consts::PI;

use glam::DVec3;
use specula::measured::fit::verdict::{verdict, verdict_of, Model};
use specula::measured::fit::{fit, Fit, Normals, Observations, Sharing, Specular};
use specula::{Brdf, Exponent, Geometry, Lobe, LobeKind, Normalisation, Rgb};

fn close(a: f64, b: f64, relative: f64) -> bool {
    (a - b).abs() <= relative * b.abs().max(1e-9)
}

#[test]
fn a_classic_model_is_fitted_back_to_its_parameters() {
    for (geometry, n) in [(Geometry::Phong, 37.0), (Geometry::Blinn, 180.0)] {
        let lobe = Lobe::new(LobeKind::Pow, Exponent::new(n));
        let (kd, ks) = (Rgb::new(0.30, 0.12, 0.05), Rgb::new(0.04, 0.05, 0.06));
        let brdf = Brdf::new(kd, ks, lobe, geometry, Normalisation::Lobe);
        let observations = Observations::of(|wo, wi| brdf.f(wo, wi) * wi.z);
        let fitted = fit(
            &observations,
            Specular::Lobe {
                kind: LobeKind::Pow,
                geometry,
            },
            Sharing::Shared,
        );
        assert!(fitted.error < 1e-6, "{geometry:?}: error {}", fitted.error);
        assert!(
            close(fitted.parameter[0], n, 1e-3),
            "n {:?}",
            fitted.parameter
        );
        let ks_lobe = fitted.ks(Normalisation::Lobe).expect("a lobe has ks");
        for c in 0..3 {
            assert!(close(fitted.kd[c], kd[c], 1e-3), "kd {:?}", fitted.kd);
            assert!(close(ks_lobe[c], ks[c], 1e-3), "ks {ks_lobe:?}");
            // K is ks N(n) under any normalisation: the analytic (n + 1) / 2 pi here.
            assert!(close(fitted.k[c], ks[c] * (n + 1.0) / (2.0 * PI), 1e-3));
        }
    }
}

#[test]
fn channels_with_their_own_exponents_need_the_per_channel_fit() {
    let exponents = [12.0, 60.0, 400.0];
    let brdfs = exponents.map(|n| {
        Brdf::new(
            Rgb::splat(0.2),
            Rgb::splat(0.05),
            Lobe::new(LobeKind::Pow, Exponent::new(n)),
            Geometry::Blinn,
            Normalisation::Lobe,
        )
    });
    let observations = Observations::of(|wo, wi| {
        Rgb::new(
            brdfs[0].f(wo, wi).x,
            brdfs[1].f(wo, wi).y,
            brdfs[2].f(wo, wi).z,
        ) * wi.z
    });
    let pow = Specular::Lobe {
        kind: LobeKind::Pow,
        geometry: Geometry::Blinn,
    };
    let per_channel = fit(&observations, pow, Sharing::PerChannel);
    let shared = fit(&observations, pow, Sharing::Shared);
    for c in 0..3 {
        assert!(
            close(per_channel.parameter[c], exponents[c], 2e-3),
            "{:?}",
            per_channel.parameter
        );
    }
    assert!(per_channel.error < 1e-6);
    assert!(shared.error > 100.0 * per_channel.error.max(1e-9));
}

/// GGX with height-correlated Smith masking, written from Heitz (2014) independently of the
/// library's.
fn ggx_f(alpha: f64, wo: DVec3, wi: DVec3) -> f64 {
    let h = (wo + wi).normalize();
    let a2 = alpha * alpha;
    let d = a2 / (PI * (h.z * h.z * (a2 - 1.0) + 1.0).powi(2));
    let lambda = |z: f64| ((1.0 + a2 * (1.0 / (z * z) - 1.0)).sqrt() - 1.0) / 2.0;
    d / (1.0 + lambda(wo.z) + lambda(wi.z)) / (4.0 * wo.z * wi.z)
}

#[test]
fn ggx_is_fitted_back_to_its_roughness() {
    let alpha = 0.12;
    fitted_back(Specular::Ggx, alpha, |wo, wi| ggx_f(alpha, wo, wi));
}

/// Schlick's Fresnel factor per channel for `F0 = (0.04, 0.5, 0.95)` (a dielectric, a
/// coloured metal's red and green), written out here.
fn fresnel(wo: DVec3, wi: DVec3) -> Rgb {
    let cos = wo.dot((wo + wi).normalize());
    let s = (1.0 - cos).powi(5);
    Rgb::new(0.04, 0.5, 0.95) * (1.0 - s) + Rgb::splat(s)
}

/// `specular` fitted to `kd / pi + K spec` (fixed `kd` and `K`; times [`fresnel`] where the
/// family has a Fresnel term) finds `parameter`, `kd`, `K` (and `F0`) again, at rounding
/// level.
fn fitted_back(specular: Specular, parameter: f64, spec: impl Fn(DVec3, DVec3) -> f64 + Sync) {
    let with_fresnel = specular.has_fresnel();
    let observations = Observations::of(|wo, wi| {
        let f = if with_fresnel {
            fresnel(wo, wi)
        } else {
            Rgb::ONE
        };
        (Rgb::new(0.1, 0.2, 0.3) / PI + Rgb::new(0.9, 0.7, 0.5) * f * spec(wo, wi)) * wi.z
    });
    let fitted = fit(&observations, specular, Sharing::Shared);
    assert!(fitted.error < 1e-6, "{}", fitted.error);
    assert!(
        close(fitted.parameter[0], parameter, 1e-3),
        "{:?}",
        fitted.parameter
    );
    assert!(close(fitted.k[1], 0.7, 1e-3) && close(fitted.kd[2], 0.3, 1e-3));
    match fitted.f0 {
        Some(f0) => {
            assert!(with_fresnel);
            for (c, expected) in [0.04, 0.5, 0.95].into_iter().enumerate() {
                assert!(close(f0[c], expected, 1e-3), "F0 {f0:?}");
            }
        }
        None => assert!(!with_fresnel, "no F0 fitted"),
    }
}

fn stub(kind: LobeKind, error: f64) -> Fit {
    Fit {
        specular: Specular::Lobe {
            kind,
            geometry: Geometry::Phong,
        },
        sharing: Sharing::Shared,
        parameter: [10.0; 3],
        kd: [0.0; 3],
        k: [0.0; 3],
        f0: None,
        error,
        channel_error: [error; 3],
    }
}

#[test]
fn the_verdict_is_the_cheapest_lobe_within_the_margin() {
    let mut ggx = stub(LobeKind::Pow, 0.5);
    ggx.specular = Specular::Ggx;
    let fits = vec![
        stub(LobeKind::Pow, 0.100),
        stub(LobeKind::Schlick, 0.104),
        stub(LobeKind::ALL[8], 0.103),
        stub(LobeKind::FasterPow, 0.2),
        ggx,
    ];
    // Rates: faster-pow is cheapest but 2x pow's error; schlick is next and within 5 %.
    let rate = [Some(1.0), Some(3.0), Some(2.0), Some(9.0), None];
    let within_5 = verdict(&fits, 0.05, &rate).expect("pow is there");
    assert_eq!(within_5.chosen, 1);
    assert!(!within_5.standings[3].meets && !within_5.standings[4].meets);
    assert!(close(within_5.standings[1].relative_to_pow, 1.04, 1e-12));
    assert!(close(within_5.standings[0].relative_to_ggx, 0.2, 1e-12));
    // Within 3.5 % schlick (4 %) is out and cosquad (3 %) the cheapest left; within 1 %, pow.
    assert_eq!(verdict(&fits, 0.035, &rate).unwrap().chosen, 2);
    assert_eq!(verdict(&fits, 0.01, &rate).unwrap().chosen, 0);
}

/// The bounds `kd, K >= 0` are reached exactly: a purely specular material is fitted with no
/// diffuse term, a purely diffuse one with no specular term.
#[test]
fn pure_terms_are_fitted_at_their_bounds() {
    let pow = Specular::Lobe {
        kind: LobeKind::Pow,
        geometry: Geometry::Phong,
    };
    let glossy = Brdf::new(
        Rgb::ZERO,
        Rgb::new(0.2, 0.3, 0.4),
        Lobe::new(LobeKind::Pow, Exponent::new(50.0)),
        Geometry::Phong,
        Normalisation::Lobe,
    );
    let fitted = fit(
        &Observations::of(|wo, wi| glossy.f(wo, wi) * wi.z),
        pow,
        Sharing::Shared,
    );
    assert!(
        fitted.error < 1e-6 && close(fitted.parameter[0], 50.0, 1e-3),
        "{fitted:?}"
    );
    assert!(fitted.kd.iter().all(|&kd| kd < 1e-6), "{:?}", fitted.kd);
    let matte = Rgb::new(0.5, 0.4, 0.3);
    let fitted = fit(
        &Observations::of(|_, wi| matte / PI * wi.z),
        pow,
        Sharing::PerChannel,
    );
    assert!(fitted.error < 1e-6, "{fitted:?}");
    for c in 0..3 {
        assert!(
            close(fitted.kd[c], matte[c], 1e-6) && fitted.k[c] < 1e-6,
            "{fitted:?}"
        );
    }
}

/// Beckmann's microfacet model written out here (its `D`, its exact `Lambda` by `erfc` and
/// Schlick's Fresnel) is fitted back to its roughness and `F0` by the microfacet model's
/// Beckmann family; and the lobes as distributions fit a model made of `pow`'s distribution
/// back to its `n`.
#[test]
fn microfacet_models_are_fitted_back_to_their_parameters() {
    let alpha: f64 = 0.2;
    let lambda = |cos: f64| {
        let a = cos / (alpha * (1.0 - cos * cos).sqrt());
        0.5 * ((-a * a).exp() / (a * PI.sqrt()) - libm::erfc(a))
    };
    let beckmann = |wo: DVec3, wi: DVec3| {
        let h = (wo + wi).normalize();
        let tan2 = (1.0 - h.z * h.z) / (h.z * h.z);
        let d = (-tan2 / (alpha * alpha)).exp() / (PI * alpha * alpha * h.z.powi(4));
        d / (1.0 + lambda(wo.z) + lambda(wi.z)) / (4.0 * wo.z * wi.z)
    };
    fitted_back(
        Specular::Microfacet {
            normals: Normals::Beckmann,
        },
        alpha,
        beckmann,
    );
    let pow = specula::microfacet::Distribution::lobe(LobeKind::Pow, Exponent::new(40.0));
    fitted_back(
        Specular::Microfacet {
            normals: Normals::Lobe(LobeKind::Pow),
        },
        40.0,
        |wo, wi| specula::measured::fit::microfacet_specular(&pow, wo, wi),
    );
}

/// In the microfacet model the candidates are the distributions and the reference GGX's fit:
/// the cheapest distribution within the margin of GGX wins, and where none is within it the
/// closest distribution is the answer, marked as not within.
#[test]
fn the_microfacet_verdict_is_the_cheapest_distribution_near_ggx() {
    let distribution = |kind, error| Fit {
        specular: Specular::Microfacet {
            normals: Normals::Lobe(kind),
        },
        ..stub(kind, error)
    };
    let mut ggx = stub(LobeKind::Pow, 0.100);
    ggx.specular = Specular::Microfacet {
        normals: Normals::Ggx,
    };
    let fits = vec![
        stub(LobeKind::Pow, 0.090),
        distribution(LobeKind::Pow, 0.101),
        distribution(LobeKind::Schlick, 0.104),
        distribution(LobeKind::Sg, 0.2),
        ggx,
    ];
    let rate = [Some(5.0), Some(1.0), Some(2.0), Some(9.0), None];
    let within_5 = verdict_of(Model::Microfacet, &fits, 0.05, &rate).expect("ggx is there");
    // The classic pow fit, cheaper still, is no candidate of this model.
    assert_eq!(within_5.chosen, 2);
    assert!(close(within_5.reference_error, 0.100, 1e-12));
    assert!(close(
        within_5.standings[2].relative_to_pow,
        0.104 / 0.101,
        1e-12
    ));
    assert_eq!(
        verdict_of(Model::Microfacet, &fits, 0.02, &rate)
            .unwrap()
            .chosen,
        1
    );
    // Within 0.5 % none meets: the closest distribution with a rate, said not to be within.
    let none_within = verdict_of(Model::Microfacet, &fits, 0.005, &rate).unwrap();
    assert!(!none_within.within_margin && none_within.standings.iter().all(|s| !s.meets));
    assert_eq!(none_within.chosen, 1);
    assert!(within_5.within_margin);
}
