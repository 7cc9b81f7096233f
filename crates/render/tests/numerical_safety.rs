//! No NaN and no infinity out of finite inputs: lobes at any cosine, BRDFs and the shader at
//! unnormalised, zero-length and grazing directions, and whole renders of random valid
//! scenes.

use glam::{DVec3, Vec3};
use proptest::prelude::*;
use specula::{Brdf, Exponent, Geometry, Lobe, LobeKind, Normalisation, Rgb};
use specula_render::{IlluminationModel, Light, Material, Scene, Shader, Shading};

fn any_lobe() -> impl Strategy<Value = LobeKind> {
    proptest::sample::select(LobeKind::ALL.to_vec())
}

fn any_exponent() -> impl Strategy<Value = Exponent> {
    (1.0f64..=1000.0).prop_map(Exponent::new)
}

/// Finite values across the whole range: huge, tiny, subnormal, zero, both signs.
fn any_finite() -> impl Strategy<Value = f64> {
    prop_oneof![
        -2.0f64..2.0,
        proptest::num::f64::NORMAL | proptest::num::f64::SUBNORMAL | proptest::num::f64::ZERO,
        Just(1.0 + f64::EPSILON),
        Just(-0.0),
    ]
}

fn any_vector() -> impl Strategy<Value = DVec3> {
    prop_oneof![
        (any_finite(), any_finite(), any_finite()).prop_map(|(x, y, z)| DVec3::new(x, y, z)),
        Just(DVec3::ZERO),
        // Grazing: almost in the surface's plane.
        (0.0f64..core::f64::consts::TAU).prop_map(|a| DVec3::new(a.cos(), a.sin(), 1e-9)),
    ]
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(3000))]

    #[test]
    fn every_lobe_is_finite_in_unit_range_for_any_finite_cosine(
        kind in any_lobe(),
        n in any_exponent(),
        t in any_finite(),
    ) {
        let lobe = Lobe::new(kind, n);
        let value = lobe.eval(t);
        prop_assert!(value.is_finite() && (0.0..=1.0).contains(&value), "{kind} n={n} t={t}: \
            {value}");
        let narrow = t as f32;
        if narrow.is_finite() {
            let value = lobe.eval(narrow);
            prop_assert!(value.is_finite() && (0.0..=1.0).contains(&value), "{kind} n={n} \
                t={narrow}: {value}");
            let mut batch = [0.0f32];
            lobe.eval_batch(&[narrow], &mut batch);
            prop_assert!(batch[0].is_finite() && (0.0..=1.0).contains(&batch[0]), "batch {kind} \
                n={n} t={narrow}");
        }
    }

    #[test]
    fn brdfs_are_finite_for_any_directions(
        kind in any_lobe(), n in any_exponent(), wo in any_vector(), wi in any_vector(),
        geometry in proptest::sample::select(Geometry::ALL.to_vec()),
        normalisation in proptest::sample::select(Normalisation::ALL.to_vec()),
    ) {
        let (kd, ks) = (Rgb::splat(0.3), Rgb::splat(0.6));
        let brdf = Brdf::new(kd, ks, Lobe::new(kind, n), geometry, normalisation);
        let f = brdf.f(wo, wi);
        prop_assert!(f.is_finite() && f.min_element() >= 0.0, "{kind} n={n} {wo} {wi}: {f}");
    }

    #[test]
    fn the_shader_is_finite_for_any_surface_and_light(
        kind in any_lobe(), n in any_exponent(), normal in any_vector(), wo in any_vector(),
        position in any_vector(), light_at in any_vector(), towards in any_vector(),
        model in proptest::sample::select(IlluminationModel::ALL.to_vec()),
        normalisation in proptest::sample::select(Normalisation::ALL.to_vec()),
    ) {
        // Into f32's finite range (huge components stay huge).
        let narrow = |v: DVec3| v.clamp(DVec3::splat(-1e30), DVec3::splat(1e30)).as_vec3();
        let material = Material {
            ka: 0.1, kd: 0.5, ks: 0.4,
            colour: Vec3::new(0.8, 0.4, 0.2), specular_colour: Vec3::ONE,
            lobe: Lobe::new(kind, n), geometry: Geometry::Blinn, normalisation,
        };
        let lights = [
            Light::Point { position: narrow(light_at), intensity: Vec3::ONE },
            Light::Directional { towards: narrow(towards), intensity: Vec3::splat(0.5) },
        ];
        let shader = Shader::new(&material, model);
        let ambient = Vec3::splat(0.1);
        let radiance =
            shader.shade(narrow(position), narrow(normal), narrow(wo), &lights, ambient);
        prop_assert!(radiance.is_finite() && radiance.min_element() >= 0.0, "{radiance}");
    }
}

