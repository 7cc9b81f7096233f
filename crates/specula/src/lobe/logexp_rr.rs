//! # `logexp-rr`: the log/exp lobe with range reduction (beyond the thesis)
//!
//! ```text
//! y            = n log2(t),   k = ceil(y),   f = y - k  in (-1, 0]
//! logexp-rr(t) = 2^k (1 - log2(1 - f) / 2)
//! ```
//!
//! `2^y = 2^k 2^f`: the integer part is an exact shift, and the thesis's approximation is only
//! asked for `2^f` on `(-1, 0]`, where it is exact at both ends. The relative error is then
//! the same in every octave of the lobe as in the epicentre, instead of growing until the
//! lobe is cut off at `t^n = 1/8`. The result is continuous: both pieces meet at each integer
//! `y`. Suggested by SPEC section 2.
//!
//! - **Parameters**: the exponent `n`.
//! - **Domain**: `t in (0, 1]`; the value lies in `(0, 1]`.
//! - **Cost**: two log2, two multiplies, three adds, one rounding, one shift.
//! - **Source**: specula.

use super::logexp::exp2_by_log2;
use crate::real::Real;
use crate::Exponent;

/// The prepared range-reduced log/exp lobe.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LogExpRr {
    n: f64,
}

impl LogExpRr {
    pub(crate) fn new(n: Exponent) -> Self {
        Self { n: n.get() }
    }

    /// Evaluates at `t in (0, 1]`.
    #[inline(always)]
    pub(crate) fn eval<R: Real>(&self, t: R) -> R {
        let y = R::from_f64(self.n) * t.log2();
        let k = y.ceil();
        exp2_by_log2(y - k).shift(k)
    }
}
