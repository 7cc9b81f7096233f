//! The sources' shape: every line of Rust within the formatter's width (`max_width` in
//! rustfmt.toml), which rustfmt itself leaves unchecked inside string literals, comments and
//! macros.

use std::path::{Path, PathBuf};

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
