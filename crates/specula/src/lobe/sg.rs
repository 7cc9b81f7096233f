//! # `sg`: the spherical Gaussian
//!
//! ```text
//! sg(t) = exp(n (t - 1)) = exp2(r (t - 1)),   r = n log2(e)
//! ```
//!
//! The lobe engines ship when they want `cos^n` from one `exp2`: `ln t <= t - 1` makes it an
//! upper bound of `t^n` that touches it at `t = 1`, with a relative error that grows like
//! `exp(n (t - 1 - ln t)) - 1`, so `2 exp(n (2^(-1/n) - 1)) - 1` at the epicentre's edge,
//! about `(ln 2)^2 / (2 n)` (0.37 % at `n = 64`): the Gaussian is wider than the power, by
//! more the further from the peak.
//! Its integral over the hemisphere has the closed form `2 pi (1 - exp(-n)) / n`.
//!
//! - **Parameters**: the exponent `n`; `sg-karis` uses the same model with a shifted rate.
//! - **Domain**: `t in (0, 1]`; the value lies in `(0, 1]`. At `t <= 0` the dispatcher's
//!   rule gives 0, where the Gaussian itself would still be `exp(-n)`.
//! - **Cost**: one add, one multiply and one `exp2`.
//! - **Sampling**: analytic. With `k = n` (or `n + offset`), `int_t^1 exp(k (s - 1)) ds =
//!   -expm1(-k (1 - t)) / k`, inverted: `t = 1 + ln(1 + u expm1(-k)) / k`.
//! - **Source**: S. Lagarde, "Spherical Gaussian approximation for Blinn-Phong, Phong and
//!   Fresnel" (2012); the Gaussian form of the Phong lobe behind real-time engines' cheap
//!   specular.

use super::batch::{clamp_unit, CLAMP, F32Bounds, LobeKernel, ModelF32, WithKernel};
use super::draw_batch::{self, remaining_share};
use super::facts::closed_form_facts;
use super::info::{LineStyle, LobeInfo, Origin};
use crate::real::Real;
use crate::simd::math::{exp2, log2, EXP2};
use crate::simd::tally::{Class, Instructions};
use crate::simd::{Kernel, Lanes, Level};
use crate::Exponent;

/// The registry's entry for this lobe.
pub(super) const INFO: LobeInfo = LobeInfo {
    id: "sg",
    summary: "the spherical Gaussian engines use for cos^n: one exp2",
    formula: "exp(n (t - 1)) = exp2(n log2(e) (t - 1))",
    takes_angle: false,
    params: &[],
    origin: Origin::Literature,
};

/// How every plot draws this lobe (`LobeKind::line_style`).
pub(super) const STYLE: LineStyle = LineStyle {
    rgb: [230, 143, 172],
    dashed: false,
};

/// What this lobe prepares (its `Model` variant holds it).
pub(super) type Prepared = Sg;

/// This lobe prepared for `n`.
pub(super) fn prepare(n: Exponent) -> Prepared {
    Sg::new(n, 0.0)
}

/// A prepared spherical Gaussian `exp2(rate (t - 1))`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Sg {
    rate: f64,
    offset: f64,
}

impl Sg {
    /// The Gaussian `exp((n + offset) (t - 1))`.
    pub(crate) fn new(n: Exponent, offset: f64) -> Self {
        Self {
            rate: Self::rate_for(n.get(), offset),
            offset,
        }
    }

    /// `r = log2(e) (n + offset)`, written once for the preparation and its recorded form.
    pub(crate) fn rate_for<R: Real>(n: R, offset: f64) -> R {
        R::from_f64(core::f64::consts::LOG2_E) * (n + R::from_f64(offset))
    }

    /// Evaluates at `t in (0, 1]`.
    #[inline(always)]
    pub(crate) fn eval<R: Real>(&self, t: R) -> R {
        ((t - R::from_f64(1.0)) * R::parameter("rate", self.rate)).exp2()
    }

    /// The natural rate `k` of `exp(k (t - 1))`.
    fn natural_rate<R: Real>(&self) -> R {
        R::parameter("rate", self.rate) * R::from_f64(core::f64::consts::LN_2)
    }

