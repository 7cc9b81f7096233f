//! The CLI's option texts (`--lobe`, `-n`, `--geometry`, `--normalisation`, and any choice by
//! id) as the libraries' values, refused with the one-line messages the CLI prints.

use pyo3::prelude::*;
use specula::{Exponent, Geometry, LobeKind, Normalisation};

use crate::errors::value_error;

/// The one of `all` whose id is `text`, or the library's message naming the valid ones.
pub fn choose<T: Copy>(
    all: &[T],
    id: fn(T) -> &'static str,
    text: &str,
    what: &str,
) -> PyResult<T> {
    specula::choose(all, id, text, what, &format!("{what}s")).map_err(value_error)
}

/// The CLI's lobe text (`cosquad`, `cosquad:v=5`, `@lobe.toml`, `=t^n`) as a lobe kind.
pub fn lobe_kind(text: &str) -> PyResult<LobeKind> {
    specula_render::lobe_file::parse_lobe(text, None).map_err(value_error)
}

/// Parses the CLI's lobe text and `n`, checking a user's lobe at `n` as the CLI does.
pub fn parse(lobe: &str, n: f64) -> PyResult<specula::Lobe> {
    let kind = lobe_kind(lobe)?;
    let n = exponent(n)?;
    specula::Lobe::checked(kind, n).map_err(|e| value_error(e.to_string()))
}

/// `n` as an [`Exponent`], refused with the library's message outside `[1, 1000]`.
pub fn exponent(n: f64) -> PyResult<Exponent> {
    Exponent::try_new(n).map_err(|e| value_error(e.to_string()))
}

/// A geometry by id.
pub fn geometry(id: &str) -> PyResult<Geometry> {
    Geometry::parse(id).map_err(|e| value_error(e.to_string()))
}

/// A normalisation by id.
pub fn normalisation(id: &str) -> PyResult<Normalisation> {
    Normalisation::parse(id).map_err(|e| value_error(e.to_string()))
}
