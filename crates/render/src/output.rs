//! Writing an output file the way Unix tools do.
//!
//! - A regular file (or a new path) is written **atomically**: to a temporary file beside it,
//!   then renamed into place, so a failed or interrupted run leaves the old file untouched. An
//!   existing file keeps its permissions.
//! - A **symlink** is followed: its final target is replaced atomically and the link stays a
//!   link.
//! - Anything else that exists (a device such as `/dev/null`, a FIFO) is written **in place**,
//!   and `-` means standard output. Their contents are encoded in memory first, since
//!   encoders may seek and these cannot.
//!
//! Temporary files are named `.specula-<pid>-<random>.tmp` and made through
//! `specula_temporaries`, registered in the same step, so that a signal handler removes every
//! one that exists ([`specula_temporaries::remove_all`]); a write removes the ones in its
//! directory whose process is gone (a run killed by `SIGKILL`).

use std::io::{BufWriter, Cursor, Seek, Write};
use std::path::{Path, PathBuf};

use crate::image_error::ImageError;

/// A writer an encoder may also seek in.
pub trait SeekWrite: Write + Seek {}
impl<T: Write + Seek> SeekWrite for T {}

/// The most symlinks followed, as the kernel's `ELOOP` limit.
const MAX_LINKS: usize = 40;

/// `path` with every symlink in its last component followed (a dangling link gives the path
/// it points to, which the write then creates).
fn follow_links(path: &Path) -> std::io::Result<PathBuf> {
    let mut current = path.to_owned();
    for _ in 0..MAX_LINKS {
        match std::fs::symlink_metadata(&current) {
            Ok(meta) if meta.file_type().is_symlink() => {
                let target = std::fs::read_link(&current)?;
                current = match current.parent() {
                    Some(parent) if target.is_relative() => parent.join(target),
                    _ => target,
                };
            }
            _ => return Ok(current),
        }
    }
    Err(std::io::Error::other("too many levels of symbolic links"))
}

/// Writes what `write` produces to `path` as the module describes: atomically for regular
/// files and new paths (through symlinks), in place for devices and FIFOs, to standard output
/// for `-`.
pub fn write_atomically(
    path: &Path,
    write: impl FnOnce(&mut dyn SeekWrite) -> Result<(), String>,
) -> Result<(), ImageError> {
    let io = |source| ImageError::Io {
        path: path.display().to_string(),
        source,
    };
    let codec = |message| ImageError::Codec {
        path: path.display().to_string(),
        message,
    };
    if path == Path::new("-") {
        let mut bytes = Cursor::new(Vec::new());
        write(&mut bytes).map_err(codec)?;
        let mut stdout = std::io::stdout().lock();
        stdout.write_all(bytes.get_ref()).map_err(io)?;
        return stdout.flush().map_err(io);
    }
    let target = follow_links(path).map_err(io)?;
    let existing = match std::fs::metadata(&target) {
        Ok(meta) => Some(meta),
        Err(error) if error.kind() == std::io::ErrorKind::NotFound => None,
        Err(error) => return Err(io(error)),
    };
    if let Some(meta) = &existing {
        if meta.is_dir() {
            return Err(io(std::io::Error::other("is a directory")));
        }
        if !meta.is_file() {
            let mut bytes = Cursor::new(Vec::new());
            write(&mut bytes).map_err(codec)?;
            let mut device = std::fs::OpenOptions::new()
                .write(true)
                .open(&target)
                .map_err(io)?;
            device.write_all(bytes.get_ref()).map_err(io)?;
            return device.flush().map_err(io);
        }
    }
    let directory = match target.parent() {
        Some(parent) if !parent.as_os_str().is_empty() => parent.to_owned(),
        _ => PathBuf::from("."),
    };
    // A new output gets the usual mode (0666 less the umask), as if created directly, and an
    // existing one keeps its own.
    let mut file = specula_temporaries::file_in(&directory, ".tmp", Some(0o666)).map_err(io)?;
    let result = (|| {
        {
            let mut writer = BufWriter::new(file.as_file_mut());
            write(&mut writer).map_err(codec)?;
            writer.flush().map_err(io)?;
        }
        if let Some(meta) = &existing {
            file.as_file()
                .set_permissions(meta.permissions())
                .map_err(io)?;
        }
        file.as_file().sync_all().map_err(io)
    })();
    result.and_then(|()| file.persist(&target).map_err(io))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn entries(directory: &Path) -> Vec<String> {
        let mut names: Vec<String> = std::fs::read_dir(directory)
            .expect("list")
            .map(|e| e.expect("entry").file_name().to_string_lossy().into_owned())
            .collect();
        names.sort();
        names
    }

    /// While a write is under way its temporary file is registered (what a signal handler
    /// removes) and afterwards it is not; a temporary file removed under the write makes it
    /// fail and leaves nothing.
    #[test]
    fn temporary_files_are_registered_while_they_exist() {
        let directory = tempfile::tempdir().expect("temporary directory");
        let result = write_atomically(&directory.path().join("out.txt"), |writer| {
            writer.write_all(b"partial").map_err(|e| e.to_string())?;
            let registered = specula_temporaries::registered_under(directory.path());
            assert_eq!(registered.len(), 1, "the temporary file is registered");
            assert!(registered[0].exists());
            std::fs::remove_file(&registered[0]).map_err(|e| e.to_string())
        });
        assert!(
            result.is_err(),
            "the temporary file was removed under the write"
        );
        assert!(entries(directory.path()).is_empty());
        assert!(specula_temporaries::registered_under(directory.path()).is_empty());
    }

    #[test]
    fn a_dangling_symlink_creates_its_target() {
        let directory = tempfile::tempdir().expect("temporary directory");
        std::os::unix::fs::symlink("made.txt", directory.path().join("link.txt")).expect("link");
        write_atomically(&directory.path().join("link.txt"), |w| {
            w.write_all(b"made").map_err(|e| e.to_string())
        })
        .expect("written");
        assert_eq!(
            std::fs::read_to_string(directory.path().join("made.txt")).expect("read"),
            "made"
        );
        assert_eq!(entries(directory.path()), ["link.txt", "made.txt"]);
    }
}
