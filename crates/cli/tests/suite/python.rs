//! The Python package (`crates/python`) as a user installs it: `pip install
//! --no-build-isolation ./crates/python` into `target/venv` with no package index (offline),
//! then its pytest suite on the installed wheel, which compares the package with this
//! build's `specula` binary.
//!
//! The wheel is built in the workspace's target folder in the profile the tests run in (`dev`,
//! optimised; `cargo test` releases the folder's lock before it runs the tests), so it reuses
//! the crates the tests were built from rather than building every dependency again in
//! release.

use std::path::Path;
use std::process::Command;

use crate::common::{have_python_module, python};

fn root() -> std::path::PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

/// Runs `command`, requiring success, and prints what it printed.
fn run(what: &str, command: &mut Command) {
    let output = command.output().unwrap_or_else(|e| panic!("{what}: {e}"));
    let text = format!(
        "{}{}",
        String::from_utf8_lossy(&output.stdout),
        String::from_utf8_lossy(&output.stderr)
    );
    println!("{text}");
    assert!(output.status.success(), "{what} failed:\n{text}");
}

/// Each dependency's features as `cargo tree` resolves them for `selection`, by package,
/// without the `pyo3` crates (the wheel alone adds their `extension-module`, as it must).
fn resolved_features(selection: &[&str]) -> std::collections::BTreeMap<String, String> {
    let output = Command::new(env!("CARGO"))
        .current_dir(root())
        .args(["tree", "--locked", "--offline", "--prefix", "none"])
        .args(["-f", "{p} [{f}]"])
        .args(selection)
        .output()
        .expect("cargo tree runs");
    assert!(
        output.status.success(),
        "cargo tree {selection:?}: {}",
        String::from_utf8_lossy(&output.stderr)
    );
    String::from_utf8_lossy(&output.stdout)
        .lines()
        .filter_map(|line| {
            // `NAME vX (PATH) [FEATURES]`, then ` (*)` where the tree was shown before.
            let (package, rest) = line.split_once(" [")?;
            let (features, _) = rest.rsplit_once(']')?;
            (!package.starts_with("pyo3")).then(|| (package.to_owned(), features.to_owned()))
        })
        .collect()
}

/// The wheel's build (`cargo rustc -p specula-python`, features resolved for that crate
/// alone) enables in every dependency the features the workspace's build enables, so it
/// reuses the tests' crates instead of building most of the tree again.
#[test]
fn the_wheel_resolves_the_features_the_workspace_does() {
    let wheel = resolved_features(&["-p", "specula-python", "-e", "normal,build"]);
    // Every target's build, the tests' dependencies included, as `cargo test` builds.
    let workspace = resolved_features(&["--workspace", "-e", "normal,build,dev"]);
    let differing: Vec<String> = wheel
        .iter()
        .filter(|(package, features)| workspace.get(*package).is_some_and(|w| w != *features))
        .map(|(package, features)| {
            format!(
                "{package}: wheel [{features}], workspace [{}]",
                workspace[package]
            )
        })
        .collect();
    assert!(
        differing.is_empty(),
        "name these features in crates/python/Cargo.toml:\n{}",
        differing.join("\n")
    );
}

#[test]
fn the_package_installs_offline_and_its_tests_pass() {
    for (module, package) in [
        ("maturin", "maturin"),
        ("pytest", "pytest"),
        ("scipy", "scipy"),
        ("nbclient", "nbclient"),
        ("nibabel", "nibabel"),
    ] {
        if !have_python_module(module, package) {
            return;
        }
    }
    let root = root();
    let venv_bin = python()
        .parent()
        .expect("the Python is in a folder")
        .to_path_buf();
    let path = std::env::join_paths(std::iter::once(venv_bin).chain(std::env::split_paths(
        &std::env::var_os("PATH").unwrap_or_default(),
    )))
    .expect("PATH joins");
    // The crates the wheel builds from, into cargo's cache (a no-op once the workspace has
    // built), so that the build itself runs offline.
    run(
        "cargo fetch",
        Command::new(env!("CARGO"))
            .current_dir(&root)
            .args(["fetch", "--locked"]),
    );
    run(
        "pip install ./crates/python",
        Command::new(python())
            .env("SPECULA_CACHE_DIR", crate::common::test_cache())
            .current_dir(&root)
            .args([
                "-m",
                "pip",
                "install",
                "--no-index",
                "--no-build-isolation",
                "--no-deps",
                "--force-reinstall",
                "--quiet",
                "./crates/python",
            ])
            .env("PATH", &path)
            .env("MATURIN_PEP517_ARGS", "--profile dev")
            .env("CARGO_NET_OFFLINE", "true"),
    );
    let scratch = tempfile::tempdir().expect("scratch folder");
    run(
        "pytest crates/python/tests",
        Command::new(python())
            .env("SPECULA_CACHE_DIR", crate::common::test_cache())
            .current_dir(scratch.path())
            .args(["-m", "pytest", "-q", "-p", "no:cacheprovider"])
            .arg(root.join("crates/python/tests"))
            .env("PATH", &path)
            .env("SPECULA_BIN", env!("CARGO_BIN_EXE_specula")),
    );
}
