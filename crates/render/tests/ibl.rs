//! Image-based lighting: the environment's sampling against its own density and its
//! integral, white furnaces against the quadrature albedo, the three strategies against one
//! another, and the error against a high-spp reference falling as `1 / sqrt(spp)`.

use core::f64::consts::PI;

use glam::{DVec3, Vec3};
use specula::analysis::albedo::specular_albedo_per_unit;
use specula::sampling::uniform;
use specula::{Geometry, LobeKind, Normalisation};
use specula_render::ibl::{render_ibl, render_ibl_lobes, Environment, IblSettings, Strategy};
use specula_render::metrics::{mean_radiance, rms_difference};
use specula_render::{read_image, write_image, Display, Image, Overrides, Scene};

fn scene(text: &str) -> Scene {
    Scene::from_toml(text, "test.toml", None).unwrap().scene
}

/// A plane filling an orthographic view from `theta_o` degrees off its normal: every pixel
/// sees the same `wo`, so every pixel is an independent estimate of the same radiance.
fn plane_at(theta_o: f64, material: &str) -> Scene {
    let (s, c) = theta_o.to_radians().sin_cos();
    scene(&format!(
        "[camera]\neye = [0, {}, {}]\ntarget = [0, 0, 0]\northographic = 1.0\n\
         [render]\nwidth = 16\nheight = 16\nsamples = 1\nmodel = \"physical\"\n\
         [[objects]]\nshape = \"plane\"\nsize = 100.0\n[objects.material]\n{material}\n",
        -10.0 * s,
        10.0 * c
    ))
}

/// The mean of the red channel over the image and its standard error.
fn mean_and_error(image: &Image) -> (f64, f64) {
    let values: Vec<f64> = image.pixels().iter().map(|p| f64::from(p.x)).collect();
    let n = values.len() as f64;
    let mean = values.iter().sum::<f64>() / n;
    let variance = values.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / (n - 1.0);
    (mean, (variance / n).sqrt())
}

/// The render, required to hold finite, non-negative radiance in every pixel.
fn render(
    scene: &Scene,
    environment: &Environment,
    spp: u32,
    seed: u64,
    strategy: Strategy,
) -> Image {
    let settings = IblSettings {
        spp,
        seed,
        strategy,
    };
    let image = render_ibl(scene, environment, &settings, &|_, _| {}).unwrap();
    for pixel in image.pixels() {
        assert!(
            pixel.is_finite() && pixel.min_element() >= 0.0,
            "{pixel} ({strategy:?})"
        );
    }
    image
}

/// The integral of the map's green channel over the sphere, pixel by pixel with each
/// row's exact solid angle.
fn map_integral(environment: &Environment) -> f64 {
    let image = environment.image();
    let (w, h) = (image.width(), image.height());
    let mut integral = 0.0;
    for y in 0..h {
        let band =
            (PI * f64::from(y) / f64::from(h)).cos() - (PI * f64::from(y + 1) / f64::from(h)).cos();
        for x in 0..w {
            integral += f64::from(image.get(x, y).y) * band * 2.0 * PI / f64::from(w);
        }
    }
    integral
}

#[test]
fn environment_draws_carry_their_density_and_integrate_the_map() {
    let sky = Environment::sky(256);
    // The map's integral over the sphere, pixel by pixel with each row's exact solid angle.
    let integral = map_integral(&sky);
    // The density integrates to 1 (midpoint rule on a grid finer than the map's).
    let (rows, columns) = (1024, 2048);
    let mut total = 0.0;
    for i in 0..rows {
        let theta = PI * (f64::from(i) + 0.5) / f64::from(rows);
        for j in 0..columns {
            let phi = 2.0 * PI * (f64::from(j) + 0.5) / f64::from(columns);
            let wi = DVec3::new(
                theta.sin() * phi.cos(),
                theta.sin() * phi.sin(),
                theta.cos(),
            );
            total += sky.pdf(wi)
                * theta.sin()
                * (PI / f64::from(rows))
                * (2.0 * PI / f64::from(columns));
        }
    }
    assert!(
        (total - 1.0).abs() < 2e-3,
        "the density integrates to {total}"
    );
    // Monte Carlo `L / pdf` over draws estimates the same integral, and each draw's density
    // is what `pdf` says.
    let count = 200_000;
    let mut values = Vec::with_capacity(count);
    for index in 0..count as u64 {
        let draw = sky
            .sample([uniform(5, index, 0), uniform(5, index, 1)])
            .unwrap();
        let again = sky.pdf(draw.wi);
        assert!(
            (draw.pdf / again - 1.0).abs() < 1e-9,
            "{draw:?} against {again}"
        );
        values.push(f64::from(draw.radiance.y) / draw.pdf);
    }
    let mean = values.iter().sum::<f64>() / count as f64;
    let error =
        (values.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / count as f64 / count as f64)
            .sqrt();
    assert!(
        (mean - integral).abs() < 5.0 * error + 1e-6 * integral,
        "{mean} +- {error} against {integral}"
    );
}

