//! # `fasterpow`: the IEEE bit-trick power, uncorrected (Schraudolph, fastapprox)
//!
//! ```text
//! t = m 2^e, m in [1/2, 1)
//! fasterpow(t) = min(1, bits_exp2(n (e + 2 m - 1.94269504) - 0.05730496))
//! ```
//!
//! The bit pattern of `t`, read as a number, is `e + 2m + 125` (with `e`, `m` from `frexp`):
//! a piecewise-linear `log2`, evaluated as `2 (m - 1) + e + 127 - 126.94269504` so that no
//! two terms near 2 cancel. fastapprox's `fasterlog2` subtracts 126.94269504 from it and
//! `fasterpow2` adds the same constant back into the result's bit pattern, the offset that
//! makes Schraudolph's `exp` best on average. For a power that offset does not cancel: at
//! `t = 1` the log is 0.0573, not 0, so `n` times it lifts the whole lobe (by `2^(0.0573 (n -
//! 1))`, a factor 12 at `n = 64`), and the linear `log2` has a slope error of up to 44 % (its
//! slope is 1 where `log2` has `1/ln 2` at the top of a binade). The `min` keeps the value in
//! `[0, 1]`; what is left is a much wider lobe. specula keeps it because engines have shipped
//! it, and because it shows what the correction in `fastpow` buys.
//!
//! - **Parameters**: the exponent `n`.
//! - **Domain**: `t in (0, 1]`.
//! - **Cost**: two multiply-adds and two float/int conversions: the cheapest lobe here.
//! - **Sampling**: table (`sampling::CosineDistribution`), as `fastpow`.
//! - **Source**: P. Mineiro, fastapprox (`fasterlog2`, `fasterpow2`, `fasterpow`), 2011;
//!   N. N. Schraudolph, "A fast, compact approximation of the exponential function" (1999).

use super::batch::{clamp_unit, CLAMP, F32Bounds, LobeKernel, ModelF32, WithKernel};
use super::facts::ModelFacts;
use super::fastpow::kinks;
use super::info::{LineStyle, LobeInfo, Origin};
use crate::real::Real;
use crate::simd::math::{bits_exp2, frexp, BITS_EXP2, FREXP};
use crate::simd::tally::{Class, Instructions};
use crate::simd::{Kernel, Lanes};
use crate::Exponent;

/// The registry's entry for this lobe.
pub(super) const INFO: LobeInfo = LobeInfo {
    id: "fasterpow",
    summary: "the IEEE bit-trick power, uncorrected (Schraudolph; fastapprox)",
    formula: "bits_exp2(n (bits_log2(t) + 0.0573) - 0.0573), clamped to 1",
    takes_angle: false,
    params: &[],
    origin: Origin::Literature,
};

/// How every plot draws this lobe (`LobeKind::line_style`).
pub(super) const STYLE: LineStyle = LineStyle {
    rgb: [194, 178, 128],
    dashed: true,
};

/// What this lobe prepares (its `Model` variant holds it).
pub(super) type Prepared = FasterPow;

/// This lobe prepared for `n`.
pub(super) fn prepare(n: Exponent) -> Prepared {
    FasterPow::new(n)
}

/// fastapprox's offset between the bit pattern and `log2`, on both sides.
const OFFSET: f64 = 126.942_695_04;

/// The prepared uncorrected bit-trick power.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FasterPow {
    n: f64,
}

impl FasterPow {
    pub(crate) fn new(n: Exponent) -> Self {
        Self { n: n.get() }
    }

    /// Evaluates at `t in (0, 1]`.
    #[inline(always)]
    pub(crate) fn eval<R: Real>(&self, t: R) -> R {
        self.exponent_bits(t).bits_exp2().min(R::from_f64(1.0))
    }

    /// The argument of `bits_exp2`: `n log2~(t) - 0.0573`.
    #[inline(always)]
    fn exponent_bits<R: Real>(&self, t: R) -> R {
        let c = R::from_f64;
        let (m, e) = t.frexp();
        let log = (m - c(1.0)) * c(2.0) + (e + c(127.0 - OFFSET));
        log * R::parameter("n", self.n) + c(OFFSET - 127.0)
    }

    /// Where the lobe is not smooth: binade boundaries and integer arguments of `bits_exp2`.
    pub(crate) fn kinks(&self) -> Vec<f64> {
        kinks(&[&|t| self.exponent_bits(t)])
    }

    pub(crate) fn kernel(&self) -> FasterPowKernel {
        FasterPowKernel { n: self.n as f32 }
    }
}

/// The batch kernel: the same two multiply-adds on the bits, and 0 where `t <= 0`.
#[derive(Clone, Copy, Debug)]
pub(crate) struct FasterPowKernel {
    n: f32,
}

impl Kernel for FasterPowKernel {
    #[inline(always)]
    fn eval_lanes<V: Lanes>(self, t: V) -> V {
        let c = |value: f64| t.splat(value as f32);
        let clamped = clamp_unit(t);
        let (m, e) = frexp(clamped);
        let log = (m - c(1.0)).mul_add(c(2.0), e + c(127.0 - OFFSET));
        bits_exp2(log.mul_add(c(f64::from(self.n)), c(OFFSET - 127.0)))
            .min(c(1.0))
            .keep(clamped.gt(c(0.0)))
    }
}

impl LobeKernel for FasterPowKernel {
    fn instructions(self) -> Instructions {
        CLAMP
            .and(FREXP)
            .and(BITS_EXP2)
            .plus(Class::Add, 2)
            .plus(Class::Fma, 2)
            .plus(Class::MinMax, 1)
            .plus(Class::Compare, 1)
            .plus(Class::Logic, 1)
    }
}

/// Kinked where its bit trick crosses a binade or an integer.
impl ModelFacts for FasterPow {
    #[inline]
    fn lobe_eval_unit<R: Real>(&self, t: R) -> R {
        self.eval(t)
    }

    fn lobe_kinks(&self) -> Vec<f64> {
        self.kinks()
    }
}

/// Its `f32` paths: the batch kernel and how far each `f32` evaluation may stray.
impl ModelF32 for FasterPow {
    fn with_kernel<F: WithKernel>(&self, f: F) -> F::Output {
        f.call(self.kernel())
    }

    fn bounds(&self, n: f64) -> F32Bounds {
        F32Bounds::bit_trick(n)
    }
}
