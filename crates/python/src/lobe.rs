//! `specula.Lobe`: one model prepared for one `n`, with its geometry and normalisation;
//! evaluated on arrays (float32 through the SIMD batch kernels, float64 exact), sampled from
//! given uniforms, analysed, and exported.

use std::sync::OnceLock;

use glam::DVec3;
use numpy::{Element, IntoPyArray, PyArrayDyn, PyArrayMethods, PyUntypedArrayMethods};
use pyo3::prelude::*;
use rayon::prelude::*;
use specula::analysis::{
    energy_ratio, error_figures, max_reciprocity_error, specular_albedo_per_unit, Precision,
    DEFAULT_SAMPLES_PER_ZONE,
};
use specula::claims::ClaimOptions;
use specula::sampling::SpecularSampler;
use specula::{Brdf, Geometry, LobeKind, Normalisation};

use crate::arrays::{
    self, contiguous, count, first_non_finite, float64_rows, floats, map_chunks, non_finite,
    shaped, tuple, Finite, Floats,
};
use crate::errors::{guarded, value_error};
use crate::options::{geometry, normalisation, parse};

/// A specular lobe prepared for one exponent.
///
/// Parameters
/// ----------
/// lobe : str
///     A lobe id (``specula.lobe_ids()``), optionally with parameters (``"cosquad:v=5"``),
///     a lobe file (``"@my_lobe.toml"``) or a formula (``"=t^n"``), as the CLI's ``--lobe``.
/// n : float
///     The specular exponent, in [1, 1000].
/// geometry : {"phong", "blinn"}
///     What the cosine ``t`` is: R.V (Phong) or N.H (Blinn).
/// normalisation : str
///     The constant ``N(n)`` of the specular term ``N(n) lobe(t)`` (``"none"``, ``"lobe"``,
///     ``"thesis-phong"``, ``"lafortune"``, ``"blinn"``, ``"blinn-approx"``).
#[pyclass(frozen, module = "specula._specula")]
pub struct Lobe {
    lobe: specula::Lobe,
    geometry: Geometry,
    normalisation: Normalisation,
    sampler: OnceLock<SpecularSampler>,
}

impl Lobe {
    /// The prepared core lobe.
    pub fn core(&self) -> &specula::Lobe {
        &self.lobe
    }

    /// Its geometry and normalisation.
    pub fn shading(&self) -> (Geometry, Normalisation) {
        (self.geometry, self.normalisation)
    }

    fn sampler(&self) -> &SpecularSampler {
        self.sampler
            .get_or_init(|| SpecularSampler::new(self.lobe, self.geometry, self.normalisation))
    }

    /// Applies `each` to every `(wo, wi)` row pair of `wo` (`(3,)` or `(..., 3)`) and `wi`
    /// (`(..., 3)`), in parallel, with the GIL released.
    fn pairs<'py>(
        &self,
        py: Python<'py>,
        wo: &Bound<'py, PyAny>,
        wi: &Bound<'py, PyAny>,
        each: &(dyn Fn(&SpecularSampler, DVec3, DVec3) -> f64 + Sync),
    ) -> PyResult<Py<PyAny>> {
        let wi = float64_rows(wi, "wi", 3)?;
        let wi_view = wi.as_array();
        let leading = wi_view.shape()[..wi_view.ndim() - 1].to_vec();
        let wi = directions(&contiguous(&wi_view)?, "wi")?;
        let wo = outgoing(wo, &leading)?;
        let sampler = self.sampler();
        let values: Vec<f64> = py.detach(|| {
            wi.par_iter()
                .enumerate()
                .map(|(k, &wi)| each(sampler, wo.at(k), wi))
                .collect()
        });
        Ok(shaped(&leading, values)?
            .into_pyarray(py)
            .into_any()
            .unbind())
    }
}

/// `wo`: one direction for every row, or one per row.
enum Outgoing {
    One(DVec3),
    Each(Vec<DVec3>),
}

impl Outgoing {
    fn at(&self, k: usize) -> DVec3 {
        match self {
            Outgoing::One(wo) => *wo,
            Outgoing::Each(all) => all[k],
        }
    }
}

