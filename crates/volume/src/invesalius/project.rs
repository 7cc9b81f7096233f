//! `main.plist`: the project's voxel file, element type, shape, spacing and modality, checked.

use std::io::{Cursor, Read};

use plist::Value;

use super::archive::{base_name, damaged};
use super::MAX_PLIST_BYTES;
use crate::volume::{Units, Volume};

/// A voxel file's element type (numpy's names).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Dtype {
    I8,
    U8,
    I16,
    U16,
    I32,
    U32,
    F32,
    F64,
}

impl Dtype {
    const ALL: [(&'static str, Dtype); 8] = [
        ("int8", Dtype::I8),
        ("uint8", Dtype::U8),
        ("int16", Dtype::I16),
        ("uint16", Dtype::U16),
        ("int32", Dtype::I32),
        ("uint32", Dtype::U32),
        ("float32", Dtype::F32),
        ("float64", Dtype::F64),
    ];

    fn parse(name: &str) -> Option<Self> {
        Self::ALL
            .iter()
            .find(|(id, _)| *id == name)
            .map(|&(_, dtype)| dtype)
    }

    fn name(self) -> &'static str {
        Self::ALL
            .iter()
            .find(|(_, dtype)| *dtype == self)
            .map_or("?", |(id, _)| id)
    }

    pub(super) fn bytes(self) -> usize {
        match self {
            Dtype::I8 | Dtype::U8 => 1,
            Dtype::I16 | Dtype::U16 => 2,
            Dtype::I32 | Dtype::U32 | Dtype::F32 => 4,
            Dtype::F64 => 8,
        }
    }

    /// One little-endian element (`bytes.len() == self.bytes()`) as `f32`.
    pub(super) fn value(self, bytes: &[u8]) -> f32 {
        let mut word = [0_u8; 8];
        word[..bytes.len()].copy_from_slice(bytes);
        let [a, b, c, d, ..] = word;
        match self {
            Dtype::I8 => f32::from(a as i8),
            Dtype::U8 => f32::from(a),
            Dtype::I16 => f32::from(i16::from_le_bytes([a, b])),
            Dtype::U16 => f32::from(u16::from_le_bytes([a, b])),
            Dtype::I32 => i32::from_le_bytes([a, b, c, d]) as f32,
            Dtype::U32 => u32::from_le_bytes([a, b, c, d]) as f32,
            Dtype::F32 => f32::from_le_bytes([a, b, c, d]),
            Dtype::F64 => f64::from_le_bytes(word) as f32,
        }
    }
}

/// What `main.plist` says, checked.
#[derive(Clone, Debug)]
pub(super) struct Project {
    /// Where `main.plist` is in the archive.
    pub(super) plist_name: String,
    /// Where the voxel file is in the archive: `main.plist`'s folder and `matrix.filename`.
    pub(super) matrix_name: String,
    /// Columns, rows, slices.
    pub(super) dims: [usize; 3],
    pub(super) dtype: Dtype,
    /// The voxel file's size: `dims` x the element size, within the input limit.
    bytes: u64,
    /// Between columns, rows and slices, in millimetres.
    pub(super) spacing: [f32; 3],
    /// As `modality` says, or `None` when it says nothing.
    pub(super) units: Option<Units>,
}

impl Project {
    /// Reads and checks the `main.plist` entry `name` of `size` bytes.
    pub(super) fn read(
        name: &str,
        size: u64,
        data: &mut dyn Read,
        limit: u64,
    ) -> Result<Self, String> {
        if size > MAX_PLIST_BYTES {
            return Err(format!(
                "{name} is {size} bytes; a project's main.plist is at most {MAX_PLIST_BYTES}"
            ));
        }
        let mut text = Vec::with_capacity(size as usize);
        data.read_to_end(&mut text).map_err(damaged)?;
        Self::parse(name, &text, limit).map_err(|problem| format!("{name}: {problem}"))
    }

