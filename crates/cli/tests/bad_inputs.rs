//! The bad-input corpus (`tests/bad-inputs/`): every scene there must be refused with exit
//! code 2, a one-line message containing its `# expect:` text, and no output file. Plus bad
//! command-line values, inputs that are nasty but valid, and outputs that must survive a
//! failed or interrupted render.

mod common;

use std::path::Path;
use std::process::Command;
use std::time::Duration;

use common::{ok, specula};

/// A copy of the corpus in a fresh directory, so that nothing is written into the sources.
fn corpus_copy() -> tempfile::TempDir {
    let directory = tempfile::tempdir().expect("temporary directory");
    let source = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/bad-inputs");
    for entry in std::fs::read_dir(source).expect("corpus") {
        let path = entry.expect("entry").path();
        std::fs::copy(
            &path,
            directory.path().join(path.file_name().expect("name")),
        )
        .expect("copy");
    }
    directory
}

fn files(directory: &Path) -> Vec<String> {
    let mut names: Vec<String> = std::fs::read_dir(directory)
        .expect("list")
        .map(|e| e.expect("entry").file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    names
}

#[test]
fn every_scene_in_the_corpus_is_refused_with_its_message() {
    let directory = corpus_copy();
    let before = files(directory.path());
    let scenes: Vec<&String> = before
        .iter()
        .filter(|name| name.ends_with(".toml"))
        .collect();
    assert!(scenes.len() >= 15, "the corpus lost files: {scenes:?}");
    for scene in scenes {
        let text = std::fs::read_to_string(directory.path().join(scene)).expect("scene");
        let expected = text
            .lines()
            .next()
            .and_then(|line| line.strip_prefix("# expect: "))
            .unwrap_or_else(|| panic!("{scene} has no `# expect:` first line"));
        let output = specula(directory.path(), &["render", scene, "-o", "out.png"]);
        let stderr = String::from_utf8_lossy(&output.stderr);
        assert_eq!(output.status.code(), Some(2), "{scene}: {stderr}");
        assert!(
            stderr.contains(expected),
            "{scene}: expected `{expected}` in: {stderr}"
        );
        assert_eq!(
            stderr.trim_end().lines().count(),
            1,
            "{scene}: one line: {stderr}"
        );
    }
    assert_eq!(
        files(directory.path()),
        before,
        "no output and no temporary file appeared"
    );
}

#[test]
fn bad_command_line_values_name_the_valid_range() {
    let directory = tempfile::tempdir().expect("temporary directory");
    let cases: [(&[&str], &str); 9] = [
        (
            &["render", "--n", "0"],
            "n must be a finite number in [1, 1000]",
        ),
        (
            &["render", "--n", "-1"],
            "n must be a finite number in [1, 1000]",
        ),
        (
            &["render", "--n", "NaN"],
            "n must be a finite number in [1, 1000]",
        ),
        (
            &["render", "--n", "1e9"],
            "n must be a finite number in [1, 1000]",
        ),
        (&["render", "--lobe", "phong"], "valid lobes: pow, schlick"),
        (&["render", "--width", "0"], "1..=16384"),
        (&["render", "--width", "100000"], "1..=16384"),
        (&["render", "--samples", "9"], "1..=8"),
        (
            &["eval", "--lobe", "cosquad", "--n", "64", "--cos", "NaN"],
            "[-1, 1]",
        ),
    ];
    for (args, message) in cases {
        let output = specula(directory.path(), args);
        let stderr = String::from_utf8_lossy(&output.stderr);
        assert_eq!(output.status.code(), Some(2), "{args:?}");
        assert!(stderr.contains(message), "{args:?}: {stderr}");
    }
    assert!(files(directory.path()).is_empty());
}

const CAMERA: &str = "[camera]\neye = [0.0, -5.0, 1.0]\ntarget = [0.0, 0.0, 0.0]\nup = [0.0, 0.0, 1.0]\nfov = 40.0\n[render]\nwidth = 96\nheight = 64\n[[lights]]\nkind = \"point\"\nposition = [0.0, -1.0, 0.5]\nintensity = [1.0, 1.0, 1.0]\n";

/// Degenerate triangles are dropped with a warning; a huge triangle through the camera's
/// plane (clipped) and a light inside the geometry render without a NaN pixel.
#[test]
fn nasty_but_valid_meshes_render_without_nan() {
    let directory = tempfile::tempdir().expect("temporary directory");
    let path = directory.path();
    std::fs::write(
        path.join("degenerate.obj"),
        "v 0 0 0\nv 1 0 0\nv 2 0 0\nv 0 1 0\nf 1 2 3\nf 1 2 4\n",
    )
    .expect("write");
    std::fs::write(
        path.join("huge.obj"),
        "v -1e7 -1e7 0\nv 1e7 -1e7 0\nv 0 1e7 0\nv -1e7 1e3 -1e6\nv 1e7 1e3 -1e6\nv 0 1e3 1e7\nf 1 2 3\nf 4 5 6\n",
    )
    .expect("write");
    let scene = format!(
        "{CAMERA}[[objects]]\nshape = \"mesh\"\npath = \"degenerate.obj\"\n[[objects]]\nshape = \"mesh\"\npath = \"huge.obj\"\n[objects.material]\nlobe = \"logexp-rr\"\nn = 1000\n"
    );
    std::fs::write(path.join("nasty.toml"), scene).expect("write");
    for shading in ["flat", "gouraud", "phong"] {
        let output = ok(
            path,
            &[
                "render",
                "nasty.toml",
                "--shading",
                shading,
                "-o",
                "out.exr",
            ],
        );
        assert!(
            String::from_utf8_lossy(&output.stderr).contains("skipped 1 degenerate triangle(s)")
        );
        let image = specula_render::read_image(&path.join("out.exr")).expect("EXR");
        assert!(
            image.pixels().iter().all(|p| p.is_finite()),
            "{shading}: a pixel is not finite"
        );
    }
}

/// A render that fails, or is killed part-way, leaves the previous output as it was and no
/// temporary file.
#[test]
fn earlier_outputs_survive_failed_and_interrupted_renders() {
    let directory = tempfile::tempdir().expect("temporary directory");
    let path = directory.path();
    let previous = b"the previous output".to_vec();
    std::fs::write(path.join("out.png"), &previous).expect("write");
    // A failing render: a bad scene.
    std::fs::write(path.join("bad.toml"), "[camera\n").expect("write");
    assert_eq!(
        specula(path, &["render", "bad.toml", "-o", "out.png"])
            .status
            .code(),
        Some(2)
    );
    // A write that cannot happen: the destination's folder does not exist.
    let output = specula(
        path,
        &[
            "render",
            "--width",
            "32",
            "--height",
            "32",
            "-o",
            "missing/out.png",
        ],
    );
    assert_eq!(
        output.status.code(),
        Some(2),
        "{}",
        String::from_utf8_lossy(&output.stderr)
    );
    // A render killed part-way (large enough to take a while on any machine).
    let mut child = Command::new(env!("CARGO_BIN_EXE_specula"))
        .current_dir(path)
        .args([
            "render",
            "--width",
            "8000",
            "--height",
            "8000",
            "--samples",
            "2",
            "-o",
            "out.png",
        ])
        .spawn()
        .expect("start a render");
    std::thread::sleep(Duration::from_millis(400));
    let still_running = child.try_wait().expect("status").is_none();
    child.kill().expect("kill");
    let _ = child.wait();
    assert!(
        still_running,
        "the render finished before it could be interrupted"
    );
    assert_eq!(std::fs::read(path.join("out.png")).expect("read"), previous);
    assert_eq!(
        files(path),
        ["bad.toml", "out.png"],
        "no partial or temporary file"
    );
}
