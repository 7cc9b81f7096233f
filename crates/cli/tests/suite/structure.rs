//! The sources' shape: every line of Rust within the formatter's width (`max_width` in
//! rustfmt.toml), which rustfmt itself leaves unchecked inside string literals, comments and
//! macros; and a lobe as its file and one registry line, proven by the registry's worked
//! example.

use std::path::{Path, PathBuf};
use std::process::Command;

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

/// Every `.rs` file under `directory`, build folders left out.
fn rust_files(directory: &Path, found: &mut Vec<PathBuf>) {
    for entry in std::fs::read_dir(directory).unwrap().map(Result::unwrap) {
        let path = entry.path();
        if path.is_dir() && entry.file_name() != "target" {
            rust_files(&path, found);
        } else if path.extension().is_some_and(|e| e == "rs") {
            found.push(path);
        }
    }
}

#[test]
fn every_line_is_within_the_formatters_width() {
    let settings = std::fs::read_to_string(root().join("rustfmt.toml")).unwrap();
    let width: usize = settings
        .lines()
        .find_map(|line| line.strip_prefix("max_width = "))
        .and_then(|value| value.trim().parse().ok())
        .expect("rustfmt.toml sets max_width");
    let mut files = Vec::new();
    for top in ["crates", "fuzz"] {
        rust_files(&root().join(top), &mut files);
    }
    assert!(files.len() > 100, "{} Rust files found", files.len());
    let mut over = Vec::new();
    for file in &files {
        let text = std::fs::read_to_string(file).unwrap();
        for (number, line) in text.lines().enumerate() {
            let length = line.chars().count();
            if length > width {
                over.push(format!("{}:{}: {length}", file.display(), number + 1));
            }
        }
    }
    assert!(
        over.is_empty(),
        "lines over {width} characters:\n{}",
        over.join("\n")
    );
}

/// A lobe is its file and one line of the registry: the worked example
/// (`crates/specula/src/lobe/example.rs`, behind the `example-lobe` feature) is named by
/// one line of `lobes!` and by no other source of the library crates, and with the feature
/// on, `crates/report/src/example_lobe.rs` finds it in the analysis, the batch path, the GPU's
/// library and evaluation, every export and the report's tables, while the core's own unit
/// tests (its kernel's counted instructions, its colour against every other) take it in as
/// they take every lobe. Both run here, in a build with the feature: cargo has released the
/// target folder's lock by the time tests run, and the feature rebuilds the core and the
/// crates above it (about a minute on 2 cores), reusing every other crate of this build.
#[test]
fn a_lobe_is_its_file_and_one_registry_line() {
    let registry = std::fs::read_to_string(root().join("crates/specula/src/lobe/mod.rs")).unwrap();
    let naming: Vec<&str> = registry
        .lines()
        .filter(|line| line.contains("example"))
        .collect();
    assert_eq!(
        naming,
        ["    #[cfg(feature = \"example-lobe\")] Example => example,"],
        "the registry's line for the example"
    );
    let mut files = Vec::new();
    for library in [
        "specula", "gpu", "targets", "render", "volume", "report", "decide", "hw",
    ] {
        rust_files(&root().join("crates").join(library).join("src"), &mut files);
    }
    let mentions: Vec<String> = files
        .iter()
        .filter(|file| {
            !file.ends_with("lobe/example.rs")
                && !file.ends_with("lobe/mod.rs")
                && !file.ends_with("report/src/example_lobe.rs")
        })
        .filter(|file| {
            let text = std::fs::read_to_string(file).unwrap();
            [
                "LobeKind::Example",
                "example::",
                "lobe_example",
                "\"example\"",
            ]
            .iter()
            .any(|name| text.contains(name))
        })
        .map(|file| file.display().to_string())
        .collect();
    assert!(
        mentions.is_empty(),
        "the example lobe named in {mentions:?}"
    );
    let output = Command::new(env!("CARGO"))
        .current_dir(root())
        .args([
            "test",
            "--locked",
            "-p",
            "specula",
            "-p",
            "specula-report",
            "--lib",
        ])
        .args(["--features", "specula-report/example-lobe"])
        .output()
        .expect("cargo runs");
    let text = format!(
        "{}{}",
        String::from_utf8_lossy(&output.stdout),
        String::from_utf8_lossy(&output.stderr)
    );
    assert!(output.status.success(), "the example lobe's tests:\n{text}");
    for test in [
        "the_registry_parses_and_prepares_it",
        "the_analysis_measures_it",
        "the_batch_path_runs_its_kernel",
        "the_gpu_library_holds_and_evaluates_it",
        "every_export_writes_it",
        "the_reports_tables_list_it",
    ] {
        let line = format!("test example_lobe::{test} ... ok");
        assert!(text.contains(&line), "`{line}` missing:\n{text}");
    }
}
