//! A folder of single-frame slices, read header-first and stacked into one volume.

use std::path::{Path, PathBuf};

use dicom_dictionary_std::tags;
use dicom_object::OpenFileOptions;
use dicom_pixeldata::PixelDecoder;
use rayon::prelude::*;
use specula_render::input;

use super::{
    integer, numbers, orientation, pixel_spacing, says_hounsfield, side, stack, text, units, Plane,
};
use crate::volume::{Volume, VolumeError, MAX_SIDE};

/// What one slice's header says.
struct Slice {
    path: PathBuf,
    plane: Plane,
    series: String,
    /// Whether its Modality or Rescale Type says Hounsfield units.
    hounsfield: bool,
}

/// Reads the series in folder `dir`. Files without DICOM's `DICM` preamble (a README, a
/// `DICOMDIR`'s companions) and subfolders are passed over; a multi-frame object among the
/// slices is refused (it is read on its own, by [`super::read_file`]).
pub fn read_series(dir: &Path) -> Result<Volume, VolumeError> {
    let fail = |what: String| VolumeError(format!("{}: {what}", dir.display()));
    let files = series_files(dir).map_err(fail)?;
    let slices: Vec<Slice> = files
        .par_iter()
        .map(|path| read_header(path))
        .collect::<Result<_, _>>()
        .map_err(fail)?;
    let mut series: Vec<&str> = slices.iter().map(|s| s.series.as_str()).collect();
    series.sort_unstable();
    series.dedup();
    if series.len() > 1 {
        return Err(fail(format!(
            "mixed series: {} Series Instance UIDs ({}); give a folder holding one series",
            series.len(),
            series.join(", ")
        )));
    }
    let hounsfield = slices.iter().any(|s| s.hounsfield);
    let (slices, planes): (Vec<PathBuf>, Vec<Plane>) =
        slices.into_iter().map(|s| (s.path, s.plane)).unzip();
    let grid = stack(&planes, "a series").map_err(fail)?;
    let slice_voxels = grid.dims[0] * grid.dims[1];
    let planes: Vec<Vec<f32>> = grid
        .order
        .par_iter()
        .map(|&i| read_pixels(&slices[i], slice_voxels))
        .collect::<Result<_, _>>()
        .map_err(fail)?;
    Volume::try_new(
        grid.dims,
        grid.to_world,
        grid.origin,
        planes.concat(),
        units(hounsfield),
    )
    .map_err(|e| fail(e.0))
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
    if let Some(frames) =
        integer(&object, tags::NUMBER_OF_FRAMES, "Number of Frames").map_err(at)?
    {
        if frames != 1 {
            return Err(at(format!(
                "a multi-frame object ({frames} frames) in a series folder, where each file is one \
                    slice; pass the file itself (--input {}) to read its frames as a volume",
                path.display()
            )));
        }
    }
    if let Some(samples) =
        integer(&object, tags::SAMPLES_PER_PIXEL, "Samples per Pixel").map_err(at)?
    {
        if samples != 1 {
            return Err(at(format!(
                "{samples} samples per pixel (colour); specula reads greyscale slices"
            )));
        }
    }
    let required = |tag, name: &str, count| {
        numbers(&object, tag, name, count)
            .map_err(at)?
            .ok_or_else(|| {
                at(format!(
                    "no {name}; specula needs each slice's {name} to place it in the volume"
                ))
            })
    };
    let position = required(tags::IMAGE_POSITION_PATIENT, "Image Position (Patient)", 3)?;
    let cosines = required(
        tags::IMAGE_ORIENTATION_PATIENT,
        "Image Orientation (Patient)",
        6,
    )?;
    let spacing = required(tags::PIXEL_SPACING, "Pixel Spacing", 2)?;
    let modality = text(&object, tags::MODALITY, "Modality").map_err(at)?;
    let rescale_type = text(&object, tags::RESCALE_TYPE, "Rescale Type").map_err(at)?;
    Ok(Slice {
        path: path.to_owned(),
        plane: Plane {
            name: path.display().to_string(),
            rows: side(&object, tags::ROWS, "Rows").map_err(at)?,
            columns: side(&object, tags::COLUMNS, "Columns").map_err(at)?,
            position: glam::DVec3::from_slice(&position),
            orientation: orientation(&cosines).map_err(at)?,
            pixel_spacing: pixel_spacing(&spacing).map_err(at)?,
        },
        series: text(&object, tags::SERIES_INSTANCE_UID, "Series Instance UID")
            .map_err(at)?
            .unwrap_or_default(),
        hounsfield: says_hounsfield(modality.as_deref(), rescale_type.as_deref()),
    })
}

fn read_pixels(path: &Path, voxels: usize) -> Result<Vec<f32>, String> {
    let at = |what: String| format!("{}: {what}", path.display());
    let object = input::open_regular(path)
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