fn outgoing(wo: &Bound<'_, PyAny>, leading: &[usize]) -> PyResult<Outgoing> {
    let wo = float64_rows(wo, "wo", 3)?;
    let view = wo.as_array();
    let rows = directions(&contiguous(&view)?, "wo")?;
    if view.ndim() == 1 {
        return Ok(Outgoing::One(rows[0]));
    }
    if &view.shape()[..view.ndim() - 1] != leading {
        return Err(value_error(format!(
            "wo has shape {}; it must be (3,) or the other array's leading shape {} with 3 last",
            tuple(view.shape()),
            tuple(leading)
        )));
    }
    Ok(Outgoing::Each(rows))
}

/// Rows of 3 as unit vectors; a non-finite or zero row is refused by index.
fn directions(flat: &[f64], name: &str) -> PyResult<Vec<DVec3>> {
    if let Some(index) = first_non_finite(flat) {
        return Err(non_finite(name, index));
    }
    flat.chunks_exact(3)
        .enumerate()
        .map(|(row, v)| {
            DVec3::new(v[0], v[1], v[2]).try_normalize().ok_or_else(|| {
                value_error(format!(
                    "{name}[{row}] has zero length; directions must be non-zero (they are \
                        normalised)"
                ))
            })
        })
        .collect()
}

#[pymethods]
impl Lobe {
    #[new]
    #[pyo3(signature = (lobe, n, geometry = "phong", normalisation = "none"))]
    fn new(lobe: &str, n: f64, geometry: &str, normalisation: &str) -> PyResult<Self> {
        guarded(|| {
            Ok(Self {
                lobe: parse(lobe, n)?,
                geometry: self::geometry(geometry)?,
                normalisation: self::normalisation(normalisation)?,
                sampler: OnceLock::new(),
            })
        })
    }

    /// The lobe's id with its parameters (``"cosquad"``, ``"cosquad:v=5"``).
    #[getter]
    fn id(&self) -> String {
        self.lobe.kind().to_string()
    }

    /// The exponent.
    #[getter]
    fn n(&self) -> f64 {
        self.lobe.exponent().get()
    }

