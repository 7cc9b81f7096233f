//! # `logexp`: the thesis's logarithmic/exponential lobe
//!
//! ```text
//! y         = n log2(t)                       (so t^n = 2^y, y <= 0)
//! logexp(t) = max(0, 1 - log2(1 - y) / 2)     (2^y ~ 1 - log2(1 - y) / 2)
//! ```
//!
//! The exponential is replaced by a second logarithm, so one log2 unit serves twice. The
//! approximation of `2^y` is exact at `y = 0` and `y = -1` (the epicentre's edge) and reaches 0
//! at `y = -3` (`t^n = 1/8`), so the lobe is accurate in the epicentre but cuts off inside the
//! bloom. `logexp-rr` carries the epicentre accuracy to the whole lobe.
//!
//! - **Parameters**: the exponent `n`.
//! - **Domain**: `t in (0, 1]`; `1 - y >= 1`, so the value lies in `[0, 1]`.
//! - **Cost**: two log2, two multiplies, two adds, one comparison.
//! - **Source**: the thesis, slide "Models based on the logarithmic and exponential functions".

use crate::real::Real;
use crate::Exponent;

/// The prepared log/exp lobe.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LogExp {
    n: f64,
}

impl LogExp {
    pub(crate) fn new(n: Exponent) -> Self {
        Self { n: n.get() }
    }

    /// Evaluates at `t in (0, 1]`.
    #[inline(always)]
    pub(crate) fn eval<R: Real>(&self, t: R) -> R {
        let y = R::from_f64(self.n) * t.log2();
        exp2_by_log2(y).max(R::from_f64(0.0))
    }
}

/// The thesis's `2^y ~ 1 - log2(1 - y) / 2` for `y <= 0`.
#[inline(always)]
pub(crate) fn exp2_by_log2<R: Real>(y: R) -> R {
    R::from_f64(1.0) - R::from_f64(0.5) * (R::from_f64(1.0) - y).log2()
}