/// Specular only, in a white furnace: the mean radiance is the lobe's directional albedo
/// `N(n) int lobe cos` from the core's quadrature, for every lobe and both geometries.
#[test]
fn the_white_furnace_gives_each_lobes_quadrature_albedo() {
    let furnace = Environment::constant(Vec3::ONE);
    for kind in LobeKind::ALL {
        for geometry in Geometry::ALL {
            for (n, theta_o) in [(8.0, 30.0), (64.0, 60.0)] {
                let material = format!(
                    "kd = 0.0\nks = 1.0\nlobe = \"{}\"\nn = {n}\ngeometry = \"{}\"\nnormalisation \
                        = \"lobe\"",
                    kind.id(),
                    geometry.id()
                );
                let scene = plane_at(theta_o, &material);
                let lobe = scene.objects[0].material.lobe;
                let albedo = Normalisation::Lobe.constant_for(&lobe)
                    * specular_albedo_per_unit(&lobe, geometry, theta_o.to_radians());
                let (mean, error) =
                    mean_and_error(&render(&scene, &furnace, 256, 1, Strategy::Mis));
                assert!(
                    (mean - albedo).abs() < 5.0 * error + 1e-5,
                    "{kind} {} n {n} at {theta_o} degrees: {mean} +- {error}, albedo {albedo}",
                    geometry.id()
                );
            }
        }
    }
}

/// A white Lambertian surface in a white furnace reflects exactly 1: drawn from the cosine,
/// every sample is `(1 / pi) cos / (cos / pi) = 1`, and each strategy averages to 1.
#[test]
fn a_white_lambertian_surface_reflects_the_furnace() {
    let furnace = Environment::constant(Vec3::ONE);
    let scene = plane_at(40.0, "kd = 1.0\nks = 0.0\ncolour = [1, 1, 1]");
    let image = render(&scene, &furnace, 16, 2, Strategy::Brdf);
    for pixel in image.pixels() {
        assert!((pixel.x - 1.0).abs() < 1e-5, "{pixel}");
    }
    for strategy in [Strategy::Mis, Strategy::Environment] {
        let (mean, error) = mean_and_error(&render(&scene, &furnace, 64, 3, strategy));
        assert!(
            (mean - 1.0).abs() < 5.0 * error + 1e-6,
            "{strategy:?}: {mean} +- {error}"
        );
    }
}

/// Under the sky, drawing from the BRDF only, from the environment only, or both with MIS
/// estimates the same image: the per-pixel differences of independent renders have mean 0
/// (a z-test on 5,184 pixels), for a closed-form, a Newton and a tabulated lobe.
#[test]
fn the_three_strategies_estimate_the_same_image() {
    let sky = Environment::sky(512);
    for kind in [LobeKind::Pow, LobeKind::Schlick, LobeKind::Cheb2] {
        let mut scene = Scene::ibl_scene();
        scene.apply(&Overrides {
            lobe: Some(kind),
            width: Some(96),
            height: Some(54),
            samples: Some(1),
            ..Overrides::default()
        });
        let mis = render(&scene, &sky, 64, 10, Strategy::Mis);
        for (strategy, seed) in [(Strategy::Brdf, 11), (Strategy::Environment, 12)] {
            let other = render(&scene, &sky, 64, seed, strategy);
            let differences: Vec<f64> = mis
                .pixels()
                .iter()
                .zip(other.pixels())
                .map(|(a, b)| f64::from((*a - *b).dot(Vec3::ONE)))
                .collect();
            let n = differences.len() as f64;
            let mean = differences.iter().sum::<f64>() / n;
            let sd =
                (differences.iter().map(|d| (d - mean).powi(2)).sum::<f64>() / (n - 1.0)).sqrt();
            let z = mean / (sd / n.sqrt());
            assert!(
                z.abs() < 5.0,
                "{kind} {strategy:?}: mean difference {mean}, z = {z}"
            );
        }
    }
}

