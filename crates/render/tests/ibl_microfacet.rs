//! The environment-lit renderer in the microfacet model: in a white furnace a plane's mean
//! radiance is the core's directional albedo of the material's microfacet model (the diffuse
//! term's `kd C` plus `ks` times the distribution's Fresnel-weighted `E(mu)`, integrated over
//! the half vector by `specula::microfacet::energy`), for lobes of each sampling kind, rough
//! and sharp, seen from 30 and 60 degrees.

use glam::Vec3;
use specula::microfacet::energy::directional_albedo_with_fresnel;
use specula::microfacet::Distribution;
use specula::{Exponent, LobeKind};
use specula_render::ibl::{Environment, IblSettings, Strategy};
use specula_render::microfacet_scene::render_ibl_microfacet;
use specula_render::Scene;

/// A plane filling an orthographic view from `theta_o` degrees off its normal.
fn plane_at(theta_o: f64, material: &str) -> Scene {
    let (s, c) = theta_o.to_radians().sin_cos();
    let text = format!(
        "[camera]\neye = [0, {}, {}]\ntarget = [0, 0, 0]\northographic = 1.0\n\
         [render]\nwidth = 16\nheight = 16\nsamples = 1\n\
         [[objects]]\nshape = \"plane\"\nsize = 100.0\n[objects.material]\n{material}\n",
        -10.0 * s,
        10.0 * c
    );
    Scene::from_toml(&text, "test.toml", None).unwrap().scene
}

#[test]
fn the_white_furnace_gives_the_microfacet_models_albedo() {
    let furnace = Environment::constant(Vec3::ONE);
    let settings = IblSettings {
        spp: 256,
        seed: 1,
        strategy: Strategy::Mis,
    };
    for kind in [
        LobeKind::Pow,
        LobeKind::Schlick,
        LobeKind::CosQuad { v: 4 },
        LobeKind::SchlickMod,
    ] {
        for (n, theta_o) in [(8.0, 30.0), (64.0, 60.0)] {
            let material = format!(
                "kd = 0.3\nks = 0.8\ncolour = [1, 1, 1]\nspecular_colour = [0.5, 0.04, 1]\n\
                 lobe = \"{kind}\"\nn = {n}"
            );
            let scene = plane_at(theta_o, &material);
            let image = render_ibl_microfacet(&scene, &furnace, &settings, &|_, _| {}).unwrap();
            let distribution = Distribution::lobe(kind, Exponent::new(n));
            let cos_o = theta_o.to_radians().cos();
            for (c, f0) in [0.5, 0.04, 1.0].into_iter().enumerate() {
                let values: Vec<f64> = image.pixels().iter().map(|p| f64::from(p[c])).collect();
                assert!(values.iter().all(|v| v.is_finite() && *v >= 0.0));
                let count = values.len() as f64;
                let mean = values.iter().sum::<f64>() / count;
                let variance =
                    values.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / (count - 1.0);
                let error = (variance / count).sqrt();
                let albedo = 0.3 + 0.8 * directional_albedo_with_fresnel(&distribution, cos_o, f0);
                assert!(
                    (mean - albedo).abs() < 5.0 * error + 2e-3,
                    "{kind} n {n} at {theta_o} degrees, channel {c}: {mean} +- {error}, \
                     albedo {albedo}"
                );
            }
        }
    }
}
