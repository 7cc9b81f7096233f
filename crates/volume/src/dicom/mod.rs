//! DICOM, with dicom-rs: a folder of single-frame slices ([`read_series`]), one multi-frame
//! (enhanced) object holding every slice as a frame ([`read_file`]), and a volume written
//! as a series ([`write_series`]).
//!
//! Each slice (a file of a series, or a frame of a multi-frame object) is placed by its
//! header: Image Position (Patient), Image Orientation (Patient) and Pixel Spacing, which a
//! multi-frame object gives per frame in its Per-Frame Functional Groups (5200,9230), or
//! (orientation and spacing) once for all frames in its Shared Functional Groups
//! (5200,9229), the per-frame value winning; its rescale is found the same way. Slices are checked
//! as one geometry and sorted along the slice normal (Image
//! Orientation's row x column) by position; one function (`stack`) does this for both kinds.
//! Voxels along a row step by Pixel Spacing's column spacing along the row direction, rows
//! by its row spacing along the column direction, and slices by the measured distance
//! between positions (Slice Thickness is not a spacing; a multi-frame object's Spacing
//! Between Slices is only checked against the positions). `dicom-pixeldata` decodes the
//! pixels (native, RLE, JPEG); each slice's Rescale Slope and Intercept turn stored values
//! into the volume's. DICOM's patient frame is LPS; [`Volume`]s are RAS, so `x` and `y` flip.
//!
//! **Units.** A volume is in Hounsfield units when the file says so: its Modality (0008,0060)
//! is `CT`, or a Rescale Type (0028,1054) is `HU`, at the top level or in a frame's Pixel
//! Value Transformation Sequence (0028,9145). Otherwise its values are
//! [`Units::Arbitrary`].
//!
//! Every refusal (mixed series, no position or spacing, a missing slice, uneven gaps,
//! inconsistent spacing, a multi-frame object without per-frame geometry, a grid over the
//! limits) is one line naming the file and comes before any pixel is decoded.

mod enhanced;
mod series;
mod write;

use std::path::Path;

use dicom_core::Tag;
use dicom_object::InMemDicomObject;
use glam::{DMat3, DVec3, Mat3, Vec3};

pub use enhanced::read_file;
pub use series::read_series;
pub use write::write_series;

use crate::volume::{Units, Volume, MAX_SIDE};

/// LPS to RAS (and back): `x` and `y` change sign.
const LPS_TO_RAS: DVec3 = DVec3::new(-1.0, -1.0, 1.0);

/// Slice gaps may differ by this fraction of their mean (scanners round positions).
const GAP_TOLERANCE: f64 = 0.01;

/// Whether `path` names a DICOM file: it ends in `.dcm`, or it is a regular file that starts
/// with DICOM's 128-byte preamble and `DICM`.
#[must_use]
pub fn is_dicom_file(path: &Path) -> bool {
    let named = path
        .extension()
        .is_some_and(|extension| extension.eq_ignore_ascii_case("dcm"));
    named || (std::fs::metadata(path).is_ok_and(|meta| meta.is_file()) && has_preamble(path))
}

/// Whether the regular file at `path` (within the input limit) starts with `DICM` at byte 128.
fn has_preamble(path: &Path) -> bool {
    let Ok(mut file) = specula_render::input::open_regular(path) else {
        return false;
    };
    let mut preamble = [0_u8; 132];
    std::io::Read::read_exact(&mut file, &mut preamble).is_ok() && &preamble[128..] == b"DICM"
}

/// One image plane, a file of a series or a frame of a multi-frame object, as its header
/// places it (LPS millimetres).
struct Plane {
    /// What messages call it: a file's path, or `frame N`.
    name: String,
    rows: usize,
    columns: usize,
    position: DVec3,
    /// Row direction (along a row, increasing column), then column direction.
    orientation: [DVec3; 2],
    /// Between rows, then between columns (DICOM's order), in millimetres.
    pixel_spacing: [f64; 2],
}

/// How planes stack into a grid.
struct Grid {
    dims: [usize; 3],
    /// Grid index to RAS millimetres.
    to_world: Mat3,
    origin: Vec3,
    /// The planes' indices in order along the slice normal: `order[k]` is slice `k`.
    order: Vec<usize>,
    /// The mean distance between neighbouring planes along the normal, in millimetres.
    gap: f64,
}

