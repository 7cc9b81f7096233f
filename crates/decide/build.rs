//! Fingerprints the sources a designed lobe, a material's fits, the claims and the datapaths'
//! sweeps depend on, so that their caches (`src/design/cache.rs`, `src/fit_cache.rs`,
//! `src/analyses.rs`) reuse a result exactly when this build would compute it alike: the
//! search, fit and verification here, the formula language, lobes, analysis, claims and
//! measured fits in `specula`, the datapaths in `specula-hw`, and the locked versions of every
//! crate (argmin's Nelder-Mead among them).
//! A change to any of them makes a new key; nothing else does.

use std::path::{Path, PathBuf};

fn main() {
    let manifest = PathBuf::from(std::env::var_os("CARGO_MANIFEST_DIR").expect("set by cargo"));
    let roots = [
        manifest.join("src"),
        manifest.join("../specula/src"),
        manifest.join("../hw/src"),
        manifest.join("../../Cargo.lock"),
    ];
    let mut files = Vec::new();
    for root in &roots {
        println!("cargo:rerun-if-changed={}", root.display());
        collect(root, &mut files);
    }
    files.sort();
    // FNV-1a over each file's path below its root and its bytes, separated.
    let mut hash: u64 = 0xcbf2_9ce4_8422_2325;
    let mut feed = |bytes: &[u8]| {
        for &byte in bytes.iter().chain(&[0xff]) {
            hash ^= u64::from(byte);
            hash = hash.wrapping_mul(0x0000_0100_0000_01b3);
        }
    };
    for file in &files {
        let relative = file.strip_prefix(&manifest).unwrap_or(file);
        feed(relative.to_string_lossy().as_bytes());
        feed(&std::fs::read(file).unwrap_or_default());
    }
    println!("cargo:rustc-env=SPECULA_SOURCES={hash:016x}");
}

/// Every `.rs`, `.toml` and `.lock` file at or below `path` (none where it is missing: a
/// packaged crate without its workspace fingerprints its own sources).
fn collect(path: &Path, files: &mut Vec<PathBuf>) {
    if path.is_file() {
        if path
            .extension()
            .is_some_and(|e| e == "rs" || e == "toml" || e == "lock")
        {
            files.push(path.to_path_buf());
        }
    } else if let Ok(entries) = std::fs::read_dir(path) {
        for entry in entries.flatten() {
            collect(&entry.path(), files);
        }
    }
}
