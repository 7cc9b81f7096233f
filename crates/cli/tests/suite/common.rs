//! Running the `specula` binary in a directory of the test's own, and the tools some tests
//! need.

use std::path::Path;

use assert_cmd::Command;

/// The suite's own cache folder (`SPECULA_CACHE_DIR` for every program it runs): never the
/// user's `~/.cache/specula`, so that what a user ran before cannot change what a test sees;
/// kept between runs of the suite, whose keys hold the tools found.
pub fn test_cache() -> std::path::PathBuf {
    Path::new(env!("CARGO_TARGET_TMPDIR")).join("specula-cache")
}

/// `specula` to run in `directory` with the suite's cache folder ([`test_cache`]); arguments
/// and more of the environment are added before it runs.
pub fn command(directory: &Path) -> Command {
    let mut command = Command::cargo_bin("specula").expect("binary built");
    command
        .env("SPECULA_CACHE_DIR", test_cache())
        .current_dir(directory);
    command
}

/// Runs `command` and requires success, showing its stderr where it fails.
pub fn succeeds(command: &mut Command) -> std::process::Output {
    let output = command.output().expect("runs");
    assert!(
        output.status.success(),
        "{command:?}: {}",
        String::from_utf8_lossy(&output.stderr)
    );
    output
}

/// Runs `specula args` in `directory`.
pub fn specula(directory: &Path, args: &[&str]) -> std::process::Output {
    command(directory).args(args).output().expect("runs")
}

/// Runs `specula args` in `directory` and requires success.
pub fn ok(directory: &Path, args: &[&str]) -> std::process::Output {
    succeeds(command(directory).args(args))
}

/// Whether `tool` runs (`tool version_flag` succeeds). When it does not, a run with `CI=true`
/// fails, naming the Debian package, and any other run prints `skipped: ...` and the caller
/// skips.
pub fn have_tool(tool: &str, version_flag: &str, package: &str) -> bool {
    let found = std::process::Command::new(tool)
        .arg(version_flag)
        .output()
        .is_ok_and(|o| o.status.success());
    if !found {
        assert!(
            std::env::var("CI").as_deref() != Ok("true"),
            "{tool} is not installed, and CI=true requires it: apt-get install {package}"
        );
        eprintln!("skipped: {tool} is not installed (apt-get install {package})");
    }
    found
}

/// Whether wgpu finds an adapter. Without one a test is skipped, except under `CI=true`,
/// where `.ci/run` installs Mesa's lavapipe and a missing adapter is a failure.
pub fn have_gpu() -> bool {
    match specula_gpu::Gpu::new() {
        Ok(_) => true,
        Err(error) if std::env::var("CI").as_deref() == Ok("true") => {
            panic!("CI=true but no GPU: {error}")
        }
        Err(error) => {
            eprintln!("skipped: {error}");
            false
        }
    }
}

/// The Python that has the renderers' packages (`bpy`, `mitsuba`, `MaterialX`): `$SPECULA_PYTHON`,
/// or the virtual environment `.ci/run` makes in the build folder.
pub fn python() -> std::path::PathBuf {
    std::env::var_os("SPECULA_PYTHON").map_or_else(
        || Path::new(env!("CARGO_MANIFEST_DIR")).join("../../target/venv/bin/python"),
        std::path::PathBuf::from,
    )
}

/// Whether [`python`] imports `module`. When it does not, a run with `CI=true` fails, naming
/// the package, and any other run prints `skipped: ...` and the caller skips.
pub fn have_python_module(module: &str, package: &str) -> bool {
    let found = std::process::Command::new(python())
        .env("SPECULA_CACHE_DIR", crate::common::test_cache())
        .args(["-c", &format!("import {module}")])
        .output()
        .is_ok_and(|o| o.status.success());
    if !found {
        assert!(
            std::env::var("CI").as_deref() != Ok("true"),
            "{} cannot import {module}, and CI=true requires it: .ci/run installs {package} into \
                target/venv",
            python().display()
        );
        eprintln!("skipped: {module} is not importable (pip install {package} into target/venv)");
    }
    found
}

