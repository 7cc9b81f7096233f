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
//! - **Sampling**: table (`sampling::CosineDistribution`), as `logexp`.
//! - **Source**: specula.

use super::batch::{clamp_unit, CLAMP, F32Bounds, LobeKernel, ModelF32, WithKernel};
use super::facts::ModelFacts;
use super::info::{LineStyle, LobeInfo, Origin};
use super::logexp::exp2_by_log2;
use crate::real::Real;
use crate::simd::math::{log2, LOG2};
use crate::simd::tally::{Class, Instructions};
use crate::simd::{Kernel, Lanes};
use crate::Exponent;

/// The registry's entry for this lobe.
pub(super) const INFO: LobeInfo = LobeInfo {
    id: "logexp-rr",
    summary: "log/exp with range reduction: exact shift for the integer part of y",
    formula: "2^k (1 - log2(1 - (y - k)) / 2), y = n log2 t, k = ceil y",
    takes_angle: false,
    params: &[],
    origin: Origin::Specula,
};

/// How every plot draws this lobe (`LobeKind::line_style`).
pub(super) const STYLE: LineStyle = LineStyle {
    rgb: [141, 182, 0],
    dashed: true,
};

/// What this lobe prepares (its `Model` variant holds it).
pub(super) type Prepared = LogExpRr;

/// This lobe prepared for `n`.
pub(super) fn prepare(n: Exponent) -> Prepared {
    LogExpRr::new(n)
}

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
        let y = R::parameter("n", self.n) * t.log2();
        let k = y.ceil();
        exp2_by_log2(y - k).shift(k)
    }
}

/// The batch kernel. `k = ceil y` is `y` truncated (`y <= 0`), in an integer register:
/// converted back it gives the reduced argument, shifted into an exponent field it gives
/// `2^k`. `y` is first clamped to `-127`, whose scale has a zero exponent field: the value is 0
/// below the normals, and for `t <= 0` and NaN (clamped to `t = 0`, `log2 0 = -127`).
#[derive(Clone, Copy, Debug)]
pub(crate) struct LogExpRrKernel {
    n: f32,
}

impl LogExpRr {
    pub(crate) fn kernel(&self) -> LogExpRrKernel {
        LogExpRrKernel { n: self.n as f32 }
    }
}

impl Kernel for LogExpRrKernel {
    #[inline(always)]
    fn eval_lanes<V: Lanes>(self, t: V) -> V {
        let one = t.splat(1.0);
        let y = (t.splat(self.n) * log2(clamp_unit(t))).max(t.splat(-127.0));
        let k = y.float_to_int();
        let reduced = one - (y - k.int_to_float());
        let value = log2(reduced).neg_mul_add(t.splat(0.5), one);
        value * k.bits_add(127).bits_shl::<23>()
    }
}

impl LobeKernel for LogExpRrKernel {
    fn instructions(self) -> Instructions {
        CLAMP
            .and(LOG2)
            .and(LOG2)
            .plus(Class::Mul, 2)
            .plus(Class::MinMax, 1)
            .plus(Class::Convert, 2)
            .plus(Class::Add, 2)
            .plus(Class::Fma, 1)
            .plus(Class::IntAdd, 1)
            .plus(Class::Shift, 1)
    }
}

/// Sampled from a table: no closed-form tail, no kinks, one structure for every `n`.
impl ModelFacts for LogExpRr {
    #[inline]
    fn lobe_eval_unit<R: Real>(&self, t: R) -> R {
        self.eval(t)
    }
}

/// Its `f32` paths: the batch kernel and how far each `f32` evaluation may stray.
impl ModelF32 for LogExpRr {
    fn with_kernel<F: WithKernel>(&self, f: F) -> F::Output {
        f.call(self.kernel())
    }

    fn bounds(&self, n: f64) -> F32Bounds {
        F32Bounds::through_log2(n)
    }
}
