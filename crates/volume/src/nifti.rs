//! NIfTI-1 volumes (`.nii`, `.nii.gz`), read and written with the `nifti` crate.
//!
//! The voxel-to-world map follows the standard's precedence: the `sform` when its code is
//! set, else the `qform` (a quaternion, `pixdim` and an offset), else the `pixdim` spacing
//! alone. World space is NIfTI's own RAS, which is [`Volume`]'s. Samples are scaled by
//! `scl_slope` and `scl_inter` (a zero slope means unscaled, as the standard says).
//!
//! Everything the header declares is checked before the voxels are read: a single-file
//! NIfTI-1 (magic `n+1`), one 3-D volume, a grid within [`Volume::check_dims`], a scalar data
//! type, positive spacing, and data no larger than the input limit (for `.nii.gz`, the
//! inflated size) and, for `.nii`, present in the file.

use std::io::Read;
use std::path::Path;

use glam::{Mat3, Vec3};
use nifti::{IntoNdArray, NiftiHeader, NiftiObject, NiftiType, ReaderOptions, Unit};
use specula_render::{input, write_atomically};

use crate::samples::Samples;
use crate::volume::{Units, Volume, VolumeError};

/// Reads a `.nii` or `.nii.gz` file.
pub fn read(path: &Path) -> Result<Volume, VolumeError> {
    let fail = |what: String| VolumeError(format!("{}: {what}", path.display()));
    let file = input::open_regular(path).map_err(fail)?;
    let file_bytes = file.metadata().map_err(|e| fail(e.to_string()))?.len();
    let gz = is_gz(path);
    let header = if gz {
        NiftiHeader::from_reader(flate2_reader(file))
    } else {
        NiftiHeader::from_reader(std::io::BufReader::new(file))
    }
    .map_err(|e| fail(format!("not a NIfTI-1 header ({e})")))?;
    let dims = check_header(&header, gz, file_bytes).map_err(fail)?;
    let (to_world, origin) = placement(&header).map_err(fail)?;
    let object = ReaderOptions::new()
        .read_file(path)
        .map_err(|e| fail(read_error(&e)))?;
    // Integers of at most 16 bits, unscaled (a CT as scanners store it), are read as the
    // `i16` they are; anything else as `f32` (whole numbers then still held as `i16`).
    let integers = matches!(
        header.data_type(),
        Ok(NiftiType::Int16 | NiftiType::Int8 | NiftiType::Uint8)
    ) && (header.scl_slope == 0.0 || header.scl_slope == 1.0)
        && header.scl_inter == 0.0;
    let samples = if integers {
        Samples::whole(voxels_in_file_order::<i16>(object).map_err(fail)?)
    } else {
        Samples::new(voxels_in_file_order::<f32>(object).map_err(fail)?)
    };
    let units = stated_units(&header).unwrap_or_else(|| Units::from_values(&samples));
    Volume::from_samples(dims, to_world, origin, samples, units).map_err(|e| fail(e.0))
}

/// The file's voxels as `T`, `i` fastest.
fn voxels_in_file_order<T: nifti::DataElement + Clone>(
    object: nifti::InMemNiftiObject,
) -> Result<Vec<T>, String> {
    let array = object
        .into_volume()
        .into_ndarray::<T>()
        .map_err(|e| read_error(&e))?;
    // The array is indexed `[i, j, k]`; its transpose, read in logical order, runs `i` fastest.
    // NIfTI stores `i` fastest, so the transpose is usually the array's own memory, taken
    // without a copy (a clinical CT's 450 MB copy was a tenth of its first image).
    let transposed = array.reversed_axes();
    let count = transposed.len();
    Ok(if transposed.is_standard_layout() {
        match transposed.into_raw_vec_and_offset() {
            (samples, None | Some(0)) if samples.len() == count => samples,
            (samples, offset) => {
                let start = offset.unwrap_or(0);
                samples[start..start + count].to_vec()
            }
        }
    } else {
        transposed.iter().cloned().collect()
    })
}

/// What the header says the values are: Hounsfield units when its description or intent
/// name says so ("Hounsfield", or "HU" as a word, as converters write it). NIfTI-1 has no
/// field for value units, so a header that says nothing leaves it to
/// [`Units::from_values`].
fn stated_units(header: &NiftiHeader) -> Option<Units> {
    let text = |bytes: &[u8]| {
        String::from_utf8_lossy(bytes)
            .trim_end_matches('\0')
            .to_ascii_lowercase()
    };
    let said = [text(&header.descrip), text(&header.intent_name)];
    said.iter()
        .any(|s| {
            s.contains("hounsfield")
                || s.split(|c: char| !c.is_ascii_alphanumeric())
                    .any(|word| word == "hu")
        })
        .then_some(Units::Hounsfield)
}

