//! Temporary files and folders that an interrupted run removes.
//!
//! Every temporary that specula makes (an output's file before its rename, a DICOM series'
//! staging folder, a synthesis' scratch folder, a cache entry) is made here and **registered
//! in the same step, under one lock**, so a `SIGINT` or `SIGTERM` handler calling
//! [`remove_all`] sees every temporary that exists: none is made between its creation and its
//! registration, and once [`remove_all`] has run, making one is refused (the run is ending),
//! so none appears after the handler's sweep. A temporary that is renamed into place
//! ([`TempFile::persist`], [`TempDir::persist`]) or dropped leaves the registry; a handler that
//! finds it gone removes nothing. A run killed by `SIGKILL` runs no handler: the next write into
//! the same folder removes the files whose process is gone ([`file_in`]).
//!
//! Temporaries are named `.specula-<pid>-<label><random><suffix>`, so a person listing a
//! folder sees whose they are. This is a crate of its own because every layer that writes files
//! (the renderer's outputs, the synthesis cache, the report's scratch folders) shares the one
//! registry the command line's signal handler sweeps.

use std::fs::File;
use std::io;
use std::path::{Path, PathBuf};
use std::sync::{Mutex, MutexGuard, PoisonError};

/// What exists now, and whether the run is ending.
struct Registry {
    paths: Vec<PathBuf>,
    closing: bool,
}

static REGISTRY: Mutex<Registry> = Mutex::new(Registry {
    paths: Vec::new(),
    closing: false,
});

fn registry() -> MutexGuard<'static, Registry> {
    REGISTRY.lock().unwrap_or_else(PoisonError::into_inner)
}

/// Makes a temporary with `make` and registers `path_of` it, under the registry's lock.
fn registered<T>(
    make: impl FnOnce() -> io::Result<T>,
    path_of: impl Fn(&T) -> &Path,
) -> io::Result<T> {
    let mut registry = registry();
    if registry.closing {
        return Err(io::Error::new(
            io::ErrorKind::Interrupted,
            "interrupted: the run is ending, so no temporary file is made",
        ));
    }
    let made = make()?;
    registry.paths.push(path_of(&made).to_owned());
    Ok(made)
}

fn unregister(path: &Path) {
    registry().paths.retain(|p| p != path);
}

/// Removes every registered temporary and refuses new ones from now on: what a `SIGINT` or
/// `SIGTERM` handler calls before the process exits.
pub fn remove_all() {
    let paths = {
        let mut registry = registry();
        registry.closing = true;
        std::mem::take(&mut registry.paths)
    };
    for path in paths {
        remove(&path);
    }
}

/// Removes a file, or a folder and what it holds (tried again while something else, such as
/// a tool still writing into it, adds entries).
fn remove(path: &Path) {
    if std::fs::remove_file(path).is_ok() {
        return;
    }
    for _ in 0..4 {
        match std::fs::remove_dir_all(path) {
            Err(error) if error.kind() != io::ErrorKind::NotFound => continue,
            _ => return,
        }
    }
}

/// The registered paths under `folder` (for tests of the callers).
#[must_use]
pub fn registered_under(folder: &Path) -> Vec<PathBuf> {
    registry()
        .paths
        .iter()
        .filter(|p| p.starts_with(folder))
        .cloned()
        .collect()
}

fn prefix(label: &str) -> String {
    format!(".specula-{}-{label}", std::process::id())
}

/// A registered temporary file, removed when dropped unless persisted.
#[derive(Debug)]
pub struct TempFile(Option<tempfile::NamedTempFile>);

impl TempFile {
    fn inner(&self) -> &tempfile::NamedTempFile {
        self.0.as_ref().expect("present until persisted or dropped")
    }

    /// The file's path.
    #[must_use]
    pub fn path(&self) -> &Path {
        self.inner().path()
    }

    /// The open file.
    #[must_use]
    pub fn as_file(&self) -> &File {
        self.inner().as_file()
    }

    /// The open file, to write.
    pub fn as_file_mut(&mut self) -> &mut File {
        self.0
            .as_mut()
            .expect("present until persisted or dropped")
            .as_file_mut()
    }