/// A random valid scene as scene-format text: camera, lights, shapes and materials of every
/// kind, in every shading method and model.
fn any_scene() -> impl Strategy<Value = String> {
    let vector = |range: core::ops::Range<f32>| {
        (range.clone(), range.clone(), range).prop_map(|(x, y, z)| format!("[{x}, {y}, {z}]"))
    };
    let object = (
        proptest::sample::select(vec!["sphere", "torus", "plane", "teapot"]),
        vector(-3.0..3.0),
        0.01f32..5.0,
        any_lobe(),
        1.0f64..=1000.0,
        proptest::sample::select(Geometry::ALL.to_vec()),
        proptest::sample::select(Normalisation::ALL.to_vec()),
        vector(0.0..1.0),
    )
        .prop_map(
            |(shape, at, scale, lobe, n, geometry, normalisation, colour)| {
                let size = match shape {
                    "plane" => "size = 20.0\n",
                    "teapot" => "level = 2\n",
                    "torus" => "segments = 12\nsides = 8\n",
                    _ => "segments = 12\nrings = 6\n",
                };
                format!(
                    "[[objects]]\nshape = \"{shape}\"\n{size}scale = {scale}\ntranslate = \
                    {at}\n[objects.material]\nlobe = \"{}\"\nn = {n}\ngeometry = \
                    \"{}\"\nnormalisation = \"{}\"\ncolour = {colour}\n",
                    lobe.id(),
                    geometry.id(),
                    normalisation.id()
                )
            },
        );
    let light = prop_oneof![
        vector(-10.0..10.0).prop_map(|p| format!(
            "[[lights]]\nkind = \"point\"\nposition = {p}\nintensity = [0.7, 0.7, 0.7]\n"
        )),
        vector(-1.0..1.0).prop_map(|d| format!(
            "[[lights]]\nkind = \"directional\"\ntowards = {d}\nintensity = [1.0, 1.0, 1.0]\n"
        )),
    ];
    (
        vector(-12.0..12.0),
        prop_oneof![
            (5.0f32..150.0).prop_map(|f| format!(
                "fov = \
            {f}"
            )),
            (0.5f32..20.0).prop_map(|h| format!("orthographic = {h}"))
        ],
        (8u32..40, 8u32..40, 1u32..=2),
        proptest::sample::select(Shading::ALL.to_vec()),
        proptest::sample::select(IlluminationModel::ALL.to_vec()),
        proptest::collection::vec(light, 1..3),
        proptest::collection::vec(object, 1..4),
    )
        .prop_map(
            |(eye, projection, (width, height, samples), shading, model, lights, objects)| {
                format!(
                    "[camera]\neye = {eye}\ntarget = [0.0, 0.0, 0.0]\nup = [0.0, 0.0, \
                    1.0]\n{projection}\n[render]\nwidth = {width}\nheight = {height}\nsamples = \
                    {samples}\nshading = \"{}\"\nmodel = \"{}\"\n{}{}",
                    shading.id(),
                    model.id(),
                    lights.concat(),
                    objects.concat()
                )
            },
        )
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]

    #[test]
    fn random_valid_scenes_render_without_a_nan_pixel(text in any_scene()) {
        // The generator writes only valid scenes: a refusal is a failure, so that no case
        // passes without rendering.
        let loaded = Scene::from_toml(&text, "random.toml", None)
            .map_err(|e| TestCaseError::fail(format!("{e}\n{text}")))?;
        let image = specula_render::render(&loaded.scene, &|_, _| {}).expect("valid size");
        let valid = |p: &Vec3| p.is_finite() && p.min_element() >= 0.0;
        prop_assert!(image.pixels().iter().all(valid), "{text}");
    }
}

/// Found by the property above: a point light a subnormal distance from the shaded point (its
/// distance squared underflows in `f32`) sent infinite radiance in the physical model.
#[test]
fn a_point_light_on_the_surface_sends_finite_radiance() {
    for kind in LobeKind::ALL {
        let material = Material {
            ka: 0.1,
            kd: 0.5,
            ks: 0.4,
            colour: Vec3::new(0.8, 0.4, 0.2),
            specular_colour: Vec3::ONE,
            lobe: Lobe::new(kind, Exponent::new(1000.0)),
            geometry: Geometry::Blinn,
            normalisation: Normalisation::Lobe,
        };
        let light = [Light::Point {
            position: Vec3::ZERO,
            intensity: Vec3::ONE,
        }];
        let normal = Vec3::new(0.890_045_2, -0.455_872_3, 1e-9);
        let radiance = Shader::new(&material, IlluminationModel::Physical).shade(
            Vec3::new(0.0, 8.664e-23, 0.0),
            normal,
            Vec3::new(1.0, 0.0, 1e-9),
            &light,
            Vec3::splat(0.1),
        );
        assert!(
            radiance.is_finite() && radiance.min_element() >= 0.0,
            "{kind}: {radiance}"
        );
    }
}