/// Checks that `planes` are one evenly spaced stack with one size, pixel spacing and
/// orientation, sorts them along their normal, and gives the grid and its placement (RAS
/// millimetres). `whole` names what holds them in messages (`a series`, `a multi-frame
/// object`).
fn stack(planes: &[Plane], whole: &str) -> Result<Grid, String> {
    let first = &planes[0];
    for plane in &planes[1..] {
        if (plane.rows, plane.columns) != (first.rows, first.columns) {
            return Err(format!(
                "{} is {} x {} pixels (Rows x Columns) where {} is {} x {}; {whole} shares one \
                    size",
                plane.name, plane.rows, plane.columns, first.name, first.rows, first.columns
            ));
        }
        let spacing = |p: &Plane| format!("{}\\{}", p.pixel_spacing[0], p.pixel_spacing[1]);
        if (plane.pixel_spacing[0] - first.pixel_spacing[0]).abs() > 1e-6
            || (plane.pixel_spacing[1] - first.pixel_spacing[1]).abs() > 1e-6
        {
            return Err(format!(
                "{} has Pixel Spacing {} mm where {} has {} mm; {whole} shares one pixel spacing",
                plane.name,
                spacing(plane),
                first.name,
                spacing(first)
            ));
        }
        if (plane.orientation[0] - first.orientation[0]).length() > 1e-4
            || (plane.orientation[1] - first.orientation[1]).length() > 1e-4
        {
            let cosines = |p: &Plane| {
                let [row, column] = p.orientation;
                point(&[row.to_array(), column.to_array()].concat())
            };
            return Err(format!(
                "{} has Image Orientation (Patient) {} where {} has {}; {whole} shares one \
                    orientation",
                plane.name,
                cosines(plane),
                first.name,
                cosines(first)
            ));
        }
    }
    let dims = [first.columns, first.rows, planes.len()];
    Volume::check_dims(dims).map_err(|e| e.0)?;
    let [row, column] = first.orientation;
    let [row_spacing, column_spacing] = first.pixel_spacing;
    let normal = row.cross(column);
    let depth = |i: usize| planes[i].position.dot(normal);
    let mut order: Vec<usize> = (0..planes.len()).collect();
    order.sort_by(|&a, &b| depth(a).total_cmp(&depth(b)));
    let gaps: Vec<f64> = order
        .windows(2)
        .map(|w| depth(w[1]) - depth(w[0]))
        .collect();
    if let Some(at) = gaps.iter().position(|&g| g < 1e-6) {
        let (a, b) = (&planes[order[at]], &planes[order[at + 1]]);
        return Err(format!(
            "{} and {} share one position {} (Image Position (Patient)); {whole} has one slice per \
                position",
            a.name,
            b.name,
            point(&a.position.to_array())
        ));
    }
    let mean = (depth(order[order.len() - 1]) - depth(order[0])) / gaps.len() as f64;
    if gaps
        .iter()
        .any(|&g| (g - mean).abs() > GAP_TOLERANCE * mean)
    {
        return Err(uneven(planes, &order, &gaps));
    }
    let (bottom, top) = (&planes[order[0]], &planes[order[order.len() - 1]]);
    let lps = DMat3::from_cols(
        row * column_spacing,
        column * row_spacing,
        (top.position - bottom.position) / gaps.len() as f64,
    );
    let to_ras = DMat3::from_diagonal(LPS_TO_RAS);
    Ok(Grid {
        dims,
        to_world: (to_ras * lps).as_mat3(),
        origin: (LPS_TO_RAS * bottom.position).as_vec3(),
        order,
        gap: mean,
    })
}

/// Why gaps that are not even cannot be stacked: slices missing where a gap is a whole
/// multiple (two or more) of the usual one and every other gap is the usual one, otherwise
/// the range of the gaps.
fn uneven(planes: &[Plane], order: &[usize], gaps: &[f64]) -> String {
    let mut sorted = gaps.to_vec();
    sorted.sort_by(f64::total_cmp);
    let usual = sorted[(sorted.len() - 1) / 2];
    let multiple = |g: f64| (g / usual).round();
    let is_usual = |g: f64| (g - usual).abs() <= GAP_TOLERANCE * usual;
    let is_missing =
        |g: f64| multiple(g) >= 2.0 && (g - multiple(g) * usual).abs() <= 2.0 * GAP_TOLERANCE * g;
    let missing = gaps.iter().position(|&g| is_missing(g));
    let neighbours = |at: usize| {
        let (a, b) = (&planes[order[at]], &planes[order[at + 1]]);
        format!(
            "positions {} of {} and {} of {} (Image Position (Patient), mm)",
            point(&a.position.to_array()),
            a.name,
            point(&b.position.to_array()),
            b.name
        )
    };
    match missing {
        Some(at) if gaps.iter().all(|&g| is_usual(g) || is_missing(g)) => {
            let count = multiple(gaps[at]) as usize - 1;
            let what = if count == 1 {
                "a slice seems".to_owned()
            } else {
                format!("{count} slices seem")
            };
            format!(
                "uneven slice spacing: {what} missing between {}, {:.3} mm apart where the others \
                    are {usual:.3} mm; specula stacks evenly spaced slices, so give the whole \
                    series",
                neighbours(at),
                gaps[at]
            )
        }
        _ => {
            let widest = (0..gaps.len())
                .max_by(|&a, &b| (gaps[a] - usual).abs().total_cmp(&(gaps[b] - usual).abs()))
                .unwrap_or(0);
            format!(
                "uneven slice spacing ({:.3} to {:.3} mm; the gap most off the usual {usual:.3} mm \
                    is between {}); specula stacks evenly spaced slices",
                sorted[0],
                sorted[sorted.len() - 1],
                neighbours(widest)
            )
        }
    }
}

