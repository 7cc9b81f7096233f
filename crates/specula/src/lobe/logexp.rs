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
//! - **Sampling**: table (`sampling::CosineDistribution`): the lobe is a chain of
//!   approximations with no useful closed-form integral.
//! - **Source**: the thesis, slide "Models based on the logarithmic and exponential functions".

use super::batch::{clamp_unit, CLAMP, F32Bounds, LobeKernel, ModelF32, WithKernel};
use super::facts::ModelFacts;
use super::info::{LineStyle, LobeInfo, Origin};
use crate::real::Real;
use crate::simd::math::{log2, LOG2};
use crate::simd::tally::{Class, Instructions};
use crate::simd::{Kernel, Lanes};
use crate::Exponent;

/// The registry's entry for this lobe.
pub(super) const INFO: LobeInfo = LobeInfo {
    id: "logexp",
    summary: "the thesis's log/exp lobe: 2^y replaced by a second log2",
    formula: "max(0, 1 - log2(1 - y) / 2), y = n log2 t",
    takes_angle: false,
    params: &[],
    origin: Origin::Thesis,
};

/// How every plot draws this lobe (`LobeKind::line_style`).
pub(super) const STYLE: LineStyle = LineStyle {
    rgb: [0, 136, 86],
    dashed: false,
};

/// What this lobe prepares (its `Model` variant holds it).
pub(super) type Prepared = LogExp;

/// This lobe prepared for `n`.
pub(super) fn prepare(n: Exponent) -> Prepared {
    LogExp::new(n)
}

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
        let y = R::parameter("n", self.n) * t.log2();
        exp2_by_log2(y).max(R::from_f64(0.0))
    }
}

/// The thesis's `2^y ~ 1 - log2(1 - y) / 2` for `y <= 0`.
#[inline(always)]
pub(crate) fn exp2_by_log2<R: Real>(y: R) -> R {
    R::from_f64(1.0) - R::from_f64(0.5) * (R::from_f64(1.0) - y).log2()
}

/// The batch kernel: `max(0, 1 - log2(1 - y) / 2)`, `y = n log2 t`, with the vector `log2`.
/// `t` clamped to `[0, 1]` makes `t <= 0` and NaN give `y <= -127`, where the value is
/// below 0 and the `max` zeroes it.
#[derive(Clone, Copy, Debug)]
pub(crate) struct LogExpKernel {
    n: f32,
}

impl LogExp {
    pub(crate) fn kernel(&self) -> LogExpKernel {
        LogExpKernel { n: self.n as f32 }
    }
}

impl Kernel for LogExpKernel {
    #[inline(always)]
    fn eval_lanes<V: Lanes>(self, t: V) -> V {
        let one = t.splat(1.0);
        let y = t.splat(self.n) * log2(clamp_unit(t));
        log2(one - y)
            .neg_mul_add(t.splat(0.5), one)
            .max(t.splat(0.0))
    }
}

impl LobeKernel for LogExpKernel {
    fn instructions(self) -> Instructions {
        CLAMP
            .and(LOG2)
            .and(LOG2)
            .plus(Class::Mul, 1)
            .plus(Class::Add, 1)
            .plus(Class::Fma, 1)
            .plus(Class::MinMax, 1)
    }
}

/// Sampled from a table: no closed-form tail, no kinks, one structure for every `n`.
impl ModelFacts for LogExp {
    #[inline]
    fn lobe_eval_unit<R: Real>(&self, t: R) -> R {
        self.eval(t)
    }
}

/// Its `f32` paths: the batch kernel and how far each `f32` evaluation may stray.
impl ModelF32 for LogExp {
    fn with_kernel<F: WithKernel>(&self, f: F) -> F::Output {
        f.call(self.kernel())
    }

    fn bounds(&self, n: f64) -> F32Bounds {
        F32Bounds::through_log2(n)
    }
}