    /// ``"phong"`` or ``"blinn"``.
    #[getter]
    fn geometry(&self) -> &'static str {
        self.geometry.id()
    }

    /// The normalisation's id.
    #[getter]
    fn normalisation(&self) -> &'static str {
        self.normalisation.id()
    }

    /// The normalisation constant ``N(n)`` for this lobe.
    #[getter]
    fn constant(&self) -> PyResult<f64> {
        guarded(|| Ok(self.normalisation.constant_for(&self.lobe)))
    }

    fn __repr__(&self) -> String {
        format!(
            "Lobe('{}', n={}, geometry='{}', normalisation='{}')",
            self.lobe.kind(),
            self.lobe.exponent(),
            self.geometry.id(),
            self.normalisation.id()
        )
    }

    /// The lobe at cosines ``t`` (values in [0, 1]; ``t <= 0`` gives 0, ``t`` above 1 is read
    /// as 1).
    ///
    /// Parameters
    /// ----------
    /// t : numpy.ndarray or float
    ///     Cosines, any shape. ``float32`` runs the SIMD batch kernels, ``float64`` the exact
    ///     path, a Python number gives a float. Other dtypes and non-finite values are refused.
    /// out : numpy.ndarray, optional
    ///     A writable C-contiguous array of ``t``'s dtype and shape to write into (no
    ///     allocation). On an error it may be partly written.
    ///
    /// Returns
    /// -------
    /// numpy.ndarray or float
    ///     The values, of ``t``'s shape and dtype (``out`` itself when given).
    #[pyo3(signature = (t, out = None))]
    fn __call__<'py>(
        &self,
        py: Python<'py>,
        t: &Bound<'py, PyAny>,
        out: Option<&Bound<'py, PyAny>>,
    ) -> PyResult<Py<PyAny>> {
        guarded(|| self.evaluate(py, t, out))
    }

    /// The same as calling the lobe: ``lobe.eval(t)`` is ``lobe(t)``.
    #[pyo3(signature = (t, out = None))]
    fn eval<'py>(
        &self,
        py: Python<'py>,
        t: &Bound<'py, PyAny>,
        out: Option<&Bound<'py, PyAny>>,
    ) -> PyResult<Py<PyAny>> {
        self.__call__(py, t, out)
    }

    /// The error figures against ``t^n`` (SPEC section 4), exact arithmetic.
    ///
    /// Returns
    /// -------
    /// dict
    ///     ``epicentre_max_rel``, ``epicentre_max_abs``, ``bloom_max_abs``, ``tail_max_abs``,
    ///     ``rms`` and the other figures of ``specula analyze --format json``, taken on
    ///     ``samples_per_zone`` cosines per zone (``specula analyze``'s where ``None``).
    #[pyo3(signature = (samples_per_zone = None))]
    fn errors_json(&self, py: Python<'_>, samples_per_zone: Option<i64>) -> PyResult<String> {
        let lobe = self.lobe;
        guarded(|| {
            let samples_per_zone = samples_per_zone.map_or(Ok(DEFAULT_SAMPLES_PER_ZONE), |s| {
                count("samples_per_zone", s, 2, 1_000_001)
            })?;
            let figures = py.detach(|| error_figures(&lobe, &mut Precision::F64, samples_per_zone));
            serde_json::to_string(&figures).map_err(|e| value_error(e.to_string()))
        })
    }

    /// The lobe's energy relative to ``t^n``: ``(n + 1) int_0^{pi/2} lobe(cos g) sin g dg``.
    fn energy_ratio(&self, py: Python<'_>) -> PyResult<f64> {
        let lobe = self.lobe;
        guarded(|| Ok(py.detach(|| energy_ratio(&lobe))))
    }

    /// The specular term's directional albedo ``int N(n) lobe(t) cos(theta_i) dwi`` for an
    /// outgoing direction at polar angle ``theta_o`` (radians, clamped to [0, pi/2]).
    fn albedo(&self, py: Python<'_>, theta_o: f64) -> PyResult<f64> {
        guarded(|| {
            if !theta_o.is_finite() {
                return Err(value_error(format!(
                    "theta_o is {theta_o}; give a finite angle in radians"
                )));
            }
            let (lobe, geometry, constant) = (self.lobe, self.geometry, self.constant()?);
            Ok(py.detach(|| constant * specular_albedo_per_unit(&lobe, geometry, theta_o)))
        })
    }

    /// The worst Helmholtz asymmetry ``|f(a, b) - f(b, a)| / max`` of the specular BRDF over
    /// ``pairs`` direction pairs drawn uniformly on the hemisphere from ``seed`` (each
    /// ``specula claims``' where ``None``).
    #[pyo3(signature = (pairs = None, seed = None))]
    fn reciprocity_error(
        &self,
        py: Python<'_>,
        pairs: Option<i64>,
        seed: Option<i64>,
    ) -> PyResult<f64> {
        guarded(|| {
            let defaults = ClaimOptions::default();
            let pairs = pairs.map_or(Ok(defaults.reciprocity_pairs), |p| {
                count("pairs", p, 1, 10_000_000)
            })?;
            let seed = seed.map_or(Ok(defaults.seed), arrays::seed)?;
            let brdf = Brdf::new(
                DVec3::ZERO,
                DVec3::ONE,
                self.lobe,
                self.geometry,
                self.normalisation,
            );
            Ok(py.detach(|| {
                use rand::SeedableRng;
                let mut rng = rand_pcg::Pcg64::seed_from_u64(seed);
                max_reciprocity_error(|a, b| brdf.f(a, b), pairs, &mut rng)
            }))
        })
    }

    /// Draws incident directions from given uniform numbers, by the lobe's importance sampler.
    ///
    /// Parameters
    /// ----------
    /// wo : numpy.ndarray
    ///     float64, shape ``(3,)`` (one outgoing direction for every draw) or ``(..., 3)``;
    ///     z is the normal; normalised here.
    /// u : numpy.ndarray
    ///     float64, shape ``(..., 2)``, each in [0, 1).
    ///
    /// Returns
    /// -------
    /// wi : numpy.ndarray
    ///     float64, shape ``(..., 3)``: unit directions towards the light; zero where there
    ///     is no sample (the draw fell below the horizon, or ``wo`` is below it).
    /// pdf : numpy.ndarray
    ///     float64, shape ``(...)``: each direction's density with respect to solid angle
    ///     (0 where there is no sample).
    fn sample<'py>(
        &self,
        py: Python<'py>,
        wo: &Bound<'py, PyAny>,
        u: &Bound<'py, PyAny>,
    ) -> PyResult<(Py<PyAny>, Py<PyAny>)> {
        guarded(|| {
            let u = float64_rows(u, "u", 2)?;
            let u_view = u.as_array();
            let leading = u_view.shape()[..u_view.ndim() - 1].to_vec();
            let flat = contiguous(&u_view)?;
            if let Some(index) = flat.iter().position(|v| !(0.0..1.0).contains(v)) {
                return Err(value_error(format!(
                    "u holds {} at flat index {index}; uniform numbers must be in [0, 1)",
                    flat[index]
                )));
            }
            let wo = outgoing(wo, &leading)?;
            let sampler = self.sampler();
            let drawn: Vec<([f64; 3], f64)> = py.detach(|| {
                flat.par_chunks_exact(2)
                    .enumerate()
                    .map(|(k, u)| match sampler.sample(wo.at(k), [u[0], u[1]]) {
                        Some(sample) => (sample.wi.to_array(), sample.pdf),
                        None => ([0.0; 3], 0.0),
                    })
                    .collect()
            });
            let mut shape = leading.clone();
            shape.push(3);
            let wi: Vec<f64> = drawn.iter().flat_map(|(wi, _)| *wi).collect();
            let pdf: Vec<f64> = drawn.iter().map(|(_, pdf)| *pdf).collect();
            Ok((
                shaped(&shape, wi)?.into_pyarray(py).into_any().unbind(),
                shaped(&leading, pdf)?.into_pyarray(py).into_any().unbind(),
            ))
        })
    }

    /// The sampler's density of ``wi`` given ``wo`` (solid angle; 0 below the horizon).
    ///
    /// ``wo`` is float64 ``(3,)`` or ``(..., 3)``, ``wi`` float64 ``(..., 3)``; both are
    /// normalised here. Returns float64 of shape ``(...)``.
    fn pdf<'py>(
        &self,
        py: Python<'py>,
        wo: &Bound<'py, PyAny>,
        wi: &Bound<'py, PyAny>,
    ) -> PyResult<Py<PyAny>> {
        guarded(|| self.pairs(py, wo, wi, &|sampler, wo, wi| sampler.pdf(wo, wi)))
    }

    /// The specular term ``N(n) lobe(t)`` (per unit ``ks``) for direction pairs, shaped as
    /// :meth:`pdf`.
    fn value<'py>(
        &self,
        py: Python<'py>,
        wo: &Bound<'py, PyAny>,
        wi: &Bound<'py, PyAny>,
    ) -> PyResult<Py<PyAny>> {
        guarded(|| self.pairs(py, wo, wi, &|sampler, wo, wi| sampler.value(wo, wi)))
    }

    /// The lobe as source text for another pipeline.
    ///
    /// Parameters
    /// ----------
    /// language : str
    ///     ``"wgsl"``, ``"glsl"``, ``"hlsl"``, ``"msl"``, ``"spirv"`` (bytes), ``"osl"``
    ///     (a Blender Cycles script node), ``"mtlx"`` (a MaterialX document) or
    ///     ``"mitsuba"`` (a Mitsuba 3 BSDF plugin), as ``specula shader --lang``.
    /// glsl_version : str
    ///     With GLSL: ``"450"``, ``"300es"`` or ``"100"``.
    /// example : bool
    ///     Include the example fragment shader that calls the functions.
    /// n_input : bool
    ///     Take ``n`` as the functions' first argument, the constants computed from it in the
    ///     shader (``specula shader --n-input``; naga's languages, lobes whose constants are
    ///     closed forms of ``n``).
    #[pyo3(signature = (language, glsl_version = "450", example = false, n_input = false))]
    fn shader(
        &self,
        py: Python<'_>,
        language: &str,
        glsl_version: &str,
        example: bool,
        n_input: bool,
    ) -> PyResult<Py<PyAny>> {
        guarded(|| {
            crate::export::shader(
                py,
                self.core(),
                self.shading(),
                language,
                glsl_version,
                example,
                n_input,
            )
        })
    }
}