    /// `int_t^1 exp(k (s - 1)) ds`.
    pub(crate) fn tail(&self, t: f64) -> f64 {
        let k: f64 = self.natural_rate();
        -(-k * (1.0 - t)).exp_m1() / k
    }

    /// `int_0^1 exp(k (s - 1)) ds = -expm1(-k) / k`.
    pub(crate) fn total<R: Real>(&self) -> R {
        let k: R = self.natural_rate();
        -(-k).exp_m1() / k
    }

    /// The cosine whose tail is the fraction `u` of the whole (generic, so that a target
    /// that samples records it).
    pub(crate) fn tail_inverse<R: Real>(&self, u: R) -> R {
        let k: R = self.natural_rate();
        (R::from_f64(1.0) + (u * (-k).exp_m1()).ln_1p() / k).max(R::from_f64(0.0))
    }

    pub(crate) fn kernel(&self) -> SgKernel {
        SgKernel {
            rate: self.rate as f32,
        }
    }
}

/// The closed-form draw on lanes: `1 + ln(1 + u expm1(-k)) / k` as
/// `1 + log2((1 - u) + u 2^-r) / r` (`k = r ln 2`), clamped to `[0, 1]`.
#[derive(Clone, Copy, Debug)]
pub(crate) struct SgDraw {
    floor: f32,
    inverse_rate: f32,
}

impl Sg {
    pub(crate) fn draw_kernel(&self) -> SgDraw {
        SgDraw {
            floor: (-self.rate).exp2() as f32,
            inverse_rate: (1.0 / self.rate) as f32,
        }
    }
}

impl Kernel for SgDraw {
    #[inline(always)]
    fn eval_lanes<V: Lanes>(self, u: V) -> V {
        let one = u.splat(1.0);
        let remaining = remaining_share(u, self.floor);
        log2(remaining)
            .mul_add(u.splat(self.inverse_rate), one)
            .max(u.splat(0.0))
    }
}

/// The batch kernel: `exp2((t - 1) r)` with the vector `exp2`, then 0 where `t <= 0` (the
/// Gaussian is not 0 there, so unlike the power it needs the mask). `t - 1` is exact for
/// `t >= 1/2`; the multiply-add `t r - r` would be one instruction fewer, but unfused (the
/// plain loop, the baseline level) it cancels to the product's rounding, `1e-5` at `n = 100`.
#[derive(Clone, Copy, Debug)]
pub(crate) struct SgKernel {
    rate: f32,
}

impl Kernel for SgKernel {
    #[inline(always)]
    fn eval_lanes<V: Lanes>(self, t: V) -> V {
        let clamped = clamp_unit(t);
        let argument = (clamped - t.splat(1.0)) * t.splat(self.rate);
        exp2(argument).keep(clamped.gt(t.splat(0.0)))
    }
}

impl LobeKernel for SgKernel {
    fn instructions(self) -> Instructions {
        CLAMP
            .and(EXP2)
            .plus(Class::Add, 1)
            .plus(Class::Mul, 1)
            .plus(Class::Compare, 1)
            .plus(Class::Logic, 1)
    }
}

// Sampled in closed form: the tail and its inverse exactly.
closed_form_facts!(Sg, {
    fn lobe_preparation<R: Real>(&self, name: &str, n: R) -> Option<R> {
        match name {
            "n" => Some(n),
            "rate" => Some(Sg::rate_for(n, self.offset)),
            _ => None,
        }
    }
});

/// Its `f32` paths: the batch kernel and how far each `f32` evaluation may stray.
impl ModelF32 for Sg {
    fn draw_batch(&self, level: Level, us: &[f32], out: &mut [f32]) -> bool {
        draw_batch::run(level, self.draw_kernel(), us, out);
        true
    }

    fn with_kernel<F: WithKernel>(&self, f: F) -> F::Output {
        f.call(self.kernel())
    }

    fn bounds(&self, _n: f64) -> F32Bounds {
        F32Bounds {
            // One fused multiply-add against a rounded product, scaled by the value times its
            // argument (at most 0.53), plus exp2's 2 ULP; on a GPU, the driver's exp2.
            batch_ulps: 8.0,
            gpu_ulps: 64.0,
            ..F32Bounds::EXACT
        }
    }
}
