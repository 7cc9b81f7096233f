//! `specula sample` from the command line: the printed directions against the closed-form
//! density of `t^n` about the mirror direction, the chi-square suite's line and images, and
//! bad requests refused in one line.

use crate::common::{ok, specula};

/// `pow` in Phong form draws `wi` with density `(n + 1) / (2 pi) (r.wi)^n` about the mirror
/// direction `r`: every printed pdf is that, and with the lobe's normalisation the value is
/// too.
#[test]
fn printed_directions_have_the_closed_form_density() {
    let directory = tempfile::tempdir().unwrap();
    let n = 20.0_f64;
    let output = ok(
        directory.path(),
        &[
            "sample",
            "--lobe",
            "pow",
            "--n",
            "20",
            "--theta-o",
            "30",
            "--count",
            "2000",
        ],
    );
    let text = String::from_utf8(output.stdout).unwrap();
    let mut lines = text.lines();
    assert_eq!(lines.next(), Some("x,y,z,pdf,value"));
    let theta = 30f64.to_radians();
    let mirror = glam::DVec3::new(-theta.sin(), 0.0, theta.cos());
    let mut count = 0;
    for line in lines {
        let v: Vec<f64> = line.split(',').map(|x| x.parse().unwrap()).collect();
        let wi = glam::DVec3::new(v[0], v[1], v[2]);
        assert!((wi.length() - 1.0).abs() < 1e-12 && wi.z > 0.0, "{line}");
        let expected = (n + 1.0) / std::f64::consts::TAU * mirror.dot(wi).powf(n);
        assert!(
            (v[3] - expected).abs() <= 1e-9 * expected,
            "{line}: pdf {expected}"
        );
        assert!(
            (v[4] - expected).abs() <= 1e-9 * expected,
            "{line}: value {expected}"
        );
        count += 1;
    }
    // Draws below the horizon print nothing: at 30 degrees and n = 20 they are rare.
    assert!((1990..=2000).contains(&count), "{count}");

    let json = ok(
        directory.path(),
        &[
            "sample", "--lobe", "schlick", "--n", "8", "--form", "blinn", "--format", "json",
            "--count", "50",
        ],
    );
    let drawn: serde_json::Value = serde_json::from_slice(&json.stdout).unwrap();
    let drawn = drawn.as_array().unwrap();
    assert!(!drawn.is_empty() && drawn.len() <= 50);
    assert!(drawn
        .iter()
        .all(|d| d["pdf"].as_f64().unwrap() > 0.0 && d["z"].as_f64().unwrap() > 0.0));
}

#[test]
fn the_suite_prints_a_line_per_case_and_its_images() {
    let directory = tempfile::tempdir().unwrap();
    let output = ok(
        directory.path(),
        &[
            "sample",
            "--test",
            "--lobe",
            "cosquad",
            "--n",
            "64",
            "--form",
            "phong",
            "--samples",
            "100000",
            "--images",
            "tables",
        ],
    );
    let text = String::from_utf8(output.stdout).unwrap();
    let cases: Vec<&str> = text.lines().filter(|l| l.starts_with("cosquad")).collect();
    assert_eq!(cases.len(), 3, "{text}");
    assert!(
        cases
            .iter()
            .all(|l| l.contains("analytic") && l.ends_with("pass")),
        "{text}"
    );
    let image =
        specula_render::read_image(&directory.path().join("tables/cosquad-n64-phong-35deg.png"))
            .unwrap();
    assert_eq!((image.width(), image.height()), (3 * 64 * 4 + 16, 64 * 4));
}

#[test]
fn bad_sample_requests_are_refused_in_one_line() {
    let directory = tempfile::tempdir().unwrap();
    for (args, says) in [
        (
            &["sample", "--lobe", "phong", "--n", "3"][..],
            "unknown lobe 'phong'",
        ),
        (
            &["sample", "--lobe", "pow", "--n", "3", "--theta-o", "95"],
            "[0, 89]",
        ),
        (
            &["sample", "--lobe", "pow", "--n", "3", "--theta-o", "NaN"],
            "[0, 89]",
        ),
        (&["sample", "--lobe", "pow", "--n", "0"], "[1, 1000]"),
        (
            &["sample", "--lobe", "pow", "--n", "3", "--count", "0"],
            "1..=10000000",
        ),
        (
            &[
                "sample",
                "--lobe",
                "pow",
                "--n",
                "3",
                "--count",
                "99999999999",
            ],
            "1..=10000000",
        ),
        (
            &["sample", "--test", "--samples", "10"],
            "[1000, 100000000]",
        ),
        (
            &["sample", "--lobe", "pow", "--n", "3", "--samples", "5000"],
            "--test",
        ),
        (&["sample", "--n", "3"], "give --lobe and --n"),
    ] {
        let output = specula(directory.path(), args);
        let stderr = String::from_utf8_lossy(&output.stderr);
        assert!(!output.status.success(), "{args:?}");
        assert!(stderr.contains(says), "{args:?}: {stderr}");
    }
}
