//! The measured-materials view through the router: the bundled materials, the `--data`
//! folder's listing, the fits of a real RGL material against the library's, the cache, and
//! refusals of anything but a listed name.

use std::path::{Path, PathBuf};
use std::time::Instant;

use super::get_from;
use axum::http::StatusCode;
use axum::Router;
use serde_json::Value;
use specula::measured::fit::{
    fit, plane_of_incidence, Observations, Sharing, Specular, POLAR_ANGLES_DEGREES,
};
use specula::{Geometry, LobeKind};
use specula_render::measured::load_measured;

use super::{json, png_size};
use crate::api::AppState;
use crate::measured::{Materials, MAX_MATERIALS, POLAR_POINTS};
use crate::router_with;

/// The real RGL files (isotropic RGB) the repository carries, read as files.
const RGL: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/../../data/rgl");

const NAMES: [&str; 5] = [
    "cc_ibiza_sunset_rgb",
    "cc_iris_purple_gem_rgb",
    "colodur_napoli_4f_rgb",
    "paper_white_rgb",
    "vch_golden_yellow_rgb",
];

/// The router offering the bundled materials (the binary's copies of the RGL files).
fn with_rgl() -> Router {
    router_with(AppState::default().with_materials(Materials::bundled()))
}

async fn json_from(app: &Router, uri: &str) -> (StatusCode, Value) {
    let (status, body) = get_from(app, uri).await;
    let value = serde_json::from_slice(&body)
        .unwrap_or_else(|e| panic!("{uri}: {e}: {}", String::from_utf8_lossy(&body)));
    (status, value)
}

/// A scratch folder of its own, removed when dropped (the crate has no `tempfile`).
struct Scratch(PathBuf);

