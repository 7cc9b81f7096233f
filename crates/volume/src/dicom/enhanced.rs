//! One multi-frame object (Enhanced CT or MR Image Storage, or any object with more than one
//! frame) holding a volume's slices as its frames, placed by its functional groups.

use std::path::Path;

use dicom_core::Tag;
use dicom_dictionary_std::tags;
use dicom_object::{InMemDicomObject, OpenFileOptions};
use dicom_pixeldata::{ConvertOptions, ModalityLutOption, PixelDecoder, Rescale};
use rayon::prelude::*;
use specula_render::input;

use super::{
    integer, numbers, orientation, pixel_spacing, says_hounsfield, side, stack, text, units, Plane,
    GAP_TOLERANCE,
};
use crate::volume::{Volume, VolumeError, MAX_SIDE};

/// What the header says about the frames.
struct Frames {
    rows: usize,
    columns: usize,
    bytes_per_sample: usize,
    /// One per frame, in the file's order, named `frame N` (from 1, as DICOM counts).
    planes: Vec<Plane>,
    /// Each frame's Rescale Slope and Intercept.
    rescales: Vec<Rescale>,
    /// The first frame's Spacing Between Slices, to check against the positions.
    spacing_between_slices: Option<f64>,
    hounsfield: bool,
}

/// Reads the multi-frame object in the file `path` as a volume, one frame per slice. A
/// single-frame file is refused (its series is read from its folder by
/// [`super::read_series`]), as is a multi-frame object whose frames have no positions of
/// their own (the Plane Position Sequence of the Per-Frame Functional Groups).
pub fn read_file(path: &Path) -> Result<Volume, VolumeError> {
    let fail = |what: String| VolumeError(format!("{}: {what}", path.display()));
    let object = input::open_regular(path)
        .and_then(|file| {
            OpenFileOptions::new()
                .from_reader(std::io::BufReader::new(file))
                .map_err(|e| format!("not a readable DICOM file ({e})"))
        })
        .map_err(fail)?;
    let header = read_header(&object).map_err(fail)?;
    let grid = stack(&header.planes, "a multi-frame object").map_err(fail)?;
    if let Some(stated) = header.spacing_between_slices {
        if (stated.abs() - grid.gap).abs() > GAP_TOLERANCE * grid.gap {
            return Err(fail(format!(
                "Spacing Between Slices says {stated} mm but the frames' positions are {:.3} mm \
                    apart along the slice normal; specula does not guess which is right",
                grid.gap
            )));
        }
    }
    let frames = header.planes.len();
    let frame_voxels = header.rows * header.columns;
    let bytes = (frame_voxels * frames * header.bytes_per_sample) as u64;
    let limit = input::max_input_bytes();
    if bytes > limit {
        return Err(fail(format!(
            "{frames} frames of {} x {} pixels decode to {bytes} bytes, above the input limit of \
                {limit} bytes ({} MiB; raise it with --max-input-mib)",
            header.rows,
            header.columns,
            limit >> 20
        )));
    }
    let decoded = object
        .decode_pixel_data()
        .map_err(|e| fail(format!("pixel data: {e}")))?;
    if decoded.data().len() as u64 != bytes || decoded.number_of_frames() as usize != frames {
        return Err(fail(format!(
            "the pixel data decodes to {} bytes in {} frames where Rows x Columns x Number of \
                Frames x {} bytes is {bytes}",
            decoded.data().len(),
            decoded.number_of_frames(),
            header.bytes_per_sample
        )));
    }
    let planes: Vec<Vec<f32>> = grid
        .order
        .par_iter()
        .map(|&frame| {
            let options = ConvertOptions::new()
                .with_modality_lut(ModalityLutOption::Override(header.rescales[frame]));
            let pixels = decoded
                .to_vec_frame_with_options::<f32>(frame as u32, &options)
                .map_err(|e| fail(format!("pixel data of frame {}: {e}", frame + 1)))?;
            if pixels.len() == frame_voxels {
                Ok(pixels)
            } else {
                Err(fail(format!(
                    "frame {} decodes to {} pixels where Rows x Columns is {frame_voxels}",
                    frame + 1,
                    pixels.len()
                )))
            }
        })
        .collect::<Result<_, _>>()?;
    Volume::try_new(
        grid.dims,
        grid.to_world,
        grid.origin,
        planes.concat(),
        units(header.hounsfield),
    )
    .map_err(|e| fail(e.0))
}