/// A harness script of the renderer tests (`tests/renderers/`).
pub fn renderer_script(name: &str) -> std::path::PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/renderers")
        .join(name)
}

/// Runs [`python`] on `script` with `args` in `directory`, requiring success.
pub fn run_python(directory: &Path, script: &str, args: &[String]) -> std::process::Output {
    let output = std::process::Command::new(python())
        .env("SPECULA_CACHE_DIR", crate::common::test_cache())
        .current_dir(directory)
        .arg(renderer_script(script))
        .args(args)
        .output()
        .expect("python runs");
    assert!(
        output.status.success(),
        "{script} {args:?}:\n{}\n{}",
        String::from_utf8_lossy(&output.stdout),
        String::from_utf8_lossy(&output.stderr)
    );
    output
}

/// A UV sphere of `radius` at the origin as OBJ text, with exact unit normals (`vn`), so
/// that two renderers given the file shade the same surface.
pub fn sphere_obj(radius: f64, segments: u32, rings: u32) -> String {
    use core::f64::consts::{PI, TAU};
    use std::fmt::Write as _;
    let mut obj = String::from("# UV sphere with exact normals\n");
    for ring in 0..=rings {
        let polar = PI * f64::from(ring) / f64::from(rings);
        for segment in 0..=segments {
            let azimuth = TAU * f64::from(segment) / f64::from(segments);
            let n = [
                polar.sin() * azimuth.cos(),
                polar.sin() * azimuth.sin(),
                polar.cos(),
            ];
            let _ = writeln!(
                obj,
                "v {} {} {}",
                radius * n[0],
                radius * n[1],
                radius * n[2]
            );
            let _ = writeln!(obj, "vn {} {} {}", n[0], n[1], n[2]);
        }
    }
    let index = |ring: u32, segment: u32| ring * (segments + 1) + segment + 1;
    for ring in 0..rings {
        for segment in 0..segments {
            let [a, b, c, d] = [
                index(ring, segment),
                index(ring + 1, segment),
                index(ring + 1, segment + 1),
                index(ring, segment + 1),
            ];
            // Counter-clockwise seen from outside; the poles' degenerate halves left out.
            if ring + 1 < rings {
                let _ = writeln!(obj, "f {a}//{a} {b}//{b} {c}//{c}");
            }
            if ring > 0 {
                let _ = writeln!(obj, "f {a}//{a} {c}//{c} {d}//{d}");
            }
        }
    }
    obj
}

/// The path of one of `docs/lobes/`'s lobe files (`quartic.toml`, ...).
pub fn docs_lobe(name: &str) -> std::path::PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../docs/lobes")
        .join(name)
}

/// `specula shader --lobe LOBE --n N --geometry GEOMETRY --lang LANG -o FILE` in `directory`,
/// requiring success: a lobe exported for a renderer test.
pub fn export_lobe(directory: &Path, lobe: &str, n: f64, geometry: &str, lang: &str, file: &str) {
    ok(
        directory,
        &[
            "shader",
            "--lobe",
            lobe,
            "--n",
            &n.to_string(),
            "--geometry",
            geometry,
            "--lang",
            lang,
            "-o",
            file,
        ],
    );
}

/// Whether every GPU vendor's compiler `specula-isa` runs is here (nvcc, RADV's null device,
/// ocloc). Without one a test is skipped, except under `CI=true`, where `.ci/run` installs
/// them and a missing one is a failure.
pub fn have_gpu_compilers() -> bool {
    for vendor in specula::gpus::Vendor::ALL {
        match specula_isa::compiler_version(&vendor.default_gpu()) {
            Ok(_) => {}
            Err(error) if std::env::var("CI").as_deref() == Ok("true") => {
                panic!("CI=true requires every GPU compiler: {error}")
            }
            Err(error) => {
                eprintln!("skipped: {error}");
                return false;
            }
        }
    }
    true
}