/// Every lobe rendered together (the environment's and the cosine's draws computed once for
/// all) is, bit for bit, each lobe rendered alone: for each strategy, for Blinn's and
/// Phong's geometry, for analytic, tabulated and Newton-sampled lobes.
#[test]
fn lobes_rendered_together_are_each_rendered_alone() {
    let sky = Environment::sky(256);
    let lobes = LobeKind::ALL;
    for (strategy, geometry) in [
        (Strategy::Mis, Geometry::Blinn),
        (Strategy::Mis, Geometry::Phong),
        (Strategy::Brdf, Geometry::Blinn),
        (Strategy::Environment, Geometry::Phong),
    ] {
        let mut scene = Scene::ibl_scene();
        scene.apply(&Overrides {
            width: Some(48),
            height: Some(27),
            samples: Some(1),
            geometry: Some(geometry),
            ..Overrides::default()
        });
        let settings = IblSettings {
            spp: 70,
            seed: 5,
            strategy,
        };
        let together = render_ibl_lobes(&scene, &lobes, &sky, &settings, &|_, _| {}).unwrap();
        assert_eq!(together.len(), lobes.len());
        for (kind, image) in lobes.iter().zip(&together) {
            let mut alone = scene.clone();
            alone.apply(&Overrides {
                lobe: Some(*kind),
                ..Overrides::default()
            });
            let alone = render_ibl(&alone, &sky, &settings, &|_, _| {}).unwrap();
            assert!(
                alone.pixels() == image.pixels(),
                "{kind} {strategy:?} {geometry:?}: rendered with the others it differs"
            );
            assert!(mean_radiance(image) > 0.0, "{kind}: black");
        }
        // Not vacuous: the lobes' images differ from one another.
        let differ = together
            .iter()
            .filter(|image| image.pixels() != together[0].pixels())
            .count();
        assert!(
            differ >= lobes.len() - 2,
            "{differ} images differ from pow's"
        );
    }
}

/// The error against a 4096-spp reference falls as `1 / sqrt(spp)`: the mean squared error
/// of an `spp` render is `sigma^2 (1 / spp + 1 / 4096)` (its own variance plus the
/// reference's), so the `sigma^2` each spp implies must agree within 25 % of their mean,
/// which puts the slope of log RMSE against log spp within about 0.05 of -1/2 over 4 to 256.
/// A few pixels (the sun's reflection on the teapot) carry most of the squared error, so each
/// spp's error is the mean over 16 independent renders.
#[test]
fn the_error_falls_as_one_over_root_spp() {
    let sky = Environment::sky(512);
    let mut scene = Scene::ibl_scene();
    scene.apply(&Overrides {
        width: Some(64),
        height: Some(36),
        samples: Some(1),
        ..Overrides::default()
    });
    let reference_spp = 4096;
    let reference = render(&scene, &sky, reference_spp, 1000, Strategy::Mis);
    let runs = 16;
    let counts = [4u32, 16, 64, 256];
    let sigmas: Vec<f64> = counts
        .iter()
        .map(|&spp| {
            let mse = (0..runs)
                .map(|run| {
                    let image =
                        render(&scene, &sky, spp, u64::from(spp) * 100 + run, Strategy::Mis);
                    image
                        .pixels()
                        .iter()
                        .zip(reference.pixels())
                        .map(|(a, b)| f64::from((*a - *b).length_squared()))
                        .sum::<f64>()
                        / image.pixels().len() as f64
                })
                .sum::<f64>()
                / runs as f64;
            mse / (1.0 / f64::from(spp) + 1.0 / f64::from(reference_spp))
        })
        .collect();
    let mean = sigmas.iter().sum::<f64>() / sigmas.len() as f64;
    println!("sigma^2 implied at spp {counts:?}: {sigmas:?}");
    for (spp, sigma) in counts.iter().zip(&sigmas) {
        assert!(
            (sigma / mean - 1.0).abs() < 0.25,
            "spp {spp}: sigma^2 {sigma} against the mean {mean} ({sigmas:?})"
        );
    }
}

#[test]
fn an_hdr_environment_round_trips_and_bad_maps_are_refused() {
    let directory = tempfile::tempdir().unwrap();
    let path = directory.path().join("sky.hdr");
    let sky = Environment::sky(128);
    write_image(&path, sky.image(), Display::default()).unwrap();
    let loaded = Environment::load(&path).unwrap();
    // RGBE keeps 8 bits of mantissa per channel beside a shared exponent.
    for (a, b) in loaded.image().pixels().iter().zip(sky.image().pixels()) {
        assert!(
            (*a - *b).abs().max_element() <= 0.01 * b.max_element(),
            "{a} against {b}"
        );
    }
    let mut image = Image::new(8, 4, Vec3::ONE);
    image.set(2, 3, Vec3::new(1.0, f32::INFINITY, 1.0));
    let path = directory.path().join("bad.exr");
    write_image(&path, &image, Display::default()).unwrap();
    assert!(read_image(&path).is_ok());
    let error = Environment::load(&path).unwrap_err().to_string();
    assert!(
        error.contains("bad.exr") && error.contains("(2, 3)") && error.contains("inf"),
        "{error}"
    );
    let error = Environment::load(directory.path()).unwrap_err().to_string();
    assert!(
        error.contains("directory") || error.contains("unknown image format"),
        "{error}"
    );
}