/// Numbers as a message shows them: `(a, b, c)`, to a thousandth.
fn point(values: &[f64]) -> String {
    let shown: Vec<String> = values
        .iter()
        .map(|&v| format!("{}", (v * 1000.0).round() / 1000.0 + 0.0))
        .collect();
    format!("({})", shown.join(", "))
}

/// A text element of `object`, trimmed, when present.
fn text(object: &InMemDicomObject, tag: Tag, name: &str) -> Result<Option<String>, String> {
    match object.element_opt(tag) {
        Ok(Some(element)) => element
            .to_str()
            .map(|s| Some(s.trim().to_owned()))
            .map_err(|e| format!("{name}: {e}")),
        _ => Ok(None),
    }
}

/// An integer element of `object`, when present.
fn integer(object: &InMemDicomObject, tag: Tag, name: &str) -> Result<Option<i64>, String> {
    match object.element_opt(tag) {
        Ok(Some(element)) => element
            .to_int::<i64>()
            .map(Some)
            .map_err(|e| format!("{name}: {e}")),
        _ => Ok(None),
    }
}

/// `count` finite numbers from `object`'s element `tag`, when present and not empty.
fn numbers(
    object: &InMemDicomObject,
    tag: Tag,
    name: &str,
    count: usize,
) -> Result<Option<Vec<f64>>, String> {
    let Ok(Some(element)) = object.element_opt(tag) else {
        return Ok(None);
    };
    if element.to_str().is_ok_and(|s| s.trim().is_empty()) {
        return Ok(None);
    }
    let values = element
        .to_multi_float64()
        .map_err(|e| format!("{name}: {e}"))?;
    if values.len() != count || values.iter().any(|v| !v.is_finite()) {
        return Err(format!("{name} must be {count} finite numbers"));
    }
    Ok(Some(values))
}

/// Rows or Columns: 2 to [`MAX_SIDE`].
fn side(object: &InMemDicomObject, tag: Tag, name: &str) -> Result<usize, String> {
    integer(object, tag, name)?
        .and_then(|v| usize::try_from(v).ok())
        .filter(|&v| (2..=MAX_SIDE).contains(&v))
        .ok_or_else(|| format!("{name} must be 2 to {MAX_SIDE}"))
}

/// Image Orientation (Patient)'s six numbers as the row and column directions, which must be
/// perpendicular unit vectors.
fn orientation(values: &[f64]) -> Result<[DVec3; 2], String> {
    let row = DVec3::new(values[0], values[1], values[2]);
    let column = DVec3::new(values[3], values[4], values[5]);
    if (row.length() - 1.0).abs() > 1e-3
        || (column.length() - 1.0).abs() > 1e-3
        || row.dot(column).abs() > 1e-3
    {
        return Err("Image Orientation (Patient) must be two perpendicular unit vectors".into());
    }
    Ok([row, column])
}

/// Pixel Spacing's two numbers, which must be positive.
fn pixel_spacing(values: &[f64]) -> Result<[f64; 2], String> {
    if values.iter().any(|&s| s <= 0.0) {
        return Err("Pixel Spacing must be positive".into());
    }
    Ok([values[0], values[1]])
}

/// Whether a Modality and a Rescale Type say Hounsfield units (see the module's rule).
fn says_hounsfield(modality: Option<&str>, rescale_type: Option<&str>) -> bool {
    modality.is_some_and(|m| m.eq_ignore_ascii_case("CT"))
        || rescale_type.is_some_and(|t| t.eq_ignore_ascii_case("HU"))
}

/// The units a volume gets from whether its file says Hounsfield units.
fn units(hounsfield: bool) -> Units {
    if hounsfield {
        Units::Hounsfield
    } else {
        Units::Arbitrary
    }
}

#[cfg(test)]
mod tests;
