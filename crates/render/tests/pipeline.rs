//! Whole-pipeline properties: watertight coverage through clipping, identical output for any
//! thread count, and bad geometry never producing a NaN pixel.

use glam::Vec3;
use specula::{Exponent, Geometry, Lobe, LobeKind, Normalisation};
use specula_render::{
    overdraw, render, sphere, Camera, Display, IlluminationModel, Light, Material, Mesh, Object,
    Overrides, Projection, Scene, Settings, Shading,
};

fn material() -> Material {
    Material {
        ka: 0.1,
        kd: 0.6,
        ks: 0.4,
        colour: Vec3::splat(0.7),
        specular_colour: Vec3::ONE,
        lobe: Lobe::new(LobeKind::SchlickMod, Exponent::new(50.0)),
        geometry: Geometry::Phong,
        normalisation: Normalisation::None,
    }
}

fn scene(camera: Camera, mesh: Mesh, width: u32, height: u32, samples: u32) -> Scene {
    Scene {
        camera,
        lights: vec![Light::Point {
            position: Vec3::new(0.5, -0.5, 0.5),
            intensity: Vec3::ONE,
        }],
        ambient: Vec3::splat(0.1),
        objects: vec![Object {
            mesh,
            analytic: None,
            material: material(),
        }],
        settings: Settings {
            width,
            height,
            samples,
            shading: Shading::Phong,
            model: IlluminationModel::Classic,
            cull_back_faces: true,
            background: Vec3::ZERO,
        },
        display: Display::default(),
    }
}

/// From inside a closed sphere turned inside out, every direction meets the surface exactly
/// once. Triangles behind the camera cross `w = 0` and are cut by the near plane; those beside
/// it project far outside the image and are cut by the guard band. Every sample must still be
/// covered exactly once: no crack along a clipped edge, no overlap.
#[test]
fn a_closed_surface_around_the_camera_covers_every_sample_exactly_once() {
    // The coarse dome's few huge triangles reach from behind the camera into the view, so they
    // are cut by the near plane and the guard band and still cover most of the image.
    for dome in [sphere(10.0, 96, 48).flipped(), sphere(10.0, 5, 3).flipped()] {
        // A tiny near distance sends vertices beside the camera millions of pixels away: only the
        // guard band keeps them in the rasterizer's exact range.
        for (eye, target, fov, near) in [
            (Vec3::ZERO, Vec3::X, 90.0, 0.05),
            (
                Vec3::new(1.0, 2.0, -3.0),
                Vec3::new(0.3, 2.5, -2.0),
                120.0,
                0.05,
            ),
            (
                Vec3::new(0.0, 0.0, 9.5),
                Vec3::new(0.0, 0.0, 10.0),
                60.0,
                0.05,
            ),
            (
                Vec3::new(0.5, -0.5, 0.0),
                Vec3::new(1.0, -0.2, 0.3),
                100.0,
                1e-4,
            ),
        ] {
            let camera = Camera::try_new(
                eye,
                target,
                Vec3::new(0.1, 0.2, 1.0),
                Projection::Perspective { fov_y_degrees: fov },
                near,
                100.0,
            )
            .unwrap();
            let counts = overdraw(&scene(camera, dome.clone(), 160, 90, 2)).unwrap();
            let wrong = counts.iter().filter(|&&c| c != 1).count();
            assert_eq!(
                wrong, 0,
                "eye {eye}: {wrong} samples not covered exactly once"
            );
        }
    }
}

/// The same dome seen from inside without flipping is all back faces: culled entirely.
#[test]
fn back_faces_are_culled() {
    let camera = Camera::try_new(
        Vec3::ZERO,
        Vec3::X,
        Vec3::Z,
        Projection::Perspective {
            fov_y_degrees: 90.0,
        },
        0.05,
        100.0,
    )
    .unwrap();
    let counts = overdraw(&scene(camera, sphere(10.0, 48, 24), 64, 36, 1)).unwrap();
    assert!(counts.iter().all(|&c| c == 0));
}

#[test]
fn output_is_identical_for_any_thread_count() {
    let mut scene = Scene::default_scene();
    scene.apply(&Overrides {
        width: Some(200),
        height: Some(120),
        samples: Some(2),
        ..Overrides::default()
    });
    let render_with = |threads: usize| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap()
            .install(|| render(&scene, &|_, _| {}).unwrap())
    };
    let one = render_with(1);
    assert!(
        one.pixels().iter().any(|p| p.max_element() > 0.2),
        "not a black image"
    );
    for threads in [2, 3, 7] {
        let other = render_with(threads);
        // Bitwise: compare the bits, not approximate values.
        let bits = |image: &specula_render::Image| -> Vec<u32> {
            image
                .pixels()
                .iter()
                .flat_map(|p| p.to_array().map(f32::to_bits))
                .collect()
        };
        assert!(
            bits(&one) == bits(&other),
            "{threads} threads differ from 1"
        );
    }
}

#[test]
fn meshes_with_nan_are_refused_naming_the_vertex() {
    let error = Mesh::try_new(
        vec![Vec3::ZERO, Vec3::X, Vec3::new(0.0, f32::NAN, 0.0)],
        vec![Vec3::Z; 3],
        vec![[0, 1, 2]],
    )
    .unwrap_err();
    assert!(error.to_string().contains("vertex 2"), "{error}");
}

