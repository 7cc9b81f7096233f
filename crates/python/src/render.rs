//! Rendering a scene (a file or the embedded default) to an `H x W x 3` float32 array of
//! linear radiance: the rasterizer with direct lights, or the path tracer under an
//! environment, as `specula render`.

use std::path::PathBuf;

use numpy::IntoPyArray;
use pyo3::exceptions::PyUserWarning;
use pyo3::prelude::*;
use specula_render::ibl::{render_ibl, Environment, IblSettings, Strategy};
use specula_render::{
    render as rasterize, IlluminationModel, Image, Overrides, Scene, Shading, DEFAULT_SCENE,
};

use crate::arrays::{self, shaped, unsigned};
use crate::errors::{file_error, guarded, value_error};
use crate::options::{choose, exponent, geometry, lobe_kind, normalisation};

/// `image` as an `H x W x 3` float32 array.
pub fn image_array(py: Python<'_>, image: &Image) -> PyResult<Py<PyAny>> {
    let shape = [image.height() as usize, image.width() as usize, 3];
    let values: Vec<f32> = image.pixels().iter().flat_map(|p| p.to_array()).collect();
    Ok(shaped(&shape, values)?.into_pyarray(py).into_any().unbind())
}

/// The embedded default scene's TOML, to copy and edit (``specula render
/// --dump-default-scene``).
#[pyfunction]
pub fn default_scene() -> &'static str {
    DEFAULT_SCENE
}

/// Renders a scene to linear radiance.
///
/// Parameters
/// ----------
/// scene : str or os.PathLike, optional
///     A scene file (TOML, see docs/scenes.md); the embedded default when omitted.
/// lobe, n, geometry, normalisation, shading, model, width, height, samples
///     Override every material's lobe and the scene's settings, as the CLI's options.
/// environment : str, optional
///     ``"sky"`` or an HDR/EXR file: path-traced image-based lighting instead of the
///     scene's lights (``shading`` and ``model`` do not apply).
/// spp, seed : int
///     With an environment: samples per pixel and the seed of the uniform numbers.
///
/// Returns
/// -------
/// numpy.ndarray
///     float32, shape ``(height, width, 3)``, linear RGB radiance.
#[pyfunction]
#[pyo3(signature = (scene = None, *, lobe = None, n = None, geometry = None, normalisation = None,
    shading = None, model = None, width = None, height = None, samples = None,
    environment = None, spp = 64, seed = 0))]
#[allow(clippy::too_many_arguments)]
pub fn render(
    py: Python<'_>,
    scene: Option<PathBuf>,
    lobe: Option<&str>,
    n: Option<f64>,
    geometry: Option<&str>,
    normalisation: Option<&str>,
    shading: Option<&str>,
    model: Option<&str>,
    width: Option<i64>,
    height: Option<i64>,
    samples: Option<i64>,
    environment: Option<PathBuf>,
    spp: i64,
    seed: i64,
) -> PyResult<Py<PyAny>> {
    guarded(|| {
        let overrides = Overrides {
            lobe: lobe.map(lobe_kind).transpose()?,
            n: n.map(exponent).transpose()?,
            geometry: geometry.map(self::geometry).transpose()?,
            normalisation: normalisation.map(self::normalisation).transpose()?,
            shading: shading
                .map(|text| choose(&Shading::ALL, Shading::id, text, "shading"))
                .transpose()?,
            model: model
                .map(|text| {
                    choose(
                        &IlluminationModel::ALL,
                        IlluminationModel::id,
                        text,
                        "model",
                    )
                })
                .transpose()?,
            // Only made unsigned here: the renderers refuse a size, samples or spp out of
            // their range, with the limits in the message.
            width: width.map(|w| unsigned("width", w)).transpose()?,
            height: height.map(|h| unsigned("height", h)).transpose()?,
            samples: samples.map(|s| unsigned("samples", s)).transpose()?,
        };
        let spp = unsigned("spp", spp)?;
        let seed = arrays::seed(seed)?;
        if environment.is_some() && (shading.is_some() || model.is_some()) {
            return Err(value_error(
                "shading and model do not apply under an environment (it is path traced); drop \
                    them",
            ));
        }
        let loaded =
            Scene::from_file_or_default(scene.as_deref(), environment.is_some()).map_err(|e| {
                match &scene {
                    Some(path) => file_error(path, e.to_string()),
                    None => value_error(e.to_string()),
                }
            })?;
        for warning in &loaded.warnings {
            let text = std::ffi::CString::new(warning.to_string())
                .unwrap_or_else(|_| c"a scene warning".to_owned());
            PyErr::warn(py, &py.get_type::<PyUserWarning>(), &text, 1)?;
        }
        let mut scene = loaded.scene;
        scene.apply(&overrides);
        scene.check_lobes().map_err(value_error)?;
        let environment = match environment {
            None => None,
            Some(name) => {
                Some(Environment::named(&name).map_err(|e| file_error(&name, e.to_string()))?)
            }
        };
        let image = py.detach(|| match &environment {
            Some(environment) => {
                let settings = IblSettings {
                    spp,
                    seed,
                    strategy: Strategy::Mis,
                };
                render_ibl(&scene, environment, &settings, &|_, _| {}).map_err(|e| e.to_string())
            }
            None => rasterize(&scene, &|_, _| {}).map_err(|e| e.to_string()),
        });
        image_array(py, &image.map_err(value_error)?)
    })
}