    fn parse(name: &str, text: &[u8], limit: u64) -> Result<Self, String> {
        let value = Value::from_reader(Cursor::new(text))
            .map_err(|e| format!("not a property list ({})", e.to_string().replace('\n', " ")))?;
        let root = value
            .as_dictionary()
            .ok_or("the property list is not a dictionary")?;
        let matrix = root
            .get("matrix")
            .and_then(Value::as_dictionary)
            .ok_or("no `matrix` dictionary (the voxel file's name, dtype and shape)")?;

        let filename = matrix
            .get("filename")
            .and_then(Value::as_string)
            .ok_or("matrix.filename is missing or not a string")?;
        if filename.is_empty() || filename.contains(['/', '\\', '\0']) || filename == ".." {
            return Err(format!(
                "matrix.filename `{}` is not a file name beside main.plist",
                specula::excerpt(filename)
            ));
        }
        let folder = &name[..name.len() - base_name(name).len()];

        let dtype_name = matrix
            .get("dtype")
            .and_then(Value::as_string)
            .ok_or("matrix.dtype is missing or not a string")?;
        let dtype = Dtype::parse(dtype_name).ok_or_else(|| {
            format!(
                "matrix.dtype `{}`: specula reads {}",
                specula::excerpt(dtype_name),
                Dtype::ALL.map(|(id, _)| id).join(", ")
            )
        })?;

        let shape = matrix
            .get("shape")
            .and_then(Value::as_array)
            .ok_or("matrix.shape is missing or not an array")?;
        let sides: Vec<usize> = shape
            .iter()
            .map(
                |side| match (side.as_signed_integer(), side.as_unsigned_integer()) {
                    (Some(n), _) if n < 0 => Err(format!(
                        "matrix.shape holds {n}; the sides must be positive"
                    )),
                    (Some(n), _) => Ok(usize::try_from(n).unwrap_or(usize::MAX)),
                    (None, Some(_)) => Ok(usize::MAX),
                    (None, None) => Err("matrix.shape holds something other than integers".into()),
                },
            )
            .collect::<Result<_, String>>()?;
        let &[z, y, x] = sides.as_slice() else {
            return Err(format!(
                "matrix.shape has {} sides; a volume has three (slices, rows, columns)",
                sides.len()
            ));
        };
        let dims = [x, y, z];
        let voxels = Volume::check_dims(dims)
            .map_err(|e| format!("matrix.shape [z, y, x] = [{z}, {y}, {x}]: {e}"))?;
        let bytes = voxels as u64 * dtype.bytes() as u64;
        if bytes > limit {
            return Err(format!(
                "the voxels ({x} x {y} x {z} {}) take {bytes} bytes, above the input limit of \
                    {limit} bytes ({} MiB; raise it with --max-input-mib)",
                dtype.name(),
                limit >> 20
            ));
        }

        let spacing = root
            .get("spacing")
            .and_then(Value::as_array)
            .ok_or("`spacing` is missing or not an array")?;
        let spacing: Vec<f64> = spacing
            .iter()
            .map(|s| {
                s.as_real()
                    .or_else(|| s.as_signed_integer().map(|n| n as f64))
                    .ok_or("`spacing` holds something other than numbers")
            })
            .collect::<Result<_, _>>()?;
        let &[sx, sy, sz] = spacing.as_slice() else {
            return Err(format!(
                "`spacing` has {} values; a volume has three (columns, rows, slices)",
                spacing.len()
            ));
        };
        if [sx, sy, sz]
            .iter()
            .any(|&s| !(s.is_finite() && s > 0.0 && s < 1e6))
        {
            return Err(format!(
                "`spacing` is {sx}, {sy}, {sz} mm; every spacing must be positive and finite"
            ));
        }

        match root.get("orientation") {
            None => {}
            Some(Value::Integer(n)) if n.as_signed() == Some(1) => {}
            Some(Value::String(s)) if s.trim().eq_ignore_ascii_case("axial") => {}
            Some(other) => {
                let said = match other {
                    Value::Integer(n) => match n.as_signed() {
                        Some(2) => "2 (coronal)".to_owned(),
                        Some(3) => "3 (sagittal)".to_owned(),
                        _ => n.to_string(),
                    },
                    Value::String(s) => specula::excerpt(s).to_string(),
                    _ => "not a number or a name".to_owned(),
                };
                return Err(format!(
                    "orientation {said}: specula reads axial projects (orientation 1 or AXIAL), \
                        whose placement it knows"
                ));
            }
        }

        let units = match root.get("modality").and_then(Value::as_string) {
            Some(modality) if modality.trim().eq_ignore_ascii_case("ct") => Some(Units::Hounsfield),
            Some(modality) if !modality.trim().is_empty() => Some(Units::Arbitrary),
            _ => None,
        };

        Ok(Self {
            plist_name: name.to_owned(),
            matrix_name: format!("{folder}{filename}"),
            dims,
            dtype,
            bytes,
            spacing: [sx as f32, sy as f32, sz as f32],
            units,
        })
    }

    /// Reads the voxel file (an entry of `size` bytes), once its size is the one declared.
    pub(super) fn read_matrix(&self, size: u64, data: &mut dyn Read) -> Result<Vec<u8>, String> {
        let [x, y, z] = self.dims;
        if size != self.bytes {
            return Err(format!(
                "{} holds {size} bytes; main.plist's {x} x {y} x {z} {} grid needs {}",
                self.matrix_name,
                self.dtype.name(),
                self.bytes
            ));
        }
        let mut raw = vec![0_u8; self.bytes as usize];
        data.read_exact(&mut raw).map_err(damaged)?;
        Ok(raw)
    }
}
