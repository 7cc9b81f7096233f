//! The live views' routes: every lobe's GLSL ES 3.00 export, and the reference sphere against
//! a closed form and against the CPU renderer's tessellated sphere.

use axum::http::StatusCode;
use glam::Vec3;
use specula::{Exponent, Geometry, Lobe, LobeKind, Normalisation};
use specula_render::IlluminationModel;

use super::{json, png_size, served_png};
use crate::explorer::{scene, Object, RenderRequest};
use crate::live::{sphere_radiance, SphereRequest};
use crate::scene_setup::{light_towards, LIVE_SCENE};

/// Every built-in lobe and a formula lobe export for WebGL 2: GLSL ES 3.00 functions with
/// `specula_specular`, no `#version` line (the page's shader puts its own first), no entry
/// point; `n` an argument, with the range the text serves, exactly where every constant and
/// the lobe's own normalisation are closed forms of `n`, and otherwise the normalisation the
/// library computes for that lobe baked in.
#[tokio::test]
async fn every_lobe_and_a_formula_export_glsl_es_300() {
    let n = 64.0;
    let mut lobes: Vec<(String, LobeKind)> = LobeKind::ALL
        .iter()
        .map(|k| (k.id().to_owned(), *k))
        .collect();
    let formula = "exp2(n * (t - 1) * 1.4427)";
    lobes.push((
        format!("%3D{}", formula.replace(' ', "%20").replace('+', "%2B")),
        LobeKind::parse(&format!("={formula}")).expect("a valid formula"),
    ));
    for (name, kind) in lobes {
        let uri = format!("/api/shader?lobe={name}&n={n}&geometry=blinn&normalisation=lobe");
        let (status, body) = json(&uri).await;
        assert_eq!(status, StatusCode::OK, "{uri}: {body}");
        let glsl = body["glsl"].as_str().expect("glsl text");
        assert!(!glsl.contains("#version"), "{name}: {glsl}");
        assert!(!glsl.contains("void main"), "{name}");
        let lobe = Lobe::new(kind, Exponent::new(n));
        let closed_forms = lobe.parameters().iter().all(|p| p.preparation.is_some())
            && (lobe.sampling_expressions().is_some() || lobe.newton_expressions().is_some());
        if closed_forms {
            assert!(glsl.contains("float specula_specular(float n"), "{name}");
            let range = lobe.structural_range();
            assert_eq!(body["n_range"], serde_json::json!(range), "{name}");
            assert!(range[0] <= n && n <= range[1], "{name}");
            continue;
        }
        assert!(body["n_range"].is_null(), "{name}");
        assert!(glsl.contains("float specula_specular(vec3"), "{name}");
        let expected = Normalisation::Lobe.constant_for(&lobe);
        let baked: f32 = glsl
            .lines()
            .find_map(|line| line.strip_prefix("const float SPECULA_NORMALISATION = "))
            .and_then(|rest| rest.trim_end_matches(';').parse().ok())
            .expect("the normalisation constant");
        assert_eq!(baked, expected as f32, "{name}");
        assert_eq!(body["tonemap"], "reinhard");
    }
    let (status, body) = json("/api/shader?lobe=pow&n=0").await;
    assert_eq!(
        (status, body["parameter"].as_str()),
        (StatusCode::BAD_REQUEST, Some("n"))
    );
    let (status, body) = json("/api/shader?lobe=nope&n=8").await;
    assert_eq!(
        (status, body["parameter"].as_str()),
        (StatusCode::BAD_REQUEST, Some("lobe"))
    );
}

fn request(light: [f64; 3], size: u32, normalisation: Normalisation) -> SphereRequest {
    SphereRequest {
        geometry: Geometry::Phong,
        normalisation,
        model: IlluminationModel::Classic,
        light: Vec3::from(light.map(|c| c as f32)),
        size,
    }
}

/// With the light behind the camera, the centre pixel looks straight down the normal: the
/// lobe's cosine is 1 and `N.L` is 1, so its radiance is `ka C A + kd C + ks` (classic); the
/// corners miss the sphere and show the background.
#[test]
fn the_reference_sphere_has_its_closed_form_at_the_centre() {
    let size = 33;
    let lobe = Lobe::new(LobeKind::Schlick, Exponent::new(40.0));
    let pixels = sphere_radiance(
        lobe,
        &request(light_towards(0.0, 0.0), size, Normalisation::None),
    );
    let scene = LIVE_SCENE;
    let colour = Vec3::from(scene.colour);
    let expected =
        scene.ka * colour * Vec3::from(scene.ambient) + scene.kd * colour + Vec3::splat(scene.ks);
    let centre = pixels[(size * size / 2) as usize];
    assert!(
        (centre - expected).abs().max_element() < 1e-5,
        "{centre} vs {expected}"
    );
    assert_eq!(pixels[0], Vec3::from(scene.background));
}