impl Scratch {
    fn new(name: &str) -> Self {
        let path =
            std::env::temp_dir().join(format!("specula-serve-{name}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&path);
        std::fs::create_dir_all(&path).expect("scratch folder");
        Self(path)
    }
}

impl Drop for Scratch {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
}

#[tokio::test]
async fn without_data_the_list_is_empty_and_says_how_to_give_a_folder() {
    let (status, list) = json("/api/materials").await;
    assert_eq!(status, StatusCode::OK);
    assert_eq!(list["materials"], serde_json::json!([]));
    assert!(list["hint"]
        .as_str()
        .expect("a hint")
        .contains("specula serve --data DIR"));
    for uri in [
        "/api/fits?material=paper_white_rgb",
        "/api/material-render?material=paper_white_rgb",
    ] {
        let (status, body) = json(uri).await;
        assert_eq!(status, StatusCode::BAD_REQUEST, "{uri}");
        assert_eq!(body["parameter"], "material");
        assert!(body["error"]
            .as_str()
            .expect("error")
            .contains("--data DIR"));
    }
}

#[tokio::test]
async fn the_list_names_the_folders_materials_and_nothing_else() {
    let app = with_rgl();
    let (status, list) = json_from(&app, "/api/materials").await;
    assert_eq!(status, StatusCode::OK);
    let names: Vec<&str> = list["materials"]
        .as_array()
        .expect("materials")
        .iter()
        .map(|m| m["name"].as_str().expect("name"))
        .collect();
    assert_eq!(names, NAMES);
    assert!(list["hint"].is_null());
    assert_eq!(list["render_fits"][0], "measured");
    assert_eq!(
        list["render_fits"].as_array().expect("labels").len(),
        1 + 2 * LobeKind::ALL.len() + 1
    );
}

/// Paths, near-misses and unknown names are refused with a 400 naming `material` and the valid
/// names, before any file is touched; so is a render's unknown fit.
#[tokio::test]
async fn anything_but_a_listed_name_is_refused_with_the_valid_names() {
    let app = with_rgl();
    let valid = NAMES.join(", ");
    for material in [
        "../x",
        "..%2Fx",
        "/etc/passwd",
        "%2Fetc%2Fpasswd",
        "paper_white_rgb.bsdf",
        "paper_white_rgb.bsdf/..",
        "paper_white_rgb%2F..",
        "./paper_white_rgb",
        "PAPER_WHITE_RGB",
        "paper_white_rgb%00",
        "",
        "nope",
    ] {
        for endpoint in ["fits", "material-render"] {
            let uri = format!("/api/{endpoint}?material={material}");
            let (status, body) = json_from(&app, &uri).await;
            assert_eq!(status, StatusCode::BAD_REQUEST, "{uri}");
            assert_eq!(body["parameter"], "material", "{uri}");
            assert_eq!(body["valid"], valid.as_str(), "{uri}");
            assert!(
                body["error"]
                    .as_str()
                    .expect("error")
                    .starts_with("unknown material `"),
                "{uri}: {body}"
            );
        }
    }
    let (status, body) = json_from(&app, "/api/fits").await;
    assert_eq!(
        (status, &body["valid"]),
        (StatusCode::BAD_REQUEST, &Value::from(valid))
    );
    for (uri, parameter) in [
        (
            "/api/material-render?material=paper_white_rgb&fit=../x",
            "fit",
        ),
        (
            "/api/material-render?material=paper_white_rgb&fit=pow",
            "fit",
        ),
        (
            "/api/material-render?material=paper_white_rgb&size=9999",
            "size",
        ),
        ("/api/material-render?material=paper_white_rgb&spp=0", "spp"),
        (
            "/api/fits?material=paper_white_rgb&path=/etc/passwd",
            "path",
        ),
        (
            "/api/fits?material=paper_white_rgb&material=nope",
            "material",
        ),
    ] {
        let (status, body) = json_from(&app, uri).await;
        assert_eq!(status, StatusCode::BAD_REQUEST, "{uri}");
        assert_eq!(body["parameter"], parameter, "{uri}: {body}");
    }
    // Nothing was fitted on the way.
    let (_, list) = json_from(&app, "/api/materials").await;
    assert!(list["materials"]
        .as_array()
        .expect("materials")
        .iter()
        .all(|m| m["fitted"] == false));
}

/// A real material's fits are the library's (`fit` with `n` shared), its polar data the
/// material's and the fits' `f cos` along the plane of incidence; the second request comes
/// from the cache, byte for byte (the list says the material is fitted; the times are printed,
/// not asserted); a render shows the measured material or a fit.
#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_real_materials_fits_are_the_librarys_and_computed_once() {
    let app = with_rgl();
    let uri = "/api/fits?material=paper_white_rgb";
    let started = Instant::now();
    let (status, first) = get_from(&app, uri).await;
    let first_time = started.elapsed();
    assert_eq!(
        status,
        StatusCode::OK,
        "{}",
        String::from_utf8_lossy(&first)
    );
    let started = Instant::now();
    let (status, second) = get_from(&app, uri).await;
    let second_time = started.elapsed();
    assert_eq!(status, StatusCode::OK);
    assert_eq!(first, second, "the cached answer is the first one");
    println!("paper_white_rgb: first request {first_time:?}, cached {second_time:?}");
    let (_, list) = json_from(&app, "/api/materials").await;
    assert_eq!(list["materials"][3]["fitted"], true);
    assert_eq!(list["materials"][0]["fitted"], false);

    let data: Value = serde_json::from_slice(&first).expect("JSON");
    let fits = data["fits"].as_array().expect("fits");
    assert_eq!(fits.len(), 2 * LobeKind::ALL.len() + 1);
    assert_eq!(fits[0]["label"], "pow/phong");
    assert_eq!(fits[1]["label"], "pow/blinn");
    assert_eq!(fits[fits.len() - 1]["label"], "ggx");
    assert!(fits[fits.len() - 1]["alpha"].as_f64().is_some());

    // The library's own fit of pow in the Phong geometry, n shared.
    let material = load_measured(&Path::new(RGL).join("paper_white_rgb.bsdf")).expect("material");
    let observations = Observations::of(|wo, wi| material.f_cos(wo, wi));
    let pow = Specular::Lobe {
        kind: LobeKind::Pow,
        geometry: Geometry::Phong,
    };
    let expected = fit(&observations, pow, Sharing::Shared);
    assert_eq!(fits[0]["n"].as_f64(), Some(expected.parameter[0]));
    assert_eq!(fits[0]["error"].as_f64(), Some(expected.error));
    let numbers = |v: &Value| -> Vec<f64> {
        v.as_array()
            .expect("numbers")
            .iter()
            .map(|x| x.as_f64().expect("number"))
            .collect()
    };
    assert_eq!(numbers(&fits[0]["kd"]), expected.kd);
    assert_eq!(numbers(&fits[0]["k"]), expected.k);
    assert_eq!(data["pairs"].as_u64(), Some(observations.len() as u64));

    // Errors relative to pow's best and GGX's.
    let error = |f: &Value| f["error"].as_f64().expect("error");
    let reference = error(&fits[0]).min(error(&fits[1]));
    assert_eq!(data["reference_error"].as_f64(), Some(reference));
    for f in fits {
        let relative = f["relative_to_pow_best"].as_f64().expect("relative");
        assert!((relative - error(f) / reference).abs() < 1e-12, "{f}");
        let to_ggx = f["relative_to_ggx"].as_f64().expect("relative");
        assert!((to_ggx - error(f) / error(&fits[fits.len() - 1])).abs() < 1e-12);
        assert!(f["label"] == "ggx" || !f["costs"].as_array().expect("costs").is_empty());
    }

    // The polar data: every viewing angle, the measured luminance and every fit's.
    let luminance = specula::brdf::luminance;
    let polar = data["polar"].as_array().expect("polar");
    assert_eq!(polar.len(), POLAR_ANGLES_DEGREES.len());
    assert_eq!(
        data["polar_elevations_deg"]
            .as_array()
            .expect("elevations")
            .len(),
        POLAR_POINTS
    );
    for (view, &theta_o) in polar.iter().zip(&POLAR_ANGLES_DEGREES) {
        assert_eq!(view["theta_o_deg"].as_f64(), Some(theta_o));
        let plane = plane_of_incidence(theta_o.to_radians(), POLAR_POINTS);
        let measured = view["measured"].as_array().expect("measured");
        assert_eq!(measured.len(), POLAR_POINTS);
        for k in (0..POLAR_POINTS).step_by(7) {
            let (_, wo, wi) = plane[k];
            let want = luminance(material.f_cos(wo, wi)) as f32;
            // f32 written in its shortest form: read back as f32, the same number.
            assert_eq!(measured[k].as_f64().map(|v| v as f32), Some(want));
            let got = view["fits"][0][k].as_f64().expect("fit value");
            assert_eq!(
                got as f32,
                luminance(expected.prepare().f_cos(wo, wi)) as f32
            );
        }
        assert_eq!(view["fits"].as_array().expect("fits").len(), fits.len());
    }

    // Renders: the measured material and a fit, the same size, different images.
    let render = |fit: &str| {
        format!("/api/material-render?material=paper_white_rgb&fit={fit}&size=32&spp=2")
    };
    let (status, measured) = get_from(&app, &render("measured")).await;
    assert_eq!(
        status,
        StatusCode::OK,
        "{}",
        String::from_utf8_lossy(&measured)
    );
    assert_eq!(png_size(&measured), (32, 18));
    let (status, fitted) = get_from(&app, &render("ggx")).await;
    assert_eq!(
        status,
        StatusCode::OK,
        "{}",
        String::from_utf8_lossy(&fitted)
    );
    assert_eq!(png_size(&fitted), (32, 18));
    assert_ne!(measured, fitted);
}

/// The folder's listing: `*.bsdf` regular files (or links to them) directly in it, by stem;
/// anything else left out; an empty folder, a missing one and one over the bound refused.
#[test]
fn the_bundled_materials_are_the_repositorys_files_byte_for_byte() {
    let materials = Materials::bundled();
    assert_eq!(materials.names().collect::<Vec<_>>(), NAMES);
    for (name, bytes) in specula_render::measured::BUNDLED_MATERIALS {
        let file = std::fs::read(Path::new(RGL).join(format!("{name}.bsdf"))).expect("file");
        assert!(
            file == bytes,
            "{name}: the embedded bytes differ from the file's"
        );
    }
    let folder_only = Materials::from_folder(Path::new(RGL)).expect("listed").0;
    assert_eq!(folder_only.names().collect::<Vec<_>>(), NAMES);
}

#[test]
fn a_folder_adds_to_the_bundled_materials_and_its_namesakes_take_their_place() {
    let scratch = Scratch::new("beside");
    std::fs::write(scratch.0.join("mine.bsdf"), b"not a material").expect("write");
    std::fs::write(scratch.0.join("paper_white_rgb.bsdf"), b"not paper").expect("write");
    let (materials, notes) = Materials::bundled()
        .with_folder(&scratch.0)
        .expect("listed");
    let mut expected = NAMES.to_vec();
    expected.push("mine");
    expected.sort_unstable();
    assert_eq!(materials.names().collect::<Vec<_>>(), expected);
    assert_eq!(notes.len(), 1, "{notes:?}");
    assert!(notes[0].contains("paper_white_rgb"), "{notes:?}");
    // The user's file is the one read: it is no material.
    let costs = AppState::default().costs;
    let paper = materials.find("paper_white_rgb").expect("listed");
    let error = materials
        .assess(paper, &costs)
        .expect_err("the user's file");
    assert!(
        error.starts_with("the material `paper_white_rgb` cannot be read"),
        "{error}"
    );
}

#[test]
fn the_folder_is_listed_once_with_regular_bsdf_files_only() {
    let scratch = Scratch::new("listing");
    let folder = &scratch.0;
    for name in ["b.bsdf", "a.bsdf", "notes.txt", "c.bsdf.txt", ".bsdf"] {
        std::fs::write(folder.join(name), b"not a material").expect("write");
    }
    std::fs::create_dir(folder.join("d.bsdf")).expect("a folder named like a material");
    std::fs::create_dir(folder.join("sub")).expect("subfolder");
    std::fs::write(folder.join("sub/e.bsdf"), b"x").expect("write");
    #[cfg(unix)]
    {
        std::os::unix::fs::symlink(folder.join("a.bsdf"), folder.join("linked.bsdf"))
            .expect("link");
        std::os::unix::fs::symlink(folder.join("missing"), folder.join("dangling.bsdf"))
            .expect("link");
    }
    let (materials, skipped) = Materials::from_folder(folder).expect("listed");
    let names: Vec<&str> = materials.names().collect();
    let expected: &[&str] = if cfg!(unix) {
        &["a", "b", "linked"]
    } else {
        &["a", "b"]
    };
    assert_eq!(names, expected);
    assert!(skipped.is_empty());

    // A listed file that is not a material: a 500 in one line naming the material, not the
    // server's folder.
    let costs = AppState::default().costs;
    let error = materials.assess(0, &costs).expect_err("not a tensor file");
    assert!(
        error.starts_with("the material `a` cannot be read: "),
        "{error}"
    );
    assert!(
        !error.contains(&*folder.to_string_lossy()) && !error.contains('\n'),
        "{error}"
    );

    let empty = Scratch::new("empty");
    let error = Materials::from_folder(&empty.0).expect_err("no material");
    assert!(error.contains("holds no .bsdf file"), "{error}");
    let error = Materials::from_folder(&empty.0.join("missing")).expect_err("no folder");
    assert!(error.contains("cannot list the folder"), "{error}");

    let many = Scratch::new("many");
    for k in 0..=MAX_MATERIALS {
        std::fs::write(many.0.join(format!("m{k}.bsdf")), b"x").expect("write");
    }
    let error = Materials::from_folder(&many.0).expect_err("too many");
    assert!(
        error.contains(&format!("more than {MAX_MATERIALS}")),
        "{error}"
    );
    std::fs::remove_file(many.0.join("m0.bsdf")).expect("remove");
    assert_eq!(
        Materials::from_folder(&many.0)
            .expect("at the bound")
            .0
            .names()
            .count(),
        MAX_MATERIALS
    );
}
