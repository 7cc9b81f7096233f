//! DICOM series: a folder of single-frame slices stacked into a volume, with dicom-rs.
//!
//! Slices are read header-first (everything before Pixel Data), checked as one series with
//! one geometry, and sorted along the slice normal (Image Orientation (Patient)'s row x
//! column) by Image Position (Patient). Voxels along a row step by Pixel Spacing's column
//! spacing along the row direction, rows by its row spacing along the column direction, and
//! slices by the measured distance between positions (Slice Thickness is not a spacing).
//! `dicom-pixeldata` decodes the pixels (native, RLE, JPEG) and applies Rescale Slope and
//! Intercept. DICOM's patient frame is LPS; [`Volume`]s are RAS, so `x` and `y` flip.
//!
//! Every refusal (mixed series, no position or spacing, uneven gaps, a grid over the limits)
//! comes before any pixel is decoded.

use std::hash::{Hash, Hasher};
use std::path::{Path, PathBuf};

use dicom_core::{DataElement, PrimitiveValue, VR};
use dicom_dictionary_std::{tags, uids};
use dicom_object::{DefaultDicomObject, FileMetaTableBuilder, InMemDicomObject, OpenFileOptions};
use dicom_pixeldata::PixelDecoder;
use glam::{DMat3, DVec3, Mat3, Vec3};
use rayon::prelude::*;

use super::{Units, Volume, VolumeError, MAX_SIDE};
use crate::input;
use crate::output::register;

/// LPS to RAS (and back): `x` and `y` change sign.
const LPS_TO_RAS: DVec3 = DVec3::new(-1.0, -1.0, 1.0);

/// Slice gaps may differ by this fraction of their mean (scanners round positions).
const GAP_TOLERANCE: f64 = 0.01;

/// What one slice's header says.
struct Slice {
    path: PathBuf,
    series: String,
    rows: usize,
    columns: usize,
    position: DVec3,
    /// Row direction (along a row, increasing column), then column direction.
    orientation: [DVec3; 2],
    /// Between rows, then between columns (DICOM's order), in millimetres.
    pixel_spacing: [f64; 2],
    modality: String,
}

/// Reads the series in folder `dir`. Files without DICOM's `DICM` preamble (a README, a
/// `DICOMDIR`'s companions) and subfolders are passed over.
pub fn read_series(dir: &Path) -> Result<Volume, VolumeError> {
    let fail = |what: String| VolumeError(format!("{}: {what}", dir.display()));
    let files = series_files(dir).map_err(fail)?;
    let mut slices: Vec<Slice> = files
        .par_iter()
        .map(|path| read_header(path))
        .collect::<Result<_, _>>()
        .map_err(fail)?;
    let (dims, to_world, origin) = geometry(&mut slices).map_err(fail)?;
    let slice_voxels = dims[0] * dims[1];
    let planes: Vec<Vec<f32>> = slices
        .par_iter()
        .map(|slice| read_pixels(slice, slice_voxels))
        .collect::<Result<_, _>>()
        .map_err(fail)?;
    let units = if slices[0].modality == "CT" {
        Units::Hounsfield
    } else {
        Units::Arbitrary
    };
    Volume::try_new(dims, to_world, origin, planes.concat(), units).map_err(|e| fail(e.0))
}

/// The DICOM files in `dir`, by name, at most [`MAX_SIDE`] of them.
fn series_files(dir: &Path) -> Result<Vec<PathBuf>, String> {
    let meta = std::fs::metadata(dir).map_err(|e| e.to_string())?;
    if !meta.is_dir() {
        return Err("not a folder; give a folder holding one DICOM series".into());
    }
    let mut files = Vec::new();
    for entry in std::fs::read_dir(dir).map_err(|e| e.to_string())? {
        let path = entry.map_err(|e| e.to_string())?.path();
        if path.is_dir() {
            continue;
        }
        let mut file =
            input::open_regular(&path).map_err(|e| format!("{}: {e}", path.display()))?;
        let mut preamble = [0_u8; 132];
        let is_dicom = std::io::Read::read_exact(&mut file, &mut preamble).is_ok()
            && &preamble[128..] == b"DICM";
        if is_dicom {
            if files.len() == MAX_SIDE {
                return Err(format!(
                    "more than {MAX_SIDE} DICOM files; a series may have at most {MAX_SIDE} slices"
                ));
            }
            files.push(path);
        }
    }
    if files.is_empty() {
        return Err("no DICOM files (none starts with the DICM preamble)".into());
    }
    files.sort();
    Ok(files)
}

