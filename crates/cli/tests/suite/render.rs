//! `specula render`, `diff` and `bench`: files written whole or not at all, figures from
//! closed forms, bad input answered with a message and exit code 2.

use crate::common;

use std::path::Path;

use crate::common::{ok, specula};
use serde_json::Value;

fn png_size(path: &Path) -> (u32, u32) {
    let bytes = std::fs::read(path).unwrap();
    assert_eq!(&bytes[1..4], b"PNG");
    let be = |k: usize| u32::from_be_bytes(bytes[k..k + 4].try_into().unwrap());
    (be(16), be(20))
}

fn files(directory: &Path) -> Vec<String> {
    let mut names: Vec<String> = std::fs::read_dir(directory)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    names
}

#[test]
fn renders_the_default_scene_to_png_and_exr() {
    let directory = tempfile::tempdir().unwrap();
    let d = directory.path();
    ok(
        d,
        &["render", "-o", "out.png", "--width", "96", "--height", "54"],
    );
    assert_eq!(png_size(&d.join("out.png")), (96, 54));
    ok(
        d,
        &[
            "render",
            "-o",
            "out.exr",
            "--width",
            "40",
            "--height",
            "30",
            "--shading",
            "gouraud",
        ],
    );
    assert_eq!(
        &std::fs::read(d.join("out.exr")).unwrap()[..4],
        &[0x76, 0x2f, 0x31, 0x01]
    );
    assert_eq!(files(d), ["out.exr", "out.png"]);
}

#[test]
fn identical_renders_differ_by_nothing_and_other_lobes_by_something() {
    let directory = tempfile::tempdir().unwrap();
    let d = directory.path();
    let size = ["--width", "120", "--height", "68"];
    ok(
        d,
        &[&["render", "-o", "a.png", "--lobe", "pow"][..], &size].concat(),
    );
    ok(
        d,
        &[&["render", "-o", "b.png", "--lobe", "pow"][..], &size].concat(),
    );
    ok(
        d,
        &[
            &["render", "-o", "c.png", "--lobe", "cheb2-thesis"][..],
            &size,
        ]
        .concat(),
    );
    let report = |a: &str, b: &str, extra: &[&str]| -> Value {
        let output = ok(
            d,
            &[&["diff", a, b, "--format", "json"][..], extra].concat(),
        );
        serde_json::from_slice(&output.stdout).unwrap()
    };
    let same = report("a.png", "b.png", &[]);
    assert_eq!(same["mean_flip"], 0.0);
    assert_eq!(same["max_abs_error"], 0.0);
    assert!(same["psnr_db"].is_null(), "infinite PSNR is null: {same}");
    let other = report("a.png", "c.png", &["--heatmap", "heat.png"]);
    assert!(other["mean_flip"].as_f64().unwrap() > 0.0);
    assert!(other["psnr_db"].as_f64().unwrap() > 10.0);
    assert_eq!(png_size(&d.join("heat.png")), (120, 68));
}

#[test]
fn a_grid_has_one_column_per_lobe_and_two_rows() {
    let directory = tempfile::tempdir().unwrap();
    let d = directory.path();
    ok(
        d,
        &[
            "render",
            "--grid",
            "lobes=pow,schlick,cosquad:v=5",
            "--width",
            "80",
            "--height",
            "50",
            "-o",
            "grid.png",
        ],
    );
    assert_eq!(png_size(&d.join("grid.png")), (240, 100));
}

#[test]
fn dumped_default_scene_renders_as_a_file() {
    let directory = tempfile::tempdir().unwrap();
    let d = directory.path();
    let output = ok(d, &["render", "--dump-default-scene"]);
    std::fs::write(d.join("scene.toml"), &output.stdout).unwrap();
    ok(
        d,
        &[
            "render",
            "scene.toml",
            "--width",
            "64",
            "--height",
            "36",
            "-o",
            "s.png",
        ],
    );
    assert_eq!(png_size(&d.join("s.png")), (64, 36));
}

/// Each failure: exit code 2, a message naming the problem, and no output file at all.
#[test]
fn bad_input_fails_cleanly_without_writing() {
    let directory = tempfile::tempdir().unwrap();
    let d = directory.path();
    std::fs::write(
        d.join("bad.toml"),
        "[camera]\neye = [0, -5, 1]\ntarget = [0, 0, 0]\nfov = 200\n",
    )
    .unwrap();
    let cases: [(&[&str], &str); 7] = [
        (&["render", "--n", "5000", "-o", "x.png"], "[1, 1000]"),
        (&["render", "--lobe", "nope", "-o", "x.png"], "valid lobes"),
        (&["render", "-o", "x.jpg"], ".png"),
        (
            &["render", "bad.toml", "-o", "x.png"],
            "bad.toml:1:1: camera: fov",
        ),
        (&["render", "missing.toml", "-o", "x.png"], "missing.toml"),
        (
            &["render", "--grid", "pow,schlick", "-o", "x.png"],
            "lobes=",
        ),
        (&["render", "--grid", "lobes=pow", "-o", "x.exr"], "PNG"),
    ];
    for (args, needle) in cases {
        let output = specula(d, args);
        let stderr = String::from_utf8_lossy(&output.stderr);
        assert_eq!(output.status.code(), Some(2), "{args:?}: {stderr}");
        assert!(
            stderr.contains(needle),
            "{args:?}: '{needle}' missing from {stderr}"
        );
        assert!(!stderr.contains("panicked"), "{stderr}");
    }
    let output = specula(d, &["diff", "bad.toml", "x.png"]);
    assert_eq!(output.status.code(), Some(2));
    assert_eq!(files(d), ["bad.toml"]);
}

