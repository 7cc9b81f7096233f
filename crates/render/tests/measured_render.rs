//! A measured material and fitted models as the environment renderer's BRDFs: in a white
//! furnace every pixel of a plane seen from `theta_o` estimates the directional albedo, so
//! the render's mean must match it by each strategy alone (the data's own sampler, and the
//! environment's uniform one) and by their combination; the albedo comes from a second
//! method (the material's stratified estimate, checked against quadrature in the core's
//! tests; the fits' closed-form quadrature).

use std::path::Path;

use glam::Vec3;
use specula::measured::fit::{Fit, Normals, Sharing, Specular};
use specula::{Geometry, LobeKind};
use specula_render::ibl::{render_ibl_with, Environment, IblSettings, Reflectance, Strategy};
use specula_render::measured::{load_measured, FittedReflectance, MeasuredReflectance};
use specula_render::{Image, Scene};

/// A plane filling an orthographic view from `theta_o` degrees off its normal.
fn plane_at(theta_o: f64) -> Scene {
    let (s, c) = theta_o.to_radians().sin_cos();
    let text = format!(
        "[camera]\neye = [0, {}, {}]\ntarget = [0, 0, 0]\nup = [0, 1, 0]\northographic = 1.0\n\
         [render]\nwidth = 16\nheight = 16\nsamples = 1\nmodel = \"physical\"\n\
         [[objects]]\nshape = \"plane\"\nsize = 100.0\n",
        -10.0 * s,
        10.0 * c
    );
    Scene::from_toml(&text, "plane.toml", None).unwrap().scene
}

/// The mean of each channel and the largest standard error.
fn mean_and_error(image: &Image) -> (Vec3, f32) {
    let n = image.pixels().len() as f32;
    let mean = image.pixels().iter().copied().sum::<Vec3>() / n;
    let variance = image
        .pixels()
        .iter()
        .map(|p| (*p - mean) * (*p - mean))
        .sum::<Vec3>()
        / (n - 1.0);
    (mean, (variance / n).max_element().sqrt())
}

fn furnace(reflectance: &dyn Reflectance, theta_o: f64, strategy: Strategy) -> (Vec3, f32) {
    let settings = IblSettings {
        spp: 512,
        seed: 3,
        strategy,
    };
    let image = render_ibl_with(
        &plane_at(theta_o),
        &Environment::constant(Vec3::ONE),
        &settings,
        reflectance,
        &|_, _| {},
    )
    .unwrap();
    assert!(image
        .pixels()
        .iter()
        .all(|p| p.is_finite() && p.min_element() >= 0.0));
    mean_and_error(&image)
}

#[test]
fn a_measured_material_reflects_its_albedo_by_every_strategy() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../data/rgl");
    for (name, theta_o) in [
        ("paper_white_rgb", 0.0_f64),
        ("cc_iris_purple_gem_rgb", 40.0),
    ] {
        let material = load_measured(&path.join(format!("{name}.bsdf"))).unwrap();
        let wo = glam::DVec3::new(theta_o.to_radians().sin(), 0.0, theta_o.to_radians().cos());
        let albedo = material.albedo(wo, 512).as_vec3();
        for strategy in [Strategy::Mis, Strategy::Brdf, Strategy::Environment] {
            let (mean, error) = furnace(&MeasuredReflectance(&material), theta_o, strategy);
            assert!(
                (mean - albedo).abs().max_element() < 5.0 * error + 2e-3,
                "{name} {strategy:?}: {mean} +- {error}, albedo {albedo}"
            );
        }
    }
}

/// `int f cos dwi` of `fit` for `wo` at `theta_o` degrees, by the midpoint rule in the
/// light's elevation and azimuth.
fn quadrature_albedo(fit: &Fit, theta_o: f64) -> Vec3 {
    let wo = glam::DVec3::new(theta_o.to_radians().sin(), 0.0, theta_o.to_radians().cos());
    let (m, k) = (400, 800);
    let model = fit.prepare();
    let mut sum = glam::DVec3::ZERO;
    for i in 0..m {
        let theta = core::f64::consts::FRAC_PI_2 * (i as f64 + 0.5) / m as f64;
        for j in 0..k {
            let phi = core::f64::consts::TAU * (j as f64 + 0.5) / k as f64;
            let wi = glam::DVec3::new(
                theta.sin() * phi.cos(),
                theta.sin() * phi.sin(),
                theta.cos(),
            );
            sum += model.f_cos(wo, wi) * theta.sin();
        }
    }
    (sum * (core::f64::consts::FRAC_PI_2 / m as f64) * (core::f64::consts::TAU / k as f64))
        .as_vec3()
}

#[test]
fn fitted_models_reflect_their_quadrature_albedo() {
    let lobe = Fit {
        specular: Specular::Lobe {
            kind: LobeKind::Pow,
            geometry: Geometry::Blinn,
        },
        sharing: Sharing::PerChannel,
        parameter: [20.0, 60.0, 200.0],
        kd: [0.3, 0.2, 0.1],
        k: [0.5, 1.5, 4.0],
        f0: None,
        error: 0.0,
        channel_error: [0.0; 3],
    };
    let ggx = Fit {
        specular: Specular::Ggx,
        parameter: [0.3, 0.2, 0.1],
        ..lobe.clone()
    };
    let phong = Fit {
        specular: Specular::Lobe {
            kind: LobeKind::Pow,
            geometry: Geometry::Phong,
        },
        parameter: [8.0, 20.0, 50.0],
        ..lobe.clone()
    };
    // A lobe as a distribution with Schlick's Fresnel: its albedo at normal incidence is the
    // Fresnel-weighted integral, its sampling the distribution's.
    let distribution = Fit {
        specular: Specular::Microfacet {
            normals: Normals::Lobe(LobeKind::CosQuad { v: 2 }),
        },
        parameter: [10.0, 40.0, 120.0],
        f0: Some([0.04, 0.5, 0.9]),
        ..lobe.clone()
    };
    for fit in [lobe, ggx, phong, distribution] {
        // At normal incidence against the closed-form albedo; at 60 degrees, where the
        // half vector leaves the normal, against a quadrature of the model itself.
        let at_normal = Vec3::from_array(fit.albedo_at_normal().map(|v| v as f32));
        for (theta_o, albedo) in [(0.0, at_normal), (60.0, quadrature_albedo(&fit, 60.0))] {
            for strategy in [Strategy::Mis, Strategy::Brdf] {
                let (mean, error) = furnace(&FittedReflectance::new(&fit), theta_o, strategy);
                assert!(
                    (mean - albedo).abs().max_element() < 5.0 * error + 2e-3,
                    "{} at {theta_o} {strategy:?}: {mean} +- {error}, albedo {albedo}",
                    fit.specular.label()
                );
            }
        }
    }
}
