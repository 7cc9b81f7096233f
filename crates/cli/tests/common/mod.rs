//! Running the `specula` binary in a directory of the test's own.

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
