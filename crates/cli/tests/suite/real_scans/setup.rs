//! The set-up shared by the real-scan tests: `real_scans.py` run through the venv's Python,
//! the real scans converted once per test binary (a `OnceLock`), and image and mask helpers.

use std::path::{Path, PathBuf};
use std::sync::OnceLock;

use serde_json::Value;
use specula_render::{read_image, Image};

use crate::common::{have_python_module, ok, python};

/// `tests/volumes/real_scans.py`.
pub fn script() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/volumes/real_scans.py")
}

/// Runs `real_scans.py args` in `directory`: its standard output, or its one error line.
pub fn try_real_scans(directory: &Path, args: &[&str]) -> Result<String, String> {
    let output = std::process::Command::new(python())
        .env("SPECULA_CACHE_DIR", crate::common::test_cache())
        .current_dir(directory)
        .arg(script())
        .args(args)
        .output()
        .map_err(|e| format!("{}: {e}", python().display()))?;
    if output.status.success() {
        Ok(String::from_utf8(output.stdout).expect("UTF-8"))
    } else {
        Err(String::from_utf8_lossy(&output.stderr).trim().to_owned())
    }
}

/// Runs `real_scans.py args` in `directory`, requiring success.
pub fn real_scans(directory: &Path, args: &[&str]) -> String {
    try_real_scans(directory, args).unwrap_or_else(|e| panic!("real_scans.py {args:?}: {e}"))
}

/// [`real_scans`]'s JSON.
pub fn real_scans_json(directory: &Path, args: &[&str]) -> Value {
    let text = real_scans(directory, args);
    serde_json::from_str(&text).unwrap_or_else(|e| panic!("real_scans.py {args:?}: {e}: {text}"))
}

/// The real scans, converted once per test binary.
pub struct Scans {
    /// The CT as NIfTI (int16 HU, no hint of Hounsfield units).
    pub ct_nifti: PathBuf,
    /// The CT as a DICOM series (Modality CT).
    pub ct_dicom: PathBuf,
    /// Colin27's T1 (`ch2.nii.gz`), as shipped.
    pub mri: PathBuf,
    /// pydicom-data's enhanced CT.
    pub enhanced_ct: PathBuf,
    /// pydicom-data's enhanced MR without per-frame geometry.
    pub enhanced_mr: PathBuf,
}

