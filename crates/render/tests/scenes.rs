//! Scene files and mesh files: what they build, and what they say when they are wrong.

use std::path::Path;

use glam::Vec3;
use specula::LobeKind;
use specula_render::{load_mesh, Analytic, Light, Scene, DEFAULT_SCENE};

fn parse(text: &str) -> Result<Scene, String> {
    Scene::from_toml(text, "test.toml", None)
        .map(|loaded| loaded.scene)
        .map_err(|e| e.to_string())
}

const CAMERA: &str = "[camera]\neye = [0, -5, 1]\ntarget = [0, 0, 0]\n";

#[test]
fn the_default_scene_has_five_spheres_from_n_4_to_1000_and_a_teapot() {
    let scene = Scene::default_scene();
    let exponents: Vec<f64> = scene
        .objects
        .iter()
        .map(|o| o.material.lobe.exponent().get())
        .collect();
    for n in [4.0, 16.0, 64.0, 256.0, 1000.0] {
        assert!(exponents.contains(&n), "{exponents:?}");
    }
    // The teapot (tessellated Bezier patches) stands on the plane: z from 0 to 0.75 * 3.15.
    let teapot = scene.objects.last().unwrap().mesh.bounds().unwrap();
    assert!(teapot.0.z.abs() < 1e-3 && (teapot.1.z - 0.75 * 3.15).abs() < 1e-3);
    assert!(DEFAULT_SCENE.contains("[camera]"));
}

#[test]
fn a_minimal_scene_takes_defaults_and_lights_are_normalised() {
    let text = format!(
        "{CAMERA}[[lights]]\nkind = \"directional\"\ntowards = [0, 0, 2]\n[[objects]]\nshape = \
            \"sphere\"\n"
    );
    let scene = parse(&text).unwrap();
    assert_eq!(scene.objects.len(), 1);
    assert_eq!(scene.objects[0].material.lobe.kind(), LobeKind::Pow);
    assert_eq!(
        scene.lights[0],
        Light::Directional {
            towards: Vec3::Z,
            intensity: Vec3::ONE
        }
    );
}

#[test]
fn transforms_place_the_object() {
    let text = format!(
        "{CAMERA}[[objects]]\nshape = \"sphere\"\nradius = 1.0\nscale = 2.0\ntranslate = [1, 2, \
            3]\n"
    );
    let scene = parse(&text).unwrap();
    let (lo, hi) = scene.objects[0].mesh.bounds().unwrap();
    assert!(
        (lo - Vec3::new(-1.0, 0.0, 1.0)).abs().max_element() < 1e-3,
        "{lo}"
    );
    assert!(
        (hi - Vec3::new(3.0, 4.0, 5.0)).abs().max_element() < 1e-3,
        "{hi}"
    );
}

/// Each malformed scene names the file, the line, the key and (for a choice) the valid values.
/// A sphere keeps its exact shape beside its tessellation: the centre its translation and
/// the radius its scaled radius, on which every vertex of the mesh lies; other shapes have
/// none.
#[test]
fn a_sphere_keeps_its_exact_shape() {
    let text = format!(
        "{CAMERA}[[objects]]\nshape = \"sphere\"\nradius = 0.9\nscale = 2.0\n\
         translate = [1.0, -2.0, 3.0]\nrotate = [10.0, 20.0, 30.0]\n\
         [[objects]]\nshape = \"torus\"\n"
    );
    let scene = parse(&text).unwrap();
    let Some(Analytic::Sphere { centre, radius }) = scene.objects[0].analytic else {
        panic!(
            "the sphere has no exact shape: {:?}",
            scene.objects[0].analytic
        );
    };
    assert_eq!(centre, Vec3::new(1.0, -2.0, 3.0));
    assert!((radius - 1.8).abs() < 1e-6, "{radius}");
    for &p in scene.objects[0].mesh.positions() {
        assert!(((p - centre).length() - radius).abs() < 1e-5, "{p}");
    }
    assert_eq!(scene.objects[1].analytic, None);
}

#[test]
fn malformed_scenes_name_file_line_and_key() {
    let cases: [(&str, usize, &[&str]); 8] = [
        (
            "[objects.material]\nn = 5000\n",
            7,
            &["material.n", "[1, 1000]"],
        ),
        (
            "[objects.material]\nlobe = \"phong\"\n",
            7,
            &["material.lobe", "schlick-mod", "cosquad"],
        ),
        (
            "[objects.material]\nnormalisation = \"x\"\n",
            7,
            &["normalisation", "lafortune"],
        ),
        ("radiuss = 2\n", 6, &["radiuss", "radius"]),
        (
            "major = 2\n",
            6,
            &["major", "does not apply", "radius, segments, rings"],
        ),
        ("segments = 2\n", 6, &["segments", "[3, 4096]"]),
        ("radius = \"big\"\n", 6, &["invalid type"]),
        ("radius = [1\n", 6, &[]),
    ];
    for (tail, line, needles) in cases {
        let text = format!("{CAMERA}[[objects]]\nshape = \"sphere\"\n{tail}");
        let error = parse(&text).unwrap_err();
        assert!(
            error.starts_with(&format!("test.toml:{line}:")),
            "{tail:?}: {error}"
        );
        for needle in needles {
            assert!(
                error.contains(needle),
                "{tail:?}: '{needle}' missing from {error}"
            );
        }
    }
    let error = parse("[render]\nshading = \"toon\"\n").unwrap_err();
    assert!(
        error.contains("flat") && error.contains("gouraud"),
        "{error}"
    );
    let error = parse(&format!("{CAMERA}[[objects]]\nshape = \"cube\"\n")).unwrap_err();
    assert!(
        error.starts_with("test.toml:5:") && error.contains("teapot"),
        "{error}"
    );
    let error = parse("[camera]\neye = [0, 0, 0]\ntarget = [0, 0, 0]\n").unwrap_err();
    assert!(error.contains("coincide"), "{error}");
}