/// Degenerate triangles (collinear corners, a repeated corner) and opposite vertex normals
/// (whose interpolation passes through zero) render without a single non-finite pixel, in
/// every shading method.
#[test]
fn degenerate_geometry_never_produces_a_non_finite_pixel() {
    let positions = vec![
        Vec3::new(-1.0, -1.0, 0.0),
        Vec3::new(1.0, -1.0, 0.0),
        Vec3::new(0.0, 1.0, 0.0),
        Vec3::new(2.0, 2.0, 0.0),
        Vec3::new(3.0, 3.0, 0.0),
    ];
    let normals = vec![Vec3::Z, -Vec3::Z, Vec3::Z, Vec3::X, Vec3::X];
    let triangles = vec![[0, 1, 2], [2, 3, 4], [0, 0, 1], [3, 3, 3]];
    let mesh = Mesh::try_new(positions, normals, triangles).unwrap();
    let camera = Camera::try_new(
        Vec3::new(0.0, 0.0, 4.0),
        Vec3::ZERO,
        Vec3::Y,
        Projection::Perspective {
            fov_y_degrees: 60.0,
        },
        0.1,
        10.0,
    )
    .unwrap();
    for shading in Shading::ALL {
        let mut s = scene(camera, mesh.clone(), 64, 64, 2);
        s.settings.shading = shading;
        s.settings.cull_back_faces = false;
        let image = render(&s, &|_, _| {}).unwrap();
        assert!(image.pixels().iter().all(|p| p.is_finite()), "{shading:?}");
        assert!(
            image.pixels().iter().any(|&p| p != Vec3::ZERO),
            "{shading:?}: nothing drawn"
        );
    }
}

#[test]
fn impossible_sizes_are_refused_with_the_limits() {
    let mut s = Scene::default_scene();
    s.settings.samples = 9;
    let error = render(&s, &|_, _| {}).unwrap_err().to_string();
    assert!(error.contains("samples in [1, 8]"), "{error}");
    s.settings.samples = 8;
    s.settings.width = 5000;
    assert!(render(&s, &|_, _| {}).is_err());
}

/// Progress reaches its total, and the image has the requested size.
#[test]
fn progress_counts_every_tile() {
    let mut s = Scene::default_scene();
    s.apply(&Overrides {
        width: Some(100),
        height: Some(70),
        samples: Some(1),
        ..Overrides::default()
    });
    let last = std::sync::Mutex::new((0, 0));
    let image = render(&s, &|done, total| {
        let mut last = last.lock().unwrap();
        *last = (last.0.max(done), total);
    })
    .unwrap();
    assert_eq!((image.width(), image.height()), (100, 70));
    // 100 x 70 pixels in 32 x 32 tiles: 4 x 3.
    assert_eq!(*last.lock().unwrap(), (12, 12));
}

/// The grid's first column is the reference render itself (below its label), and its FLIP
/// row is black: FLIP of an image against itself is zero.
#[test]
fn the_grids_reference_column_is_the_plain_render() {
    use specula_render::{render_grid, GridOptions};
    let mut s = Scene::default_scene();
    s.apply(&Overrides {
        width: Some(90),
        height: Some(60),
        samples: Some(1),
        ..Overrides::default()
    });
    let options = GridOptions {
        lobes: vec![LobeKind::Pow, LobeKind::Schlick],
        reference: LobeKind::Pow,
    };
    let grid = render_grid(&s, &options, &|_, _| {}).unwrap();
    assert_eq!((grid.width, grid.height), (180, 120));
    let plain = render(&s, &|_, _| {}).unwrap().to_srgb8(s.display);
    let label_rows = 24;
    for y in label_rows..60 {
        for x in 0..90 {
            let g = 3 * (y * 180 + x) as usize;
            let p = 3 * (y * 90 + x) as usize;
            assert_eq!(grid.bytes[g..g + 3], plain[p..p + 3], "({x}, {y})");
        }
    }
    let magma_zero = &grid.bytes[3 * (100 * 180 + 45)..][..3];
    let heat_schlick: Vec<&[u8]> = (label_rows..60)
        .map(|y| &grid.bytes[3 * ((60 + y) * 180 + 90 + 45) as usize..][..3])
        .collect();
    assert!(
        heat_schlick.iter().any(|&c| c != magma_zero),
        "schlick differs from pow somewhere"
    );
    // The columns the grid keeps: each lobe's bytes as displayed, and its difference from pow
    // over them (none for pow itself; schlick's PSNR from its own squared byte errors).
    let grid = specula_render::render_grid_columns(&s, &options, &mut |variant, _| {
        render(variant, &|_, _| {}).map_err(|e| e.to_string())
    })
    .unwrap();
    assert_eq!(grid.columns[0].srgb8, plain);
    let pow = &grid.columns[0].difference;
    assert!(pow.mean_flip == 0.0 && pow.max_abs_error == 0.0, "{pow:?}");
    let schlick = &grid.columns[1];
    let squared = plain
        .iter()
        .zip(&schlick.srgb8)
        .map(|(&a, &b)| ((f64::from(a) - f64::from(b)) / 255.0).powi(2))
        .sum::<f64>()
        / plain.len() as f64;
    assert!(
        (schlick.difference.psnr_db + 10.0 * squared.log10()).abs() < 1e-9,
        "{} against {squared}",
        schlick.difference.psnr_db
    );
    assert!(schlick.difference.mean_flip > 0.0);
}