/// The analytic sphere is the renderer's sphere: away from the silhouette (where the
/// tessellated outline differs by a pixel) every pixel of the CPU render of the same scene
/// (128 x 64 facets, per-pixel Phong shading) agrees within 1 % of the peak.
#[test]
fn the_reference_sphere_agrees_with_the_cpu_render() {
    let size = 96;
    let (theta, phi) = (35_f64.to_radians(), 40_f64.to_radians());
    let (kind, n) = (
        LobeKind::parse("cosquad").expect("a lobe"),
        Exponent::new(30.0),
    );
    let cpu = scene(&RenderRequest {
        object: Object::Sphere,
        kind,
        n,
        geometry: Geometry::Phong,
        normalisation: Normalisation::None,
        shading: specula_render::Shading::Phong,
        model: IlluminationModel::Classic,
        light_theta: theta,
        light_phi: phi,
        size,
    })
    .and_then(|scene| specula_render::render(&scene, &|_, _| {}).map_err(|e| e.to_string()))
    .expect("the CPU render");
    let live = sphere_radiance(
        Lobe::new(kind, n),
        &request(light_towards(theta, phi), size, Normalisation::None),
    );
    let peak = live.iter().map(|p| p.max_element()).fold(0.0, f32::max);
    let background = Vec3::from(LIVE_SCENE.background);
    let (mut compared, mut worst) = (0, 0.0_f32);
    for y in 2..size - 2 {
        for x in 2..size - 2 {
            let near = |p: Vec3| p == background;
            let around = (y - 2..=y + 2)
                .flat_map(|v| (x - 2..=x + 2).map(move |u| (u, v)))
                .any(|(u, v)| near(live[(v * size + u) as usize]));
            if around {
                continue;
            }
            compared += 1;
            let difference = (cpu.get(x, y) - live[(y * size + x) as usize])
                .abs()
                .max_element();
            worst = worst.max(difference);
        }
    }
    assert!(compared > 3000, "{compared} pixels compared");
    assert!(
        worst < 0.01 * peak,
        "worst difference {worst} of peak {peak}"
    );
}

#[tokio::test]
async fn the_live_sphere_route_serves_the_asked_size_and_refuses_bad_values() {
    let png = served_png(
        "/api/live-sphere?lobe=sg&n=100&size=48&light_theta=20",
        (48, 48),
    )
    .await;
    assert_eq!(png_size(&png), (48, 48));
    let (status, body) = json("/api/live-sphere?size=4096").await;
    assert_eq!(
        (status, body["parameter"].as_str()),
        (StatusCode::BAD_REQUEST, Some("size"))
    );
}

/// The teapot's mesh: as many normals as positions, unit normals, every triangle's corners
/// among them, every vertex in front of the camera and nearly all inside its square image.
#[tokio::test]
async fn the_teapot_route_serves_a_mesh_the_camera_sees() {
    let (status, body) = json("/api/teapot").await;
    assert_eq!(status, StatusCode::OK);
    let numbers = |key: &str| -> Vec<f32> {
        let values = body[key].as_array().expect("an array");
        values
            .iter()
            .map(|v| v.as_f64().expect("a number") as f32)
            .collect()
    };
    let (positions, normals) = (numbers("positions"), numbers("normals"));
    assert_eq!(positions.len(), normals.len());
    let vertices = positions.len() / 3;
    assert!(vertices > 1000, "{vertices} vertices");
    for normal in normals.chunks(3) {
        assert!(
            (Vec3::from_slice(normal).length() - 1.0).abs() < 1e-3,
            "{normal:?}"
        );
    }
    let triangles = numbers("triangles");
    assert!(triangles.len() % 3 == 0 && triangles.iter().all(|&k| (k as usize) < vertices));
    let matrix = glam::Mat4::from_cols_slice(&numbers("view_projection"));
    // In front of the camera, and inside its image but for the spout's tip, which the
    // explorer's framing cuts.
    let clips: Vec<glam::Vec4> = positions
        .chunks(3)
        .map(|p| matrix * Vec3::from_slice(p).extend(1.0))
        .collect();
    assert!(clips.iter().all(|c| c.w > 0.0));
    let inside = clips
        .iter()
        .filter(|c| c.x.abs() < c.w && c.y.abs() < c.w)
        .count();
    assert!(
        inside as f64 > 0.99 * vertices as f64,
        "{inside} of {vertices} inside"
    );
    let (status, _) = json("/api/teapot?size=3").await;
    assert_eq!(status, StatusCode::BAD_REQUEST);
}

/// `/api/microfacet` gives the lobe's distribution terms at `n`: for `pow` the closed-form
/// normaliser `(n + 2) / (2 pi)` (Walter's), a masking table from 0 at the horizon to 1 at the
/// normal, never falling; a bad `n` or lobe refused.
#[tokio::test]
async fn the_microfacet_route_serves_the_distributions_terms() {
    for n in [4.0, 64.0, 700.0] {
        let (status, body) = json(&format!("/api/microfacet?lobe=pow&n={n}")).await;
        assert_eq!(status, StatusCode::OK, "{body}");
        let normaliser = body["normaliser"].as_f64().expect("a normaliser");
        let walter = (n + 2.0) / core::f64::consts::TAU;
        assert!(
            (normaliser - walter).abs() < 1e-5 * walter,
            "n = {n}: {normaliser}"
        );
        let masking: Vec<f64> = body["masking"]
            .as_array()
            .expect("the masking table")
            .iter()
            .map(|v| v.as_f64().expect("a number"))
            .collect();
        assert_eq!(masking.len(), specula_render::MASKING_ENTRIES);
        assert_eq!(masking[0], 0.0);
        assert!(
            (masking[masking.len() - 1] - 1.0).abs() < 1e-6,
            "{masking:?}"
        );
        assert!(masking.windows(2).all(|w| w[0] <= w[1]), "{masking:?}");
    }
    for bad in [
        "/api/microfacet?lobe=pow&n=0",
        "/api/microfacet?lobe=nope&n=8",
    ] {
        let (status, _) = json(bad).await;
        assert_eq!(status, StatusCode::BAD_REQUEST, "{bad}");
    }
}