/// A folder of this process under the build's temporary folder; those of processes that
/// have ended are removed first (a static's folder is never dropped).
pub fn scratch() -> PathBuf {
    let root = Path::new(env!("CARGO_TARGET_TMPDIR"));
    let prefix = "real_scans-";
    if let Ok(entries) = std::fs::read_dir(root) {
        for entry in entries.flatten() {
            let name = entry.file_name().to_string_lossy().into_owned();
            let Some(pid) = name.strip_prefix(prefix) else {
                continue;
            };
            let alive = Path::new("/proc").join(pid).exists() || !Path::new("/proc/self").exists();
            if !alive {
                let _ = std::fs::remove_dir_all(entry.path());
            }
        }
    }
    let dir = root.join(format!("{prefix}{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).expect("scratch folder");
    dir
}

/// The converted scans, or why they are not there. A missing package or file fails under
/// `CI=true`.
pub fn prepare() -> Result<Scans, String> {
    for (module, package) in [
        ("numpy", "numpy"),
        ("nibabel", "nibabel"),
        ("pydicom", "pydicom"),
        ("data_store", "pydicom-data"),
    ] {
        if !have_python_module(module, package) {
            return Err(format!("{module} is not importable"));
        }
    }
    let here = Path::new(env!("CARGO_MANIFEST_DIR"));
    let path = |args: &[&str]| -> Result<PathBuf, String> {
        match try_real_scans(here, args) {
            Ok(path) => Ok(PathBuf::from(path.trim())),
            Err(e) => {
                assert!(
                    std::env::var("CI").as_deref() != Ok("true"),
                    "CI=true requires the real scans: {e}"
                );
                Err(e)
            }
        }
    };
    path(&["ct-path"])?;
    let mri = path(&["mri-path"])?;
    let enhanced_ct = path(&["enhanced-path", "eCT_Supplemental.dcm"])?;
    let enhanced_mr = path(&["enhanced-path", "emri_small.dcm"])?;
    let dir = scratch();
    real_scans(&dir, &["ct-nifti", "ct.nii.gz"]);
    real_scans(&dir, &["ct-dicom", "ct-dicom"]);
    Ok(Scans {
        ct_nifti: dir.join("ct.nii.gz"),
        ct_dicom: dir.join("ct-dicom"),
        mri,
        enhanced_ct,
        enhanced_mr,
    })
}

/// The scans, or `None` after printing `skipped: ...`.
pub fn scans() -> Option<&'static Scans> {
    static SCANS: OnceLock<Result<Scans, String>> = OnceLock::new();
    match SCANS.get_or_init(prepare) {
        Ok(scans) => Some(scans),
        Err(why) => {
            eprintln!("skipped: {why}");
            None
        }
    }
}

pub fn text(path: &Path) -> &str {
    path.to_str().expect("UTF-8 path")
}

/// Renders `input` with `args` into `directory/name` (an .exr: linear) and reads it back.
pub fn render(directory: &Path, input: &Path, name: &str, size: u32, args: &[&str]) -> Image {
    let size = size.to_string();
    let mut all = vec![
        "volume",
        "--input",
        text(input),
        "--width",
        &size,
        "--height",
        &size,
        "-o",
        name,
    ];
    all.extend_from_slice(args);
    ok(directory, &all);
    read_image(&directory.join(name)).expect("the render reads back")
}

/// Mean absolute difference over every pixel and channel (values clamped to [0, 1], as an
/// 8-bit image holds them).
pub fn mean_abs(a: &[[f32; 3]], b: &[[f32; 3]]) -> f64 {
    assert_eq!(a.len(), b.len());
    let sum: f64 = a
        .iter()
        .zip(b)
        .flat_map(|(p, q)| {
            (0..3).map(move |c| f64::from((p[c].clamp(0.0, 1.0) - q[c].clamp(0.0, 1.0)).abs()))
        })
        .sum();
    sum / (3 * a.len()) as f64
}

/// An image's linear RGB values, row-major from the top left.
pub type Pixels = Vec<[f32; 3]>;

/// An image's pixels as arrays.
pub fn rgb(image: &Image) -> Pixels {
    image.pixels().iter().map(|p| p.to_array()).collect()
}

/// Which pixels have a channel above `threshold`.
pub fn covered(image: &Image, threshold: f32) -> Vec<bool> {
    image
        .pixels()
        .iter()
        .map(|p| p.max_element() > threshold)
        .collect()
}

/// `real_scans.py projection`'s silhouette, row-major with the top row first (as images).
pub fn silhouette(projection: &Value) -> Vec<bool> {
    projection["silhouette"]
        .as_array()
        .expect("silhouette")
        .iter()
        .flat_map(|row| {
            row.as_array()
                .expect("row")
                .iter()
                .map(|v| v.as_bool().expect("bool"))
        })
        .collect()
}

/// The silhouette of `input`'s voxels above `above` seen from `axis`, `size` bins square,
/// framed as specula frames its standard views (a square of 1.05 times the larger half
/// extent of the grid's box, centred on it).
pub fn projection(directory: &Path, input: &Path, axis: &str, above: f64, size: u32) -> Vec<bool> {
    let json = real_scans_json(
        directory,
        &[
            "projection",
            text(input),
            "--axis",
            axis,
            "--above",
            &above.to_string(),
            "--size",
            &size.to_string(),
            "--square",
            "1.05",
        ],
    );
    silhouette(&json)
}

/// `mask` grown by one pixel (8-connected).
pub fn dilate(mask: &[bool], size: usize) -> Vec<bool> {
    (0..mask.len())
        .map(|p| {
            let (x, y) = ((p % size) as isize, (p / size) as isize);
            (-1..=1).any(|dy| {
                (-1..=1).any(|dx| {
                    let (u, v) = (x + dx, y + dy);
                    (0..size as isize).contains(&u)
                        && (0..size as isize).contains(&v)
                        && mask[v as usize * size + u as usize]
                })
            })
        })
        .collect()
}

/// Intersection over union of two masks.
pub fn iou(a: &[bool], b: &[bool]) -> f64 {
    let both = a.iter().zip(b).filter(|(x, y)| **x && **y).count();
    let either = a.iter().zip(b).filter(|(x, y)| **x || **y).count();
    both as f64 / either.max(1) as f64
}

/// Of the pixels in `of`, the fraction also in `mask`.
pub fn fraction_in(mask: &[bool], of: &[bool]) -> f64 {
    let total = of.iter().filter(|v| **v).count();
    let inside = of.iter().zip(mask).filter(|(o, m)| **o && **m).count();
    inside as f64 / total.max(1) as f64
}

pub fn count(mask: &[bool]) -> usize {
    mask.iter().filter(|v| **v).count()
}

/// The grid's world box (RAS, voxel centres) from the silhouettes' framing: from the front
/// the image's right is -x and its up z, from above right is x and up y.
pub fn grid_box(directory: &Path, input: &Path) -> ([f64; 3], [f64; 3]) {
    let interval = |axis: &str, which: &str| -> [f64; 2] {
        let json = real_scans_json(
            directory,
            &[
                "projection",
                text(input),
                "--axis",
                axis,
                "--above",
                "1e30",
                "--size",
                "2",
            ],
        );
        let pair = json[which].as_array().expect("an interval");
        [pair[0].as_f64().unwrap(), pair[1].as_f64().unwrap()]
    };
    let (minus_x, z, y) = (
        interval("A", "right_mm"),
        interval("A", "up_mm"),
        interval("S", "up_mm"),
    );
    ([-minus_x[1], y[0], z[0]], [-minus_x[0], y[1], z[1]])
}