impl Lobe {
    fn evaluate<'py>(
        &self,
        py: Python<'py>,
        t: &Bound<'py, PyAny>,
        out: Option<&Bound<'py, PyAny>>,
    ) -> PyResult<Py<PyAny>> {
        let lobe = self.lobe;
        match floats(t, "t")? {
            Floats::Scalar(_) if out.is_some() => Err(value_error(
                "out is given but t is a number; out= takes an array of t's dtype and shape",
            )),
            Floats::Scalar(t) => {
                if !t.is_finite() {
                    return Err(non_finite("t", 0));
                }
                Ok(lobe.eval(t).into_pyobject(py)?.into_any().unbind())
            }
            Floats::Single(array) => {
                let view = array.as_array();
                let input = contiguous(&view)?;
                let kernel = |t: &[f32], o: &mut [f32]| lobe.eval_batch(t, o);
                evaluate_into(py, &input, view.shape(), out, "float32", &kernel)
            }
            Floats::Double(array) => {
                let view = array.as_array();
                let input = contiguous(&view)?;
                let kernel = |t: &[f64], o: &mut [f64]| {
                    for (o, &t) in o.iter_mut().zip(t) {
                        *o = lobe.eval(t);
                    }
                };
                evaluate_into(py, &input, view.shape(), out, "float64", &kernel)
            }
        }
    }
}

