//! Volumes: a scan read from NIfTI, DICOM (a series folder or an enhanced object) or an
//! InVesalius project, or a built-in phantom, as an array with its affine; and rendered by
//! the CPU ray marcher with any lobe as the specular term, as `specula volume`.

use std::path::{Path, PathBuf};

use numpy::ndarray::{Array2, ShapeBuilder};
use numpy::{IntoPyArray, ToPyArray};
use pyo3::prelude::*;
use specula_volume::dvr::{render_dvr, DvrSettings, Shading, View};
use specula_volume::phantom::BuiltIn;
use specula_volume::transfer::TransferFunction;
use specula_volume::{self as volume, Units};

use crate::arrays::unsigned;
use crate::errors::{file_error, guarded, value_error};
use crate::options::{choose, geometry, normalisation, parse};
use crate::render::image_array;

/// A scalar volume on a regular grid, placed in world millimetres (RAS, as NIfTI).
///
/// Build one with :meth:`Volume.load` (a file or folder) or :meth:`Volume.phantom`.
#[pyclass(frozen, module = "specula._specula")]
pub struct Volume {
    volume: volume::Volume,
    /// The built-in it was made from, whose transfer function is its default.
    built_in: Option<BuiltIn>,
}

#[pymethods]
impl Volume {
    /// Reads a NIfTI file (``.nii``, ``.nii.gz``), a DICOM series folder or enhanced
    /// multi-frame object, or an InVesalius project (``.inv3``).
    #[staticmethod]
    fn load(py: Python<'_>, path: PathBuf) -> PyResult<Self> {
        guarded(|| {
            let read = py.detach(|| volume::read(&path));
            Ok(Self {
                volume: read.map_err(|e| volume_error(&path, e.to_string()))?,
                built_in: None,
            })
        })
    }

    /// A built-in volume (``"phantom"``, the 3D Shepp-Logan head, or ``"marschner-lobb"``)
    /// of ``side`` voxels a side (8 to 512).
    #[staticmethod]
    #[pyo3(signature = (name, side = 128))]
    fn phantom(py: Python<'_>, name: &str, side: i64) -> PyResult<Self> {
        guarded(|| {
            let built_in = choose(&BuiltIn::ALL, BuiltIn::id, name, "phantom")?;
            // `make` refuses a side out of `BuiltIn::SIDES`, naming the range.
            let side = unsigned("side", side)?;
            let made = py.detach(|| built_in.make(side));
            Ok(Self {
                volume: made.map_err(|e| value_error(e.to_string()))?,
                built_in: Some(built_in),
            })
        })
    }

    /// The samples, float32 of shape ``(nx, ny, nz)`` indexed ``[i, j, k]`` as nibabel's
    /// ``get_fdata()`` (a Fortran-ordered copy).
    #[getter]
    fn data(&self, py: Python<'_>) -> PyResult<Py<PyAny>> {
        guarded(|| {
            let [nx, ny, nz] = self.volume.dims();
            let samples = self.volume.samples().to_f32();
            let array = numpy::ndarray::ArrayView3::from_shape((nx, ny, nz).f(), &samples)
                .map_err(|e| value_error(e.to_string()))?;
            Ok(array.to_pyarray(py).into_any().unbind())
        })
    }

    /// The 4 x 4 float64 map from grid index ``(i, j, k, 1)`` to world millimetres (RAS).
    #[getter]
    fn affine(&self, py: Python<'_>) -> Py<PyAny> {
        let (linear, origin) = (self.volume.to_world(), self.volume.origin());
        let mut affine = Array2::<f64>::eye(4);
        for row in 0..3 {
            for column in 0..3 {
                affine[[row, column]] = f64::from(linear.col(column)[row]);
            }
            affine[[row, 3]] = f64::from(origin[row]);
        }
        affine.into_pyarray(py).into_any().unbind()
    }

    /// The grid's size ``(nx, ny, nz)``.
    #[getter]
    fn shape(&self) -> (usize, usize, usize) {
        let [nx, ny, nz] = self.volume.dims();
        (nx, ny, nz)
    }

    /// The voxel spacing along each grid axis, in millimetres.
    #[getter]
    fn spacing(&self) -> (f32, f32, f32) {
        self.volume.spacing().into()
    }

    /// ``"hounsfield"`` (CT) or ``"arbitrary"``.
    #[getter]
    fn units(&self) -> &'static str {
        match self.volume.units() {
            Units::Hounsfield => "hounsfield",
            Units::Arbitrary => "arbitrary",
        }
    }

    fn __repr__(&self) -> String {
        let [nx, ny, nz] = self.volume.dims();
        format!("Volume({nx} x {ny} x {nz}, {})", self.units())
    }
}

/// `OSError` for a path that cannot be read as a file or folder, `ValueError` otherwise.
fn volume_error(path: &Path, message: String) -> PyErr {
    if path.is_dir() {
        value_error(message)
    } else {
        file_error(path, message)
    }
}

/// Renders a volume by direct volume rendering (ray marching) with ``lobe`` as the specular
/// term.
///
/// Parameters
/// ----------
/// volume : Volume
/// lobe, n, geometry, normalisation
///     The specular lobe, as :class:`Lobe`.
/// width, height : int
///     The image size.
/// view : str
///     ``"anterior"``, ``"posterior"``, ``"left"``, ``"right"``, ``"superior"``,
///     ``"inferior"`` (or their aliases).
/// transfer : str, optional
///     A preset (``"ct-bone"``, ``"ct-soft-tissue"``, ``"mr"``, ``"surface"``); the
///     volume's default when omitted.
///
/// Returns
/// -------
/// numpy.ndarray
///     float32, shape ``(height, width, 3)``, linear RGB.
#[pyfunction]
#[pyo3(signature = (volume, *, lobe = "pow", n = 64.0, geometry = "blinn",
    normalisation = "none", width = 256, height = 256, view = "anterior", transfer = None))]
#[allow(clippy::too_many_arguments)]
pub fn render_volume(
    py: Python<'_>,
    volume: &Volume,
    lobe: &str,
    n: f64,
    geometry: &str,
    normalisation: &str,
    width: i64,
    height: i64,
    view: &str,
    transfer: Option<&str>,
) -> PyResult<Py<PyAny>> {
    guarded(|| {
        let shading = Shading::new(
            parse(lobe, n)?,
            self::geometry(geometry)?,
            self::normalisation(normalisation)?,
        );
        // The ray marcher's plan refuses an image beyond its pixel budget.
        let width = unsigned("width", width)?;
        let height = unsigned("height", height)?;
        let view = View::parse(view).map_err(value_error)?;
        let data = &volume.volume;
        let function = match (transfer, volume.built_in) {
            (Some(name), _) => {
                TransferFunction::preset(name).map_err(|e| value_error(e.to_string()))?
            }
            (None, Some(built_in)) => built_in.transfer(),
            (None, None) => TransferFunction::default_for(data),
        }
        .for_volume(data);
        let settings = DvrSettings::new(width, height, view, Some(shading));
        let image = py
            .detach(|| render_dvr(data, &function, &settings, &|| {}))
            .map_err(|e| value_error(e.to_string()))?;
        image_array(py, &image)
    })
}
