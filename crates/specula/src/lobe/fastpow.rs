//! # `fastpow`: the IEEE bit-trick power with a rational correction (fastapprox)
//!
//! ```text
//! t = m 2^e, m in [1/2, 1);   u = m - 1;   z = p - floor(p)
//! log2~(t)  = e + 0.77448501 + 0.501969698 m - 1.72587999 / (0.3520887068 + m)
//!           = e + (N0 + u (N1 + 0.501969698 u)) / (1.3520887068 + u)
//! exp2~(p)  = bits_exp2(p - 5.7259425 + 27.7280233 / (4.84252568 - z) - 1.49012907 z)
//! fastpow(t) = min(1, exp2~(n log2~(t)))
//! ```
//!
//! A float's bit pattern, read as a number, is a piecewise-linear `log2` of it (Schraudolph
//! 1999); P. Mineiro's fastapprox adds a small rational correction to each direction and
//! composes them as `fastpow(x, p) = fastpow2(p fastlog2(x))`. The constants are
//! fastapprox's. Three differences in evaluation, none in the function: the exponent field
//! is kept apart from the mantissa (fastapprox converts the whole bit pattern to a float,
//! which rounds `log2` to `2^-16` absolute, 0.5 % of the value at `n = 512`), the correction is
//! one fraction expanded around `m = 1`, where its terms cancel (evaluated as written, the
//! cancellation leaves `1e-16` of noise in `log2`, `1e-13` of the value at `n = 1000`, enough
//! to stall adaptive integration), and the `f64` path evaluates the same formulas exactly,
//! with `bits_exp2` as the exact piecewise-linear `2^x`. The log's residual error (about `5e-5`
//! absolute) is multiplied by `n`, so the lobe
//! is accurate at small `n` and drifts at large `n`. At `t = 1` the corrected log is `4e-9`,
//! not 0, and the exp's correction `-4e-6`: the value stays just below 1 in `f64`, and a `min`
//! keeps the `f32` roundings from lifting it above.
//!
//! - **Parameters**: the exponent `n`.
//! - **Domain**: `t in (0, 1]`.
//! - **Cost**: two divides, a few multiply-adds, two float/int conversions; no transcendental.
//! - **Sampling**: table (`sampling::CosineDistribution`): the bit trick is piecewise, with
//!   kinks at every binade, so it has no closed-form integral worth inverting.
//! - **Source**: P. Mineiro, fastapprox (`fastlog2`, `fastpow2`, `fastpow`), 2011;
//!   N. N. Schraudolph, "A fast, compact approximation of the exponential function" (1999).

use super::batch::{clamp_unit, CLAMP, F32Bounds, LobeKernel, ModelF32, WithKernel};
use super::facts::ModelFacts;
use super::info::{LineStyle, LobeInfo, Origin};
use crate::real::Real;
use crate::simd::math::{bits_exp2, frexp, BITS_EXP2, FREXP};
use crate::simd::tally::{Class, Instructions};
use crate::simd::{Kernel, Lanes};
use crate::Exponent;

/// The registry's entry for this lobe.
pub(super) const INFO: LobeInfo = LobeInfo {
    id: "fastpow",
    summary: "the IEEE bit-trick power with fastapprox's rational corrections",
    formula: "fastpow2(n fastlog2(t)), log and exp read off the float's bits",
    takes_angle: false,
    params: &[],
    origin: Origin::Literature,
};

/// How every plot draws this lobe (`LobeKind::line_style`).
pub(super) const STYLE: LineStyle = LineStyle {
    rgb: [132, 132, 130],
    dashed: false,
};

/// What this lobe prepares (its `Model` variant holds it).
pub(super) type Prepared = FastPow;

/// This lobe prepared for `n`.
pub(super) fn prepare(n: Exponent) -> Prepared {
    FastPow::new(n)
}

// fastapprox's `fastlog2` correction, `A + B m - D / (C + m)`, as one fraction whose numerator
// `(A + B m)(C + m) - D` is expanded around `m = 1`, where it nearly vanishes: with `u = m - 1`
// (exact) it is `N0 + u (N1 + B u)`, and the cancellation happens once, here, in `f64`.
const LOG_A: f64 = 0.774_485_01;
const LOG_B: f64 = 0.501_969_698;
const LOG_C: f64 = 0.352_088_706_8;
const LOG_D: f64 = 1.725_879_99;
const LOG_N0: f64 = (LOG_A + LOG_B) * (LOG_C + 1.0) - LOG_D;
const LOG_N1: f64 = (LOG_A + LOG_B) + LOG_B * (LOG_C + 1.0);

// fastapprox's `fastpow2` correction: `121.2740575 + 27.7280233 / (4.84252568 - z) -
// 1.49012907 z` added to `p` gives the bit pattern's `x + 127`.
const EXP_NUMERATOR: f64 = 27.728_023_3;
const EXP_POLE: f64 = 4.842_525_68;
const EXP_SLOPE: f64 = 1.490_129_07;
const EXP_OFFSET: f64 = 127.0 - 121.274_057_5;

