//! The anatomical views, with a marker voxel.

use std::path::Path;

use serde_json::Value;
use specula_render::Image;

use super::setup::{grid_box, real_scans_json, render, scans, text};

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
            "{}: {view}: blob of {lit} pixels centred at ({x:.1}, {y:.1}), expected \
                ({expected_x:.1}, {expected_y:.1})",
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
