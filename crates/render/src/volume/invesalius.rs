//! InVesalius 3 projects (`.inv3`), read natively: the scan a project was made from, without
//! its masks, surfaces or measurements.
//!
//! **The format.** An `.inv3` file is a tar archive, gzip-compressed (InVesalius 3.1 and later
//! can also write it uncompressed; both are read), holding one folder (`tmpocjcea/` in Debian's
//! `Cranium.inv3`) with:
//! - `main.plist`: an XML (or binary) property list whose `matrix` dictionary names the voxel
//!   file (`filename`, `matrix.dat`), its numpy element type (`dtype`: `int16` for CT, or
//!   `int8`, `uint8`, `uint16`, `int32`, `uint32`, `float32`, `float64`) and its shape
//!   (`shape`, `[z, y, x]`: slices, rows, columns), and whose `spacing` is `[sx, sy, sz]` in
//!   millimetres (between columns, rows and slices). `modality` is the DICOM modality the
//!   project came from (`CT`), `orientation` the acquisition plane (`1` or `AXIAL` for axial),
//!   `window_level` and `window_width` the slice viewer's window; masks, surfaces and
//!   measurements have their own entries;
//! - the voxel file: the array as numpy keeps it in memory, C order (column index fastest,
//!   then row, then slice), little-endian, no header.
//!
//! Everything is checked before anything large is allocated: the compressed file within the
//! input limit ([`crate::input::max_input_bytes`]), `main.plist` at most [`MAX_PLIST_BYTES`],
//! the declared shape within [`Volume::check_dims`], the voxel data (shape x element size)
//! within the input limit and equal to the voxel file's size in the archive, every tar
//! entry's declared size before it is read, and the archive's inflated bytes at most four
//! times the input limit (a gzip bomb stops there). Tar long-name and PAX header entries are
//! read only up to 64 KiB. A truncated or damaged archive, a missing or second `main.plist`,
//! a missing voxel file or a malformed property list is refused in one line naming the file
//! and the problem, and nothing is returned.
//!
//! **Orientation.** The project stores no placement in space (no position, no direction
//! cosines: InVesalius keeps only the spacing), so the orientation was established by looking
//! at the slices of Debian's `Cranium.inv3` (a head CT): the CT table lies at low row index,
//! the frontal sinus at high row index, the vertex at high slice index; the face is on the
//! side the rows increase towards, and the patient's left on the side the columns increase
//! towards. (InVesalius flips the rows vertically when it shows a slice, so the matrix read
//! as a plain image, row 0 at the top, looks upside down.) So column index increasing is the
//! patient's **Left**, row index **Anterior**, slice index **Superior**, and in [`Volume`]'s
//! RAS world the index-to-world map is `diag(-sx, +sy, +sz)`: exactly what
//! `crates/cli/tests/volumes/real_scans.py` (numpy and nibabel, independent of this reader)
//! writes into its NIfTI conversion.
//!
//! **Origin.** That script also sets an arbitrary, scanner-like origin (voxel `(0, 0, 0)` at
//! RAS `(122, -140, -60)` mm), a constant of its own that the project does not hold, so it
//! cannot be derived from the file. This reader centres the grid on the world origin
//! instead (as [`Volume::centred`] does): the two readings agree voxel for voxel and in the
//! linear part of the map, and differ by a translation only.
//!
//! Only axial projects (`orientation` 1 or `AXIAL`, or none) are read: a coronal or sagittal
//! acquisition is refused in one line rather than placed by a guess. The `affine` key that
//! newer InVesalius versions may write, and the window, are not used.
//!
//! **Units.** Hounsfield units when `modality` is `CT`; arbitrary for any other stated
//! modality; decided from the values ([`Units::from_values`]) when none is stated.

use std::io::{self, BufRead, BufReader, Cursor, Read};
use std::path::Path;

use glam::{Mat3, Vec3};
use plist::Value;

use super::{Units, Volume, VolumeError};
use crate::input;

/// The largest `main.plist` read: 64 KiB (InVesalius writes about 2 KiB).
pub const MAX_PLIST_BYTES: u64 = 64 << 10;

/// The largest tar long-name (GNU `L`) or PAX header entry read.
const MAX_HEADER_ENTRY_BYTES: u64 = 64 << 10;