/// Cosines in `(0, 1]` where a bit-trick lobe is not smooth while it is above `2^-64`: the
/// binade boundaries `2^-k`, and where each of `crossings` (increasing functions of `t` that
/// the value is `2^` of, roughly) passes an integer, found by bisection. Integrators split
/// there: a piecewise-smooth lobe with a kink inside a panel defeats adaptive refinement.
pub(crate) fn kinks(crossings: &[&dyn Fn(f64) -> f64]) -> Vec<f64> {
    const LOWEST: f64 = -64.0;
    let Some(first) = crossings.first() else {
        return Vec::new();
    };
    let mut cosines: Vec<f64> = (1..1075)
        .map(|k| (-f64::from(k)).exp2())
        .take_while(|&t| first(t) >= LOWEST)
        .collect();
    for crossing in crossings {
        let top = crossing(1.0).floor();
        let mut level = top;
        while level >= LOWEST {
            let (mut low, mut high) = (0.0_f64, 1.0_f64);
            if crossing(f64::MIN_POSITIVE) < level {
                for _ in 0..64 {
                    let mid = 0.5 * (low + high);
                    if crossing(mid) < level {
                        low = mid;
                    } else {
                        high = mid;
                    }
                }
                cosines.push(high);
            }
            level -= 1.0;
        }
    }
    cosines.retain(|&t| t > 0.0 && t < 1.0);
    cosines
}

/// The prepared bit-trick power.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FastPow {
    n: f64,
}

impl FastPow {
    pub(crate) fn new(n: Exponent) -> Self {
        Self { n: n.get() }
    }

    /// Evaluates at `t in (0, 1]`.
    #[inline(always)]
    pub(crate) fn eval<R: Real>(&self, t: R) -> R {
        self.exponent_bits(self.power(t))
            .bits_exp2()
            .min(R::from_f64(1.0))
    }

    /// `p = n log2~(t)`.
    #[inline(always)]
    fn power<R: Real>(&self, t: R) -> R {
        let c = R::from_f64;
        let (m, e) = t.frexp();
        let u = m - c(1.0);
        let numerator = u * (u * c(LOG_B) + c(LOG_N1)) + c(LOG_N0);
        R::parameter("n", self.n) * (numerator / (u + c(LOG_C + 1.0)) + e)
    }

    /// The corrected argument of `bits_exp2` for power `p`.
    #[inline(always)]
    fn exponent_bits<R: Real>(&self, p: R) -> R {
        let c = R::from_f64;
        let z = p + (-p).ceil();
        let correction = c(EXP_NUMERATOR) / (c(EXP_POLE) - z);
        (p + correction - c(EXP_OFFSET)) - c(EXP_SLOPE) * z
    }

    /// Where the lobe is not smooth (see [`kinks`]): `p` and the bits' argument cross
    /// integers there (the correction jumps by `1e-5` at each integer `p`).
    pub(crate) fn kinks(&self) -> Vec<f64> {
        kinks(&[&|t| self.power(t), &|t| self.exponent_bits(self.power(t))])
    }

    pub(crate) fn kernel(&self) -> FastPowKernel {
        FastPowKernel { n: self.n as f32 }
    }
}

/// The batch kernel, the same formulas on the bits, with `floor` as fastapprox has it
/// (`p - trunc(p) + 1`, equal for the non-positive `p` of a lobe) and 0 where `t <= 0`.
#[derive(Clone, Copy, Debug)]
pub(crate) struct FastPowKernel {
    n: f32,
}

impl Kernel for FastPowKernel {
    #[inline(always)]
    fn eval_lanes<V: Lanes>(self, t: V) -> V {
        let c = |value: f32| t.splat(value);
        let clamped = clamp_unit(t);
        let (m, e) = frexp(clamped);
        let u = m - c(1.0);
        let numerator = u.mul_add(
            u.mul_add(c(LOG_B as f32), c(LOG_N1 as f32)),
            c(LOG_N0 as f32),
        );
        let p = c(self.n) * (numerator / (u + c((LOG_C + 1.0) as f32)) + e);
        let z = (p - p.float_to_int().int_to_float()) + c(1.0);
        let correction = c(EXP_NUMERATOR as f32) / (c(EXP_POLE as f32) - z);
        let x = z.neg_mul_add(c(EXP_SLOPE as f32), (p + correction) - c(EXP_OFFSET as f32));
        bits_exp2(x).min(c(1.0)).keep(clamped.gt(c(0.0)))
    }
}

impl LobeKernel for FastPowKernel {
    fn instructions(self) -> Instructions {
        CLAMP
            .and(FREXP)
            .and(BITS_EXP2)
            .plus(Class::Fma, 3)
            .plus(Class::Add, 8)
            .plus(Class::Div, 2)
            .plus(Class::Mul, 1)
            .plus(Class::Convert, 2)
            .plus(Class::MinMax, 1)
            .plus(Class::Compare, 1)
            .plus(Class::Logic, 1)
    }
}

/// Kinked where its bit trick crosses a binade or an integer.
impl ModelFacts for FastPow {
    #[inline]
    fn lobe_eval_unit<R: Real>(&self, t: R) -> R {
        self.eval(t)
    }

    fn lobe_kinks(&self) -> Vec<f64> {
        self.kinks()
    }
}

/// Its `f32` paths: the batch kernel and how far each `f32` evaluation may stray.
impl ModelF32 for FastPow {
    fn with_kernel<F: WithKernel>(&self, f: F) -> F::Output {
        f.call(self.kernel())
    }

    fn bounds(&self, n: f64) -> F32Bounds {
        F32Bounds::bit_trick(n)
    }
}
