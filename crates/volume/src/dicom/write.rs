//! Writing a volume as a DICOM series of single-frame 16-bit slices.

use std::hash::{Hash, Hasher};
use std::path::{Path, PathBuf};

use dicom_core::{DataElement, PrimitiveValue, VR};
use dicom_dictionary_std::{tags, uids};
use dicom_object::{DefaultDicomObject, FileMetaTableBuilder, InMemDicomObject};
use glam::Vec3;
use rayon::prelude::*;

use super::LPS_TO_RAS;
use crate::volume::{Units, Volume, VolumeError};

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
    // Registered, so that an interrupted run's signal handler removes it.
    let staging =
        specula_temporaries::dir_in(&parent, "series-").map_err(|e| fail(e.to_string()))?;
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
        let samples = volume.samples();
        let stored: Vec<u16> = (k * nx * ny..(k + 1) * nx * ny)
            .map(|n| samples.get(n))
            .map(|v| {
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
    written
        .and_then(|()| staging.persist(dir).map_err(|e| e.to_string()))
        .map_err(fail)
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