/// The archive may inflate to this many times the input limit: room for a project's masks
/// and surfaces beside its voxels, and a stop for a gzip bomb.
const INFLATION: u64 = 4;

/// Whether `path` names an InVesalius project by its extension (`.inv3`).
#[must_use]
pub fn is_invesalius_path(path: &Path) -> bool {
    path.extension()
        .is_some_and(|extension| extension.eq_ignore_ascii_case("inv3"))
}

/// Reads the scan of the InVesalius 3 project at `path`.
pub fn read(path: &Path) -> Result<Volume, VolumeError> {
    read_within(path, input::max_input_bytes())
}

/// [`read`] with `limit` as the input limit (the voxel data's largest size; the compressed
/// file's too, and a quarter of the inflated archive's).
fn read_within(path: &Path, limit: u64) -> Result<Volume, VolumeError> {
    let fail = |what: String| VolumeError(format!("{}: {what}", path.display()));
    let mut project: Option<Project> = None;
    let mut matrix: Option<Vec<u8>> = None;
    walk(path, limit, &mut |name, size, data| {
        if base_name(name) == "main.plist" {
            if let Some(first) = &project {
                return Err(format!(
                    "two main.plist files ({} and {name}); a project has one",
                    first.plist_name
                ));
            }
            project = Some(Project::read(name, size, data, limit)?);
        } else if let Some(project) = project.as_ref().filter(|p| p.matrix_name == name) {
            if matrix.is_some() {
                return Err(format!("{name} appears twice in the archive"));
            }
            matrix = Some(project.read_matrix(size, data)?);
        }
        Ok(Walk::On)
    })
    .map_err(fail)?;
    let project = project
        .ok_or_else(|| fail("no main.plist in the archive: not an InVesalius 3 project".into()))?;
    let raw = match matrix {
        Some(raw) => raw,
        // The voxel file came before main.plist (InVesalius writes main.plist first): a second
        // pass reads it, now that its size is known.
        None => {
            let mut found = None;
            walk(path, limit, &mut |name, size, data| {
                if name != project.matrix_name {
                    return Ok(Walk::On);
                }
                found = Some(project.read_matrix(size, data)?);
                Ok(Walk::Stop)
            })
            .map_err(fail)?;
            found.ok_or_else(|| {
                fail(format!(
                    "{}, the voxel file main.plist names, is not in the archive",
                    project.matrix_name
                ))
            })?
        }
    };
    project.volume(&raw).map_err(fail)
}

/// Whether [`walk`] goes on to the next entry.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Walk {
    On,
    Stop,
}

/// What [`walk`] calls for each regular file: its name, its size and its data.
type Visit<'a> = dyn FnMut(&str, u64, &mut dyn Read) -> Result<Walk, String> + 'a;