/// Whether `path` names a NIfTI file by its extension.
#[must_use]
pub fn is_nifti_path(path: &Path) -> bool {
    let name = path.to_string_lossy().to_ascii_lowercase();
    name.ends_with(".nii") || name.ends_with(".nii.gz")
}

fn is_gz(path: &Path) -> bool {
    path.to_string_lossy().to_ascii_lowercase().ends_with(".gz")
}

fn flate2_reader(file: std::fs::File) -> impl Read {
    flate2::read::GzDecoder::new(std::io::BufReader::new(file))
}

fn read_error(error: &nifti::NiftiError) -> String {
    match error {
        nifti::NiftiError::IncompatibleLength(got, expected) => format!(
            "truncated: the header declares {expected} bytes of voxels, the file holds {got}"
        ),
        other => other.to_string(),
    }
}

/// The grid's size, once the header has passed every check that needs no voxel.
fn check_header(header: &NiftiHeader, gz: bool, file_bytes: u64) -> Result<[usize; 3], String> {
    if &header.magic != nifti::header::MAGIC_CODE_NIP1 {
        return Err(
            "a header without its voxels (an .hdr/.img pair); give a single-file .nii or .nii.gz"
                .into(),
        );
    }
    let rank = usize::from(header.dim[0]);
    if !(3..=7).contains(&rank) {
        return Err(format!(
            "a {rank}-dimensional image; specula renders 3-D volumes"
        ));
    }
    let extra: usize = header.dim[4..=rank]
        .iter()
        .map(|&d| usize::from(d.max(1)))
        .product();
    if extra > 1 {
        return Err(format!(
            "{extra} volumes in one file (a time series); specula renders one 3-D volume, so \
                extract one first"
        ));
    }
    let dims = [
        usize::from(header.dim[1]),
        usize::from(header.dim[2]),
        usize::from(header.dim[3]),
    ];
    let voxels = Volume::check_dims(dims).map_err(|e| e.0)?;
    let datatype = header
        .data_type()
        .map_err(|_| format!("unknown data type code {}", header.datatype))?;
    let bytes_per_voxel = match datatype {
        NiftiType::Uint8 | NiftiType::Int8 => 1,
        NiftiType::Int16 | NiftiType::Uint16 => 2,
        NiftiType::Int32 | NiftiType::Uint32 | NiftiType::Float32 => 4,
        NiftiType::Int64 | NiftiType::Uint64 | NiftiType::Float64 => 8,
        other => {
            return Err(format!(
                "voxels of type {other:?}; specula reads scalar volumes (8- to 64-bit integers, \
                    32- or 64-bit floats)"
            ))
        }
    };
    let data_bytes = voxels as u64 * bytes_per_voxel;
    let limit = input::max_input_bytes();
    if data_bytes > limit {
        return Err(format!(
            "the voxels take {data_bytes} bytes, above the input limit of {limit} bytes ({} MiB; \
                raise it with --max-input-mib)",
            limit >> 20
        ));
    }
    let offset = header.vox_offset.max(352.0);
    if !offset.is_finite() || offset > 1e9 {
        return Err(format!(
            "voxel offset {} is out of range",
            header.vox_offset
        ));
    }
    if !gz && file_bytes < offset as u64 + data_bytes {
        return Err(format!(
            "truncated: the header declares {data_bytes} bytes of voxels from byte {offset}, the \
                file has {file_bytes} bytes"
        ));
    }
    if !(header.scl_slope.is_finite() && header.scl_inter.is_finite()) {
        return Err("the value scaling (scl_slope, scl_inter) is not finite".into());
    }
    Ok(dims)
}

/// Millimetres per unit of the header's spatial unit.
fn millimetres(header: &NiftiHeader) -> f32 {
    match header.xyzt_to_space() {
        Ok(Unit::Meter) => 1000.0,
        Ok(Unit::Micron) => 0.001,
        // Unknown units are millimetres by the convention every reader follows.
        _ => 1.0,
    }
}

