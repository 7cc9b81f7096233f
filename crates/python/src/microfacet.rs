//! `specula.Microfacet`: a lobe as a microfacet normal distribution, or Beckmann's or GGX's
//! (`specula::microfacet`), evaluated on float64 arrays of cosines.

use numpy::IntoPyArray;
use pyo3::prelude::*;
use specula::microfacet::Distribution;

use crate::arrays::{contiguous, first_non_finite, floats, non_finite, shaped, Floats};
use crate::errors::{guarded, value_error};

/// A normal distribution of a microfacet model: ``D(h)``, Smith's ``Lambda``, ``G1`` and the
/// height-correlated ``G2``.
///
/// Make one with ``Microfacet(lobe)`` (a ``specula.Lobe``, read as ``C(n) lobe(cos theta_h)``
/// normalised to a projected area of one, its masking tabulated from its own projected area),
/// ``Microfacet.beckmann(alpha)`` or ``Microfacet.ggx(alpha)`` (closed forms).
#[pyclass(frozen, module = "specula._specula")]
pub struct Microfacet {
    distribution: Distribution,
}

#[pymethods]
impl Microfacet {
    #[new]
    fn new(py: Python<'_>, lobe: &crate::lobe::Lobe) -> PyResult<Self> {
        let core = *lobe.core();
        guarded(|| {
            let distribution = py.detach(|| Distribution::lobe(core.kind(), core.exponent()));
            Ok(Self { distribution })
        })
    }

    /// Beckmann's distribution of roughness ``alpha`` in (0, 10].
    #[staticmethod]
    fn beckmann(alpha: f64) -> PyResult<Self> {
        Ok(Self {
            distribution: Distribution::Beckmann {
                alpha: roughness(alpha)?,
            },
        })
    }

    /// GGX (Trowbridge-Reitz) of roughness ``alpha`` in (0, 10].
    #[staticmethod]
    fn ggx(alpha: f64) -> PyResult<Self> {
        Ok(Self {
            distribution: Distribution::Ggx {
                alpha: roughness(alpha)?,
            },
        })
    }

    /// ``D`` at the half vector's cosines (float64 array or number).
    fn d(&self, py: Python<'_>, cos_h: &Bound<'_, PyAny>) -> PyResult<Py<PyAny>> {
        apply(py, cos_h, "cos_h", |c| self.distribution.d(c))
    }

    /// Smith's ``Lambda`` at directions of these cosines (infinite at or below the horizon).
    fn smith_lambda(&self, py: Python<'_>, cos: &Bound<'_, PyAny>) -> PyResult<Py<PyAny>> {
        apply(py, cos, "cos", |c| self.distribution.lambda(c))
    }

    /// Smith's masking ``G1 = 1 / (1 + Lambda)``.
    fn g1(&self, py: Python<'_>, cos: &Bound<'_, PyAny>) -> PyResult<Py<PyAny>> {
        apply(py, cos, "cos", |c| self.distribution.g1(c))
    }

    /// The height-correlated masking-shadowing of a pair of directions' cosines (numbers).
    fn g2(&self, cos_o: f64, cos_i: f64) -> f64 {
        self.distribution.g2(cos_o, cos_i)
    }

    fn __repr__(&self) -> String {
        format!("Microfacet({})", self.distribution.label())
    }
}

fn roughness(alpha: f64) -> PyResult<f64> {
    if alpha.is_finite() && alpha > 0.0 && alpha <= 10.0 {
        Ok(alpha)
    } else {
        Err(value_error(format!(
            "alpha must be a roughness in (0, 10], not {alpha}"
        )))
    }
}

/// `f` at each of `values` (a float64 array of any shape, or a number).
fn apply(
    py: Python<'_>,
    values: &Bound<'_, PyAny>,
    name: &str,
    f: impl Fn(f64) -> f64,
) -> PyResult<Py<PyAny>> {
    match floats(values, name)? {
        Floats::Scalar(x) if !x.is_finite() => Err(non_finite(name, 0)),
        Floats::Scalar(x) => Ok(f(x).into_pyobject(py)?.into_any().unbind()),
        Floats::Single(_) => Err(value_error(format!(
            "{name} is float32; the microfacet distributions take float64 (exact): convert \
             with {name}.astype(numpy.float64)"
        ))),
        Floats::Double(array) => {
            let view = array.as_array();
            let input = contiguous(&view)?;
            if let Some(index) = first_non_finite(&input) {
                return Err(non_finite(name, index));
            }
            let output: Vec<f64> = input.iter().map(|&x| f(x)).collect();
            Ok(shaped(view.shape(), output)?
                .into_pyarray(py)
                .into_any()
                .unbind())
        }
    }
}
