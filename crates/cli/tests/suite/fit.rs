//! `specula fit` and `recommend --material` on real measured materials: one JSON line per
//! material, whose figures hold together (each per-channel fit at least as good as its shared
//! one, the verdict within the margin of pow's best and the cheapest such, GGX without
//! `ks`); the table's verdict; and bad files refused in one line before any output.

use std::path::{Path, PathBuf};

use crate::common::{ok, specula};
use serde_json::Value;

fn rgl(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../data/rgl")
        .join(format!("{name}.bsdf"))
}

fn text(path: &Path) -> String {
    path.to_str().expect("utf-8 path").to_owned()
}

fn number(value: &Value) -> f64 {
    value.as_f64().expect("a number")
}

#[test]
fn each_material_is_one_consistent_json_line() {
    let dir = tempfile::tempdir().unwrap();
    let files = [rgl("paper_white_rgb"), rgl("cc_iris_purple_gem_rgb")];
    let output = ok(
        dir.path(),
        &[
            "fit",
            "--material",
            &text(&files[0]),
            &text(&files[1]),
            "--format",
            "json",
        ],
    );
    let stdout = String::from_utf8(output.stdout).unwrap();
    let lines: Vec<&str> = stdout.lines().collect();
    assert_eq!(lines.len(), 2, "{stdout}");
    for (line, file) in lines.iter().zip(&files) {
        let report: Value = serde_json::from_str(line).expect("one JSON object per line");
        assert_eq!(report["file"], text(file));
        let fits = report["fits"].as_array().unwrap();
        // Every built-in lobe in both geometries and GGX, each shared and per channel.
        assert_eq!(fits.len(), (13 * 2 + 1) * 2);
        for pair in fits.chunks(2) {
            let (shared, per_channel) = (&pair[0], &pair[1]);
            assert_eq!(
                (shared["sharing"].as_str(), per_channel["sharing"].as_str()),
                (Some("shared"), Some("per-channel"))
            );
            // The per-channel model contains the shared one: a fit that does worse is stuck.
            assert!(
                number(&per_channel["error"]) <= number(&shared["error"]) * (1.0 + 1e-6),
                "{shared} {per_channel}"
            );
            let ggx = shared["specular"]["family"] == "ggx";
            assert_eq!(shared.get("ks").is_none(), ggx);
        }
        let is_shared_pow = |f: &&Value| f["specular"]["kind"] == "pow" && f["sharing"] == "shared";
        let reference = fits
            .iter()
            .filter(is_shared_pow)
            .map(|f| number(&f["error"]))
            .fold(f64::INFINITY, f64::min);
        assert!((number(&report["reference_error"]) - reference).abs() < 1e-12);
        let margin = number(&report["margin"]);
        let chosen = &fits[report["chosen"].as_u64().unwrap() as usize];
        assert!(number(&chosen["error"]) <= (1.0 + margin) * reference);
        let meeting: Vec<&Value> = fits
            .iter()
            .filter(|f| f["sharing"] == "shared" && f["specular"]["family"] == "lobe")
            .filter(|f| number(&f["error"]) <= (1.0 + margin) * reference)
            .collect();
        let best_rate = meeting
            .iter()
            .map(|f| number(&f["rate"]))
            .fold(0.0, f64::max);
        assert_eq!(number(&chosen["rate"]), best_rate);
        assert!(meeting.iter().all(|f| f["meets"] == true));
    }
}

#[test]
fn recommend_names_the_verdict_and_refuses_the_fpga() {
    let dir = tempfile::tempdir().unwrap();
    let paper = text(&rgl("paper_white_rgb"));
    let output = ok(
        dir.path(),
        &["recommend", "--material", &paper, "--target", "gpu-amd"],
    );
    let stdout = String::from_utf8(output.stdout).unwrap();
    assert!(
        stdout.contains("the cheapest lobe on gpu-amd whose fit is within 5 % of pow's"),
        "{stdout}"
    );
    let refused = specula(
        dir.path(),
        &["recommend", "--material", &paper, "--target", "fpga"],
    );
    let stderr = String::from_utf8_lossy(&refused.stderr);
    assert!(!refused.status.success());
    assert!(
        stderr.contains("valid targets: cpu, gpu-nvidia, gpu-amd, gpu-intel"),
        "{stderr}"
    );
}

#[test]
fn bad_files_are_refused_in_one_line_before_any_output() {
    let dir = tempfile::tempdir().unwrap();
    let truncated = dir.path().join("truncated.bsdf");
    let bytes = std::fs::read(rgl("paper_white_rgb")).unwrap();
    std::fs::write(&truncated, &bytes[..bytes.len() / 2]).unwrap();
    let not_tensor = dir.path().join("scene.bsdf");
    std::fs::write(&not_tensor, "not a tensor file").unwrap();
    let paper = text(&rgl("paper_white_rgb"));
    for (bad, expected) in [
        (text(&truncated), "truncated"),
        (text(&not_tensor), "not a tensor file"),
        (text(dir.path()), "not a regular file"),
        ("/dev/zero".to_owned(), "not a regular file"),
    ] {
        // The good file first: nothing may be printed for it when a later one is bad.
        let output = specula(
            dir.path(),
            &["fit", "--material", &paper, &bad, "--format", "json"],
        );
        let stderr = String::from_utf8_lossy(&output.stderr);
        assert!(!output.status.success(), "{bad}");
        assert!(output.stdout.is_empty(), "{bad}: printed before refusing");
        assert!(stderr.contains(expected), "{bad}: {stderr}");
        assert_eq!(stderr.trim().lines().count(), 1, "{stderr}");
    }
}

