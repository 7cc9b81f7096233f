//! Reading the files a user names: regular files only, each under a size limit, checked before
//! anything is read.
//!
//! A FIFO would block forever and `/dev/zero` (or a symlink to it) would fill memory, so a
//! path whose final target is not a regular file is refused with what it is; a regular file
//! above the limit is refused with its size and the limit; and a whole-file read stops one
//! byte past the limit, in case the file grows after the check.
//!
//! The limit is process-wide, [`DEFAULT_MAX_INPUT_BYTES`] unless the CLI raises it
//! (`--max-input-mib`), because every reader of the scene's meshes and images shares it.

use std::io::Read;
use std::path::Path;
use std::sync::atomic::{AtomicU64, Ordering};

/// The default largest input file: 512 MiB.
pub const DEFAULT_MAX_INPUT_BYTES: u64 = 512 << 20;

static MAX_INPUT_BYTES: AtomicU64 = AtomicU64::new(DEFAULT_MAX_INPUT_BYTES);

/// Sets the largest input file this process reads.
pub fn set_max_input_bytes(bytes: u64) {
    MAX_INPUT_BYTES.store(bytes, Ordering::Relaxed);
}

/// The largest input file this process reads.
#[must_use]
pub fn max_input_bytes() -> u64 {
    MAX_INPUT_BYTES.load(Ordering::Relaxed)
}

/// What `path` is, when it is not a regular file.
fn kind(meta: &std::fs::Metadata) -> &'static str {
    #[cfg(unix)]
    {
        use std::os::unix::fs::FileTypeExt;
        let file_type = meta.file_type();
        if file_type.is_fifo() {
            return "a FIFO";
        }
        if file_type.is_char_device() || file_type.is_block_device() {
            return "a device";
        }
        if file_type.is_socket() {
            return "a socket";
        }
    }
    if meta.is_dir() {
        "a directory"
    } else {
        "not a regular file"
    }
}

/// The largest scene file: 16 MiB of TOML (meshes live in their own files).
pub const MAX_SCENE_BYTES: u64 = 16 << 20;

/// Opens `path` for reading if it is a regular file within the limit (parsers that seek, as
/// the STL reader does, get the file itself), or a one-line reason.
pub fn open_regular(path: &Path) -> Result<std::fs::File, String> {
    open_within(path, max_input_bytes())
}

fn open_within(path: &Path, limit: u64) -> Result<std::fs::File, String> {
    let meta = std::fs::metadata(path).map_err(|e| e.to_string())?;
    if !meta.is_file() {
        return Err(format!(
            "is {}, not a regular file; give the path of a file",
            kind(&meta)
        ));
    }
    if meta.len() > limit {
        return Err(too_large(meta.len(), limit));
    }
    std::fs::File::open(path).map_err(|e| e.to_string())
}

fn too_large(bytes: u64, limit: u64) -> String {
    format!(
        "is {bytes} bytes, above the input limit of {limit} bytes ({} MiB; raise it with \
            --max-input-mib)",
        limit >> 20
    )
}

/// Reads `path` whole (see [`open_regular`]).
pub fn read_regular(path: &Path) -> Result<Vec<u8>, String> {
    read_within(path, max_input_bytes())
}

/// Reads `path` whole if it is a regular file of at most `limit` bytes.
pub fn read_within(path: &Path, limit: u64) -> Result<Vec<u8>, String> {
    let mut bytes = Vec::new();
    open_within(path, limit)?
        .take(limit + 1)
        .read_to_end(&mut bytes)
        .map_err(|e| e.to_string())?;
    if bytes.len() as u64 > limit {
        return Err(too_large(bytes.len() as u64, limit));
    }
    Ok(bytes)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn non_regular_paths_are_refused_with_what_they_are() {
        let directory = tempfile::tempdir().expect("temporary directory");
        assert!(read_regular(directory.path())
            .unwrap_err()
            .contains("a directory"));
        #[cfg(unix)]
        assert!(read_regular(Path::new("/dev/zero"))
            .unwrap_err()
            .contains("a device"));
        let link = directory.path().join("zero.obj");
        #[cfg(unix)]
        {
            std::os::unix::fs::symlink("/dev/zero", &link).expect("symlink");
            assert!(read_regular(&link).unwrap_err().contains("a device"));
        }
    }
}
