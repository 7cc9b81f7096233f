//! # `cosquad`: the thesis's cosine-quadratic lobe `K_v`
//!
//! ```text
//! cosquad(t) = max(0, a (t - 1) + 1)^(2^v),   a = (n + 1) / (2^v + 1)
//! K_4(t)     = max(0, (n + 1)/17 (t - 1) + 1)^16
//! ```
//!
//! A low-order polynomial in the cosine raised to a power of two, so it costs `v` squarings.
//! `a` is chosen so that the lobe has the energy of `t^n`:
//! `int_0^{acos((a-1)/a)} (a (cos g - 1) + 1)^(2^v) sin g dg = 1 / ((2^v + 1) a) = 1 / (n + 1)`.
//! That holds exactly when the lobe's support ends inside the hemisphere, i.e. `a >= 1`, i.e.
//! `n >= 2^v`; for smaller `n` the part beyond `g = pi/2` is cut off (SPEC: `t <= 0` gives 0)
//! and the energy falls short.
//!
//! - **Parameters**: the exponent `n`; `v`, the number of squarings (default 4, `K_4`),
//!   0 to 10.
//! - **Domain**: `t in (0, 1]`; the base is at most 1, so the value lies in `[0, 1]`.
//! - **Cost**: two adds, one multiply (by the per-material constant `a`), one comparison,
//!   `v` squarings.
//! - **Sampling**: analytic. With `m = 2^v` and `x = a (t - 1) + 1`, `int_t^1 cosquad =
//!   (1 - max(0, x)^(m+1)) / (a (m + 1))`, inverted: `x = (1 - u (1 - x_0^(m+1)))^(1/(m+1))`,
//!   `x_0 = max(0, 1 - a)` the base at `t = 0`.
//! - **Source**: the thesis, slide "A model based on a cosine-quadratic function".

use super::batch::{with_squarings, F32Bounds, LobeKernel, ModelF32, WithKernel};
use super::draw_batch::{self, remaining_share};
use super::facts::closed_form_facts;
use super::info::{LineStyle, LobeInfo, Origin, ParamInfo};
use crate::real::Real;
use crate::simd::math::{exp2, log2};
use crate::simd::tally::{Class, Instructions};
use crate::simd::{Kernel, Lanes, Level};
use crate::Exponent;

/// The registry's entry for this lobe.
pub(super) const INFO: LobeInfo = LobeInfo {
    id: "cosquad",
    summary: "the thesis's cosine-quadratic K_v, energy-matched to t^n",
    formula: "max(0, a (t - 1) + 1)^(2^v), a = (n + 1) / (2^v + 1)",
    takes_angle: false,
    params: &[V_PARAM],
    origin: Origin::Thesis,
};

/// How every plot draws this lobe (`LobeKind::line_style`).
pub(super) const STYLE: LineStyle = LineStyle {
    rgb: [136, 45, 23],
    dashed: false,
};

/// What this lobe prepares (its `Model` variant holds it).
pub(super) type Prepared = CosQuad;

/// This lobe prepared for `n` and `v` squarings.
pub(super) fn prepare(n: Exponent, v: u8) -> Prepared {
    CosQuad::new(n, v)
}

/// The parameter `v` (`cosquad:v=5`).
pub(super) const V_PARAM: ParamInfo = ParamInfo {
    name: "v",
    description: "number of squarings; the lobe is a polynomial of degree 2^v in the cosine",
    default: CosQuad::DEFAULT_V as u32,
    min: 0,
    max: CosQuad::MAX_V as u32,
};

/// The prepared cosine-quadratic lobe.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CosQuad {
    a: f64,
    v: u8,
}

impl CosQuad {
    /// The default number of squarings (the thesis's `K_4`).
    pub const DEFAULT_V: u8 = 4;
    /// The largest supported number of squarings.
    pub const MAX_V: u8 = 10;

    pub(crate) fn new(n: Exponent, v: u8) -> Self {
        let v = v.min(Self::MAX_V);
        Self {
            a: Self::slope_for(n.get(), v),
            v,
        }
    }

    /// `a = (n + 1) / (2^v + 1)`, written once for the preparation and its recorded form.
    pub(crate) fn slope_for<R: Real>(n: R, v: u8) -> R {
        (n + R::from_f64(1.0)) / R::from_f64(f64::from(1u32 << v) + 1.0)
    }

