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
//! input limit ([`input::max_input_bytes`]), `main.plist` at most [`MAX_PLIST_BYTES`],
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

mod archive;
mod project;
#[cfg(test)]
mod tests;

use std::path::Path;

use glam::{Mat3, Vec3};
use specula_render::input;

use crate::samples::Samples;
use crate::volume::{Units, Volume, VolumeError};
use archive::{base_name, walk, Walk};
use project::Project;

/// The largest `main.plist` read: 64 KiB (InVesalius writes about 2 KiB).
pub const MAX_PLIST_BYTES: u64 = 64 << 10;

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

impl Project {
    /// The volume: `raw` (the voxel file) as samples, placed as the module describes.
    fn volume(&self, raw: &[u8]) -> Result<Volume, String> {
        let samples = Samples::new(
            raw.chunks_exact(self.dtype.bytes())
                .map(|element| self.dtype.value(element))
                .collect(),
        );
        let [sx, sy, sz] = self.spacing;
        let to_world = Mat3::from_diagonal(Vec3::new(-sx, sy, sz));
        let last = Vec3::new(
            (self.dims[0] - 1) as f32,
            (self.dims[1] - 1) as f32,
            (self.dims[2] - 1) as f32,
        );
        let origin = -0.5 * (to_world * last);
        let units = self.units.unwrap_or_else(|| Units::from_values(&samples));
        Volume::from_samples(self.dims, to_world, origin, samples, units).map_err(|e| e.0)
    }
}