fn write(directory: &Path, name: &str, bytes: &[u8]) -> std::path::PathBuf {
    let path = directory.join(name);
    std::fs::write(&path, bytes).unwrap();
    path
}

/// A unit right tetrahedron: area `3/2 + sqrt(3)/2`, in each format.
#[test]
fn obj_stl_and_ply_files_load_the_same_tetrahedron() {
    let directory = tempfile::tempdir().unwrap();
    let obj = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n";
    let ply = "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float \
        y\nproperty float z\nelement face 4\nproperty list uchar int vertex_indices\nend_header\n0 \
        0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 2 1\n3 0 1 3\n3 0 3 2\n3 1 2 3\n";
    let corners = [
        [0.0_f32, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
        [0.0, 0.0, 1.0],
    ];
    let faces = [[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]];
    let mut stl = vec![0_u8; 80];
    stl.extend(4_u32.to_le_bytes());
    for face in faces {
        stl.extend([0_u8; 12]);
        for corner in face {
            for c in corners[corner] {
                stl.extend(c.to_le_bytes());
            }
        }
        stl.extend([0_u8; 2]);
    }
    let expected_area = 1.5 + 3.0_f32.sqrt() / 2.0;
    for path in [
        write(directory.path(), "t.obj", obj.as_bytes()),
        write(directory.path(), "t.ply", ply.as_bytes()),
        write(directory.path(), "t.stl", &stl),
    ] {
        let loaded = load_mesh(&path).unwrap_or_else(|e| panic!("{e}"));
        let mesh = &loaded.mesh;
        assert_eq!(mesh.triangles().len(), 4, "{}", path.display());
        assert!(
            (mesh.area() - expected_area).abs() < 1e-5,
            "{}",
            path.display()
        );
        // Faces wind outwards: the centroid is inside every face's back half-space.
        let centroid = Vec3::splat(0.25);
        for t in mesh.triangles() {
            let [a, b, c] = t.map(|i| mesh.positions()[i as usize]);
            assert!(
                (b - a).cross(c - a).dot(a - centroid) > 0.0,
                "{}",
                path.display()
            );
        }
    }
}

#[test]
fn broken_mesh_files_are_refused_and_degenerate_triangles_counted() {
    let directory = tempfile::tempdir().unwrap();
    let nan = write(
        directory.path(),
        "nan.obj",
        b"v 0 0 0\nv 1 0 0\nv nan 1 0\nf 1 2 3\n",
    );
    let error = load_mesh(&nan).unwrap_err().to_string();
    assert!(
        error.contains("nan.obj") && error.contains("vertex 2"),
        "{error}"
    );

    let degenerate = write(
        directory.path(),
        "flat.obj",
        b"v 0 0 0\nv 1 0 0\nv 0 1 0\nv 2 0 0\nf 1 2 3\nf 1 2 4\nf 1 1 3\n",
    );
    let loaded = load_mesh(&degenerate).unwrap();
    assert_eq!(
        (loaded.mesh.triangles().len(), loaded.degenerate_triangles),
        (1, 2)
    );

    let text = format!("{CAMERA}[[objects]]\nshape = \"mesh\"\npath = \"nan.obj\"\n");
    let error = Scene::from_toml(&text, "s.toml", Some(directory.path())).unwrap_err();
    assert_eq!(error.line, 6);
    assert!(error.to_string().contains("vertex 2"), "{error}");
    let text = format!("{CAMERA}[[objects]]\nshape = \"mesh\"\npath = \"flat.obj\"\n");
    let loaded = Scene::from_toml(&text, "s.toml", Some(directory.path())).unwrap();
    assert!(
        loaded.warnings[0].contains("skipped 2 degenerate"),
        "{:?}",
        loaded.warnings
    );

    let unknown = write(directory.path(), "m.fbx", b"");
    assert!(load_mesh(&unknown)
        .unwrap_err()
        .to_string()
        .contains("obj, stl, ply"));
    // A binary STL header announcing 4 triangles, and none after it.
    let mut truncated = vec![0_u8; 80];
    truncated.extend(4_u32.to_le_bytes());
    let truncated = write(directory.path(), "t.stl", &truncated);
    assert!(load_mesh(&truncated).is_err());
}

#[test]
fn the_environment_scene_is_a_sphere_and_a_teapot_without_lights() {
    let scene = Scene::ibl_scene();
    assert!(scene.lights.is_empty());
    assert_eq!(scene.objects.len(), 2);
    assert_eq!(
        scene.settings.model,
        specula_render::IlluminationModel::Physical
    );
    // The sphere of radius 0.9 rests on z = 0; the teapot (height 3.15 x 0.55) stands there too.
    let sphere = scene.objects[0].mesh.bounds().unwrap();
    assert!(sphere.0.z.abs() < 1e-3 && (sphere.1.z - 1.8).abs() < 1e-3);
    let teapot = scene.objects[1].mesh.bounds().unwrap();
    assert!(teapot.0.z.abs() < 1e-3 && (teapot.1.z - 0.55 * 3.15).abs() < 1e-3);
}