/// The first item of `object`'s sequence `tag`, when there is one.
fn item(object: &InMemDicomObject, tag: Tag) -> Option<&InMemDicomObject> {
    object
        .element_opt(tag)
        .ok()
        .flatten()
        .and_then(|element| element.items())
        .and_then(<[InMemDicomObject]>::first)
}

fn read_header(object: &InMemDicomObject) -> Result<Frames, String> {
    let frames = match integer(object, tags::NUMBER_OF_FRAMES, "Number of Frames")? {
        None | Some(1) => {
            return Err(
                "a single-frame DICOM image (one slice); give the folder holding its series, or a \
                    multi-frame object"
                    .into(),
            )
        }
        Some(frames) => usize::try_from(frames)
            .ok()
            .filter(|&f| (2..=MAX_SIDE).contains(&f))
            .ok_or_else(|| {
                format!("Number of Frames is {frames}; a multi-frame volume has 2 to {MAX_SIDE}")
            })?,
    };
    if let Some(samples) = integer(object, tags::SAMPLES_PER_PIXEL, "Samples per Pixel")? {
        if samples != 1 {
            return Err(format!(
                "{samples} samples per pixel (colour); specula reads greyscale frames"
            ));
        }
    }
    if let Some(photometric) = text(
        object,
        tags::PHOTOMETRIC_INTERPRETATION,
        "Photometric Interpretation",
    )? {
        if !photometric.starts_with("MONOCHROME") {
            return Err(format!(
                "Photometric Interpretation {photometric}; specula reads MONOCHROME1 or \
                    MONOCHROME2 frames"
            ));
        }
    }
    let bytes_per_sample = match integer(object, tags::BITS_ALLOCATED, "Bits Allocated")? {
        Some(8) => 1,
        Some(16) => 2,
        other => {
            let said = other.map_or_else(|| "missing".to_owned(), |bits| bits.to_string());
            return Err(format!(
                "Bits Allocated is {said}; specula reads 8- or 16-bit samples"
            ));
        }
    };
    let rows = side(object, tags::ROWS, "Rows")?;
    let columns = side(object, tags::COLUMNS, "Columns")?;
    let shared = item(object, tags::SHARED_FUNCTIONAL_GROUPS_SEQUENCE);
    let per_frame = object
        .element_opt(tags::PER_FRAME_FUNCTIONAL_GROUPS_SEQUENCE)
        .ok()
        .flatten()
        .and_then(|element| element.items())
        .unwrap_or(&[]);
    if per_frame.is_empty() {
        return Err(format!(
            "{frames} frames without per-frame geometry: no Per-Frame Functional Groups Sequence \
                (5200,9230) giving each frame's Plane Position Sequence (0020,9113) > Image \
                Position (Patient); specula needs every frame's position, with Plane Orientation \
                (0020,9116) and Pixel Measures (0028,9110) per frame or shared, to stack the \
                frames into a volume"
        ));
    }
    if per_frame.len() != frames {
        return Err(format!(
            "the Per-Frame Functional Groups Sequence has {} items for {frames} frames; it needs \
                one per frame",
            per_frame.len()
        ));
    }
    let modality = text(object, tags::MODALITY, "Modality")?;
    let top_type = text(object, tags::RESCALE_TYPE, "Rescale Type")?;
    let mut hounsfield = says_hounsfield(modality.as_deref(), top_type.as_deref());
    let mut planes = Vec::with_capacity(frames);
    let mut rescales = Vec::with_capacity(frames);
    let mut spacing_between_slices = None;
    for (index, own) in per_frame.iter().enumerate() {
        let name = format!("frame {}", index + 1);
        let at = |what: String| format!("{name}: {what}");
        // A functional group: the frame's own, else the shared one.
        let group = |tag| item(own, tag).or_else(|| shared.and_then(|s| item(s, tag)));
        let lacking = |what: &str| {
            format!(
                "{name} lacks per-frame geometry: no {what}; specula needs each frame's Image \
                    Position (Patient), Image Orientation (Patient) and Pixel Spacing to stack the \
                    frames into a volume"
            )
        };
        let position = item(own, tags::PLANE_POSITION_SEQUENCE)
            .map(|g| {
                numbers(
                    g,
                    tags::IMAGE_POSITION_PATIENT,
                    "Image Position (Patient)",
                    3,
                )
            })
            .transpose()
            .map_err(at)?
            .flatten()
            .ok_or_else(|| {
                lacking(
                    "Plane Position Sequence (0020,9113) > Image Position (Patient) in its \
                    Per-Frame Functional Groups",
                )
            })?;
        let cosines = group(tags::PLANE_ORIENTATION_SEQUENCE)
            .map(|g| {
                numbers(
                    g,
                    tags::IMAGE_ORIENTATION_PATIENT,
                    "Image Orientation (Patient)",
                    6,
                )
            })
            .transpose()
            .map_err(at)?
            .flatten()
            .ok_or_else(|| {
                lacking(
                    "Plane Orientation Sequence (0020,9116) > Image Orientation (Patient), per \
                    frame or shared",
                )
            })?;
        let measures = group(tags::PIXEL_MEASURES_SEQUENCE);
        let spacing = measures
            .map(|g| numbers(g, tags::PIXEL_SPACING, "Pixel Spacing", 2))
            .transpose()
            .map_err(at)?
            .flatten()
            .ok_or_else(|| {
                lacking("Pixel Measures Sequence (0028,9110) > Pixel Spacing, per frame or shared")
            })?;
        if index == 0 {
            let stated = |o| numbers(o, tags::SPACING_BETWEEN_SLICES, "Spacing Between Slices", 1);
            spacing_between_slices = match measures.map(stated).transpose().map_err(at)?.flatten() {
                Some(values) => Some(values[0]),
                None => stated(object)?.map(|values| values[0]),
            };
        }
        // Rescale from the frame's Pixel Value Transformation, else the top level, else none.
        let transform = group(tags::PIXEL_VALUE_TRANSFORMATION_SEQUENCE);
        let rescale_value = |tag, name: &str, default: f64| -> Result<f64, String> {
            let from = |o| numbers(o, tag, name, 1).map_err(at);
            let found = match transform.map(from).transpose()?.flatten() {
                Some(values) => Some(values),
                None => from(object)?,
            };
            Ok(found.map_or(default, |values| values[0]))
        };
        rescales.push(Rescale::new(
            rescale_value(tags::RESCALE_SLOPE, "Rescale Slope", 1.0)?,
            rescale_value(tags::RESCALE_INTERCEPT, "Rescale Intercept", 0.0)?,
        ));
        if let Some(group) = transform {
            let kind = text(group, tags::RESCALE_TYPE, "Rescale Type").map_err(at)?;
            hounsfield |= says_hounsfield(None, kind.as_deref());
        }
        planes.push(Plane {
            rows,
            columns,
            position: glam::DVec3::from_slice(&position),
            orientation: orientation(&cosines).map_err(at)?,
            pixel_spacing: pixel_spacing(&spacing).map_err(at)?,
            name,
        });
    }
    Ok(Frames {
        rows,
        columns,
        bytes_per_sample,
        planes,
        rescales,
        spacing_between_slices,
        hounsfield,
    })
}
