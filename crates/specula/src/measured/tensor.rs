//! The "tensor_file" container (Mitsuba's `TensorFile`): named, typed, shaped arrays.
//!
//! Layout, little-endian: the 12-byte magic `tensor_file\0`; the version (major `u8`, minor
//! `u8`; major must be 1); the field count (`u32`); then per field its name (`u16` length,
//! bytes), its rank (`u16`), its type (`u8`: 1 = `u8`, 10 = `f32`, the two a measured
//! material uses), the byte offset of its data (`u64`) and its shape (`u64` per axis). Every
//! declared size is checked against the bytes there are and against [`MAX_ELEMENTS`] before
//! anything is allocated, so a lying header costs nothing.

use core::fmt;

/// The magic bytes a tensor file starts with.
pub const MAGIC: &[u8; 12] = b"tensor_file\0";

/// The most elements one field may declare (a 4 x 32 x 3 x 128 x 128 RGB table is 6.3 M).
pub const MAX_ELEMENTS: u64 = 1 << 26;

/// The longest field name (Mitsuba's are a few characters).
pub const MAX_NAME_BYTES: usize = 64;

/// The most fields a file may declare (Mitsuba's measured files have about a dozen).
pub const MAX_FIELDS: u32 = 256;

/// Why bytes are not a tensor file.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct TensorError(pub String);

impl fmt::Display for TensorError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.0)
    }
}

impl std::error::Error for TensorError {}

fn error(message: impl Into<String>) -> TensorError {
    TensorError(message.into())
}

/// An element type.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum DType {
    /// Unsigned bytes (`description`, `jacobian`, `valid`).
    U8,
    /// 32-bit floats (every table).
    F32,
    /// Any other of the container's types, kept so that its size is known.
    Other {
        /// The type's code.
        code: u8,
        /// Bytes per element.
        size: u64,
    },
}

impl DType {
    fn from_code(code: u8) -> Result<Self, TensorError> {
        // Mitsuba's `Struct::Type` numbering: Int8..Float64 after Invalid = 0.
        Ok(match code {
            1 => DType::U8,
            10 => DType::F32,
            2 => DType::Other { code, size: 1 },
            3 | 4 | 9 => DType::Other { code, size: 2 },
            5 | 6 => DType::Other { code, size: 4 },
            7 | 8 | 11 => DType::Other { code, size: 8 },
            _ => {
                return Err(error(format!(
                    "unknown element type code {code} (valid: 1 to 11)"
                )))
            }
        })
    }

    fn size(self) -> u64 {
        match self {
            DType::U8 => 1,
            DType::F32 => 4,
            DType::Other { size, .. } => size,
        }
    }

    fn name(self) -> String {
        match self {
            DType::U8 => "u8".into(),
            DType::F32 => "f32".into(),
            DType::Other { code, .. } => format!("type {code}"),
        }
    }
}

/// One field's declaration; its data stays in the file's bytes until asked for.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Field {
    /// The field's name.
    pub name: String,
    /// Its element type.
    pub dtype: DType,
    /// Its shape, outermost axis first (the last is contiguous).
    pub shape: Vec<u64>,
    offset: u64,
}

impl Field {
    /// How many elements it holds.
    #[must_use]
    pub fn len(&self) -> u64 {
        self.shape.iter().product()
    }

    /// Whether it holds none.
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }
}

/// A tensor file's fields over its bytes.
#[derive(Debug)]
pub struct TensorFile<'a> {
    bytes: &'a [u8],
    fields: Vec<Field>,
}

struct Reader<'a> {
    bytes: &'a [u8],
    at: usize,
}

impl Reader<'_> {
    fn take(&mut self, count: usize, what: &str) -> Result<&[u8], TensorError> {
        let end = self
            .at
            .checked_add(count)
            .filter(|&end| end <= self.bytes.len());
        let Some(end) = end else {
            return Err(error(format!(
                "truncated: the header ends inside {what} (byte {} of {})",
                self.at,
                self.bytes.len()
            )));
        };
        let slice = &self.bytes[self.at..end];
        self.at = end;
        Ok(slice)
    }

    fn u16(&mut self, what: &str) -> Result<u16, TensorError> {
        let b = self.take(2, what)?;
        Ok(u16::from_le_bytes([b[0], b[1]]))
    }

    fn u32(&mut self, what: &str) -> Result<u32, TensorError> {
        let b = self.take(4, what)?;
        Ok(u32::from_le_bytes([b[0], b[1], b[2], b[3]]))
    }

    fn u64(&mut self, what: &str) -> Result<u64, TensorError> {
        let b = self.take(8, what)?;
        let mut word = [0; 8];
        word.copy_from_slice(b);
        Ok(u64::from_le_bytes(word))
    }
}