    /// Renames the file to `target` (atomic within a file system); on failure it is removed.
    pub fn persist(mut self, target: &Path) -> io::Result<()> {
        let file = self.0.take().expect("present until persisted or dropped");
        let path = file.path().to_owned();
        let result = file.persist(target).map(|_| ()).map_err(|e| e.error);
        unregister(&path);
        result
    }
}

impl Drop for TempFile {
    fn drop(&mut self) {
        if let Some(file) = self.0.take() {
            let path = file.path().to_owned();
            drop(file);
            unregister(&path);
        }
    }
}

/// A registered temporary folder, removed with its contents when dropped unless persisted.
#[derive(Debug)]
pub struct TempDir(Option<tempfile::TempDir>);

impl TempDir {
    /// The folder's path.
    #[must_use]
    pub fn path(&self) -> &Path {
        self.0
            .as_ref()
            .expect("present until persisted or dropped")
            .path()
    }

    /// Renames the folder to `target` (which must not exist or be an empty folder); on
    /// failure it is removed.
    pub fn persist(mut self, target: &Path) -> io::Result<()> {
        let path = self
            .0
            .take()
            .expect("present until persisted or dropped")
            .keep();
        let result = std::fs::rename(&path, target);
        if result.is_err() {
            remove(&path);
        }
        unregister(&path);
        result
    }
}

impl Drop for TempDir {
    fn drop(&mut self) {
        if let Some(dir) = self.0.take() {
            let path = dir.path().to_owned();
            drop(dir);
            unregister(&path);
        }
    }
}

/// A new temporary file in `folder`, named `.specula-<pid>-<random><suffix>`, with
/// permissions `mode` (Unix; before the umask) where given, else private. The first time a
/// process writes into a folder, the files there of processes that no longer run (killed by
/// `SIGKILL`) are removed.
pub fn file_in(folder: &Path, suffix: &str, mode: Option<u32>) -> io::Result<TempFile> {
    remove_stale(folder);
    let prefix = prefix("");
    let mut builder = tempfile::Builder::new();
    builder.prefix(&prefix).suffix(suffix);
    #[cfg(unix)]
    if let Some(mode) = mode {
        builder.permissions(std::os::unix::fs::PermissionsExt::from_mode(mode));
    }
    #[cfg(not(unix))]
    let _ = mode;
    registered(
        || builder.tempfile_in(folder),
        tempfile::NamedTempFile::path,
    )
    .map(|file| TempFile(Some(file)))
}

/// A new temporary folder in `parent`, named `.specula-<pid>-<label><random>`.
pub fn dir_in(parent: &Path, label: &str) -> io::Result<TempDir> {
    let prefix = prefix(label);
    registered(
        || tempfile::Builder::new().prefix(&prefix).tempdir_in(parent),
        tempfile::TempDir::path,
    )
    .map(|dir| TempDir(Some(dir)))
}

/// A new temporary folder in the system's temporary folder (`TMPDIR`, else `/tmp`).
pub fn dir(label: &str) -> io::Result<TempDir> {
    dir_in(&std::env::temp_dir(), label)
}

/// Removes `.specula-<pid>-*` files and folders in `folder` whose process no longer runs (read from
/// `/proc`; elsewhere nothing is removed, since liveness is unknown). Once per folder and
/// process: a report writes sixty files into one folder.
fn remove_stale(folder: &Path) {
    static CLEANED: Mutex<Vec<PathBuf>> = Mutex::new(Vec::new());
    {
        let mut cleaned = CLEANED.lock().unwrap_or_else(PoisonError::into_inner);
        if cleaned.iter().any(|d| d == folder) {
            return;
        }
        cleaned.push(folder.to_owned());
    }
    if !Path::new("/proc/self").exists() {
        return;
    }
    let Ok(entries) = std::fs::read_dir(folder) else {
        return;
    };
    for entry in entries.flatten() {
        let name = entry.file_name();
        let Some(pid) = name
            .to_str()
            .and_then(|name| name.strip_prefix(".specula-"))
            .and_then(|rest| rest.split_once('-'))
            .and_then(|(pid, _)| pid.parse::<u32>().ok())
        else {
            continue;
        };
        if pid != std::process::id() && !Path::new(&format!("/proc/{pid}")).exists() {
            remove(&entry.path());
        }
    }
}

#[cfg(test)]
mod tests;
