//! # `example`: a lobe added as every lobe is, for the test that proves it
//!
//! ```text
//! example(t) = (t / (h (1 - t) + t))^2,   h = n / 2
//! ```
//!
//! `t^n = (t^(n/2))^2`, each half by Schlick's rational form: the tail falls like
//! `1 / (h (1 - t))^2`, faster than Schlick's `1 / (n (1 - t))`. It is compiled only with the
//! `example-lobe` feature, and is this file plus one line of the registry (`lobes!` in
//! `lobe/mod.rs`); with it, `crates/report/src/example_lobe.rs` finds it in the analysis,
//! the GPU's lobe library, every export and the report's tables. A new lobe starts from a copy
//! of this file: everything specula knows of a lobe is here.
//!
//! - **Parameters**: the exponent `n`; its formula's one named parameter is `h`, prepared
//!   from `n` (so that targets taking `n` as an input compute it).
//! - **Domain**: `t in (0, 1]`; the value lies in `(0, 1]` since the denominator is at least
//!   `t`.
//! - **Cost**: one multiply, two adds, one divide, one square.
//! - **Sampling**: table (it states no closed-form tail, so the facts' defaults say so).
//! - **Source**: specula's tests.

use super::batch::{clamp_unit, CLAMP, F32Bounds, LobeKernel, ModelF32, WithKernel};
use super::facts::ModelFacts;
use super::info::{LineStyle, LobeInfo, Origin};
use crate::real::Real;
use crate::simd::tally::{Class, Instructions};
use crate::simd::{Kernel, Lanes};
use crate::Exponent;

/// The registry's entry for this lobe.
pub(super) const INFO: LobeInfo = LobeInfo {
    id: "example",
    summary: "Schlick's form at half the exponent, squared (the registry's worked example)",
    formula: "(t / (h (1 - t) + t))^2, h = n / 2",
    takes_angle: false,
    params: &[],
    origin: Origin::Specula,
};

/// How every plot draws this lobe (`LobeKind::line_style`).
pub(super) const STYLE: LineStyle = LineStyle {
    rgb: [0, 0, 240],
    dashed: true,
};

/// What this lobe prepares (its `Model` variant holds it).
pub(super) type Prepared = Example;

/// This lobe prepared for `n`.
pub(super) fn prepare(n: Exponent) -> Prepared {
    Example {
        half_n: half(n.get()),
    }
}

/// `h = n / 2`, written once over `Real` for the preparation and its recorded form.
fn half<R: Real>(n: R) -> R {
    n * R::from_f64(0.5)
}

/// The prepared lobe: `h`, computed once per material.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Example {
    half_n: f64,
}

impl Example {
    /// Evaluates at `t in (0, 1]`.
    #[inline(always)]
    fn eval<R: Real>(&self, t: R) -> R {
        let h = R::parameter("h", self.half_n);
        (t / (h * (R::from_f64(1.0) - t) + t)).square()
    }
}

/// Its formula and the preparation of `h`; every other fact is the default's "not this
/// model".
impl ModelFacts for Example {
    #[inline]
    fn lobe_eval_unit<R: Real>(&self, t: R) -> R {
        self.eval(t)
    }

    fn lobe_preparation<R: Real>(&self, name: &str, n: R) -> Option<R> {
        (name == "h").then(|| half(n))
    }
}

/// The batch kernel: Schlick's ratio with the denominator fused, squared; `t` clamped to
/// `[0, 1]` makes `t <= 0` and NaN give 0.
#[derive(Clone, Copy, Debug)]
pub(crate) struct ExampleKernel {
    half_n: f32,
}

impl Kernel for ExampleKernel {
    #[inline(always)]
    fn eval_lanes<V: Lanes>(self, t: V) -> V {
        let c = clamp_unit(t);
        let ratio = c / t.splat(self.half_n).mul_add(t.splat(1.0) - c, c);
        ratio * ratio
    }
}

impl LobeKernel for ExampleKernel {
    fn instructions(self) -> Instructions {
        CLAMP
            .plus(Class::Add, 1)
            .plus(Class::Fma, 1)
            .plus(Class::Div, 1)
            .plus(Class::Mul, 1)
    }
}

/// Its `f32` paths: the batch kernel and how far each `f32` evaluation may stray.
impl ModelF32 for Example {
    fn with_kernel<F: WithKernel>(&self, f: F) -> F::Output {
        f.call(ExampleKernel {
            half_n: self.half_n as f32,
        })
    }

    fn bounds(&self, _n: f64) -> F32Bounds {
        // Schlick's exact operations, their rounding doubled by the square.
        F32Bounds {
            batch_ulps: 8.0,
            gpu_ulps: 64.0,
            ..F32Bounds::EXACT
        }
    }
}
