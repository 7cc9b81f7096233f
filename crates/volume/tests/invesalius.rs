//! The InVesalius reader on Debian's real `Cranium.inv3`, against an independent reading:
//! `crates/cli/tests/volumes/real_scans.py ct-nifti` (numpy, nibabel, Python's tarfile and
//! plistlib) converts the same project to NIfTI, and specula's NIfTI reader reads that back.
//!
//! Both are needed: the CT (Debian's `invesalius-examples`) and the Python with nibabel (the
//! virtual environment `.ci/run` makes in `target/venv`, or `$SPECULA_PYTHON`). Without one a
//! run prints `skipped: ...`, except under `CI=true`, where `.ci/run` installs both and a
//! missing one is a failure (the conventions of `crates/cli/tests/suite/common.rs/mod.rs`).

use std::path::{Path, PathBuf};

use glam::Vec3;
use specula_volume::{self as volume, Units};

const CRANIUM: &str = "/usr/share/doc/invesalius-examples/examples/Cranium.inv3";

/// Voxel (0, 0, 0)'s RAS position in real_scans.py's conversion: a constant of the script's
/// own (`CT_ORIGIN_RAS`), not something the project holds.
const SCRIPT_ORIGIN: Vec3 = Vec3::new(122.0, -140.0, -60.0);

fn in_ci() -> bool {
    std::env::var("CI").as_deref() == Ok("true")
}

/// The Python with nibabel: `$SPECULA_PYTHON`, or the build folder's virtual environment.
fn python() -> PathBuf {
    std::env::var_os("SPECULA_PYTHON").map_or_else(
        || Path::new(env!("CARGO_MANIFEST_DIR")).join("../../target/venv/bin/python"),
        PathBuf::from,
    )
}

/// Whether what the test needs is here; under `CI=true` a missing piece fails the test.
fn ready() -> bool {
    if !Path::new(CRANIUM).is_file() {
        assert!(
            !in_ci(),
            "{CRANIUM} is missing, and CI=true requires it: apt-get install invesalius-examples"
        );
        eprintln!("skipped: {CRANIUM} is missing (apt-get install invesalius-examples)");
        return false;
    }
    let found = std::process::Command::new(python())
        .args(["-c", "import nibabel, numpy"])
        .output()
        .is_ok_and(|o| o.status.success());
    if !found {
        assert!(
            !in_ci(),
            "{} cannot import nibabel, and CI=true requires it: .ci/run installs it into \
                target/venv",
            python().display()
        );
        eprintln!("skipped: nibabel is not importable (pip install nibabel into target/venv)");
    }
    found
}

#[test]
fn cranium_reads_as_real_scans_py_converts_it() {
    if !ready() {
        return;
    }
    let directory = tempfile::tempdir().expect("temporary folder");
    let nifti = directory.path().join("ct.nii.gz");
    let script = Path::new(env!("CARGO_MANIFEST_DIR")).join("../cli/tests/volumes/real_scans.py");
    let output = std::process::Command::new(python())
        .arg(&script)
        .arg("ct-nifti")
        .arg(&nifti)
        .output()
        .expect("python runs");
    assert!(
        output.status.success(),
        "real_scans.py ct-nifti: {}",
        String::from_utf8_lossy(&output.stderr)
    );

    let started = std::time::Instant::now();
    let project = volume::read(Path::new(CRANIUM)).expect("Cranium.inv3 reads");
    eprintln!(
        "read Cranium.inv3 in {:.2} s",
        started.elapsed().as_secs_f64()
    );
    let converted = volume::read(&nifti).expect("the conversion reads");

    // The same voxels, exactly (int16 Hounsfield units in both), on the same grid.
    assert_eq!(project.dims(), [256, 256, 108]);
    assert_eq!(project.dims(), converted.dims());
    assert!(
        project.samples() == converted.samples(),
        "the voxels differ"
    );
    // Air padding at -1024 HU, bone up to about 3000 HU.
    assert_eq!(project.range(), (-1024.0, 2986.0));
    // CT by its modality here; the NIfTI says nothing, so by its values: both Hounsfield.
    assert_eq!(project.units(), Units::Hounsfield);
    assert_eq!(converted.units(), Units::Hounsfield);

    // The same axes: column = the patient's left (-x), row = anterior, slice = superior, with
    // main.plist's spacing.
    let (a, b) = (project.to_world(), converted.to_world());
    for (column, (p, c)) in [
        (a.x_axis, b.x_axis),
        (a.y_axis, b.y_axis),
        (a.z_axis, b.z_axis),
    ]
    .into_iter()
    .enumerate()
    {
        assert!((p - c).length() < 1e-6, "axis {column}: {p} != {c}");
    }
    assert!((a.x_axis - Vec3::new(-0.957_031_2, 0.0, 0.0)).length() < 1e-6);
    assert!((a.z_axis - Vec3::new(0.0, 0.0, 1.5)).length() < 1e-6);

    // The origins differ by a translation only: the script's constant origin, and specula's
    // grid centred on the world origin (the project holds no position).
    assert!((converted.origin() - SCRIPT_ORIGIN).length() < 1e-3);
    let centre = project.world(0.5 * project.last_index());
    assert!(centre.length() < 1e-3, "the grid's centre is at {centre}");
    let shift = converted.origin() - project.origin();
    for index in [
        Vec3::ZERO,
        Vec3::new(255.0, 0.0, 0.0),
        Vec3::new(17.0, 200.0, 99.0),
        project.last_index(),
    ] {
        let moved = project.world(index) + shift;
        assert!(
            (moved - converted.world(index)).length() < 1e-3,
            "voxel {index}: {moved} != {}",
            converted.world(index)
        );
    }
}
