//! The array contracts: which dtypes and shapes each function takes, checked by name before
//! any work, and the chunked parallel loops that evaluate them.
//!
//! An input of another dtype is refused (never converted behind the caller's back), a
//! non-finite value is refused with its index, and a non-contiguous array is read in order
//! (a copy of the view, not of garbage). Outputs are new C-ordered arrays of the input's shape.

use numpy::ndarray::{ArrayD, ArrayViewD, IxDyn};
use numpy::{PyReadonlyArrayDyn, PyUntypedArray, PyUntypedArrayMethods};
use pyo3::exceptions::PyTypeError;
use pyo3::prelude::*;
use rayon::prelude::*;

use crate::errors::value_error;

/// Elements per parallel chunk: small enough that a chunk's input stays in L2 between the
/// finiteness check and the kernel, large enough that scheduling is noise.
pub const CHUNK: usize = 16 * 1024;

/// An array argument of one of the two float dtypes.
pub enum Floats<'py> {
    /// `float32`: the SIMD batch kernels.
    Single(PyReadonlyArrayDyn<'py, f32>),
    /// `float64`: the exact path.
    Double(PyReadonlyArrayDyn<'py, f64>),
    /// A Python `float` or `int` (or NumPy scalar): the exact path, a `float` back.
    Scalar(f64),
}

/// Reads `object` as `name`: a `float32` or `float64` array, or a number.
pub fn floats<'py>(object: &Bound<'py, PyAny>, name: &str) -> PyResult<Floats<'py>> {
    if let Ok(array) = object.extract::<PyReadonlyArrayDyn<'py, f32>>() {
        return Ok(Floats::Single(array));
    }
    if let Ok(array) = object.extract::<PyReadonlyArrayDyn<'py, f64>>() {
        return Ok(Floats::Double(array));
    }
    if let Ok(array) = object.cast::<PyUntypedArray>() {
        return Err(value_error(format!(
            "{name} has dtype {}; specula takes float32 (the SIMD kernels) or float64 (exact): \
             convert with {name}.astype(numpy.float32) or numpy.float64",
            array.dtype()
        )));
    }
    if let Ok(value) = object.extract::<f64>() {
        return Ok(Floats::Scalar(value));
    }
    Err(PyTypeError::new_err(format!(
        "{name} is a {}; specula takes a NumPy array of float32 or float64, or a number",
        object.get_type().name()?
    )))
}

/// A `float64` array argument of shape `(..., last)` (or `(last,)` when `single` allows it).
pub fn float64_rows<'py>(
    object: &Bound<'py, PyAny>,
    name: &str,
    last: usize,
) -> PyResult<PyReadonlyArrayDyn<'py, f64>> {
    let array = object
        .extract::<PyReadonlyArrayDyn<'py, f64>>()
        .map_err(|_| match object.cast::<PyUntypedArray>() {
            Ok(array) => value_error(format!(
                "{name} has dtype {}; it must be float64 of shape (..., {last})",
                array.dtype()
            )),
            Err(_) => PyTypeError::new_err(format!(
                "{name} must be a NumPy float64 array of shape (..., {last})"
            )),
        })?;
    if array.shape().last() != Some(&last) {
        return Err(value_error(format!(
            "{name} has shape {:?}; it must be (..., {last})",
            array.shape()
        )));
    }
    Ok(array)
}

/// `view` as a contiguous slice: borrowed when it is one, copied in logical order when not.
pub fn contiguous<'a, T: Copy>(view: &'a ArrayViewD<'a, T>) -> std::borrow::Cow<'a, [T]> {
    match view.as_slice() {
        Some(slice) => std::borrow::Cow::Borrowed(slice),
        None => std::borrow::Cow::Owned(view.iter().copied().collect()),
    }
}

/// The index of a non-finite value in `values`, if any (a vectorisable scan first, the
/// search only on failure).
pub fn first_non_finite<T: Copy + Into<f64>>(values: &[T]) -> Option<usize> {
    let all_finite = values
        .iter()
        .fold(true, |ok, &v| ok & Into::<f64>::into(v).is_finite());
    if all_finite {
        None
    } else {
        values
            .iter()
            .position(|&v| !Into::<f64>::into(v).is_finite())
    }
}

/// The refusal of a non-finite value at flat index `index` of `name`.
pub fn non_finite(name: &str, index: usize) -> PyErr {
    value_error(format!(
        "{name} holds a non-finite value (NaN or infinity) at flat index {index}; \
         specula refuses it rather than return a NaN"
    ))
}

/// Applies `kernel` to `input` in parallel chunks after checking each chunk is finite;
/// `Err(index)` names a non-finite input.
pub fn map_chunks<T: Copy + Send + Sync + Into<f64>>(
    input: &[T],
    output: &mut [T],
    kernel: &(dyn Fn(&[T], &mut [T]) + Sync),
) -> Result<(), usize> {
    input
        .par_chunks(CHUNK)
        .zip(output.par_chunks_mut(CHUNK))
        .enumerate()
        .try_for_each(|(k, (input, output))| {
            if let Some(i) = first_non_finite(input) {
                return Err(k * CHUNK + i);
            }
            kernel(input, output);
            Ok(())
        })
}

/// A new array of `shape` from `values` (C order).
pub fn shaped<T>(shape: &[usize], values: Vec<T>) -> PyResult<ArrayD<T>> {
    ArrayD::from_shape_vec(IxDyn(shape), values).map_err(|e| value_error(e.to_string()))
}