    /// The per-material slope `a = (n + 1) / (2^v + 1)`.
    #[must_use]
    pub fn slope(&self) -> f64 {
        self.a
    }

    /// The number of squarings `v`.
    #[must_use]
    pub fn squarings(&self) -> u32 {
        u32::from(self.v)
    }

    /// Evaluates at `t in (0, 1]`.
    #[inline(always)]
    pub(crate) fn eval<R: Real>(&self, t: R) -> R {
        let one = R::from_f64(1.0);
        let mut value = (R::parameter("slope", self.a) * (t - one) + one).max(R::from_f64(0.0));
        for _ in 0..self.v {
            value = value.square();
        }
        value
    }

    /// `m + 1 = 2^v + 1`, the power of the integrated base.
    fn power_plus_one(&self) -> f64 {
        f64::from(1u32 << self.v) + 1.0
    }

    /// `int_t^1 cosquad(s) ds`, with `1 - x^(m+1)` as `-expm1((m + 1) ln x)`.
    pub(crate) fn tail(&self, t: f64) -> f64 {
        let power = self.power_plus_one();
        let base = self.a * (t - 1.0) + 1.0;
        let remaining = if base > 0.0 {
            -(power * (self.a * (t - 1.0)).ln_1p()).exp_m1()
        } else {
            1.0
        };
        remaining / (self.a * power)
    }

    /// The base at `t = 0` to the power `m + 1`: what the tail leaves out below the horizon.
    fn floor<R: Real>(&self) -> R {
        let one = R::from_f64(1.0);
        (one - R::parameter("slope", self.a))
            .max(R::from_f64(0.0))
            .powf(R::from_f64(self.power_plus_one()))
    }

    /// `int_0^1 cosquad = (1 - floor) / (a (m + 1))`.
    pub(crate) fn total<R: Real>(&self) -> R {
        let slope = R::parameter("slope", self.a);
        (R::from_f64(1.0) - self.floor()) / (slope * R::from_f64(self.power_plus_one()))
    }

    /// The cosine whose tail is the fraction `u` of the whole (generic, so that a target
    /// that samples records it).
    pub(crate) fn tail_inverse<R: Real>(&self, u: R) -> R {
        let one = R::from_f64(1.0);
        let power = R::from_f64(self.power_plus_one());
        let floor: R = self.floor();
        let log_base = (-u * (one - floor)).ln_1p() / power;
        (one + log_base.exp_m1() / R::parameter("slope", self.a)).max(R::from_f64(0.0))
    }
}

/// The closed-form draw on lanes: the base `x = (1 - u (1 - x_0^(m+1)))^(1/(m+1))` as
/// `exp2(log2((1 - u) + u x_0^(m+1)) / (m + 1))`, then `t = max(0, 1 + (x - 1) / a)`.
#[derive(Clone, Copy, Debug)]
pub(crate) struct CosQuadDraw {
    floor: f32,
    inverse_power: f32,
    inverse_slope: f32,
}

impl CosQuad {
    pub(crate) fn draw_kernel(&self) -> CosQuadDraw {
        CosQuadDraw {
            floor: self.floor::<f64>() as f32,
            inverse_power: (1.0 / self.power_plus_one()) as f32,
            inverse_slope: (1.0 / self.a) as f32,
        }
    }
}

impl Kernel for CosQuadDraw {
    #[inline(always)]
    fn eval_lanes<V: Lanes>(self, u: V) -> V {
        let one = u.splat(1.0);
        let remaining = remaining_share(u, self.floor);
        let base = exp2(log2(remaining) * u.splat(self.inverse_power));
        (base - one)
            .mul_add(u.splat(self.inverse_slope), one)
            .max(u.splat(0.0))
    }
}

