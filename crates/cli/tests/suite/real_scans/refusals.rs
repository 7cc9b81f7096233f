//! Bad real-world files: one line each, nothing written.

use super::setup::{real_scans, scans, text};
use crate::common::specula;

/// The CT series with its slice at position rank 54 left out, the series with one slice's
/// Pixel Spacing 0.5\0.5 (`real_scans.py bad-dicom`) and pydicom-data's emri_small.dcm (ten
/// frames without per-frame geometry; `enhanced_dicom.rs` checks its message in full): each
/// gets one line on stderr naming the problem, a failing exit status, and no file (PNG or
/// EXR, nor a temporary one) in the folder.
#[test]
fn bad_real_world_files_are_refused_in_one_line_and_nothing_is_written() {
    let Some(scans) = scans() else { return };
    let directory = tempfile::tempdir().unwrap();
    let d = directory.path();
    real_scans(d, &["bad-dicom", "missing-slice", "missing-slice"]);
    real_scans(
        d,
        &["bad-dicom", "inconsistent-spacing", "inconsistent-spacing"],
    );
    for (input, says) in [
        (d.join("missing-slice"), "a slice seems missing"),
        (
            d.join("inconsistent-spacing"),
            "a series shares one pixel spacing",
        ),
        (
            scans.enhanced_mr.clone(),
            "10 frames without per-frame geometry",
        ),
    ] {
        let outputs: &[&str] = if input == scans.enhanced_mr {
            &["out.png"]
        } else {
            &["out.png", "out.exr"]
        };
        for &output in outputs {
            let refused = specula(
                d,
                &[
                    "volume",
                    "--input",
                    text(&input),
                    "--width",
                    "64",
                    "--height",
                    "64",
                    "-o",
                    output,
                ],
            );
            let stderr = String::from_utf8_lossy(&refused.stderr);
            assert!(!refused.status.success(), "{}: {stderr}", input.display());
            assert_eq!(stderr.trim_end().lines().count(), 1, "{stderr}");
            assert!(stderr.contains(says), "{stderr}");
            assert!(
                !d.join(output).exists(),
                "{output} written for {}",
                input.display()
            );
        }
    }
    let leftovers: Vec<_> = std::fs::read_dir(d)
        .unwrap()
        .flatten()
        .map(|e| e.file_name().to_string_lossy().into_owned())
        .filter(|name| name != "missing-slice" && name != "inconsistent-spacing")
        .collect();
    assert!(leftovers.is_empty(), "{leftovers:?}");
}