/// The voxel-to-world map: linear part and origin, in millimetres.
fn placement(header: &NiftiHeader) -> Result<(Mat3, Vec3), String> {
    let scale = millimetres(header);
    if header.sform_code > 0 {
        let [x, y, z] = [header.srow_x, header.srow_y, header.srow_z];
        let linear = Mat3::from_cols(
            Vec3::new(x[0], y[0], z[0]),
            Vec3::new(x[1], y[1], z[1]),
            Vec3::new(x[2], y[2], z[2]),
        ) * scale;
        return Ok((linear, Vec3::new(x[3], y[3], z[3]) * scale));
    }
    let spacing = Vec3::new(header.pixdim[1], header.pixdim[2], header.pixdim[3]);
    if !(spacing.is_finite() && spacing.min_element() > 0.0) {
        return Err(format!(
            "no voxel spacing: pixdim is {}, {}, {} and there is no sform; every spacing must be \
                positive",
            spacing.x, spacing.y, spacing.z
        ));
    }
    if header.qform_code > 0 {
        let (b, c, d) = (header.quatern_b, header.quatern_c, header.quatern_d);
        let a = (1.0 - (b * b + c * c + d * d)).max(0.0).sqrt();
        let rotation = Mat3::from_cols(
            Vec3::new(
                a * a + b * b - c * c - d * d,
                2.0 * (b * c + a * d),
                2.0 * (b * d - a * c),
            ),
            Vec3::new(
                2.0 * (b * c - a * d),
                a * a + c * c - b * b - d * d,
                2.0 * (c * d + a * b),
            ),
            Vec3::new(
                2.0 * (b * d + a * c),
                2.0 * (c * d - a * b),
                a * a + d * d - b * b - c * c,
            ),
        );
        // pixdim[0] is the handedness: -1 flips the third axis.
        let qfac = if header.pixdim[0] < 0.0 { -1.0 } else { 1.0 };
        let linear = rotation * Mat3::from_diagonal(spacing * Vec3::new(1.0, 1.0, qfac));
        let offset = Vec3::new(header.quatern_x, header.quatern_y, header.quatern_z);
        return Ok((linear * scale, offset * scale));
    }
    Ok((Mat3::from_diagonal(spacing * scale), Vec3::ZERO))
}

/// Writes `volume` as NIfTI-1 with its placement as the `sform` (code 2, aligned to an
/// anatomical frame), atomically; `.nii.gz` is compressed. The voxels are written in the
/// form the volume holds them ([`Samples`]): 16-bit integers when every sample is a whole
/// number in `i16`'s range (a CT in Hounsfield units, as scanners store it, and as a reader
/// such as VTK then takes it), 32-bit floats otherwise.
pub fn write(volume: &Volume, path: &Path) -> Result<(), VolumeError> {
    let fail = |what: String| VolumeError(format!("{}: {what}", path.display()));
    match volume.samples() {
        Samples::Whole(values) => write_values(volume, path, values),
        Samples::Float(values) => write_values(volume, path, values),
    }
    .map_err(fail)
}

/// [`write`] with `values`, the volume's samples as held.
fn write_values<A: nifti::DataElement + bytemuck::Pod>(
    volume: &Volume,
    path: &Path,
    values: &[A],
) -> Result<(), String> {
    let [nx, ny, nz] = volume.dims();
    let shape = ndarray::ShapeBuilder::f((nx, ny, nz));
    let array = ndarray::ArrayView3::from_shape(shape, values).map_err(|e| e.to_string())?;
    write_with(volume, path, |staged, header| {
        nifti::writer::WriterOptions::new(staged)
            .reference_header(header)
            .write_nifti(&array)
    })
}

/// [`write`] with the voxels written by `write_array` (to the staged file, with the header).
fn write_with(
    volume: &Volume,
    path: &Path,
    write_array: impl FnOnce(&Path, &NiftiHeader) -> nifti::Result<()>,
) -> Result<(), String> {
    let linear = volume.to_world();
    let origin = volume.origin();
    let row = |r: usize| {
        let m = linear.transpose();
        let axis = m.col(r);
        [axis.x, axis.y, axis.z, origin[r]]
    };
    let spacing = volume.spacing();
    // NIfTI's description is 80 bytes, zero-padded.
    let mut descrip = vec![0_u8; 80];
    if volume.units() == Units::Hounsfield {
        let said = b"Hounsfield units";
        descrip[..said.len()].copy_from_slice(said);
    }
    let header = NiftiHeader {
        descrip,
        pixdim: [1.0, spacing.x, spacing.y, spacing.z, 1.0, 1.0, 1.0, 1.0],
        sform_code: 2,
        srow_x: row(0),
        srow_y: row(1),
        srow_z: row(2),
        xyzt_units: 2,
        ..NiftiHeader::default()
    };
    let staging = specula_temporaries::dir("nifti-").map_err(|e| e.to_string())?;
    let name = if is_gz(path) {
        "volume.nii.gz"
    } else {
        "volume.nii"
    };
    let staged = staging.path().join(name);
    write_array(&staged, &header).map_err(|e| e.to_string())?;
    write_atomically(path, |writer| {
        let mut file = std::fs::File::open(&staged).map_err(|e| e.to_string())?;
        std::io::copy(&mut file, writer)
            .map(|_| ())
            .map_err(|e| e.to_string())
    })
    .map_err(|e| e.to_string())
}
