//! Running the `specula` binary in a directory of the test's own, and the tools some tests
//! need. Each test file compiles this module on its own and uses part of it.
#![allow(dead_code)]

use std::path::Path;

use assert_cmd::Command;

/// Runs `specula args` in `directory`.
pub fn specula(directory: &Path, args: &[&str]) -> std::process::Output {
    Command::cargo_bin("specula")
        .expect("binary built")
        .current_dir(directory)
        .args(args)
        .output()
        .expect("runs")
}

/// Runs `specula args` in `directory` and requires success.
pub fn ok(directory: &Path, args: &[&str]) -> std::process::Output {
    let output = specula(directory, args);
    assert!(
        output.status.success(),
        "{args:?}: {}",
        String::from_utf8_lossy(&output.stderr)
    );
    output
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
