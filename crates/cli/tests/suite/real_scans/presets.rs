//! The presets on the real CT and MRI: the CT as NIfTI and as a DICOM series (Hounsfield
//! units recognised), and the presets against the voxels' silhouettes.

use super::setup::{
    count, covered, dilate, fraction_in, iou, mean_abs, projection, render, rgb, scans, text,
};
use crate::common::python;

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
    eprintln!(
        "NIfTI against series: mean absolute difference {same:.2e}, mean FLIP {flip:.2e}; \
        ct-bone against mr: {fog:.3}"
    );
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
            "{view}: {figures:?}; skin only ({} px) covered by ct-bone, ct-soft-tissue, window: \
                {shown:?}",
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
        .env("SPECULA_CACHE_DIR", crate::common::test_cache())
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
        "the defect: {} pixels, {in_skin} in the skin silhouette, {} not background with ct-bone, \
            {soft} covered with ct-soft-tissue",
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
