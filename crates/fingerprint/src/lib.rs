//! # specula-fingerprint: what a cached result was computed by
//!
//! The caches of designed lobes, fits, claims, sweeps (`specula-decide`) and the report's
//! stored sections (`specula-report`) reuse a result exactly when the build would compute it
//! alike. Their build scripts call [`sources`] on the source trees the result runs, and the
//! crate reads the fingerprint back with `env!`: a change to any file of those trees makes a
//! new key; nothing else does.

use std::path::{Path, PathBuf};

/// Which files of a tree count.
#[derive(Clone, Copy, Debug)]
pub struct Filter<'a> {
    /// Only files with one of these extensions, or every file when `None`.
    pub extensions: Option<&'a [&'a str]>,
    /// Folders by name that are never entered (a crate's `tests`, which no result runs).
    pub skipped_folders: &'a [&'a str],
}

/// FNV-1a (64 bits) over every counted file at or below `roots` (its path below `manifest`,
/// then its bytes, each separated), in path order, as 16 hexadecimal digits; prints cargo's
/// `rerun-if-changed` for each root. A root that is missing counts nothing: a packaged crate
/// without its workspace fingerprints its own sources.
#[must_use]
pub fn sources(manifest: &Path, roots: &[PathBuf], filter: Filter<'_>) -> String {
    let mut files = Vec::new();
    for root in roots {
        println!("cargo:rerun-if-changed={}", root.display());
        collect(root, filter, &mut files);
    }
    files.sort();
    let mut hash: u64 = 0xcbf2_9ce4_8422_2325;
    let mut feed = |bytes: &[u8]| {
        for &byte in bytes.iter().chain(&[0xff]) {
            hash ^= u64::from(byte);
            hash = hash.wrapping_mul(0x0000_0100_0000_01b3);
        }
    };
    for file in &files {
        let relative = file.strip_prefix(manifest).unwrap_or(file);
        feed(relative.to_string_lossy().as_bytes());
        feed(&std::fs::read(file).unwrap_or_default());
    }
    format!("{hash:016x}")
}

fn collect(path: &Path, filter: Filter<'_>, files: &mut Vec<PathBuf>) {
    if path.is_file() {
        let counted = filter.extensions.is_none_or(|extensions| {
            path.extension()
                .is_some_and(|e| extensions.iter().any(|x| e == *x))
        });
        if counted {
            files.push(path.to_path_buf());
        }
    } else if let Ok(entries) = std::fs::read_dir(path) {
        for entry in entries.flatten() {
            let name = entry.file_name();
            if !filter
                .skipped_folders
                .iter()
                .any(|skipped| name == *skipped)
            {
                collect(&entry.path(), filter, files);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A change to a counted file's bytes or name changes the fingerprint; a skipped folder's
    /// file and an uncounted extension do not.
    #[test]
    fn counted_files_alone_make_the_fingerprint() {
        let scratch = tempfile::tempdir().unwrap();
        let tree = scratch.path();
        std::fs::create_dir_all(tree.join("src/tests")).unwrap();
        let filter = Filter {
            extensions: Some(&["rs"]),
            skipped_folders: &["tests"],
        };
        let of = || sources(tree, &[tree.join("src")], filter);
        std::fs::write(tree.join("src/a.rs"), "one").unwrap();
        let first = of();
        std::fs::write(tree.join("src/tests/t.rs"), "ignored").unwrap();
        std::fs::write(tree.join("src/notes.md"), "ignored").unwrap();
        assert_eq!(of(), first);
        std::fs::write(tree.join("src/a.rs"), "two").unwrap();
        let second = of();
        assert_ne!(second, first);
        std::fs::rename(tree.join("src/a.rs"), tree.join("src/b.rs")).unwrap();
        assert_ne!(of(), second);
    }
}
