//! Fingerprints the sources the report's stored sections depend on (`src/stored.rs`): this
//! crate and every crate of the workspace beneath it (the lobes, the renderers with the GPU's
//! shaders, the volumes, the decisions and fits, the datapaths) and the locked versions of
//! every crate (FLIP's among them), their tests and benchmarks aside (no section runs them).
//! A stored section is reused exactly when this build would compute it alike.

use std::path::PathBuf;

fn main() {
    let manifest = PathBuf::from(std::env::var_os("CARGO_MANIFEST_DIR").expect("set by cargo"));
    let crates = [
        "specula",
        "render",
        "gpu",
        "volume",
        "targets",
        "decide",
        "hw",
        "synth",
        "temporaries",
    ];
    let mut roots = vec![manifest.join("src"), manifest.join("../../Cargo.lock")];
    roots.extend(crates.map(|name| manifest.join("..").join(name)));
    let filter = specula_fingerprint::Filter {
        extensions: None,
        skipped_folders: &["tests", "benches"],
    };
    let fingerprint = specula_fingerprint::sources(&manifest, &roots, filter);
    println!("cargo:rustc-env=SPECULA_REPORT_SOURCES={fingerprint}");
}
