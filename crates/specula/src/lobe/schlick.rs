//! # `schlick`: Schlick's rational approximation
//!
//! ```text
//! schlick(t) = t / (n - n t + t)  =  t / (n (1 - t) + t)
//! ```
//!
//! Exact at `t = 1` (value 1) and for `n = 1` (value `t`); falls off like `1 / (n (1 - t))`,
//! far more slowly than `t^n`, which is the "unnatural" wide highlight the thesis criticises.
//! The denominator is evaluated as `n (1 - t) + t`: `1 - t` is exact for `t >= 1/2` and every
//! term is non-negative, so there is no cancellation near the peak even in `f32`.
//!
//! - **Parameters**: the exponent `n`.
//! - **Domain**: `t in (0, 1]`; the value lies in `(0, 1]` because the denominator is at
//!   least `t`.
//! - **Cost**: one multiply, two adds, one divide.
//! - **Sampling**: Newton. With `c = n - 1` and `d = 1 - t`, `int_t^1 schlick =
//!   (n / c^2) ln(1 + c d) - d / c` (a series in `c d` where that cancels), which mixes `d`
//!   and `ln d` and has no closed-form inverse; safeguarded Newton solves it from the
//!   near-peak guess `d = expm1(c u L) / c`.
//! - **Source**: C. Schlick, "A customizable reflectance model for everyday rendering" (1993).

use super::batch::{clamp_unit, CLAMP, F32Bounds, LobeKernel, ModelF32, WithKernel};
use super::facts::ModelFacts;
use super::info::{LineStyle, LobeInfo, Origin};
use super::invert::{solve_increasing, Inverted, NewtonStart};
use super::NewtonForm;
use crate::real::Real;
use crate::simd::tally::{Class, Instructions};
use crate::simd::{Kernel, Lanes};
use crate::Exponent;

/// The registry's entry for this lobe.
pub(super) const INFO: LobeInfo = LobeInfo {
    id: "schlick",
    summary: "Schlick's rational approximation",
    formula: "t / (n (1 - t) + t)",
    takes_angle: false,
    params: &[],
    origin: Origin::Literature,
};

/// How every plot draws this lobe (`LobeKind::line_style`).
pub(super) const STYLE: LineStyle = LineStyle {
    rgb: [190, 0, 50],
    dashed: false,
};

/// What this lobe prepares (its `Model` variant holds it).
pub(super) type Prepared = Schlick;

/// This lobe prepared for `n`.
pub(super) fn prepare(n: Exponent) -> Prepared {
    Schlick::new(n)
}

/// The prepared Schlick lobe.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Schlick {
    n: f64,
    /// `int_0^1 schlick`, the tail a draw's fraction is taken of.
    total: f64,
}

impl Schlick {
    pub(crate) fn new(n: Exponent) -> Self {
        let mut schlick = Self {
            n: n.get(),
            total: 0.0,
        };
        schlick.total = schlick.tail_from_peak(1.0);
        schlick
    }

    /// Evaluates at `t in (0, 1]`.
    #[inline(always)]
    pub(crate) fn eval<R: Real>(&self, t: R) -> R {
        schlick_denominator_ratio(t, t, self.n)
    }

    /// `int_{1-d}^1 schlick(s) ds = int_0^d (1 - s) / (1 + c s) ds`, `c = n - 1` (generic,
    /// so that a target that samples records it).
    pub(crate) fn tail_from_peak<R: Real>(&self, d: R) -> R {
        let n = R::parameter("n", self.n);
        let c = n - R::from_f64(1.0);
        let x = c * d;
        // (n / c^2) ln(1 + x) - d / c = d - n d^2 sum_k (-x)^k / (k + 2), where it cancels.
        x.branch_less(
            R::from_f64(0.05),
            || {
                let series = (0..16).rev().fold(R::from_f64(0.0), |sum, k| {
                    sum * -x + R::from_f64(1.0 / f64::from(k + 2))
                });
                d - n * d * d * series
            },
            || n / (c * c) * x.ln_1p() - d / c,
        )
    }

