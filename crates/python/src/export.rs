//! Shader export: a lobe as text (or SPIR-V bytes) for another pipeline, as `specula shader`.

use pyo3::prelude::*;
use pyo3::types::PyBytes;
use specula::{Geometry, Normalisation};
use specula_gpu::export::{ExportFormat, GlslVersion, Options, ShaderCode};

use crate::errors::value_error;
use crate::options::choose;

/// The languages and formats :meth:`Lobe.shader` writes.
#[pyfunction]
pub fn languages() -> Vec<&'static str> {
    ExportFormat::ALL.iter().map(|format| format.id()).collect()
}

/// `lobe`, shaded with `geometry` and `normalisation`, in `language`: a `str`, or `bytes` for
/// SPIR-V.
pub fn shader(
    py: Python<'_>,
    lobe: &specula::Lobe,
    (geometry, normalisation): (Geometry, Normalisation),
    language: &str,
    glsl_version: &str,
    example: bool,
    n_input: bool,
) -> PyResult<Py<PyAny>> {
    let format = ExportFormat::parse(language).map_err(value_error)?;
    let glsl = choose(
        &GlslVersion::ALL,
        GlslVersion::id,
        glsl_version,
        "GLSL version",
    )?;
    let code = format
        .write(
            lobe,
            geometry,
            normalisation,
            Options {
                example,
                glsl,
                n_input,
            },
        )
        .map_err(value_error)?;
    Ok(match code {
        ShaderCode::Text(text) => text.into_pyobject(py)?.into_any().unbind(),
        ShaderCode::SpirV(_) => PyBytes::new(py, &code.to_bytes()).into_any().unbind(),
    })
}
