//! The bit tricks as arithmetic: what a target without bit casts (OSL, MaterialX's node
//! graphs) computes instead of reading or building a float's fields. Each function gives the
//! `f32` bits of the [`Real`] operation it replaces for the inputs the lobes give it
//! (`frexp` of a normal positive float, `bits_exp2` below 128), using only operations that
//! are exact there: scaling by powers of two, `floor`, and `exp2` at integers.

use crate::real::Real;

fn c<R: Real>(value: f64) -> R {
    R::from_f64(value)
}

fn floor<R: Real>(x: R) -> R {
    -(-x).ceil()
}

/// [`Real::shift`] in `f32`: `x 2^k`, and 0 once `2^k` is below the normal range.
pub(super) fn shift<R: Real>(x: R, k: R) -> R {
    k.select_less(c(-126.5), c(0.0), x * k.exp2())
}

/// [`Real::frexp`] for a normal positive `x`: `log2` gives the exponent to within one, and
/// the mantissa's range settles it (an inexact `log2` near a power of two lands on either
/// side of it).
pub(super) fn frexp<R: Real>(x: R) -> (R, R) {
    let guess = floor(x.log2()) + c(1.0);
    let m = x * (-guess).exp2();
    let below = m.select_less(c(0.5), c(1.0), c(0.0));
    let within = m.select_less(c(1.0), c(1.0), c(0.0));
    // below: m * 2, guess - 1; within: m, guess; above: m / 2, guess + 1.
    let mantissa = m.select_less(c(0.5), m * c(2.0), m.select_less(c(1.0), m, m * c(0.5)));
    let exponent = guess + c(1.0) - below - within;
    (mantissa, exponent)
}

/// [`Real::bits_exp2`] in `f32`: the bit pattern `y = (max(x, -127) + 127) 2^23` (rounded
/// as the `f32` trick rounds it, then truncated) read back as a float, field by field.
pub(super) fn bits_exp2<R: Real>(x: R) -> R {
    let y = x.max(c(-127.0)) * c(8_388_608.0) + c(1_065_353_216.0);
    let pattern = floor(y);
    let fields = pattern * c(1.0 / 8_388_608.0);
    let biased_exponent = floor(fields);
    let fraction = fields - biased_exponent;
    let normal = (c::<R>(1.0) + fraction) * (biased_exponent - c(127.0)).exp2();
    let subnormal = pattern * c(2f64.powi(-149));
    biased_exponent.select_less(c(0.5), subnormal, normal)
}
