//! Fingerprints the sources a designed lobe, a material's fits, the claims and the datapaths'
//! sweeps depend on, so that their caches (`src/design/cache.rs`, `src/fit_cache.rs`,
//! `src/analyses.rs`) reuse a result exactly when this build would compute it alike: the
//! search, fit and verification here, the formula language, lobes, analysis, claims and
//! measured fits in `specula`, the datapaths in `specula-hw`, and the locked versions of every
//! crate (argmin's Nelder-Mead among them).

use std::path::PathBuf;

fn main() {
    let manifest = PathBuf::from(std::env::var_os("CARGO_MANIFEST_DIR").expect("set by cargo"));
    let roots =
        ["src", "../specula/src", "../hw/src", "../../Cargo.lock"].map(|r| manifest.join(r));
    let filter = specula_fingerprint::Filter {
        extensions: Some(&["rs", "toml", "lock"]),
        skipped_folders: &[],
    };
    let fingerprint = specula_fingerprint::sources(&manifest, &roots, filter);
    println!("cargo:rustc-env=SPECULA_SOURCES={fingerprint}");
}
