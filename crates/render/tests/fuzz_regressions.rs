//! Replays the fuzzers' seeds and every crash input they found (`fuzz/regressions/`, kept
//! minimised by `fuzz/run`) through the same checks as the fuzz targets, so that CI needs no
//! fuzzer: parsing answers with a value or an error, never a panic, and an accepted mesh has
//! only finite positions and in-range indices.

use std::path::{Path, PathBuf};

use specula_render::{MeshFormat, Scene};

/// The fuzz targets' own checks.
#[path = "../../../fuzz/fuzz_targets/checks/mesh.rs"]
mod checks;
#[path = "../../../fuzz/fuzz_targets/checks/measured.rs"]
mod measured_checks;

fn inputs(target: &str) -> Vec<PathBuf> {
    let fuzz = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../fuzz");
    ["seeds", "regressions"]
        .iter()
        .flat_map(|kind| {
            std::fs::read_dir(fuzz.join(kind).join(target))
                .into_iter()
                .flatten()
        })
        .map(|entry| entry.expect("entry").path())
        .filter(|path| path.file_name().is_some_and(|name| name != ".gitkeep"))
        .collect()
}

#[test]
fn scene_inputs_parse_or_fail_cleanly() {
    let files = inputs("scene");
    assert!(!files.is_empty(), "the scene seeds are missing");
    for path in files {
        let bytes = std::fs::read(&path).expect("read");
        if let Ok(text) = std::str::from_utf8(&bytes) {
            let _ = Scene::from_toml(text, "fuzz.toml", None);
        }
    }
}

#[test]
fn mesh_inputs_load_valid_meshes_or_fail_cleanly() {
    for (target, format) in [
        ("obj", MeshFormat::Obj),
        ("stl", MeshFormat::Stl),
        ("ply", MeshFormat::Ply),
    ] {
        let files = inputs(target);
        assert!(!files.is_empty(), "the {target} seeds are missing");
        for path in files {
            checks::check_mesh(&std::fs::read(&path).expect("read"), format);
        }
    }
}

#[test]
fn measured_material_inputs_load_or_fail_cleanly() {
    let files = inputs("measured");
    assert!(!files.is_empty(), "the measured-material seeds are missing");
    for path in files {
        let bytes = std::fs::read(&path).expect("read");
        if path.ends_with("seeds/measured/minimal.bsdf") {
            // The seed is a valid material, so the check evaluates it.
            specula::measured::MeasuredBrdf::from_bytes(&bytes).expect("the minimal seed loads");
        }
        measured_checks::check_measured(&bytes);
    }
}