#[test]
fn a_users_lobe_is_fitted_beside_the_built_in_ones() {
    // `t^n` written as a formula is pow: its fits must be pow's, to rounding.
    let dir = tempfile::tempdir().unwrap();
    let file = text(&rgl("colodur_napoli_4f_rgb"));
    let output = ok(
        dir.path(),
        &[
            "fit",
            "--material",
            &file,
            "--lobe",
            "=t^n",
            "--format",
            "json",
        ],
    );
    let report: Value = serde_json::from_slice(&output.stdout).unwrap();
    let fits = report["fits"].as_array().unwrap();
    let find = |kind: &str, geometry: &str| {
        fits.iter()
            .find(|f| {
                f["specular"]["kind"] == kind
                    && f["specular"]["geometry"] == geometry
                    && f["sharing"] == "shared"
            })
            .unwrap_or_else(|| panic!("no {kind}/{geometry} fit"))
    };
    for geometry in ["phong", "blinn"] {
        let (pow, yours) = (find("pow", geometry), find("formula", geometry));
        let (a, b) = (number(&pow["error"]), number(&yours["error"]));
        assert!((a - b).abs() <= 1e-9 * a, "{geometry}: {a} vs {b}");
        let (n, m) = (number(&pow["parameter"][0]), number(&yours["parameter"][0]));
        assert!((n - m).abs() <= 1e-6 * n, "{geometry}: n {n} vs {m}");
    }
}

/// `fit --model microfacet` on the material: every lobe fitted as a distribution
/// beside its classic fit, Beckmann and GGX; the verdict is the cheapest distribution within
/// the margin of GGX's shared fit (checked from the JSON's own figures), or, where none is,
/// the closest one, said so.
#[test]
fn the_microfacet_model_fits_every_lobe_as_a_distribution() {
    let dir = tempfile::tempdir().unwrap();
    let fit_paper = |more: &[&str]| {
        let paper = text(&rgl("paper_white_rgb"));
        let mut args = vec!["fit", "--material", &paper, "--model", "microfacet"];
        args.extend_from_slice(more);
        ok(dir.path(), &args)
    };
    let report: Value =
        serde_json::from_slice(&fit_paper(&["--format", "json"]).stdout).expect("JSON");
    assert_eq!(report["model"], "microfacet");
    let fits = report["fits"].as_array().unwrap();
    let family = |f: &Value| f["specular"]["family"].as_str().unwrap().to_owned();
    let normals = |f: &Value| f["specular"]["normals"].as_str().unwrap_or("").to_owned();
    let shared: Vec<&Value> = fits.iter().filter(|f| f["sharing"] == "shared").collect();
    let in_model: Vec<&&Value> = shared
        .iter()
        .filter(|f| family(f) == "microfacet")
        .collect();
    let distributions: Vec<&&Value> = in_model
        .iter()
        .copied()
        .filter(|f| !["ggx", "beckmann"].contains(&normals(f).as_str()))
        .collect();
    // Every built-in lobe as a distribution, beside its two classic fits, Beckmann and GGX.
    assert_eq!(distributions.len(), 13, "{report}");
    assert_eq!(shared.iter().filter(|f| family(f) == "lobe").count(), 26);
    let ggx = in_model
        .iter()
        .find(|f| normals(f) == "ggx")
        .expect("GGX's distribution");
    assert!(in_model.iter().any(|f| normals(f) == "beckmann"));
    // Every fit of the model has its Fresnel F0 per channel, in [0, 1]; the classic ones none.
    for f in &shared {
        let f0 = &f["f0"];
        if family(f) == "microfacet" {
            let f0: Vec<f64> = f0.as_array().expect("an F0").iter().map(number).collect();
            assert!(
                f0.len() == 3 && f0.iter().all(|v| (0.0..=1.0).contains(v)),
                "{f}"
            );
        } else {
            assert!(f0.is_null(), "{f}");
        }
    }
    let ggx_error = number(&ggx["error"]);
    let margin = number(&report["margin"]);
    let chosen = &fits[report["chosen"].as_u64().unwrap() as usize];
    assert_eq!(family(chosen), "microfacet");
    assert!(!["ggx", "beckmann"].contains(&normals(chosen).as_str()));
    let within = |f: &Value| number(&f["error"]) <= (1.0 + margin) * ggx_error;
    if report["within_margin"] == true {
        assert!(within(chosen));
        // No distribution within the margin is cheaper on the target.
        for d in distributions.iter().filter(|d| within(d)) {
            assert!(number(&d["rate"]) <= number(&chosen["rate"]), "{d}");
        }
    } else {
        assert!(distributions.iter().all(|d| !within(d)));
    }
    // The table's verdict line names the model's reference.
    let table = fit_paper(&[]);
    let stdout = String::from_utf8_lossy(&table.stdout);
    assert!(stdout.contains("GGX's"), "{stdout}");
}