    /// `int_t^1 schlick(s) ds`.
    pub(crate) fn tail(&self, t: f64) -> f64 {
        self.tail_from_peak(1.0 - t)
    }

    /// The cosine whose tail is the fraction `u` of the whole, by Newton on the tail, from
    /// the cosine `near` when given, to `resolution`.
    pub(crate) fn tail_inverse(
        &self,
        u: f64,
        NewtonStart { near, resolution }: NewtonStart,
    ) -> Inverted {
        let c = self.n - 1.0;
        let target = u * self.total;
        let guess = match near {
            Some(t) => 1.0 - t,
            None if c > 0.0 => (c * target).exp_m1() / c,
            None => target,
        };
        let root = solve_increasing(
            |d: f64| self.tail_from_peak(d),
            |d: f64| self.eval(1.0 - d),
            target,
            (0.0, 1.0),
            (guess, resolution),
        );
        Inverted {
            x: 1.0 - root.x,
            ..root
        }
    }
}

/// `numerator / (n (1 - t) + t)`, the shared tail of `schlick` and `schlick-mod`.
#[inline(always)]
pub(crate) fn schlick_denominator_ratio<R: Real>(numerator: R, t: R, n: f64) -> R {
    numerator / (R::parameter("n", n) * (R::from_f64(1.0) - t) + t)
}

/// The batch kernel: `t / (n (1 - t) + t)` with the denominator fused; `t` clamped to
/// `[0, 1]` makes `t <= 0` and NaN give `0 / n = 0`.
#[derive(Clone, Copy, Debug)]
pub(crate) struct SchlickKernel<const SQUARINGS: u32> {
    pub(crate) n: f32,
}

impl Schlick {
    pub(crate) fn kernel(&self) -> SchlickKernel<0> {
        SchlickKernel { n: self.n as f32 }
    }
}

impl<const SQUARINGS: u32> Kernel for SchlickKernel<SQUARINGS> {
    #[inline(always)]
    fn eval_lanes<V: Lanes>(self, t: V) -> V {
        let c = clamp_unit(t);
        let mut numerator = c;
        for _ in 0..SQUARINGS {
            numerator = numerator * numerator;
        }
        numerator / t.splat(self.n).mul_add(t.splat(1.0) - c, c)
    }
}

impl<const SQUARINGS: u32> LobeKernel for SchlickKernel<SQUARINGS> {
    fn instructions(self) -> Instructions {
        CLAMP
            .plus(Class::Mul, SQUARINGS)
            .plus(Class::Add, 1)
            .plus(Class::Fma, 1)
            .plus(Class::Div, 1)
    }
}

/// Sampled by Newton on its closed-form tail, in `d = 1 - t`.
impl ModelFacts for Schlick {
    #[inline]
    fn lobe_eval_unit<R: Real>(&self, t: R) -> R {
        self.eval(t)
    }

    fn lobe_tail(&self, t: f64) -> Option<f64> {
        Some(self.tail(t))
    }

    fn lobe_tail_inverse(&self, u: f64, start: NewtonStart) -> Option<Inverted> {
        Some(self.tail_inverse(u, start))
    }

    fn lobe_newton_sampling<R: Real>(&self, x: R) -> Option<NewtonForm<R>> {
        let one = R::from_f64(1.0);
        Some(NewtonForm {
            tail: self.tail_from_peak(x),
            slope: self.eval(one - x),
            cosine: one - x,
            upper: one,
            total: self.tail_from_peak(one),
        })
    }
}

/// Its `f32` paths: the batch kernel and how far each `f32` evaluation may stray.
impl ModelF32 for Schlick {
    fn with_kernel<F: WithKernel>(&self, f: F) -> F::Output {
        f.call(self.kernel())
    }

    fn bounds(&self, _n: f64) -> F32Bounds {
        // One fused rounding in the denominator.
        F32Bounds::EXACT
    }
}
