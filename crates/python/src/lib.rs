//! specula for Python: the extension module `specula._specula`, one thin face over the
//! workspace's libraries, as the `specula` command is the other.
//!
//! Every function here converts Python values to the libraries' types, calls one library
//! function with the GIL released where the work is long, and converts back: NumPy arrays for
//! arrays, JSON text (the CLI's own serialisation, parsed by `python/specula/__init__.py`)
//! for rows and reports, so a row reads the same from both faces. Errors are `ValueError`
//! (a bad value), `OSError` (a file that cannot be read) or `TypeError` (not an array), each
//! with the one-line message the CLI prints; a panic is caught before it reaches Python.

mod analysis;
mod arrays;
mod decide;
mod errors;
mod export;
mod lobe;
mod microfacet;
mod options;
mod render;
mod volume;

use pyo3::prelude::*;

/// The extension module: classes and functions that `specula/__init__.py` re-exports.
#[pymodule]
fn _specula(module: &Bound<'_, PyModule>) -> PyResult<()> {
    module.add_class::<lobe::Lobe>()?;
    module.add_class::<volume::Volume>()?;
    module.add_class::<microfacet::Microfacet>()?;
    module.add_function(wrap_pyfunction!(lobe::lobe_ids, module)?)?;
    module.add_function(wrap_pyfunction!(lobe::models_json, module)?)?;
    module.add_function(wrap_pyfunction!(analysis::zones_json, module)?)?;
    module.add_function(wrap_pyfunction!(analysis::analyze_json, module)?)?;
    module.add_function(wrap_pyfunction!(analysis::claims_json, module)?)?;
    module.add_function(wrap_pyfunction!(decide::recommend_json, module)?)?;
    module.add_function(wrap_pyfunction!(decide::design_json, module)?)?;
    module.add_function(wrap_pyfunction!(decide::cost_json, module)?)?;
    module.add_function(wrap_pyfunction!(decide::report, module)?)?;
    module.add_function(wrap_pyfunction!(render::render, module)?)?;
    module.add_function(wrap_pyfunction!(render::default_scene, module)?)?;
    module.add_function(wrap_pyfunction!(volume::render_volume, module)?)?;
    module.add_function(wrap_pyfunction!(export::languages, module)?)?;
    module.add("__version__", env!("CARGO_PKG_VERSION"))?;
    Ok(())
}