/// Calls `visit(name, size, data)` for every regular file in the archive at `path`, in order,
/// until it answers [`Walk::Stop`] or the archive ends. Names are as stored, less a leading
/// `./`, with GNU long names and PAX `path` records applied.
fn walk(path: &Path, limit: u64, visit: &mut Visit<'_>) -> Result<(), String> {
    let file = input::open_regular(path)?;
    let mut buffered = BufReader::new(file);
    let gzip = buffered
        .fill_buf()
        .map_err(|e| format!("cannot be read ({e})"))?
        .starts_with(&[0x1f, 0x8b]);
    let stream: Box<dyn Read> = if gzip {
        Box::new(flate2::read::MultiGzDecoder::new(buffered))
    } else {
        Box::new(buffered)
    };
    let cap = limit.saturating_mul(INFLATION);
    let mut archive = tar::Archive::new(Capped {
        inner: stream,
        left: cap,
        cap,
    });
    // Raw entries: long names and PAX headers are read here, within a limit, rather than by
    // the tar crate, which would read one of any declared size into memory.
    let mut entries = archive.entries().map_err(damaged)?.raw(true);
    let mut long_name: Option<Vec<u8>> = None;
    for entry in entries.by_ref() {
        let mut entry = entry.map_err(damaged)?;
        let kind = entry.header().entry_type();
        let size = entry.size();
        if kind.is_gnu_longname() || kind.is_pax_local_extensions() {
            if size > MAX_HEADER_ENTRY_BYTES {
                return Err(format!(
                    "a tar header entry (long name or PAX) of {size} bytes; the most read is {MAX_HEADER_ENTRY_BYTES}"
                ));
            }
            let mut bytes = Vec::with_capacity(size as usize);
            entry.read_to_end(&mut bytes).map_err(damaged)?;
            if kind.is_gnu_longname() {
                while bytes.last() == Some(&0) {
                    bytes.pop();
                }
                long_name = Some(bytes);
            } else {
                for extension in tar::PaxExtensions::new(&bytes) {
                    let extension = extension.map_err(damaged)?;
                    match extension.key_bytes() {
                        b"path" => long_name = Some(extension.value_bytes().to_vec()),
                        b"size" => return Err(
                            "a PAX size record (a member over 8 GiB); not an InVesalius project"
                                .into(),
                        ),
                        _ => {}
                    }
                }
            }
            continue;
        }
        let stored = long_name
            .take()
            .unwrap_or_else(|| entry.path_bytes().into_owned());
        if !(kind.is_file() || kind.is_contiguous()) {
            continue;
        }
        let stored = String::from_utf8_lossy(&stored);
        let name = stored.trim_start_matches("./");
        if visit(name, size, &mut entry)? == Walk::Stop {
            return Ok(());
        }
    }
    // What follows the end-of-archive blocks is read too, so that a gzip stream cut short or
    // damaged there (its checksum is at its very end) is refused like one damaged earlier.
    io::copy(&mut archive.into_inner(), &mut io::sink()).map_err(damaged)?;
    Ok(())
}

/// A tar or gzip failure, in a line.
fn damaged(error: io::Error) -> String {
    let said = error.to_string().replace('\n', " ");
    if said.starts_with(CAPPED) {
        said
    } else if error.kind() == io::ErrorKind::UnexpectedEof {
        format!("the archive is truncated ({said})")
    } else {
        format!("not a readable InVesalius project: the tar.gz archive is damaged or truncated ({said})")
    }
}

/// The start of [`Capped`]'s error.
const CAPPED: &str = "the archive inflates to more than";

/// A reader that fails once more than `cap` bytes have come through.
struct Capped<R> {
    inner: R,
    left: u64,
    cap: u64,
}

impl<R: Read> Read for Capped<R> {
    fn read(&mut self, buf: &mut [u8]) -> io::Result<usize> {
        if buf.is_empty() {
            return Ok(0);
        }
        if self.left == 0 {
            let mut probe = [0_u8; 1];
            return match self.inner.read(&mut probe)? {
                0 => Ok(0),
                _ => Err(io::Error::other(format!(
                    "{CAPPED} {} bytes ({INFLATION} x the input limit; raise it with --max-input-mib)",
                    self.cap
                ))),
            };
        }
        let most = buf
            .len()
            .min(usize::try_from(self.left).unwrap_or(usize::MAX));
        let read = self.inner.read(&mut buf[..most])?;
        self.left -= read as u64;
        Ok(read)
    }
}

/// The last component of an archive path.
fn base_name(name: &str) -> &str {
    name.rsplit('/').next().unwrap_or(name)
}