#[test]
fn bench_render_prints_a_row_per_shading_method() {
    let directory = tempfile::tempdir().unwrap();
    let output = ok(
        directory.path(),
        &[
            "bench", "render", "--width", "64", "--height", "36", "--frames", "1",
        ],
    );
    let text = String::from_utf8_lossy(&output.stdout);
    for method in ["flat", "gouraud", "phong"] {
        assert!(text.lines().any(|l| l.starts_with(method)), "{text}");
    }
    assert!(text.contains("threads"), "{text}");
}

/// `--env`: the sky and a file (an .hdr this command wrote) both light the environment
/// scene; a seed gives the same image every time and another seed another image; bad
/// environments and sample counts are refused with what is wrong, writing nothing.
#[test]
fn renders_lit_by_an_environment_and_refuses_bad_ones() {
    let directory = tempfile::tempdir().unwrap();
    let d = directory.path();
    let small = ["--width", "48", "--height", "27", "--spp", "4"];
    let env_render = |output: &str, env: &str, seed: &str| {
        let mut args = vec!["render", "--env", env, "--seed", seed, "-o", output];
        args.extend(small);
        ok(d, &args)
    };
    let output = env_render("a.png", "sky", "1");
    assert!(
        String::from_utf8_lossy(&output.stderr).contains("4 spp, lit by sky"),
        "{}",
        String::from_utf8_lossy(&output.stderr)
    );
    assert_eq!(png_size(&d.join("a.png")), (48, 27));
    env_render("b.png", "sky", "1");
    env_render("c.png", "sky", "2");
    let read = |name: &str| std::fs::read(d.join(name)).unwrap();
    assert_eq!(
        read("a.png"),
        read("b.png"),
        "the same seed, the same image"
    );
    assert_ne!(read("a.png"), read("c.png"), "another seed, another image");
    // A panorama written by `render` itself lights the scene from a file.
    ok(
        d,
        &[
            "render", "-o", "pano.hdr", "--width", "64", "--height", "32",
        ],
    );
    env_render("d.png", "pano.hdr", "1");
    assert_eq!(png_size(&d.join("d.png")), (48, 27));

    std::fs::create_dir(d.join("folder.hdr")).unwrap();
    let exr = specula_render::Image::from_pixels(
        2,
        1,
        vec![glam::Vec3::ONE, glam::Vec3::new(f32::NAN, 0.0, 0.0)],
    )
    .unwrap();
    specula_render::write_image(&d.join("nan.exr"), &exr, specula_render::Display::default())
        .unwrap();
    let before = files(d);
    let cases: [(&[&str], &str); 11] = [
        (&["--env", "missing.hdr"], "missing.hdr"),
        (&["--env", "folder.hdr"], "a directory"),
        (&["--env", "nan.exr"], "pixel (1, 0) is NaN"),
        (&["--env", "notes.txt"], "unknown image format"),
        (&["--env", "sky", "--spp", "0"], "1..=65536"),
        (&["--env", "sky", "--spp", "70000"], "1..=65536"),
        (&["--spp", "16"], "--env"),
        (
            &["--env", "sky", "--shading", "flat"],
            "cannot be used with",
        ),
        (&["--env", "sky", "--backend", "gpu"], "CPU only"),
        (
            &["--env", "sky", "--model", "classic"],
            "valid --model values with --env: physical, microfacet",
        ),
        (
            &[
                "--env",
                "sky",
                "--model",
                "microfacet",
                "--grid",
                "lobes=pow,sg",
            ],
            "drop --grid",
        ),
    ];
    for (args, message) in cases {
        let mut command = vec!["render", "-o", "out.png"];
        command.extend(args);
        let output = common::specula(d, &command);
        let stderr = String::from_utf8_lossy(&output.stderr);
        assert_eq!(output.status.code(), Some(2), "{args:?}: {stderr}");
        assert!(stderr.contains(message), "{args:?}: {stderr}");
        assert_eq!(stderr.trim_end().lines().count(), 1, "{args:?}: {stderr}");
    }
    assert_eq!(files(d), before, "nothing written");
}
