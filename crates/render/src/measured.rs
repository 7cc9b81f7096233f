//! Measured materials from files: an RGL `.bsdf` read through [`crate::input`] (a regular
//! file, within [`MAX_MATERIAL_BYTES`], checked before a byte is read) and handed to the
//! core's [`MeasuredBrdf`], whose refusals come back prefixed by the path.

use std::path::Path;

pub use specula::measured::MeasuredBrdf;

/// The largest material file read: 64 MiB (the RGL RGB files are 0.7 to 10 MiB).
pub const MAX_MATERIAL_BYTES: u64 = 64 << 20;

/// Reads the measured material at `path`; every refusal is one line naming the file.
pub fn load_measured(path: &Path) -> Result<MeasuredBrdf, String> {
    let bytes = crate::input::read_within(path, MAX_MATERIAL_BYTES)?;
    MeasuredBrdf::from_bytes(&bytes).map_err(|e| format!("{}: {e}", path.display()))
}

/// The material's name: the file's stem (`paper_white_rgb` for `.../paper_white_rgb.bsdf`).
#[must_use]
pub fn material_name(path: &Path) -> String {
    path.file_stem().map_or_else(
        || path.display().to_string(),
        |s| s.to_string_lossy().into_owned(),
    )
}
