//! Errors as Python exceptions, and the guard that keeps a Rust panic out of Python.

use std::panic::{catch_unwind, AssertUnwindSafe};
use std::path::Path;

use pyo3::exceptions::{PyOSError, PyRuntimeError, PyValueError};
use pyo3::PyErr;

/// A bad value: the library's one-line message.
pub fn value_error(message: impl Into<String>) -> PyErr {
    PyValueError::new_err(message.into())
}

/// `message` about reading `path`: `OSError` when the path is not a readable regular file
/// (missing, a folder, a device), `ValueError` when the file was read and its content refused.
pub fn file_error(path: &Path, message: impl Into<String>) -> PyErr {
    let message = message.into();
    match std::fs::metadata(path) {
        Ok(metadata) if metadata.is_file() => PyValueError::new_err(message),
        _ => PyOSError::new_err(message),
    }
}

/// Runs `work`, turning a panic (a bug in specula) into a `RuntimeError` that says so, so a
/// panic never unwinds into the interpreter.
pub fn guarded<T>(work: impl FnOnce() -> Result<T, PyErr>) -> Result<T, PyErr> {
    catch_unwind(AssertUnwindSafe(work)).unwrap_or_else(|panic| {
        let what = panic
            .downcast_ref::<&str>()
            .map(|s| (*s).to_owned())
            .or_else(|| panic.downcast_ref::<String>().cloned())
            .unwrap_or_else(|| "unknown panic".to_owned());
        Err(PyRuntimeError::new_err(format!(
            "internal error in specula (a bug, please report it): {what}"
        )))
    })
}
