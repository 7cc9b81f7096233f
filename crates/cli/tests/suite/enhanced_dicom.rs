//! Enhanced (multi-frame) DICOM from the command line, on the real files `pydicom-data`
//! ships: `eCT_Supplemental.dcm` (an enhanced CT, two 512 x 512 frames with functional
//! groups) is read, and what specula makes of it is checked against pydicom's own reading,
//! and `emri_small.dcm` (an enhanced MR of ten frames without any functional groups) is
//! refused in one line.

use std::path::{Path, PathBuf};

use crate::common::{have_python_module, ok, python, specula};

/// Whether the Python has pydicom, its test data and nibabel (under `CI=true`, it must).
fn have_packages() -> bool {
    [
        ("pydicom", "pydicom"),
        ("data_store", "pydicom-data"),
        ("nibabel", "nibabel"),
        ("numpy", "numpy"),
    ]
    .iter()
    .all(|&(module, package)| have_python_module(module, package))
}

/// Runs the Python `script` with `args`, requiring success, and gives its standard output.
fn run(script: &str, args: &[&str]) -> String {
    let output = std::process::Command::new(python())
        .env("SPECULA_CACHE_DIR", crate::common::test_cache())
        .args(["-c", script])
        .args(args)
        .output()
        .expect("python runs");
    assert!(
        output.status.success(),
        "{}",
        String::from_utf8_lossy(&output.stderr)
    );
    String::from_utf8(output.stdout).unwrap()
}

/// The path of one of pydicom-data's files.
fn test_file(name: &str) -> PathBuf {
    let script = "import sys; from pydicom.data import get_testdata_file; \
        print(get_testdata_file(sys.argv[1]))";
    PathBuf::from(run(script, &[name]).trim())
}

/// Reads the enhanced CT with pydicom alone and compares the NIfTI file `argv[1]` (specula's
/// conversion, read with nibabel) to it: the frames sorted along the slice normal (row x
/// column of Image Orientation (Patient)) by Image Position (Patient), each rescaled by its
/// Pixel Value Transformation (per frame, else shared) to HU, and voxel `(i, j, k)` placed at
/// the LPS position of slice `k` plus `i` column spacings along the row direction and `j` row
/// spacings along the column direction, with `x` and `y` negated for RAS.
const CHECK: &str = r#"
import json, sys
import numpy as np, nibabel, pydicom
from pydicom.data import get_testdata_file

ds = pydicom.dcmread(get_testdata_file("eCT_Supplemental.dcm"))
frames = int(ds.NumberOfFrames)
shared = ds.SharedFunctionalGroupsSequence[0]
per_frame = ds.PerFrameFunctionalGroupsSequence

def group(f, name):
    own = per_frame[f]
    return (own if name in own else shared)[name][0]

stored = ds.pixel_array.astype(np.float64)
positions = [np.array(per_frame[f].PlanePositionSequence[0].ImagePositionPatient, float)
             for f in range(frames)]
cosines = np.array(group(0, "PlaneOrientationSequence").ImageOrientationPatient, float)
row, column = cosines[:3], cosines[3:]
row_spacing, column_spacing = map(float, group(0, "PixelMeasuresSequence").PixelSpacing)
normal = np.cross(row, column)
order = sorted(range(frames), key=lambda f: positions[f] @ normal)
hu = []
for f in order:
    t = group(f, "PixelValueTransformationSequence")
    hu.append(stored[f] * float(t.RescaleSlope) + float(t.RescaleIntercept))
expected = np.stack([h.T for h in hu], axis=-1)

image = nibabel.load(sys.argv[1])
got = np.asarray(image.dataobj, dtype=np.float64)
corner_error = 0.0
for k in (0, frames - 1):
    for i in (0, ds.Columns - 1):
        for j in (0, ds.Rows - 1):
            lps = positions[order[k]] + i * column_spacing * row + j * row_spacing * column
            ras = np.append(lps * np.array([-1.0, -1.0, 1.0]), 1.0)
            off = np.abs(image.affine @ [i, j, k, 1.0] - ras).max()
            corner_error = max(corner_error, float(off))
print(json.dumps({
    "shape": list(got.shape),
    "expected_shape": list(expected.shape),
    "value_error": float(np.abs(got - expected).max()) if got.shape == expected.shape else None,
    "corner_error": corner_error,
    "hu_range": [float(expected.min()), float(expected.max())],
    "slices_differ": bool(np.any(hu[0] != hu[-1])),
    "normal_step": float((positions[order[-1]] - positions[order[0]]) @ normal) / (frames - 1),
}))
"#;

#[test]
fn the_enhanced_ct_reads_as_pydicom_reads_it() {
    if !have_packages() {
        return;
    }
    let directory = tempfile::tempdir().unwrap();
    let d = directory.path();
    let ct = test_file("eCT_Supplemental.dcm");
    let input = ct.to_str().unwrap();
    let drawn = ok(
        d,
        &[
            "volume", "--input", input, "--width", "64", "--height", "64", "-o", "x.png",
        ],
    );
    let stderr = String::from_utf8_lossy(&drawn.stderr);
    assert!(stderr.contains(" 512x512x2,"), "{stderr}");
    assert!(d.join("x.png").is_file());
    ok(d, &["volume-convert", "--input", input, "-o", "x.nii"]);
    let report = run(CHECK, &[d.join("x.nii").to_str().unwrap()]);
    let report: serde_json::Value = serde_json::from_str(&report).unwrap();
    assert_eq!(report["shape"], report["expected_shape"], "{report}");
    assert_eq!(
        report["shape"],
        serde_json::json!([512, 512, 2]),
        "{report}"
    );
    // Stored integers rescaled by -1024 and written as f32: exact.
    assert_eq!(report["value_error"].as_f64(), Some(0.0), "{report}");
    assert!(report["corner_error"].as_f64().unwrap() < 1e-3, "{report}");
    // Not vacuous: the frames differ, lie 10 mm apart, and hold air and tissue in HU.
    assert_eq!(report["slices_differ"], true, "{report}");
    assert!(
        (report["normal_step"].as_f64().unwrap() - 10.0).abs() < 1e-6,
        "{report}"
    );
    assert_eq!(report["hu_range"][0].as_f64(), Some(-1024.0), "{report}");
    assert!(report["hu_range"][1].as_f64().unwrap() > 0.0, "{report}");
}

#[test]
fn the_enhanced_mr_without_per_frame_geometry_is_refused_in_one_line() {
    if !have_packages() {
        return;
    }
    let directory = tempfile::tempdir().unwrap();
    let d = directory.path();
    let mr = test_file("emri_small.dcm");
    let input = mr.to_str().unwrap();
    for (args, output) in [
        (
            vec![
                "volume", "--input", input, "--width", "64", "--height", "64", "-o", "y.png",
            ],
            "y.png",
        ),
        (
            vec!["volume-convert", "--input", input, "-o", "y.nii"],
            "y.nii",
        ),
    ] {
        let refused = specula(d, &args);
        let stderr = String::from_utf8_lossy(&refused.stderr);
        assert!(!refused.status.success(), "{args:?}: {stderr}");
        assert_eq!(stderr.trim_end().lines().count(), 1, "{stderr}");
        assert!(
            stderr.contains("emri_small.dcm: 10 frames without per-frame geometry")
                && stderr.contains("Plane Position Sequence"),
            "{stderr}"
        );
        assert!(!Path::new(&d.join(output)).exists(), "{output} written");
    }
}
