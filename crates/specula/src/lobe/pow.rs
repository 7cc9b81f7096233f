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
//! - **Sampling**: analytic. `int_t^1 s^n ds = (1 - t^(n+1)) / (n + 1)`, inverted:
//!   `t = (1 - u)^(1/(n+1))`, the classic Phong warp.
//! - **Source**: B. T. Phong (1975); J. F. Blinn (1977); the thesis's reference function.

use super::batch::{clamp_unit, CLAMP, F32Bounds, LobeKernel, ModelF32, WithKernel};
use super::draw_batch::{self, remaining_share};
use super::facts::closed_form_facts;
use super::info::{LineStyle, LobeInfo, Origin};
use crate::real::Real;
use crate::simd::math::{exp2, log2, EXP2, LOG2};
use crate::simd::tally::{Class, Instructions};
use crate::simd::{Kernel, Lanes, Level};
use crate::Exponent;

/// The registry's entry for this lobe.
pub(super) const INFO: LobeInfo = LobeInfo {
    id: "pow",
    summary: "the exact lobe t^n (Phong, Blinn): the reference",
    formula: "t^n",
    takes_angle: false,
    params: &[],
    origin: Origin::Reference,
};

/// How every plot draws this lobe (`LobeKind::line_style`).
pub(super) const STYLE: LineStyle = LineStyle {
    rgb: [0, 0, 0],
    dashed: false,
};

/// What this lobe prepares (its `Model` variant holds it).
pub(super) type Prepared = Pow;

/// This lobe prepared for `n`.
pub(super) fn prepare(n: Exponent) -> Prepared {
    Pow::new(n)
}

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
        t.powf(R::parameter("n", self.n))
    }

    /// `int_t^1 s^n ds`, with `1 - t^(n+1)` as `-expm1((n + 1) ln t)` (exact near the peak).
    pub(crate) fn tail(&self, t: f64) -> f64 {
        -((self.n + 1.0) * t.ln()).exp_m1() / (self.n + 1.0)
    }

    /// The cosine whose tail is the fraction `u` of the whole (generic, so that a target
    /// that samples records it).
    pub(crate) fn tail_inverse<R: Real>(&self, u: R) -> R {
        ((-u).ln_1p() / (R::parameter("n", self.n) + R::from_f64(1.0))).exp()
    }

    /// `int_0^1 s^n ds = 1 / (n + 1)`.
    pub(crate) fn total<R: Real>(&self) -> R {
        R::from_f64(1.0) / (R::parameter("n", self.n) + R::from_f64(1.0))
    }
}

/// The batch kernel: `exp2(n log2 t)` with the vector `log2` and `exp2`. The clamp to
/// `[0, 1]` sends `t <= 0` and NaN to `log2 0 = -127`, whose `exp2` is 0: no mask needed.
#[derive(Clone, Copy, Debug)]
pub(crate) struct PowKernel {
    n: f32,
}

impl Pow {
    pub(crate) fn kernel(&self) -> PowKernel {
        PowKernel { n: self.n as f32 }
    }
}

/// The closed-form draw on lanes: `(1 - u)^(1/(n+1))` as `exp2(log2(1 - u) / (n + 1))`.
#[derive(Clone, Copy, Debug)]
pub(crate) struct PowDraw {
    inverse_power: f32,
}

impl Pow {
    pub(crate) fn draw_kernel(&self) -> PowDraw {
        PowDraw {
            inverse_power: (1.0 / (self.n + 1.0)) as f32,
        }
    }
}

impl Kernel for PowDraw {
    #[inline(always)]
    fn eval_lanes<V: Lanes>(self, u: V) -> V {
        exp2(log2(remaining_share(u, 0.0)) * u.splat(self.inverse_power))
    }
}

impl Kernel for PowKernel {
    #[inline(always)]
    fn eval_lanes<V: Lanes>(self, t: V) -> V {
        exp2(t.splat(self.n) * log2(clamp_unit(t)))
    }
}

impl LobeKernel for PowKernel {
    fn instructions(self) -> Instructions {
        CLAMP.and(LOG2).and(EXP2).plus(Class::Mul, 1)
    }
}

// Sampled in closed form: the tail and its inverse exactly.
closed_form_facts!(Pow);

/// Its `f32` paths: the batch kernel and how far each `f32` evaluation may stray.
impl ModelF32 for Pow {
    fn draw_batch(&self, level: Level, us: &[f32], out: &mut [f32]) -> bool {
        draw_batch::run(level, self.draw_kernel(), us, out);
        true
    }

    fn with_kernel<F: WithKernel>(&self, f: F) -> F::Output {
        f.call(self.kernel())
    }

    fn bounds(&self, n: f64) -> F32Bounds {
        // exp2(n log2 t).
        F32Bounds::through_log2(n)
    }
}