fn read_header(path: &Path) -> Result<Slice, String> {
    let at = |what: String| format!("{}: {what}", path.display());
    let object = OpenFileOptions::new()
        .read_until(tags::PIXEL_DATA)
        .open_file(path)
        .map_err(|e| at(format!("not a readable DICOM file ({e})")))?;
    let text = |tag, name: &str| -> Result<Option<String>, String> {
        match object.element_opt(tag) {
            Ok(Some(element)) => element
                .to_str()
                .map(|s| Some(s.trim().to_owned()))
                .map_err(|e| at(format!("{name}: {e}"))),
            _ => Ok(None),
        }
    };
    let numbers = |tag, name: &str, count: usize| -> Result<Vec<f64>, String> {
        let missing = || {
            at(format!(
                "no {name}; specula needs each slice's {name} to place it in the volume"
            ))
        };
        let values = object
            .element_opt(tag)
            .ok()
            .flatten()
            .ok_or_else(missing)?
            .to_multi_float64()
            .map_err(|e| at(format!("{name}: {e}")))?;
        if values.len() != count || values.iter().any(|v| !v.is_finite()) {
            return Err(at(format!("{name} must be {count} finite numbers")));
        }
        Ok(values)
    };
    let integer = |tag, name: &str| -> Result<Option<i64>, String> {
        match object.element_opt(tag) {
            Ok(Some(element)) => element
                .to_int::<i64>()
                .map(Some)
                .map_err(|e| at(format!("{name}: {e}"))),
            _ => Ok(None),
        }
    };
    if let Some(frames) = integer(tags::NUMBER_OF_FRAMES, "Number of Frames")? {
        if frames != 1 {
            return Err(at(format!(
                "{frames} frames in one file; specula reads series of single-frame slices"
            )));
        }
    }
    if let Some(samples) = integer(tags::SAMPLES_PER_PIXEL, "Samples per Pixel")? {
        if samples != 1 {
            return Err(at(format!(
                "{samples} samples per pixel (colour); specula reads greyscale slices"
            )));
        }
    }
    let side = |tag, name: &str| -> Result<usize, String> {
        integer(tag, name)?
            .and_then(|v| usize::try_from(v).ok())
            .filter(|&v| (2..=MAX_SIDE).contains(&v))
            .ok_or_else(|| at(format!("{name} must be 2 to {MAX_SIDE}")))
    };
    let position = numbers(tags::IMAGE_POSITION_PATIENT, "Image Position (Patient)", 3)?;
    let orientation = numbers(
        tags::IMAGE_ORIENTATION_PATIENT,
        "Image Orientation (Patient)",
        6,
    )?;
    let spacing = numbers(tags::PIXEL_SPACING, "Pixel Spacing", 2)?;
    if spacing.iter().any(|&s| s <= 0.0) {
        return Err(at("Pixel Spacing must be positive".into()));
    }
    let row = DVec3::new(orientation[0], orientation[1], orientation[2]);
    let column = DVec3::new(orientation[3], orientation[4], orientation[5]);
    if (row.length() - 1.0).abs() > 1e-3
        || (column.length() - 1.0).abs() > 1e-3
        || row.dot(column).abs() > 1e-3
    {
        return Err(at(
            "Image Orientation (Patient) must be two perpendicular unit vectors".into(),
        ));
    }
    Ok(Slice {
        path: path.to_owned(),
        series: text(tags::SERIES_INSTANCE_UID, "Series Instance UID")?.unwrap_or_default(),
        rows: side(tags::ROWS, "Rows")?,
        columns: side(tags::COLUMNS, "Columns")?,
        position: DVec3::new(position[0], position[1], position[2]),
        orientation: [row, column],
        pixel_spacing: [spacing[0], spacing[1]],
        modality: text(tags::MODALITY, "Modality")?.unwrap_or_default(),
    })
}

