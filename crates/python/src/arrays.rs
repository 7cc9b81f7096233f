//! The array contracts: which dtypes and shapes each function takes, checked by name before
//! any work, and the chunked parallel loops that evaluate them.
//!
//! An input of another dtype is refused (never converted behind the caller's back), a
//! non-finite value is refused with its index, and a non-contiguous array is read in order
//! (a copy of the view, not of garbage). Outputs are new C-ordered arrays of the input's shape.

use numpy::ndarray::{ArrayD, ArrayViewD, IxDyn};
use numpy::{PyReadonlyArrayDyn, PyUntypedArray, PyUntypedArrayMethods};
use pyo3::exceptions::{PyMemoryError, PyTypeError};
use pyo3::prelude::*;
use rayon::prelude::*;

use crate::errors::value_error;

/// Elements per piece: small enough that a piece's input stays in L2 between the finiteness
/// check and the kernel.
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

/// A `float64` array argument of shape `(..., last)`.
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
            "{name} has shape {}; it must be (..., {last})",
            tuple(array.shape())
        )));
    }
    Ok(array)
}

/// `shape` as Python writes a tuple: `(3, 4)`, `(3,)`, `()`.
pub fn tuple(shape: &[usize]) -> String {
    match shape {
        [one] => format!("({one},)"),
        _ => {
            let parts: Vec<String> = shape.iter().map(usize::to_string).collect();
            format!("({})", parts.join(", "))
        }
    }
}

/// `view` as a contiguous slice: borrowed when it is one, copied in logical order when not
/// (a `MemoryError` rather than an abort where the copy does not fit: a broadcast view of a
/// few bytes can stand for terabytes).
pub fn contiguous<'a, T: Copy>(view: &'a ArrayViewD<'a, T>) -> PyResult<std::borrow::Cow<'a, [T]>> {
    if let Some(slice) = view.as_slice() {
        return Ok(std::borrow::Cow::Borrowed(slice));
    }
    let mut copy = Vec::new();
    copy.try_reserve_exact(view.len()).map_err(|_| {
        PyMemoryError::new_err(format!(
            "a strided array of {} elements does not fit in memory as a contiguous copy",
            view.len()
        ))
    })?;
    copy.extend(view.iter().copied());
    Ok(std::borrow::Cow::Owned(copy))
}

/// `value` as a count in `[low, high]`, or a `ValueError` naming `name` and the range (Python
/// integers may be negative or huge; neither reaches the library).
pub fn count(name: &str, value: i64, low: usize, high: usize) -> PyResult<usize> {
    usize::try_from(value)
        .ok()
        .filter(|v| (low..=high).contains(v))
        .ok_or_else(|| {
            value_error(format!(
                "{name} {value} is out of range; give {low} to {high}"
            ))
        })
}

/// `value` as the unsigned integer type `T` (a Python integer may be negative or huge), or a
/// `ValueError` naming `name`; the range beyond that is the library's to check.
pub fn unsigned<T: TryFrom<i64>>(name: &str, value: i64) -> PyResult<T> {
    T::try_from(value).map_err(|_| {
        value_error(if value < 0 {
            format!("{name} {value} is negative; give 0 or more")
        } else {
            let max = u128::MAX >> (128 - 8 * std::mem::size_of::<T>());
            format!("{name} {value} is out of range; give at most {max}")
        })
    })
}

/// A seed of the random numbers: 0 or more.
pub fn seed(value: i64) -> PyResult<u64> {
    unsigned("seed", value)
}

/// A float element whose finiteness is checked on its bits (an exponent of all ones is a NaN
/// or an infinity): integer compares, which vectorise (measured faster than a max-reduction
/// of the magnitudes' bits).
pub trait Finite: Copy + Send + Sync {
    /// Whether the value is neither NaN nor infinite.
    fn finite(self) -> bool;
}

impl Finite for f32 {
    #[inline(always)]
    fn finite(self) -> bool {
        self.to_bits() & 0x7f80_0000 != 0x7f80_0000
    }
}

impl Finite for f64 {
    #[inline(always)]
    fn finite(self) -> bool {
        self.to_bits() & 0x7ff0_0000_0000_0000 != 0x7ff0_0000_0000_0000
    }
}

/// The index of a non-finite value in `values`, if any (a branch-free scan first, the
/// search only on failure).
pub fn first_non_finite<T: Finite>(values: &[T]) -> Option<usize> {
    if values.iter().fold(true, |ok, &v| ok & v.finite()) {
        None
    } else {
        values.iter().position(|&v| !v.finite())
    }
}

/// The refusal of a non-finite value at flat index `index` of `name`.
pub fn non_finite(name: &str, index: usize) -> PyErr {
    value_error(format!(
        "{name} holds a non-finite value (NaN or infinity) at flat index {index}; \
         specula refuses it rather than return a NaN"
    ))
}

/// Applies `kernel` to `input`: a few large chunks per thread (so the pool schedules a
/// handful of tasks, not thousands), each walked in [`CHUNK`]-sized pieces that are checked
/// finite and then evaluated while still in L2. `Err(index)` names a non-finite input.
pub fn map_chunks<T: Finite>(
    input: &[T],
    output: &mut [T],
    kernel: &(dyn Fn(&[T], &mut [T]) + Sync),
) -> Result<(), usize> {
    let tasks = 4 * rayon::current_num_threads();
    let task = input.len().div_ceil(tasks).div_ceil(CHUNK).max(1) * CHUNK;
    input
        .par_chunks(task)
        .zip(output.par_chunks_mut(task))
        .enumerate()
        .try_for_each(|(k, (input, output))| {
            for (piece, (input, output)) in input
                .chunks(CHUNK)
                .zip(output.chunks_mut(CHUNK))
                .enumerate()
            {
                if let Some(i) = first_non_finite(input) {
                    return Err(k * task + piece * CHUNK + i);
                }
                kernel(input, output);
            }
            Ok(())
        })
}

/// A new array of `shape` from `values` (C order).
pub fn shaped<T>(shape: &[usize], values: Vec<T>) -> PyResult<ArrayD<T>> {
    ArrayD::from_shape_vec(IxDyn(shape), values).map_err(|e| value_error(e.to_string()))
}