impl<'a> TensorFile<'a> {
    /// Reads the header of `bytes`, checking every field's extent against them.
    pub fn parse(bytes: &'a [u8]) -> Result<Self, TensorError> {
        if bytes.len() < MAGIC.len() || &bytes[..MAGIC.len()] != MAGIC {
            return Err(error(
                "not a tensor file: it does not start with the magic 'tensor_file\\0'",
            ));
        }
        let mut reader = Reader {
            bytes,
            at: MAGIC.len(),
        };
        let version = reader.take(2, "the version")?;
        if version[0] != 1 {
            return Err(error(format!(
                "tensor file version {}.{} is not supported (valid: 1.x)",
                version[0], version[1]
            )));
        }
        let count = reader.u32("the field count")?;
        if count > MAX_FIELDS {
            return Err(error(format!(
                "the header declares {count} fields (at most {MAX_FIELDS})"
            )));
        }
        let mut fields = Vec::new();
        let mut declared = 0u64;
        for index in 0..count {
            let what = format!("field {index}");
            let length = reader.u16(&what)?;
            let raw = reader.take(usize::from(length), &what)?;
            if raw.len() > MAX_NAME_BYTES || !raw.iter().all(|b| b.is_ascii_graphic()) {
                return Err(error(format!(
                    "field {index}'s name is not up to {MAX_NAME_BYTES} printable ASCII characters"
                )));
            }
            let name = String::from_utf8_lossy(raw).into_owned();
            let rank = reader.u16(&name)?;
            if rank > 8 {
                return Err(error(format!(
                    "field '{name}' declares rank {rank} (at most 8)"
                )));
            }
            let dtype = DType::from_code(reader.take(1, &name)?[0])
                .map_err(|e| error(format!("field '{name}': {e}")))?;
            let offset = reader.u64(&name)?;
            let shape = (0..rank)
                .map(|_| reader.u64(&name))
                .collect::<Result<Vec<_>, _>>()?;
            let elements = shape
                .iter()
                .try_fold(1u64, |product, &axis| product.checked_mul(axis))
                .filter(|&n| n <= MAX_ELEMENTS)
                .ok_or_else(|| {
                    error(format!(
                        "field '{name}' declares shape {shape:?}, over the limit of {MAX_ELEMENTS} \
                            elements"
                    ))
                })?;
            let end = offset.checked_add(elements * dtype.size());
            if end.is_none_or(|end| end > bytes.len() as u64) {
                return Err(error(format!(
                    "truncated: field '{name}' ({} x {shape:?}) extends past the end of the file \
                        ({} bytes)",
                    dtype.name(),
                    bytes.len()
                )));
            }
            // Fields may not share bytes beyond the file's size in all: a header whose tables
            // alias one another cannot make the reader copy the file many times over.
            declared += elements * dtype.size();
            if declared > bytes.len() as u64 {
                return Err(error(format!(
                    "the fields declare {declared} bytes of data, more than the file's {} bytes",
                    bytes.len()
                )));
            }
            if fields.iter().any(|f: &Field| f.name == name) {
                return Err(error(format!("field '{name}' is declared twice")));
            }
            fields.push(Field {
                name,
                dtype,
                shape,
                offset,
            });
        }
        Ok(Self { bytes, fields })
    }

    /// Every field, in the order declared.
    #[must_use]
    pub fn fields(&self) -> &[Field] {
        &self.fields
    }

    /// The field called `name`.
    pub fn field(&self, name: &str) -> Result<&Field, TensorError> {
        self.fields.iter().find(|f| f.name == name).ok_or_else(|| {
            let names: Vec<&str> = self.fields.iter().map(|f| f.name.as_str()).collect();
            error(format!(
                "no field '{name}' (the file has: {})",
                names.join(", ")
            ))
        })
    }

    fn data(&self, field: &Field) -> &'a [u8] {
        // In range: `parse` checked offset + size against the bytes.
        let start = field.offset as usize;
        &self.bytes[start..start + (field.len() * field.dtype.size()) as usize]
    }

    /// `name`'s elements as `f32`, checking its type and rank.
    pub fn f32s(&self, name: &str, rank: usize) -> Result<(Vec<f32>, Vec<usize>), TensorError> {
        let field = self.typed(name, DType::F32, rank)?;
        let values = self
            .data(field)
            .chunks_exact(4)
            .map(|b| f32::from_le_bytes([b[0], b[1], b[2], b[3]]))
            .collect();
        Ok((values, field.shape.iter().map(|&n| n as usize).collect()))
    }

    /// `name`'s bytes, checking its type and rank.
    pub fn u8s(&self, name: &str, rank: usize) -> Result<&'a [u8], TensorError> {
        let field = self.typed(name, DType::U8, rank)?;
        Ok(self.data(field))
    }

    fn typed(&self, name: &str, dtype: DType, rank: usize) -> Result<&Field, TensorError> {
        let field = self.field(name)?;
        if field.dtype != dtype || field.shape.len() != rank {
            return Err(error(format!(
                "field '{name}' is {} of rank {} (expected {} of rank {rank})",
                field.dtype.name(),
                field.shape.len(),
                dtype.name()
            )));
        }
        Ok(field)
    }
}