/// Checks that the slices are one evenly spaced series, sorts them along their normal, and
/// gives the grid and its placement (RAS millimetres).
fn geometry(slices: &mut [Slice]) -> Result<([usize; 3], Mat3, Vec3), String> {
    let first = &slices[0];
    let mut series: Vec<&str> = slices.iter().map(|s| s.series.as_str()).collect();
    series.sort_unstable();
    series.dedup();
    if series.len() > 1 {
        return Err(format!(
            "mixed series: {} Series Instance UIDs ({}); give a folder holding one series",
            series.len(),
            series.join(", ")
        ));
    }
    for slice in &slices[1..] {
        let same = slice.rows == first.rows
            && slice.columns == first.columns
            && (slice.pixel_spacing[0] - first.pixel_spacing[0]).abs() < 1e-6
            && (slice.pixel_spacing[1] - first.pixel_spacing[1]).abs() < 1e-6
            && (slice.orientation[0] - first.orientation[0]).length() < 1e-4
            && (slice.orientation[1] - first.orientation[1]).length() < 1e-4;
        if !same {
            return Err(format!(
                "{} differs from {} in size, pixel spacing or orientation; a series shares one geometry",
                slice.path.display(),
                first.path.display()
            ));
        }
    }
    let dims = [first.columns, first.rows, slices.len()];
    Volume::check_dims(dims).map_err(|e| e.0)?;
    let [row, column] = first.orientation;
    let [row_spacing, column_spacing] = first.pixel_spacing;
    let normal = row.cross(column);
    slices.sort_by(|a, b| a.position.dot(normal).total_cmp(&b.position.dot(normal)));
    let depths: Vec<f64> = slices.iter().map(|s| s.position.dot(normal)).collect();
    let gaps: Vec<f64> = depths.windows(2).map(|w| w[1] - w[0]).collect();
    let mean = (depths[depths.len() - 1] - depths[0]) / gaps.len() as f64;
    if gaps.iter().any(|&g| g < 1e-6) {
        return Err("two slices share one position; a series has one slice per position".into());
    }
    if gaps
        .iter()
        .any(|&g| (g - mean).abs() > GAP_TOLERANCE * mean)
    {
        let (lo, hi) = gaps.iter().fold((f64::INFINITY, 0.0_f64), |(lo, hi), &g| {
            (lo.min(g), hi.max(g))
        });
        return Err(format!(
            "uneven slice spacing ({lo:.3} to {hi:.3} mm); specula stacks evenly spaced slices"
        ));
    }
    let last = &slices[slices.len() - 1];
    let lps = DMat3::from_cols(
        row * column_spacing,
        column * row_spacing,
        (last.position - slices[0].position) / gaps.len() as f64,
    );
    let to_ras = DMat3::from_diagonal(LPS_TO_RAS);
    Ok((
        dims,
        (to_ras * lps).as_mat3(),
        (LPS_TO_RAS * slices[0].position).as_vec3(),
    ))
}

fn read_pixels(slice: &Slice, voxels: usize) -> Result<Vec<f32>, String> {
    let at = |what: String| format!("{}: {what}", slice.path.display());
    let object = input::open_regular(&slice.path)
        .and_then(|file| {
            OpenFileOptions::new()
                .from_reader(std::io::BufReader::new(file))
                .map_err(|e| e.to_string())
        })
        .map_err(|e| at(format!("not a readable DICOM file ({e})")))?;
    let pixels = object
        .decode_pixel_data()
        .and_then(|decoded| decoded.to_vec::<f32>())
        .map_err(|e| at(format!("pixel data: {e}")))?;
    if pixels.len() != voxels {
        return Err(at(format!(
            "{} pixels where Rows x Columns is {voxels}",
            pixels.len()
        )));
    }
    Ok(pixels)
}