/// The `f32` draw by alias carries the density [`Environment::pdf`] gives its direction and
/// that [`Environment::look_up`] gives back (except at a texel's border, where `f32` and
/// `f64` may round into neighbours), and `L / pdf` over its draws integrates the map.
#[test]
fn the_alias_draws_carry_the_maps_density() {
    use specula::sampling::{random_bits, unit_f32};
    let sky = Environment::sky(256);
    let count = 200_000u64;
    let (mut agree, mut sum) = (0u64, 0.0);
    for index in 0..count {
        let (bits, within) = (random_bits(3, index, 0), random_bits(3, index, 1));
        let Some((wi, pdf, radiance)) = sky.draw(
            bits,
            [unit_f32(within as u32), unit_f32((within >> 32) as u32)],
        ) else {
            continue;
        };
        let exact = sky.pdf(wi.as_dvec3());
        let (back_radiance, back) = sky.look_up(wi);
        if (f64::from(pdf) / exact - 1.0).abs() < 1e-3
            && (back / pdf - 1.0).abs() < 1e-3
            && back_radiance == radiance
        {
            agree += 1;
        }
        sum += f64::from(radiance.y) / f64::from(pdf);
    }
    assert!(
        agree as f64 > 0.995 * count as f64,
        "{agree} of {count} agree"
    );
    let integral = map_integral(&sky);
    let mean = sum / count as f64;
    assert!(
        (mean / integral - 1.0).abs() < 0.01,
        "{mean} against {integral}"
    );
}

/// The packet estimator (`f32`, alias draws, one lobe evaluation per direction) and the same
/// estimator written plainly in `f64` ([`MaterialReflectance`] through `render_ibl_with`)
/// render the sky-lit sphere alike: they differ by no more than two seeds of the plain one
/// do, and their means agree within 1 %, for a closed-form, a Newton-sampled and a
/// tabulated lobe in both geometries, and with 2 x 2 positions a pixel (the sphere's edge
/// antialiased, background inside the runs of pixels whose environment draws are made
/// ahead: debug builds check that each packet takes the draws made for it).
#[test]
fn the_packet_estimator_agrees_with_the_plain_one() {
    use specula_render::ibl::{render_ibl_with, MaterialReflectance};
    let sky = Environment::sky(512);
    for (lobe, samples) in [("pow", 1), ("schlick", 1), ("schlick-mod", 1), ("pow", 2)] {
        for geometry in Geometry::ALL {
            let material = format!(
                "kd = 0.35\nks = 0.65\ncolour = [0.7, 0.1, 0.08]\nlobe = \"{lobe}\"\nn = \
                    64\ngeometry = \"{}\"\nnormalisation = \"lobe\"",
                geometry.id()
            );
            let scene = scene(&format!(
                "[camera]\neye = [0, -2.2, 0]\ntarget = [0, 0, 0]\nfov = 30\n\
                 [render]\nwidth = 48\nheight = 48\nsamples = {samples}\nmodel = \"physical\"\n\
                 [[objects]]\nshape = \"sphere\"\nradius = 0.9\n[objects.material]\n{material}\n"
            ));
            let reference = MaterialReflectance::new(&scene.objects[0].material);
            let plain = |seed| {
                let settings = IblSettings {
                    spp: 256,
                    seed,
                    strategy: Strategy::Mis,
                };
                render_ibl_with(&scene, &sky, &settings, &reference, &|_, _| {}).unwrap()
            };
            let packets = render(&scene, &sky, 256, 1, Strategy::Mis);
            let (first, second) = (plain(2), plain(3));
            let (noise, against) = (
                rms_difference(&first, &second),
                rms_difference(&first, &packets),
            );
            let bias = mean_radiance(&packets) / mean_radiance(&first) - 1.0;
            assert!(
                against < 1.3 * noise && bias.abs() < 0.01,
                "{lobe} {} ({samples} x {samples}): packets differ by {against} against noise \
                 {noise}, bias {bias}",
                geometry.id()
            );
        }
    }
}
