//! `specula volume` on real scans (issue 32): InVesalius' head CT (Debian's
//! `invesalius-examples`, converted to a NIfTI file and to a DICOM CT series by
//! `tests/volumes/real_scans.py` with numpy, nibabel and pydicom), Colin27's T1 MRI with skull
//! (Debian's `mricron-data`, read as shipped) and pydicom-data's enhanced (multi-frame) CT.
//!
//! Every expected value comes from outside specula: silhouettes and marker positions from
//! `real_scans.py` (numpy over the voxels), the views' orientations from their definitions
//! (closed form), and VTK's CPU ray caster (`vtkFixedPointVolumeRayCastMapper`) through
//! `specula bench volume`. Nothing is downloaded: without the packages a test prints
//! `skipped: ...`, and under `CI=true` it fails.

mod common;

use std::path::{Path, PathBuf};
use std::sync::OnceLock;

use common::{have_gpu, have_python_module, ok, python, specula};
use serde_json::Value;
use specula_render::{read_image, Image};

/// `tests/volumes/real_scans.py`.
fn script() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/volumes/real_scans.py")
}

/// Runs `real_scans.py args` in `directory`: its standard output, or its one error line.
fn try_real_scans(directory: &Path, args: &[&str]) -> Result<String, String> {
    let output = std::process::Command::new(python())
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
fn real_scans(directory: &Path, args: &[&str]) -> String {
    try_real_scans(directory, args).unwrap_or_else(|e| panic!("real_scans.py {args:?}: {e}"))
}

/// [`real_scans`]'s JSON.
fn real_scans_json(directory: &Path, args: &[&str]) -> Value {
    let text = real_scans(directory, args);
    serde_json::from_str(&text).unwrap_or_else(|e| panic!("real_scans.py {args:?}: {e}: {text}"))
}

/// The real scans, converted once per test binary.
struct Scans {
    /// The CT as NIfTI (int16 HU, no hint of Hounsfield units).
    ct_nifti: PathBuf,
    /// The CT as a DICOM series (Modality CT).
    ct_dicom: PathBuf,
    /// Colin27's T1 (`ch2.nii.gz`), as shipped.
    mri: PathBuf,
    /// pydicom-data's enhanced CT.
    enhanced_ct: PathBuf,
    /// pydicom-data's enhanced MR without per-frame geometry.
    enhanced_mr: PathBuf,
}

/// A folder of this process under the build's temporary folder; those of processes that
/// have ended are removed first (a static's folder is never dropped).
fn scratch() -> PathBuf {
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
fn prepare() -> Result<Scans, String> {
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
fn scans() -> Option<&'static Scans> {
    static SCANS: OnceLock<Result<Scans, String>> = OnceLock::new();
    match SCANS.get_or_init(prepare) {
        Ok(scans) => Some(scans),
        Err(why) => {
            eprintln!("skipped: {why}");
            None
        }
    }
}

fn text(path: &Path) -> &str {
    path.to_str().expect("UTF-8 path")
}

/// Renders `input` with `args` into `directory/name` (an .exr: linear) and reads it back.
fn render(directory: &Path, input: &Path, name: &str, size: u32, args: &[&str]) -> Image {
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
fn mean_abs(a: &[[f32; 3]], b: &[[f32; 3]]) -> f64 {
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
type Pixels = Vec<[f32; 3]>;

/// An image's pixels as arrays.
fn rgb(image: &Image) -> Pixels {
    image.pixels().iter().map(|p| p.to_array()).collect()
}

/// Which pixels have a channel above `threshold`.
fn covered(image: &Image, threshold: f32) -> Vec<bool> {
    image
        .pixels()
        .iter()
        .map(|p| p.max_element() > threshold)
        .collect()
}

/// `real_scans.py projection`'s silhouette, row-major with the top row first (as images).
fn silhouette(projection: &Value) -> Vec<bool> {
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
fn projection(directory: &Path, input: &Path, axis: &str, above: f64, size: u32) -> Vec<bool> {
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
fn dilate(mask: &[bool], size: usize) -> Vec<bool> {
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
fn iou(a: &[bool], b: &[bool]) -> f64 {
    let both = a.iter().zip(b).filter(|(x, y)| **x && **y).count();
    let either = a.iter().zip(b).filter(|(x, y)| **x || **y).count();
    both as f64 / either.max(1) as f64
}

/// Of the pixels in `of`, the fraction also in `mask`.
fn fraction_in(mask: &[bool], of: &[bool]) -> f64 {
    let total = of.iter().filter(|v| **v).count();
    let inside = of.iter().zip(mask).filter(|(o, m)| **o && **m).count();
    inside as f64 / total.max(1) as f64
}

fn count(mask: &[bool]) -> usize {
    mask.iter().filter(|v| **v).count()
}

// ---------------------------------------------------------------------------------------
// 1. The CT as NIfTI and as a DICOM series; Hounsfield units recognised.

/// The CT converted to NIfTI (int16 HU, no hint of units: recognised as CT by its value
/// range, `Units::from_values`) and to a DICOM CT series (Modality CT, files in shuffled order,
/// stored as HU + 1024 with a rescale), from the front at 128 x 128: each default render is
/// the explicit `--transfer ct-bone` render, pixel for pixel, and not the mr preset's fog
/// (measured mean absolute difference 0.063 between the two; asserted > 0.03). The two files
/// hold the same values at the same world positions, so they render alike: measured mean
/// absolute difference 1.0e-7 (linear) and mean FLIP 7.4e-6; asserted <= 1e-5 and <= 1e-4.
#[test]
fn the_ct_as_nifti_and_as_a_dicom_series_render_alike_as_ct() {
    let Some(scans) = scans() else { return };
    let directory = tempfile::tempdir().unwrap();
    let d = directory.path();
    let size = 128;
    let nifti = render(d, &scans.ct_nifti, "nifti.exr", size, &[]);
    let nifti_bone = render(
        d,
        &scans.ct_nifti,
        "nifti-bone.exr",
        size,
        &["--transfer", "ct-bone"],
    );
    let nifti_mr = render(
        d,
        &scans.ct_nifti,
        "nifti-mr.exr",
        size,
        &["--transfer", "mr"],
    );
    let series = render(d, &scans.ct_dicom, "series.exr", size, &[]);
    let series_bone = render(
        d,
        &scans.ct_dicom,
        "series-bone.exr",
        size,
        &["--transfer", "ct-bone"],
    );
    // Compared as booleans: a failing assert_eq! would print 16,384 pixels.
    assert!(
        nifti.pixels() == nifti_bone.pixels(),
        "the NIfTI's default is not ct-bone"
    );
    assert!(
        series.pixels() == series_bone.pixels(),
        "the series' default is not ct-bone"
    );
    let fog = mean_abs(&rgb(&nifti), &rgb(&nifti_mr));
    let same = mean_abs(&rgb(&nifti), &rgb(&series));
    let flip =
        specula_render::metrics::compare(&nifti, &series, specula_render::Display::default())
            .unwrap()
            .mean_flip;
    eprintln!("NIfTI against series: mean absolute difference {same:.2e}, mean FLIP {flip:.2e}; ct-bone against mr: {fog:.3}");
    assert!(
        fog > 0.03,
        "ct-bone and mr look alike ({fog}): the test could not tell them apart"
    );
    assert!(same <= 1e-5, "{same}");
    assert!(flip <= 1e-4, "{flip}");
}

// ---------------------------------------------------------------------------------------
// 2. The presets on the real CT and MRI, against the voxels' silhouettes.

/// `mask` shrunk by one pixel (8-connected; the border's pixels dropped).
fn erode(mask: &[bool], size: usize) -> Vec<bool> {
    let outside: Vec<bool> = mask.iter().map(|v| !*v).collect();
    let grown = dilate(&outside, size);
    (0..mask.len())
        .map(|p| {
            let (x, y) = (p % size, p / size);
            mask[p] && !grown[p] && x > 0 && y > 0 && x + 1 < size && y + 1 < size
        })
        .collect()
}

/// The presets on the real CT against the silhouettes of its voxels above 300 HU (bone) and
/// above -300 HU (skin and everything inside it), from the front and from the patient's
/// left, at 128 x 128 (a pixel is about 2 mm, two voxels). A pixel counts as covered when a
/// channel exceeds 0.01 (linear). The silhouettes bin voxel centres (a bin is covered when
/// any centre falls in it) where specula's rays go through pixel centres and interpolate, so
/// the two differ by about a pixel along the outline: measured intersection over union
/// (front, left) 0.977 and 0.980 (ct-bone against bone), 0.972 and 0.976 (ct-soft-tissue
/// against skin), 0.978 and 0.979 (ct-bone at window 400 level 40, whose ramp then starts at
/// -160 HU, against the silhouette above -160 HU); asserted >= 0.95. (The head holder, above
/// 300 HU, is in both.)
///
/// "Skin only" is where the skin silhouette is covered well inside (the pixel and its 8
/// neighbours) and the bone silhouette is not within a pixel: the nose, lips and the soft
/// tissue of the face seen from the side (185 pixels from the left; from the front the skin
/// lies within a pixel of the bone's outline almost everywhere). ct-bone leaves it
/// transparent (measured: none of it covered; asserted <= 2 %), ct-soft-tissue and the
/// window from -160 HU show it (measured 100 % of it; asserted >= 95 %).
#[test]
fn ct_presets_show_bone_or_skin_as_the_voxels_silhouettes_predict() {
    let Some(scans) = scans() else { return };
    let directory = tempfile::tempdir().unwrap();
    let d = directory.path();
    let size = 128;
    for (view, axis) in [("anterior", "A"), ("left", "L")] {
        let bone = projection(d, &scans.ct_nifti, axis, 300.0, size);
        let skin = projection(d, &scans.ct_nifti, axis, -300.0, size);
        let ramp = projection(d, &scans.ct_nifti, axis, -160.0, size);
        let near_bone = dilate(&bone, size as usize);
        let skin_only: Vec<bool> = erode(&skin, size as usize)
            .iter()
            .zip(&near_bone)
            .map(|(s, b)| *s && !*b)
            .collect();
        let drawn = |transfer: &str, extra: &[&str]| {
            let name = format!("{transfer}-{view}-{}.exr", extra.len());
            let mut args = vec!["--view", view, "--transfer", transfer];
            args.extend_from_slice(extra);
            covered(&render(d, &scans.ct_nifti, &name, size, &args), 0.01)
        };
        let bone_drawn = drawn("ct-bone", &[]);
        let soft_drawn = drawn("ct-soft-tissue", &[]);
        let window_drawn = drawn("ct-bone", &["--window", "400", "--level", "40"]);
        let figures = [
            ("ct-bone vs bone", iou(&bone_drawn, &bone)),
            ("ct-soft-tissue vs skin", iou(&soft_drawn, &skin)),
            ("window vs -160 HU", iou(&window_drawn, &ramp)),
        ];
        let shown = [
            fraction_in(&bone_drawn, &skin_only),
            fraction_in(&soft_drawn, &skin_only),
            fraction_in(&window_drawn, &skin_only),
        ];
        eprintln!(
            "{view}: {figures:?}; skin only ({} px) covered by ct-bone, ct-soft-tissue, window: {shown:?}",
            count(&skin_only)
        );
        for (what, value) in figures {
            assert!(
                value >= 0.95,
                "{view}: {what}: intersection over union {value}"
            );
        }
        if view == "left" {
            assert!(count(&skin_only) >= 100, "{}", count(&skin_only));
            assert!(shown[0] <= 0.02, "ct-bone shows skin: {shown:?}");
            assert!(shown[1] >= 0.95, "ct-soft-tissue hides skin: {shown:?}");
            assert!(
                shown[2] >= 0.95,
                "window 400 level 40 hides skin: {shown:?}"
            );
        }
    }
}

/// Writes the part of the NIfTI `argv[1]` anterior of RAS y = `argv[3]` mm into `argv[2]`
/// (nibabel: the same affine, its origin moved to the first kept row).
const CROP: &str = r#"
import sys
import numpy as np, nibabel as nib
image = nib.load(sys.argv[1])
values = np.asarray(image.dataobj)
affine = image.affine.copy()
assert affine[1, 1] > 0 and affine[1, 0] == 0 and affine[1, 2] == 0, affine
first = int(np.ceil((float(sys.argv[3]) - affine[1, 3]) / affine[1, 1]))
affine[:3, 3] = affine[:3, :3] @ [0, first, 0] + affine[:3, 3]
out = nib.Nifti1Image(np.ascontiguousarray(values[:, first:, :]), affine, image.header)
out.set_sform(affine, code=1)
out.set_qform(affine, code=1)
nib.save(out, sys.argv[2])
print(values.shape[1] - first)
"#;

/// The non-`solid` pixels that cannot be reached from the image's border through non-`solid`
/// pixels (4-connected): the holes of a silhouette.
fn holes(solid: &[bool], size: usize) -> Vec<bool> {
    let mut outside = vec![false; solid.len()];
    let mut stack: Vec<usize> = (0..size)
        .flat_map(|k| [k, (size - 1) * size + k, k * size, k * size + size - 1])
        .filter(|&p| !solid[p])
        .collect();
    while let Some(p) = stack.pop() {
        if outside[p] || solid[p] {
            continue;
        }
        outside[p] = true;
        let (x, y) = (p % size, p / size);
        if x > 0 {
            stack.push(p - 1);
        }
        if x + 1 < size {
            stack.push(p + 1);
        }
        if y > 0 {
            stack.push(p - size);
        }
        if y + 1 < size {
            stack.push(p + size);
        }
    }
    (0..solid.len()).map(|p| !solid[p] && !outside[p]).collect()
}

/// The skull's defect: InVesalius' patient lacks part of the frontal bone on the right,
/// above the orbit. Through the whole head a ray through the defect still meets the back of
/// the skull, so the test crops the CT (nibabel) to its anterior half (RAS y >= 0 mm) and
/// looks from the front: there the defect is a hole in the silhouette of the voxels above
/// 300 HU (pixels not reachable from the image's border outside the bone silhouette, in the
/// image's upper left quarter: the patient's right, superior; shrunk by a pixel), covered by
/// the silhouette above -300 HU (scalp and brain). Measured at 128 x 128: 84 pixels, all
/// inside the skin silhouette, all exactly background (black) with ct-bone and all covered
/// with ct-soft-tissue.
#[test]
fn the_skull_defect_renders_as_background_with_ct_bone() {
    let Some(scans) = scans() else { return };
    let directory = tempfile::tempdir().unwrap();
    let d = directory.path();
    let crop = d.join("anterior-half.nii.gz");
    let output = std::process::Command::new(python())
        .args(["-c", CROP, text(&scans.ct_nifti), text(&crop), "0"])
        .output()
        .unwrap();
    assert!(
        output.status.success(),
        "{}",
        String::from_utf8_lossy(&output.stderr)
    );
    let size = 128usize;
    let bone = projection(d, &crop, "A", 300.0, size as u32);
    let skin = projection(d, &crop, "A", -300.0, size as u32);
    let defect: Vec<bool> = erode(&holes(&bone, size), size)
        .into_iter()
        .enumerate()
        .map(|(p, hole)| hole && p % size < size / 2 && p / size < size / 2)
        .collect();
    let bone_drawn = render(
        d,
        &crop,
        "bone.exr",
        size as u32,
        &["--transfer", "ct-bone"],
    );
    let soft_drawn = render(
        d,
        &crop,
        "soft.exr",
        size as u32,
        &["--transfer", "ct-soft-tissue"],
    );
    let lit: Vec<f32> = (0..size * size)
        .filter(|&p| defect[p])
        .map(|p| bone_drawn.pixels()[p].max_element())
        .filter(|&v| v != 0.0)
        .collect();
    let in_skin = fraction_in(&skin, &defect);
    let soft = fraction_in(&covered(&soft_drawn, 0.01), &defect);
    eprintln!(
        "the defect: {} pixels, {in_skin} in the skin silhouette, {} not background with ct-bone, {soft} covered with ct-soft-tissue",
        count(&defect),
        lit.len()
    );
    assert!(
        count(&defect) >= 40,
        "no defect in the bone silhouette: {}",
        count(&defect)
    );
    assert!(in_skin >= 0.99, "{in_skin}");
    assert!(lit.is_empty(), "ct-bone draws in the defect: {lit:?}");
    assert!(
        soft >= 0.95,
        "ct-soft-tissue does not cover the defect: {soft}"
    );
}

/// The mr preset on Colin27's T1 (as shipped: uint8, no units, so mr by default) against the
/// silhouette of its voxels above 20 % of the maximum (255), from the front and the left, at
/// 128 x 128, covered meaning a channel above 0.01: intersection over union measured 0.996
/// and 0.993; asserted >= 0.97.
#[test]
fn the_mr_preset_shows_the_head_of_the_real_t1() {
    let Some(scans) = scans() else { return };
    let directory = tempfile::tempdir().unwrap();
    let d = directory.path();
    let size = 128;
    for (view, axis) in [("anterior", "A"), ("left", "L")] {
        let head = projection(d, &scans.mri, axis, 0.2 * 255.0, size);
        let name = format!("mr-{view}.exr");
        let default = render(d, &scans.mri, &name, size, &["--view", view]);
        let explicit = render(
            d,
            &scans.mri,
            "mr.exr",
            size,
            &["--view", view, "--transfer", "mr"],
        );
        assert!(
            default.pixels() == explicit.pixels(),
            "{view}: ch2's default is not mr"
        );
        let overlap = iou(&covered(&default, 0.01), &head);
        eprintln!(
            "mr, {view}: intersection over union {overlap:.3} ({} pixels in the silhouette)",
            count(&head)
        );
        assert!(overlap >= 0.97, "{view}: {overlap}");
    }
}

// ---------------------------------------------------------------------------------------
// 3. The anatomical views, with a marker voxel.

/// How each view shows the patient (the views' definitions, `View`'s documentation): the
/// world (RAS) directions of the image's right and up.
const VIEWS: [(&str, [f64; 3], [f64; 3]); 6] = [
    // From the front: the patient's left on the image's right, superior up.
    ("anterior", [-1.0, 0.0, 0.0], [0.0, 0.0, 1.0]),
    // From behind: the patient's left on the image's left.
    ("posterior", [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]),
    // From the patient's left: anterior on the image's left.
    ("left", [0.0, -1.0, 0.0], [0.0, 0.0, 1.0]),
    // From the patient's right: anterior on the image's right.
    ("right", [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]),
    // From above: anterior up, the patient's right on the image's right.
    ("superior", [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]),
    // From the feet: anterior up, the patient's left on the image's right.
    ("inferior", [-1.0, 0.0, 0.0], [0.0, 1.0, 0.0]),
];

fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

fn triple(value: &Value) -> [f64; 3] {
    let v: Vec<f64> = value
        .as_array()
        .expect("three numbers")
        .iter()
        .map(|x| x.as_f64().expect("a number"))
        .collect();
    [v[0], v[1], v[2]]
}

/// The grid's world box (RAS, voxel centres) from the silhouettes' framing: from the front
/// the image's right is -x and its up z, from above right is x and up y.
fn grid_box(directory: &Path, input: &Path) -> ([f64; 3], [f64; 3]) {
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

/// The luminance-weighted centroid of an image's pixels (x right, y down, in pixels from
/// the top left corner, pixel centres at half-integers) and how many pixels are lit.
fn centroid(image: &Image) -> Option<([f64; 2], usize)> {
    let (mut sum, mut x, mut y, mut lit) = (0.0, 0.0, 0.0, 0);
    let width = image.width() as usize;
    for (p, colour) in image.pixels().iter().enumerate() {
        let weight = f64::from(colour.max_element());
        if weight > 0.0 {
            sum += weight;
            x += weight * ((p % width) as f64 + 0.5);
            y += weight * ((p / width) as f64 + 0.5);
            lit += 1;
        }
    }
    (sum > 0.0).then(|| ([x / sum, y / sum], lit))
}

/// Which real file a marker test marks.
#[derive(Clone, Copy, PartialEq)]
enum Kind {
    /// A NIfTI file (`marker`).
    Nifti,
    /// A DICOM series folder (`marker-dicom-series`).
    Series,
    /// An enhanced DICOM file (`marker`); only two frames, 10 mm apart.
    Enhanced,
}

/// Writes a copy of `input` with a bright 5-voxel cube at the patient's left-anterior-superior
/// part of the head (fractions 0.25, 0.8, 0.8 of the head's box along R, A, S: `corner`),
/// renders the six views at 128 x 128 with a transfer function that shows only the marker
/// (transparent up to 70 % of the way from the rest's maximum to the marker's value, opaque
/// white just above), unlit (ambient 1), and checks the blob's centroid: in the half of the
/// image the view's definition ([`VIEWS`]) puts the marker (from the front: right half, the
/// patient's left, and top half, superior; from the left: left half, anterior; from above:
/// top half, anterior, and left half, the patient's left; ...), and within 2 pixels of where
/// the definition and the framing (a square of 1.05 times the grid box's larger half extent,
/// centred on the box) put the marker's world position. Measured: within 0.45 pixel on every
/// view of the CT (both files), the MRI and, along the axes checked, the enhanced CT.
///
/// The enhanced CT has two frames 10 mm apart: the marker's cube spans both, so along the
/// superior-inferior axis the blob fills the grid's whole (10 mm) extent and its centroid
/// says nothing (it lies 3.1 pixels from the marked frame's position); only the in-plane
/// directions are checked there: left-right on the front, back, top and bottom views,
/// anterior-posterior on the side, top and bottom views.
fn marker_views(input: &Path, kind: Kind) {
    let directory = tempfile::tempdir().unwrap();
    let d = directory.path();
    let corner = real_scans_json(d, &["corner", text(input), "--fraction", "0.25,0.8,0.8"]);
    let at = triple(&corner["world_ras"]);
    let at_text = format!("{},{},{}", at[0], at[1], at[2]);
    let marked = d.join(match kind {
        Kind::Nifti => "marked.nii.gz",
        Kind::Series => "marked",
        Kind::Enhanced => "marked.dcm",
    });
    let command = if kind == Kind::Series {
        "marker-dicom-series"
    } else {
        "marker"
    };
    let marker = real_scans_json(d, &[command, text(input), text(&marked), "--at", &at_text]);
    let value = marker["value"].as_f64().unwrap();
    let world = triple(&marker["world_ras"]);
    // The marker's value is the maximum + 2000 (CT) or 3 x the maximum: show from 70 % of the
    // way up from the rest's maximum, opaque almost at once.
    let rest = if corner["ct"].as_bool().unwrap() {
        value - 2000.0
    } else {
        value / 3.0
    };
    let from = rest + 0.7 * (value - rest);
    let transfer = d.join("marker.toml");
    std::fs::write(
        &transfer,
        format!(
            "units = \"absolute\"\npoints = [[{from}, 0, 1, 1, 1], [{}, 50, 1, 1, 1]]\n",
            from + 0.05 * (value - rest)
        ),
    )
    .unwrap();
    let (lo, hi) = grid_box(d, &marked);
    let size = 128u32;
    let half_image = f64::from(size) / 2.0;
    for (view, right, up) in VIEWS {
        let image = render(
            d,
            &marked,
            &format!("{view}.exr"),
            size,
            &[
                "--view",
                view,
                "--transfer",
                text(&transfer),
                "--ambient",
                "1",
                "--diffuse",
                "0",
                "--specular",
                "0",
            ],
        );
        let ([x, y], lit) =
            centroid(&image).unwrap_or_else(|| panic!("{view}: the marker is not drawn"));
        // Where the view's definition puts the marker: the box's corners projected onto the
        // image's axes, framed by a square of 1.05 times the larger half extent.
        let extent = |axis: [f64; 3]| {
            let a = dot(lo, axis);
            let b = dot(hi, axis);
            (a.min(b), a.max(b))
        };
        let ((r0, r1), (u0, u1)) = (extent(right), extent(up));
        let half = 1.05 * (r1 - r0).max(u1 - u0) / 2.0;
        let expected_x = half_image + (dot(world, right) - (r0 + r1) / 2.0) / half * half_image;
        let expected_y = half_image - (dot(world, up) - (u0 + u1) / 2.0) / half * half_image;
        eprintln!(
            "{}: {view}: blob of {lit} pixels centred at ({x:.1}, {y:.1}), expected ({expected_x:.1}, {expected_y:.1})",
            input.display()
        );
        let checked = |axis: [f64; 3]| kind != Kind::Enhanced || axis[2] == 0.0;
        // The quadrant: which half of the image, as the view's definition says (the marker
        // lies well off the image's centre lines, so the half is not a matter of a pixel).
        if checked(right) {
            assert!(
                (expected_x - half_image).abs() >= 8.0,
                "{view}: {expected_x}"
            );
            assert_eq!(
                x > half_image,
                expected_x > half_image,
                "{view}: left-right: x {x}, expected {expected_x}"
            );
            assert!(
                (x - expected_x).abs() <= 2.0,
                "{view}: x {x}, expected {expected_x}"
            );
        }
        if checked(up) {
            assert!(
                (expected_y - half_image).abs() >= 8.0,
                "{view}: {expected_y}"
            );
            assert_eq!(
                y < half_image,
                expected_y < half_image,
                "{view}: up-down: y {y}, expected {expected_y}"
            );
            assert!(
                (y - expected_y).abs() <= 2.0,
                "{view}: y {y}, expected {expected_y}"
            );
        }
    }
}

#[test]
fn views_put_a_marker_where_anatomy_says_on_the_ct_nifti() {
    let Some(scans) = scans() else { return };
    marker_views(&scans.ct_nifti, Kind::Nifti);
}

#[test]
fn views_put_a_marker_where_anatomy_says_on_the_ct_series() {
    let Some(scans) = scans() else { return };
    marker_views(&scans.ct_dicom, Kind::Series);
}

#[test]
fn views_put_a_marker_where_anatomy_says_on_the_mri() {
    let Some(scans) = scans() else { return };
    marker_views(&scans.mri, Kind::Nifti);
}

#[test]
fn views_put_a_marker_where_anatomy_says_on_the_enhanced_ct() {
    let Some(scans) = scans() else { return };
    marker_views(&scans.enhanced_ct, Kind::Enhanced);
}

// ---------------------------------------------------------------------------------------
// 4. VTK's CPU ray caster as the yardstick.

/// An 8-bit PNG's values as written (VTK's framebuffer: linear values, no gamma), read through
/// [`read_image`] (which decodes sRGB) and encoded back: exact for every byte (checked).
fn png_bytes(path: &Path) -> Pixels {
    use specula_render::{srgb_decode, srgb_encode};
    for byte in 0..=255u8 {
        let back = (srgb_encode(srgb_decode(f32::from(byte) / 255.0)) * 255.0).round();
        assert_eq!(back, f32::from(byte), "sRGB does not round-trip {byte}");
    }
    let image = read_image(path).expect("vtk.png reads");
    image
        .pixels()
        .iter()
        .map(|p| {
            p.to_array()
                .map(|c| (srgb_encode(c) * 255.0).round() / 255.0)
        })
        .collect()
}

/// `specula bench volume` on `input` with `transfer`, 256 x 256, one frame: specula's image
/// (linear) and VTK's (8-bit linear); `None` after `skipped: ...` where VTK imports but
/// cannot render (no EGL), which fails under `CI=true`.
fn bench_images(d: &Path, input: &Path, transfer: &str) -> Option<(Pixels, Pixels)> {
    let output = std::process::Command::new(assert_cmd::cargo::cargo_bin("specula"))
        .current_dir(d)
        .env("SPECULA_PYTHON", python())
        .args([
            "bench",
            "volume",
            "--input",
            text(input),
            "--frames",
            "1",
            "--width",
            "256",
            "--height",
            "256",
            "--images",
            "images",
            "--transfer",
            transfer,
        ])
        .output()
        .expect("runs");
    let stdout = String::from_utf8_lossy(&output.stdout);
    assert!(
        output.status.success(),
        "{stdout}{}",
        String::from_utf8_lossy(&output.stderr)
    );
    if let Some(line) = stdout.lines().find(|l| l.starts_with("VTK not measured")) {
        assert!(
            std::env::var("CI").as_deref() != Ok("true"),
            "CI=true requires VTK to render (apt-get install libegl1 libegl-mesa0 libgl1-mesa-dri): {line}"
        );
        eprintln!("skipped: {line}");
        return None;
    }
    let specula = rgb(&read_image(&d.join("images/specula.exr")).expect("specula.exr"));
    let vtk = png_bytes(&d.join("images/vtk.png"));
    Some((specula, vtk))
}

/// What the comparison measures: (mean absolute difference over pixels and channels, the
/// fraction of pixels whose largest channel difference exceeds 0.1, the fraction of pixels
/// black in one image only, intersection over union of the covered pixels (a channel above
/// 0.02), whether every pixel outside the grid's projected box is black in both).
fn agreement(
    specula: &[[f32; 3]],
    vtk: &[[f32; 3]],
    outside: &[bool],
) -> (f64, f64, f64, f64, bool) {
    let n = specula.len() as f64;
    let largest = |p: &[f32; 3], q: &[f32; 3]| {
        (0..3)
            .map(|c| (p[c].clamp(0.0, 1.0) - q[c]).abs())
            .fold(0.0, f32::max)
    };
    let far = specula
        .iter()
        .zip(vtk)
        .filter(|(p, q)| largest(p, q) > 0.1)
        .count() as f64
        / n;
    let black = |p: &[f32; 3]| p.iter().all(|&c| c == 0.0);
    let one_black = specula
        .iter()
        .zip(vtk)
        .filter(|(p, q)| black(p) != black(q))
        .count() as f64
        / n;
    let cover = |image: &[[f32; 3]]| {
        image
            .iter()
            .map(|p| p.iter().any(|&c| c > 0.02))
            .collect::<Vec<_>>()
    };
    let background = outside
        .iter()
        .zip(specula.iter().zip(vtk))
        .all(|(out, (p, q))| !out || (black(p) && black(q)));
    (
        mean_abs(specula, vtk),
        far,
        one_black,
        iou(&cover(specula), &cover(vtk)),
        background,
    )
}

/// The pixels of a `size` square anterior view outside the grid's projected box.
fn outside_box(d: &Path, input: &Path, size: usize) -> Vec<bool> {
    let (lo, hi) = grid_box(d, input);
    let (rx, uz) = ((-hi[0], -lo[0]), (lo[2], hi[2]));
    let half = 1.05 * (rx.1 - rx.0).max(uz.1 - uz.0) / 2.0;
    let (cx, cz) = ((rx.0 + rx.1) / 2.0, (uz.0 + uz.1) / 2.0);
    (0..size * size)
        .map(|p| {
            let r = cx + ((p % size) as f64 + 0.5 - size as f64 / 2.0) / (size as f64 / 2.0) * half;
            let u = cz - ((p / size) as f64 + 0.5 - size as f64 / 2.0) / (size as f64 / 2.0) * half;
            // A pixel's ray a whole pixel clear of the box's edge.
            let pixel = 2.0 * half / size as f64;
            r < rx.0 - pixel || r > rx.1 + pixel || u < uz.0 - pixel || u > uz.1 + pixel
        })
        .collect()
}

/// specula against VTK on one real scan (see [`vtk_agrees_on_the_real_ct`]): the bounds on
/// (mean absolute difference, fraction of pixels off by more than 0.1, fraction black in one
/// image only, intersection over union of the covered pixels).
fn vtk_comparison(input: &Path, transfer: &str, bounds: (f64, f64, f64, f64)) {
    let directory = tempfile::tempdir().unwrap();
    let d = directory.path();
    let Some((specula, vtk)) = bench_images(d, input, transfer) else {
        return;
    };
    let outside = outside_box(d, input, 256);
    let (mean, far, one_black, overlap, background) = agreement(&specula, &vtk, &outside);
    eprintln!(
        "{} ({transfer}) against VTK: mean absolute difference {mean:.4}, pixels off by more than 0.1: {far:.4}, black in one only: {one_black:.4}, covered: intersection over union {overlap:.4}; {} pixels outside the grid's box",
        input.display(),
        count(&outside)
    );
    assert!(
        count(&outside) > 1000,
        "the test would not see the background"
    );
    assert!(
        background,
        "a pixel outside the grid's box is not black in both"
    );
    assert!(mean <= bounds.0, "mean absolute difference {mean}");
    assert!(far <= bounds.1, "pixels off by more than 0.1: {far}");
    assert!(
        one_black <= bounds.2,
        "pixels black in one image only: {one_black}"
    );
    assert!(
        overlap >= bounds.3,
        "covered pixels: intersection over union {overlap}"
    );
}

/// `specula bench volume` renders the real CT (NIfTI, ct-bone, from the front, 256 x 256,
/// 0.5 mm between samples, the headlight, Blinn-Phong of power 64 as the `pow` lobe, every
/// sample fully shaded) and VTK's `vtkFixedPointVolumeRayCastMapper` set up alike
/// (`vtk_volume.py`); specula's image is linear (clamped to 1 as VTK's framebuffer clamps),
/// VTK's 8-bit linear.
///
/// Measured (vtk 9.7.2, 2 threads): mean absolute difference 0.0112 over pixels and channels,
/// 1.08 % of the pixels off by more than 0.1 in some channel, 1.21 % black in one image only,
/// covered pixels (a channel above 0.02) agreeing with intersection over union 0.979, and
/// every pixel a pixel or more outside the grid's projected box black in both. Asserted:
/// <= 0.015, <= 1.5 %, <= 2 %, >= 0.97.
///
/// Why they differ (docs/vtk-notes.md): VTK's normals are central differences of the voxels
/// quantised to 65,280 directions and its shading is the 8 corners' lit values interpolated
/// (specula: the gradient of the trilinear field at the sample), so lighting differs in the
/// fine texture of the bone; a voxel whose central difference is exactly zero (uniform
/// tissue, saturated bone, common in integer data) is lit black by VTK; VTK's samples lie on
/// a lattice anchored at the near plane (the ring artefacts on the skull's top) where specula
/// jitters each ray's first segment; VTK composites in 15-bit fixed point and writes 8 bits.
/// Along every outline VTK's image spreads one pixel further than specula's (at the grid's
/// bottom face, the row beyond holds about half the edge's value in VTK and nothing in
/// specula, whose rays there miss the grid): those outline pixels are most of the "black in
/// one only" and of the pixels off by more than 0.1.
#[test]
fn vtk_agrees_on_the_real_ct() {
    let Some(scans) = scans() else { return };
    if !have_python_module("vtk", "vtk") {
        return;
    }
    vtk_comparison(&scans.ct_nifti, "ct-bone", (0.015, 0.015, 0.02, 0.97));
}

/// As [`vtk_agrees_on_the_real_ct`], on Colin27's T1 with the mr preset. Measured: mean
/// absolute difference 0.0117, 0.45 % of the pixels off by more than 0.1, 0.15 % black in
/// one only, covered pixels' intersection over union 0.992, the background black in both.
/// Asserted: <= 0.015, <= 0.8 %, <= 0.5 %, >= 0.985. Besides the reasons above, VTK's
/// gradients computed by 2 threads have a seam (a one-sided z difference on slice 89 of 181:
/// a line across the middle of VTK's image).
#[test]
fn vtk_agrees_on_the_real_mri() {
    let Some(scans) = scans() else { return };
    if !have_python_module("vtk", "vtk") {
        return;
    }
    vtk_comparison(&scans.mri, "mr", (0.015, 0.008, 0.005, 0.985));
}

// ---------------------------------------------------------------------------------------
// 5. The GPU renders the real scans as the CPU does.

/// `--backend gpu` (Mesa's lavapipe here, so small images) against the CPU on the real CT
/// (NIfTI, from the front and the left; the series from above) and the real MRI, with their
/// default presets, at 96 x 96. The GPU marches the same rays (the same jittered first
/// segments) in `f32`: measured on lavapipe (llvmpipe, LLVM 15) mean FLIP 6.8e-5 (CT, front),
/// 1.4e-5 (CT, left) and 0 (the series from above, the MRI), the largest difference of an
/// 8-bit sRGB value 1/255; asserted mean FLIP <= 1e-3 and largest difference <= 0.05, room
/// for a real GPU's arithmetic.
#[test]
fn the_gpu_renders_the_real_scans_as_the_cpu_does() {
    let Some(scans) = scans() else { return };
    if !have_gpu() {
        return;
    }
    let directory = tempfile::tempdir().unwrap();
    let d = directory.path();
    let size = 96;
    for (name, input, view) in [
        ("ct", &scans.ct_nifti, "anterior"),
        ("ct", &scans.ct_nifti, "left"),
        ("series", &scans.ct_dicom, "superior"),
        ("mri", &scans.mri, "anterior"),
    ] {
        let cpu = render(
            d,
            input,
            &format!("{name}-{view}-cpu.exr"),
            size,
            &["--view", view],
        );
        let gpu_name = format!("{name}-{view}-gpu.exr");
        let drawn = ok(
            d,
            &[
                "volume",
                "--input",
                text(input),
                "--view",
                view,
                "--width",
                "96",
                "--height",
                "96",
                "--backend",
                "gpu",
                "-o",
                &gpu_name,
            ],
        );
        let stderr = String::from_utf8_lossy(&drawn.stderr);
        assert!(
            !stderr.contains(", CPU, "),
            "not drawn by the GPU: {stderr}"
        );
        let gpu = read_image(&d.join(&gpu_name)).unwrap();
        let difference =
            specula_render::metrics::compare(&cpu, &gpu, specula_render::Display::default())
                .unwrap();
        eprintln!(
            "{name}, {view}: GPU against CPU: mean FLIP {:.2e}, largest 8-bit difference {:.4}",
            difference.mean_flip, difference.max_abs_error
        );
        assert!(
            difference.mean_flip <= 1e-3,
            "{name}, {view}: {}",
            difference.mean_flip
        );
        assert!(
            difference.max_abs_error <= 0.05,
            "{name}, {view}: {}",
            difference.max_abs_error
        );
        assert!(
            cpu.pixels()
                .iter()
                .filter(|p| p.max_element() > 0.02)
                .count()
                > 96 * 96 / 4,
            "{name}, {view}: nearly empty, the comparison would say nothing"
        );
    }
}

// ---------------------------------------------------------------------------------------
// 6. Bad real-world files: one line each, nothing written.

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