/// A voxel file's element type (numpy's names).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Dtype {
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

    fn bytes(self) -> usize {
        match self {
            Dtype::I8 | Dtype::U8 => 1,
            Dtype::I16 | Dtype::U16 => 2,
            Dtype::I32 | Dtype::U32 | Dtype::F32 => 4,
            Dtype::F64 => 8,
        }
    }

    /// One little-endian element (`bytes.len() == self.bytes()`) as `f32`.
    fn value(self, bytes: &[u8]) -> f32 {
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
struct Project {
    /// Where `main.plist` is in the archive.
    plist_name: String,
    /// Where the voxel file is in the archive: `main.plist`'s folder and `matrix.filename`.
    matrix_name: String,
    /// Columns, rows, slices.
    dims: [usize; 3],
    dtype: Dtype,
    /// The voxel file's size: `dims` x the element size, within the input limit.
    bytes: u64,
    /// Between columns, rows and slices, in millimetres.
    spacing: [f32; 3],
    /// As `modality` says, or `None` when it says nothing.
    units: Option<Units>,
}

impl Project {
    /// Reads and checks the `main.plist` entry `name` of `size` bytes.
    fn read(name: &str, size: u64, data: &mut dyn Read, limit: u64) -> Result<Self, String> {
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
                "the voxels ({x} x {y} x {z} {}) take {bytes} bytes, above the input limit of {limit} bytes ({} MiB; raise it with --max-input-mib)",
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
                    "orientation {said}: specula reads axial projects (orientation 1 or AXIAL), whose placement it knows"
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
    fn read_matrix(&self, size: u64, data: &mut dyn Read) -> Result<Vec<u8>, String> {
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

    /// The volume: `raw` (the voxel file) as samples, placed as the module describes.
    fn volume(&self, raw: &[u8]) -> Result<Volume, String> {
        let samples: Vec<f32> = raw
            .chunks_exact(self.dtype.bytes())
            .map(|element| self.dtype.value(element))
            .collect();
        let [sx, sy, sz] = self.spacing;
        let to_world = Mat3::from_diagonal(Vec3::new(-sx, sy, sz));
        let last = Vec3::new(
            (self.dims[0] - 1) as f32,
            (self.dims[1] - 1) as f32,
            (self.dims[2] - 1) as f32,
        );
        let origin = -0.5 * (to_world * last);
        let units = self.units.unwrap_or_else(|| Units::from_values(&samples));
        Volume::try_new(self.dims, to_world, origin, samples, units).map_err(|e| e.0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::io::Write as _;

    /// A `main.plist` for a `[z, y, x]` grid.
    fn plist(shape: [i64; 3], dtype: &str, spacing: [f64; 3], extra: &str) -> String {
        format!(
            r#"<?xml version="1.0" encoding="UTF-8"?>
<!DOCTYPE plist PUBLIC "-//Apple Computer//DTD PLIST 1.0//EN" "http://www.apple.com/DTDs/PropertyList-1.0.dtd">
<plist version="1.0">
<dict>
	<key>matrix</key>
	<dict>
		<key>dtype</key>
		<string>{dtype}</string>
		<key>filename</key>
		<string>matrix.dat</string>
		<key>shape</key>
		<array>
			<integer>{}</integer>
			<integer>{}</integer>
			<integer>{}</integer>
		</array>
	</dict>
	<key>spacing</key>
	<array>
		<real>{}</real>
		<real>{}</real>
		<real>{}</real>
	</array>
	<key>window_level</key>
	<real>-18.0</real>
	{extra}
</dict>
</plist>
"#,
            shape[0], shape[1], shape[2], spacing[0], spacing[1], spacing[2]
        )
    }

    /// A tar archive of `entries` (name, bytes), gzip-compressed when `gzip`.
    fn archive(entries: &[(&str, &[u8])], gzip: bool) -> Vec<u8> {
        let mut builder = tar::Builder::new(Vec::new());
        for (name, bytes) in entries {
            let mut header = tar::Header::new_gnu();
            header.set_size(bytes.len() as u64);
            header.set_mode(0o644);
            builder
                .append_data(&mut header, name, *bytes)
                .expect("append");
        }
        let tar = builder.into_inner().expect("tar");
        if !gzip {
            return tar;
        }
        let mut encoder = flate2::write::GzEncoder::new(Vec::new(), flate2::Compression::fast());
        encoder.write_all(&tar).expect("gzip");
        encoder.finish().expect("gzip")
    }

    /// `bytes` in a temporary `.inv3` file.
    fn file(bytes: &[u8]) -> tempfile::NamedTempFile {
        let mut file = tempfile::Builder::new()
            .suffix(".inv3")
            .tempfile()
            .expect("temporary file");
        file.write_all(bytes).expect("write");
        file
    }

    /// A 4 x 3 x 2 (x, y, z) int16 grid whose voxel `(i, j, k)` holds `100 k + 10 j + i - 1000`.
    fn small_matrix() -> Vec<u8> {
        let mut raw = Vec::new();
        for k in 0..2_i16 {
            for j in 0..3_i16 {
                for i in 0..4_i16 {
                    raw.extend_from_slice(&(100 * k + 10 * j + i - 1000).to_le_bytes());
                }
            }
        }
        raw
    }

    const CT: &str =
        "<key>modality</key><string>CT</string><key>orientation</key><integer>1</integer>";

    fn small_plist() -> String {
        plist([2, 3, 4], "int16", [0.5, 0.75, 1.5], CT)
    }

    fn read_bytes(bytes: &[u8]) -> Result<Volume, VolumeError> {
        let file = file(bytes);
        read(file.path())
    }

    fn refusal(bytes: &[u8]) -> String {
        let file = file(bytes);
        let error = read(file.path()).expect_err("refused").0;
        assert!(!error.contains('\n'), "one line: {error}");
        assert!(
            error.starts_with(&file.path().display().to_string()),
            "names the file: {error}"
        );
        error
    }

    fn check_small(volume: &Volume) {
        assert_eq!(volume.dims(), [4, 3, 2]);
        assert_eq!(volume.units(), Units::Hounsfield);
        for (k, j, i) in [(0, 0, 0), (1, 2, 3), (0, 1, 2), (1, 0, 1)] {
            assert_eq!(
                volume.at(i, j, k),
                (100 * k + 10 * j + i - 1000) as f32,
                "voxel {i} {j} {k}"
            );
        }
        assert_eq!(
            volume.to_world(),
            Mat3::from_diagonal(Vec3::new(-0.5, 0.75, 1.5))
        );
        // The grid is centred on the world origin.
        let centre = volume.world(0.5 * volume.last_index());
        assert!(centre.length() < 1e-6, "{centre}");
    }

    #[test]
    fn a_project_reads_with_its_placement_and_units() {
        let plist = small_plist();
        let matrix = small_matrix();
        let entries: [(&str, &[u8]); 4] = [
            ("tmpabc/main.plist", plist.as_bytes()),
            ("tmpabc/mask_0.dat", &[7; 100]),
            ("tmpabc/matrix.dat", &matrix),
            ("tmpabc/surface_0.vtp", b"<VTKFile/>"),
        ];
        check_small(&read_bytes(&archive(&entries, true)).expect("gzip'd"));
        // Uncompressed, as InVesalius 3.1 writes with compression off.
        check_small(&read_bytes(&archive(&entries, false)).expect("plain tar"));
        // The voxel file before main.plist: a second pass finds it.
        let reversed: Vec<_> = entries.iter().rev().copied().collect();
        check_small(&read_bytes(&archive(&reversed, true)).expect("reversed"));
        // A folder name over tar's 100 bytes: a GNU long-name entry.
        let folder = format!("./{}", "d".repeat(150));
        let (plist_name, matrix_name) = (
            format!("{folder}/main.plist"),
            format!("{folder}/matrix.dat"),
        );
        let long = [
            (plist_name.as_str(), plist.as_bytes()),
            (matrix_name.as_str(), matrix.as_slice()),
        ];
        check_small(&read_bytes(&archive(&long, true)).expect("long names"));
    }

    #[test]
    fn the_units_follow_the_modality_then_the_values() {
        let matrix = small_matrix();
        let project = |extra: &str| {
            let plist = plist([2, 3, 4], "int16", [1.0, 1.0, 1.0], extra);
            read_bytes(&archive(
                &[
                    ("p/main.plist", plist.as_bytes()),
                    ("p/matrix.dat", &matrix),
                ],
                true,
            ))
            .expect("reads")
            .units()
        };
        assert_eq!(project(CT), Units::Hounsfield);
        assert_eq!(
            project("<key>modality</key><string>MRI</string>"),
            Units::Arbitrary
        );
        // Nothing said: every value here is air (-1000 to -879), so CT by the values.
        assert_eq!(project(""), Units::Hounsfield);
        // Every dtype is read as little-endian values.
        let bytes: Vec<u8> = (0..24_u16).flat_map(|v| v.to_le_bytes()).collect();
        let plist = plist([2, 3, 4], "uint16", [1.0, 1.0, 1.0], "");
        let volume = read_bytes(&archive(
            &[("p/main.plist", plist.as_bytes()), ("p/matrix.dat", &bytes)],
            true,
        ))
        .expect("uint16");
        assert_eq!(
            volume.samples(),
            (0..24).map(|v| v as f32).collect::<Vec<_>>()
        );
        assert_eq!(volume.units(), Units::Arbitrary);
        let bytes: Vec<u8> = (0..24)
            .flat_map(|v| (f64::from(v) * 0.5).to_le_bytes())
            .collect();
        let plist = self::plist([2, 3, 4], "float64", [1.0, 1.0, 1.0], "");
        let volume = read_bytes(&archive(
            &[("p/main.plist", plist.as_bytes()), ("p/matrix.dat", &bytes)],
            false,
        ))
        .expect("float64");
        assert_eq!(volume.at(3, 2, 1), 11.5);
    }

    #[test]
    fn bad_projects_are_refused_in_one_line_naming_the_problem() {
        let matrix = small_matrix();
        let good = small_plist();
        let with = |plist: &str, matrix: &[u8]| {
            archive(
                &[("p/main.plist", plist.as_bytes()), ("p/matrix.dat", matrix)],
                true,
            )
        };
        let cases: Vec<(Vec<u8>, &str)> = vec![
            (archive(&[("p/matrix.dat", &matrix)], true), "no main.plist"),
            (
                archive(
                    &[
                        ("p/main.plist", good.as_bytes()),
                        ("q/main.plist", good.as_bytes()),
                    ],
                    true,
                ),
                "two main.plist files (p/main.plist and q/main.plist)",
            ),
            (
                archive(&[("p/main.plist", good.as_bytes())], true),
                "p/matrix.dat, the voxel file main.plist names, is not in the archive",
            ),
            (
                with(&good, &matrix[..46]),
                "p/matrix.dat holds 46 bytes; main.plist's 4 x 3 x 2 int16 grid needs 48",
            ),
            (
                with(&plist([2, 3, 1], "int16", [1.0; 3], CT), &matrix),
                "every side must be 2 to 4096",
            ),
            (
                with(
                    &plist([100_000, 100_000, 100_000], "int16", [1.0; 3], CT),
                    &matrix,
                ),
                "every side must be 2 to 4096",
            ),
            (
                with(&plist([2, -3, 4], "int16", [1.0; 3], CT), &matrix),
                "matrix.shape holds -3",
            ),
            (
                // 2^28 voxels of 8 bytes: 2 GiB, over the 512 MiB limit, refused before reading.
                with(&plist([1024, 512, 512], "float64", [1.0; 3], CT), &matrix),
                "take 2147483648 bytes, above the input limit",
            ),
            (
                with(&plist([2, 3, 4], "complex64", [1.0; 3], CT), &matrix),
                "matrix.dtype `complex64`: specula reads int8, uint8, int16",
            ),
            (
                with(&plist([2, 3, 4], "int16", [1.0, 0.0, 1.0], CT), &matrix),
                "every spacing must be positive",
            ),
            (
                with(
                    &plist(
                        [2, 3, 4],
                        "int16",
                        [1.0; 3],
                        "<key>orientation</key><string>CORONAL</string>",
                    ),
                    &matrix,
                ),
                "orientation CORONAL: specula reads axial projects",
            ),
            (
                with(
                    &plist(
                        [2, 3, 4],
                        "int16",
                        [1.0; 3],
                        "<key>orientation</key><integer>3</integer>",
                    ),
                    &matrix,
                ),
                "orientation 3 (sagittal)",
            ),
            (
                with(&good.replace("matrix.dat", "../matrix.dat"), &matrix),
                "is not a file name beside main.plist",
            ),
            (
                with(
                    &good.replace("<key>matrix</key>", "<key>matrices</key>"),
                    &matrix,
                ),
                "no `matrix` dictionary",
            ),
            (
                with("<plist><array></array></plist>", &matrix),
                "not a dictionary",
            ),
            (
                with("{ not a plist", &matrix),
                "p/main.plist: not a property list",
            ),
            (
                with(&"x".repeat(70_000), &matrix),
                "p/main.plist is 70000 bytes; a project's main.plist is at most 65536",
            ),
            (
                b"just some text, not an archive".to_vec(),
                "damaged or truncated",
            ),
        ];
        for (bytes, expected) in cases {
            let error = refusal(&bytes);
            assert!(error.contains(expected), "{expected:?} not in {error}");
        }
    }

    /// A deeply nested property list within the size limit is refused or read, never a crash
    /// (the plist crate builds and drops values without recursion up to this depth).
    #[test]
    fn a_deeply_nested_plist_is_no_crash() {
        let depth = (MAX_PLIST_BYTES as usize - 64) / "<array></array>".len();
        let nested = format!(
            "<plist>{}{}</plist>",
            "<array>".repeat(depth),
            "</array>".repeat(depth)
        );
        assert!(nested.len() as u64 <= MAX_PLIST_BYTES);
        let bytes = archive(
            &[
                ("p/main.plist", nested.as_bytes()),
                ("p/matrix.dat", &[0; 8]),
            ],
            true,
        );
        assert!(refusal(&bytes).contains("not a dictionary"));
    }

    /// Every truncation of a gzip'd project, and many garbled copies of it, is refused in one
    /// line (or, for a byte changed where nothing checks it, read); none panics.
    #[test]
    fn truncated_and_garbled_archives_are_refused_without_a_panic() {
        let plist = small_plist();
        let matrix = small_matrix();
        let entries: [(&str, &[u8]); 3] = [
            ("tmpabc/main.plist", plist.as_bytes()),
            ("tmpabc/matrix.dat", &matrix),
            ("tmpabc/surface_0.vtp", &[1; 700]),
        ];
        for gzip in [true, false] {
            let whole = archive(&entries, gzip);
            let full = read_bytes(&whole).expect("whole");
            let step = if gzip { 1 } else { 97 };
            for cut in (0..whole.len()).step_by(step) {
                match read_bytes(&whole[..cut]) {
                    Err(error) => assert!(!error.0.contains('\n'), "{error}"),
                    // A tar cut after its last member, before the end-of-archive blocks,
                    // still holds the whole project (as Python's tarfile reads it).
                    Ok(volume) => {
                        assert!(!gzip, "a gzip stream cut at {cut} was read");
                        assert_eq!(volume, full, "cut at {cut}");
                    }
                }
            }
            // Bytes changed at pseudo-random places (a fixed sequence).
            let mut state = 0x2545_f491_u64;
            for _ in 0..400 {
                state = state
                    .wrapping_mul(6_364_136_223_846_793_005)
                    .wrapping_add(1_442_695_040_888_963_407);
                let at = (state >> 33) as usize % whole.len();
                let mut garbled = whole.clone();
                garbled[at] ^= 1 << ((state >> 20) % 8);
                if let Err(error) = read_bytes(&garbled) {
                    assert!(!error.0.contains('\n'), "{error}");
                }
            }
        }
    }

    /// A long-name entry declaring more than 64 KiB is refused before it is read, and an
    /// archive that inflates past four times the input limit stops there.
    #[test]
    fn header_entries_and_inflation_are_bounded() {
        let plist = small_plist();
        let matrix = small_matrix();
        let mut tar = Vec::new();
        {
            let mut header = tar::Header::new_gnu();
            header.set_entry_type(tar::EntryType::GNULongName);
            header.set_path("././@LongLink").expect("path");
            header.set_size(1 << 30);
            header.set_mode(0o644);
            header.set_cksum();
            tar.extend_from_slice(header.as_bytes());
            tar.extend_from_slice(&[b'a'; 512]);
        }
        let error = refusal(&tar);
        assert!(
            error.contains("a tar header entry (long name or PAX) of 1073741824 bytes"),
            "{error}"
        );

        let padding = vec![0_u8; 40_000];
        let bytes = archive(
            &[
                ("p/main.plist", plist.as_bytes()),
                ("p/mask_0.dat", &padding),
                ("p/matrix.dat", &matrix),
            ],
            true,
        );
        let file = file(&bytes);
        let error = read_within(file.path(), 8_000).expect_err("capped").0;
        assert!(
            error.contains("the archive inflates to more than 32000 bytes"),
            "{error}"
        );
        assert!(read_within(file.path(), 20_000).is_ok());
    }

    #[test]
    fn inv3_paths_are_recognised() {
        assert!(is_invesalius_path(Path::new("/a/Cranium.inv3")));
        assert!(is_invesalius_path(Path::new("X.INV3")));
        assert!(!is_invesalius_path(Path::new("x.nii.gz")));
        assert!(!is_invesalius_path(Path::new("inv3")));
    }
}