/// Runs `kernel` over `input` into `out` (checked: same dtype and shape, writable,
/// contiguous) or into a new array of `shape`.
fn evaluate_into<'py, T>(
    py: Python<'py>,
    input: &[T],
    shape: &[usize],
    out: Option<&Bound<'py, PyAny>>,
    dtype: &str,
    kernel: &(dyn Fn(&[T], &mut [T]) + Sync),
) -> PyResult<Py<PyAny>>
where
    T: Element + Finite,
{
    // Either `out`, checked, or a new array allocated by `numpy.empty`, as NumPy allocates
    // its own results (with its huge-page advice for large arrays; measured: 3.5x faster
    // than a zeroed allocation from here at 10 M); then written in place with the GIL
    // released.
    let refused = || {
        value_error(format!(
            "out must be a writable {dtype} array of t's shape {} (and not t itself)",
            tuple(shape)
        ))
    };
    let target = match out {
        Some(out) => {
            let array = out.cast::<PyArrayDyn<T>>().map_err(|_| refused())?;
            if array.shape() != shape {
                return Err(value_error(format!(
                    "out has shape {}; it must be t's, {}",
                    tuple(array.shape()),
                    tuple(shape)
                )));
            }
            array.clone()
        }
        None => py
            .import("numpy")?
            .getattr("empty")?
            .call1((shape.to_vec(), T::get_dtype(py)))?
            .cast_into::<PyArrayDyn<T>>()?,
    };
    {
        let mut written = target.try_readwrite().map_err(|_| refused())?;
        let slice = written.as_slice_mut().map_err(|_| {
            value_error("out is not C-contiguous; give a contiguous array (numpy.empty_like(t))")
        })?;
        py.detach(|| map_chunks(input, slice, kernel))
            .map_err(|index| non_finite("t", index))?;
    }
    Ok(target.into_any().unbind())
}

/// The ids of the built-in lobes, in the registry's order.
#[pyfunction]
pub fn lobe_ids() -> Vec<&'static str> {
    LobeKind::ALL.iter().map(|kind| kind.id()).collect()
}

/// The built-in lobes' registry as JSON: `specula models`' rows (id, summary, formula,
/// parameters, origin) with each lobe's plot colour.
#[pyfunction]
pub fn models_json() -> PyResult<String> {
    let rows = LobeKind::ALL
        .iter()
        .map(|kind| {
            let mut row = serde_json::to_value(kind.info())?;
            row["colour"] = kind.line_style().hex().into();
            Ok(row)
        })
        .collect::<Result<Vec<serde_json::Value>, serde_json::Error>>()
        .map_err(|e| value_error(e.to_string()))?;
    serde_json::to_string(&rows).map_err(|e| value_error(e.to_string()))
}
