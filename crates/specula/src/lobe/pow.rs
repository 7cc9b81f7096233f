//! # `pow`: the reference lobe
//!
//! ```text
//! pow(t) = t^n
//! ```
//!
//! Phong's lobe with `t = R.V`, Blinn's with `t = N.H`. Every approximation in specula is
//! measured against this function evaluated in `f64`.
//!
//! - **Parameters**: the exponent `n` only.
//! - **Domain**: `t in (0, 1]` (the dispatcher maps `t <= 0` to 0 and clamps `t` to 1).
//! - **Cost**: one general power, i.e. `exp2(n * log2 t)` in a math library.
//! - **Source**: B. T. Phong (1975); J. F. Blinn (1977); the thesis's reference function.

use crate::real::Real;
use crate::Exponent;

/// The prepared reference lobe `t^n`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Pow {
    n: f64,
}

impl Pow {
    pub(crate) fn new(n: Exponent) -> Self {
        Self { n: n.get() }
    }

    /// Evaluates at `t in (0, 1]`.
    #[inline(always)]
    pub(crate) fn eval<R: Real>(&self, t: R) -> R {
        t.powf(R::from_f64(self.n))
    }
}