/// The batch kernel: the base `a (t - 1) + 1` fused, clamped to `[0, 1]`, squared
/// `SQUARINGS` times, unrolled. The clamp on the base serves both range rules that a clamp
/// of `t` and a `max` on the base spent three instructions on: `t > 1` gives a base above 1,
/// clamped to 1; `t <= 0` gives at most `1 - a`, which the lower clamp zeroes when `a >= 1`
/// (`n >= 2^v`); NaN gives NaN, which `max` turns into 0 (x86's `maxps` returns its second
/// operand). Below `a = 1` (`MASKED`) the base stays above `1 - a > 0` for every `t > 0`, so
/// a compare zeroes `t <= 0` and NaN instead of the lower clamp. (`a t + (1 - a)` would save
/// the subtraction, on a pipe this kernel leaves idle, but cancels catastrophically unfused,
/// as the plain loop runs it.)
#[derive(Clone, Copy, Debug)]
pub(crate) struct CosQuadKernel<const SQUARINGS: u32, const MASKED: bool> {
    slope: f32,
}

impl CosQuad {
    /// Whether `t <= 0` needs an explicit zero (the slope is below 1).
    pub(crate) fn needs_mask(&self) -> bool {
        self.a < 1.0
    }

    /// The batch kernel (the caller picks `SQUARINGS = v` and `MASKED = needs_mask()`).
    pub(crate) fn kernel<const SQUARINGS: u32, const MASKED: bool>(
        &self,
    ) -> CosQuadKernel<SQUARINGS, MASKED> {
        debug_assert_eq!((SQUARINGS, MASKED), (self.squarings(), self.needs_mask()));
        CosQuadKernel {
            slope: self.a as f32,
        }
    }
}

impl<const SQUARINGS: u32, const MASKED: bool> Kernel for CosQuadKernel<SQUARINGS, MASKED> {
    #[inline(always)]
    fn eval_lanes<V: Lanes>(self, t: V) -> V {
        let one = t.splat(1.0);
        let base = (t - one).mul_add(t.splat(self.slope), one);
        let mut value = if MASKED {
            base.min(one)
        } else {
            base.max(t.splat(0.0)).min(one)
        };
        for _ in 0..SQUARINGS {
            value = value * value;
        }
        if MASKED {
            value.keep(t.gt(t.splat(0.0)))
        } else {
            value
        }
    }
}

impl<const SQUARINGS: u32, const MASKED: bool> LobeKernel for CosQuadKernel<SQUARINGS, MASKED> {
    fn instructions(self) -> Instructions {
        if MASKED {
            Instructions::of(&[
                (Class::Add, 1),
                (Class::Fma, 1),
                (Class::MinMax, 1),
                (Class::Mul, SQUARINGS),
                (Class::Compare, 1),
                (Class::Logic, 1),
            ])
        } else {
            Instructions::of(&[
                (Class::Add, 1),
                (Class::Fma, 1),
                (Class::MinMax, 2),
                (Class::Mul, SQUARINGS),
            ])
        }
    }
}

// Sampled in closed form: the tail and its inverse exactly.
closed_form_facts!(CosQuad, {
    fn lobe_squarings(&self) -> Option<u32> {
        Some(self.squarings())
    }

    fn lobe_preparation<R: Real>(&self, name: &str, n: R) -> Option<R> {
        match name {
            "n" => Some(n),
            "slope" => Some(CosQuad::slope_for(n, self.v)),
            _ => None,
        }
    }
});

/// Its `f32` paths: the batch kernel and how far each `f32` evaluation may stray.
impl ModelF32 for CosQuad {
    fn draw_batch(&self, level: Level, us: &[f32], out: &mut [f32]) -> bool {
        draw_batch::run(level, self.draw_kernel(), us, out);
        true
    }

    fn draw_batch_slope(&self) -> f64 {
        self.slope().min(1.0)
    }

    fn with_kernel<F: WithKernel>(&self, f: F) -> F::Output {
        with_squarings!(self.squarings(), K => {
            if self.needs_mask() {
                f.call(self.kernel::<K, true>())
            } else {
                f.call(self.kernel::<K, false>())
            }
        })
    }

    fn bounds(&self, n: f64) -> F32Bounds {
        // The base (near 1, where the f32 spacing is 6e-8) rounds by half an ULP, and each
        // squaring doubles its effect; on a GPU its slope grows with n as well.
        let v = self.squarings();
        F32Bounds {
            batch_ulps: 4.0 + f64::from(1u32 << v) / 2.0,
            f32_tolerance: 4e-6 * f64::from(1u32 << v.saturating_sub(4)),
            gpu_ulps: (32.0 + n / 2.0) * 2f64.powi(v as i32 - 4).max(1.0),
        }
    }
}