/// Writes `volume` into the new (or empty) folder `dir` as a series of 16-bit slices, one per
/// `k`: CT with Hounsfield units as stored values when the volume is CT, otherwise MR with
/// Rescale Slope and Intercept spreading its range over the 16 bits. UIDs are derived from
/// the volume's contents, so the same volume gives the same files. The folder appears whole:
/// it is written beside its place and renamed into it.
pub fn write_series(volume: &Volume, dir: &Path) -> Result<(), VolumeError> {
    let fail = |what: String| VolumeError(format!("{}: {what}", dir.display()));
    if let Ok(meta) = std::fs::symlink_metadata(dir) {
        let empty = meta.is_dir()
            && std::fs::read_dir(dir)
                .map(|mut e| e.next().is_none())
                .unwrap_or(false);
        if !empty {
            return Err(fail(
                "exists and is not an empty folder; give a new folder for the series".into(),
            ));
        }
    }
    let to_world = volume.to_world();
    let (row, column) = (to_world.x_axis, to_world.y_axis);
    if row.normalize().dot(column.normalize()).abs() > 1e-4 {
        return Err(fail(
            "the grid's rows and columns are not perpendicular, which DICOM slices cannot say"
                .into(),
        ));
    }
    let parent = match dir.parent() {
        Some(parent) if !parent.as_os_str().is_empty() => parent.to_owned(),
        _ => PathBuf::from("."),
    };
    let staging = tempfile::Builder::new()
        .prefix(".specula-series-")
        .tempdir_in(&parent)
        .map_err(|e| fail(e.to_string()))?;
    // Registered, so that an interrupted run's signal handler removes it.
    register(staging.path(), true);
    let [nx, ny, nz] = volume.dims();
    let (lo, hi) = volume.range();
    let (slope, intercept, modality, class) = match volume.units() {
        Units::Hounsfield => (1.0, 0.0, "CT", uids::CT_IMAGE_STORAGE),
        Units::Arbitrary => (
            f64::from(hi - lo).max(f64::from(f32::MIN_POSITIVE)) / 65_000.0,
            0.5 * (f64::from(lo) + f64::from(hi)),
            "MR",
            uids::MR_IMAGE_STORAGE,
        ),
    };
    let study = uid(volume, 1);
    let series = uid(volume, 2);
    let frame = uid(volume, 3);
    let to_lps = |v: Vec3| LPS_TO_RAS * v.as_dvec3();
    let orientation = [to_lps(row.normalize()), to_lps(column.normalize())];
    let written: Result<(), String> = (0..nz).into_par_iter().try_for_each(|k| {
        let position = to_lps(volume.world(Vec3::new(0.0, 0.0, k as f32)));
        let stored: Vec<u16> = volume.samples()[k * nx * ny..(k + 1) * nx * ny]
            .iter()
            .map(|&v| {
                ((f64::from(v) - intercept) / slope)
                    .round()
                    .clamp(-32768.0, 32767.0) as i16 as u16
            })
            .collect();
        let instance = format!("{series}.{}", k + 1);
        let strings = |values: &[f64]| {
            values
                .iter()
                .map(|&v| decimal(v))
                .collect::<Vec<_>>()
                .join("\\")
        };
        let elements = [
            (tags::SOP_CLASS_UID, VR::UI, PrimitiveValue::from(class)),
            (tags::SOP_INSTANCE_UID, VR::UI, instance.as_str().into()),
            (tags::STUDY_INSTANCE_UID, VR::UI, study.as_str().into()),
            (tags::SERIES_INSTANCE_UID, VR::UI, series.as_str().into()),
            (tags::FRAME_OF_REFERENCE_UID, VR::UI, frame.as_str().into()),
            (tags::MODALITY, VR::CS, modality.into()),
            (tags::PATIENT_NAME, VR::PN, "specula^phantom".into()),
            (tags::PATIENT_ID, VR::LO, "specula".into()),
            (
                tags::SERIES_DESCRIPTION,
                VR::LO,
                "written by specula".into(),
            ),
            (tags::INSTANCE_NUMBER, VR::IS, (k + 1).to_string().into()),
            (
                tags::IMAGE_POSITION_PATIENT,
                VR::DS,
                strings(&position.to_array()).into(),
            ),
            (
                tags::IMAGE_ORIENTATION_PATIENT,
                VR::DS,
                strings(&[orientation[0].to_array(), orientation[1].to_array()].concat()).into(),
            ),
            (
                tags::PIXEL_SPACING,
                VR::DS,
                strings(&[f64::from(column.length()), f64::from(row.length())]).into(),
            ),
            (tags::SAMPLES_PER_PIXEL, VR::US, PrimitiveValue::from(1_u16)),
            (
                tags::PHOTOMETRIC_INTERPRETATION,
                VR::CS,
                "MONOCHROME2".into(),
            ),
            (tags::ROWS, VR::US, PrimitiveValue::from(ny as u16)),
            (tags::COLUMNS, VR::US, PrimitiveValue::from(nx as u16)),
            (tags::BITS_ALLOCATED, VR::US, PrimitiveValue::from(16_u16)),
            (tags::BITS_STORED, VR::US, PrimitiveValue::from(16_u16)),
            (tags::HIGH_BIT, VR::US, PrimitiveValue::from(15_u16)),
            (
                tags::PIXEL_REPRESENTATION,
                VR::US,
                PrimitiveValue::from(1_u16),
            ),
            (tags::RESCALE_INTERCEPT, VR::DS, decimal(intercept).into()),
            (tags::RESCALE_SLOPE, VR::DS, decimal(slope).into()),
            (tags::PIXEL_DATA, VR::OW, PrimitiveValue::U16(stored.into())),
        ];
        let object = InMemDicomObject::from_element_iter(
            elements
                .into_iter()
                .map(|(tag, vr, value)| DataElement::new(tag, vr, value)),
        )
        .with_meta(FileMetaTableBuilder::new().transfer_syntax(uids::EXPLICIT_VR_LITTLE_ENDIAN))
        .map_err(|e| e.to_string())?;
        write_slice(
            &object,
            &staging.path().join(format!("slice-{:04}.dcm", k + 1)),
        )
    });
    // rename(2) replaces an empty folder, so an existing empty target needs no removal.
    let staged = staging.keep();
    let result = written.and_then(|()| std::fs::rename(&staged, dir).map_err(|e| e.to_string()));
    if result.is_err() {
        let _ = std::fs::remove_dir_all(&staged);
    }
    register(&staged, false);
    result.map_err(fail)
}

fn write_slice(object: &DefaultDicomObject, path: &Path) -> Result<(), String> {
    object.write_to_file(path).map_err(|e| e.to_string())
}

/// A Decimal String value: at most 16 characters.
fn decimal(value: f64) -> String {
    let plain = format!("{}", value as f32);
    if plain.len() <= 16 {
        plain
    } else {
        format!("{:.8e}", value as f32)
    }
}

/// A UID under the `2.25` root (a decimal 128-bit number), from the volume's contents and
/// `salt`.
fn uid(volume: &Volume, salt: u64) -> String {
    let half = |seed: u64| {
        let mut hasher = std::hash::DefaultHasher::new();
        (seed, salt, volume.dims()).hash(&mut hasher);
        for v in volume.samples().iter().step_by(97) {
            v.to_bits().hash(&mut hasher);
        }
        hasher.finish()
    };
    let number = u128::from(half(0)) << 64 | u128::from(half(1));
    format!("2.25.{number}")
}
