//! # `schlick-mod`: the thesis's modified Schlick lobe
//!
//! ```text
//! schlick-mod(t) = t^a / (n (1 - t) + t),   a = 2^max(0, floor(log2 n) - 2)
//! ```
//!
//! The thesis replaces Schlick's numerator `t` by a low power `t^a`, `a << n`, growing with
//! `n`, to pull in the slowly decaying bloom. Because `a` is a power of two, `t^a` costs
//! `log2(a)` squarings; for `n < 8`, `a = 1` and the lobe is plain Schlick.
//! `floor(log2 n)` is read exactly from the binary exponent of `n`.
//!
//! | n        | a  | squarings |
//! |----------|----|-----------|
//! | 1 .. 7   | 1  | 0         |
//! | 8 .. 15  | 2  | 1         |
//! | 16 .. 31 | 4  | 2         |
//! | 512 ..   | 128| 7         |
//!
//! - **Parameters**: the exponent `n` (which fixes `a`).
//! - **Domain**: `t in (0, 1]`; the value lies in `(0, 1]` since `t^a <= t <= n (1 - t) + t`.
//! - **Cost**: `log2(a)` squarings, one multiply, two adds, one divide.
//! - **Sampling**: table. `int t^a / (n (1 - t) + t)` has a closed form only as a long
//!   polynomial division plus a logarithm for each `a`; the tabulated density
//!   (`sampling::CosineDistribution`) is exact enough and cheaper to trust.
//! - **Source**: the thesis, slide "Modified Schlick BRDF".

use super::batch::{with_squarings, F32Bounds, ModelF32, WithKernel};
use super::facts::ModelFacts;
use super::info::{LineStyle, LobeInfo, Origin};
use super::schlick::schlick_denominator_ratio;
use super::schlick::SchlickKernel;
use crate::real::Real;
use crate::Exponent;

/// The registry's entry for this lobe.
pub(super) const INFO: LobeInfo = LobeInfo {
    id: "schlick-mod",
    summary: "the thesis's modified Schlick: a power of two of t in the numerator",
    formula: "t^a / (n (1 - t) + t), a = 2^max(0, floor(log2 n) - 2)",
    takes_angle: false,
    params: &[],
    origin: Origin::Thesis,
};

/// How every plot draws this lobe (`LobeKind::line_style`).
pub(super) const STYLE: LineStyle = LineStyle {
    rgb: [243, 132, 0],
    dashed: true,
};

/// What this lobe prepares (its `Model` variant holds it).
pub(super) type Prepared = SchlickMod;

/// This lobe prepared for `n`.
pub(super) fn prepare(n: Exponent) -> Prepared {
    SchlickMod::new(n)
}

/// The prepared modified Schlick lobe.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SchlickMod {
    n: f64,
    squarings: u32,
}

impl SchlickMod {
    pub(crate) fn new(n: Exponent) -> Self {
        let floor_log2_n = floor_log2(n.get());
        Self {
            n: n.get(),
            squarings: floor_log2_n.saturating_sub(2),
        }
    }

    /// How many times `t` is squared: `log2` of the power `a`.
    pub(crate) fn squarings(&self) -> u32 {
        self.squarings
    }

    /// Evaluates at `t in (0, 1]`.
    #[inline(always)]
    pub(crate) fn eval<R: Real>(&self, t: R) -> R {
        let mut numerator = t;
        for _ in 0..self.squarings {
            numerator = numerator.square();
        }
        schlick_denominator_ratio(numerator, t, self.n)
    }
}

/// `floor(log2 x)` for a normal `x >= 1`, read from the IEEE exponent field (exact, unlike
/// `x.log2().floor()` just below a power of two).
fn floor_log2(x: f64) -> u32 {
    let biased = (x.to_bits() >> 52) & 0x7ff;
    (biased as i64 - 1023).max(0) as u32
}

impl SchlickMod {
    /// The batch kernel: Schlick's with the numerator squared `SQUARINGS` times, unrolled
    /// (the caller picks `SQUARINGS = self.squarings()`).
    pub(crate) fn kernel<const SQUARINGS: u32>(&self) -> SchlickKernel<SQUARINGS> {
        debug_assert_eq!(SQUARINGS, self.squarings);
        SchlickKernel { n: self.n as f32 }
    }
}

/// Its squarings change at every power of two of `n` from 8 on.
impl ModelFacts for SchlickMod {
    #[inline]
    fn lobe_eval_unit<R: Real>(&self, t: R) -> R {
        self.eval(t)
    }

    fn lobe_structural_range(&self, _n: f64) -> [f64; 2] {
        let shape = self.squarings() as usize;
        // Up to the next shape's least exponent, less an amount `f32` still resolves.
        let high = SHAPE_EXPONENTS
            .get(shape + 1)
            .map_or(Exponent::MAX, |next| next * (1.0 - 2f64.powi(-20)));
        [SHAPE_EXPONENTS[shape], high]
    }

    fn lobe_shape_exponents(&self) -> &'static [f64] {
        &SHAPE_EXPONENTS
    }

    fn lobe_squarings(&self) -> Option<u32> {
        Some(self.squarings)
    }
}

/// Where the squarings change: one more at every power of two from 8 on, the last (7) from
/// 512 to `Exponent::MAX`.
const SHAPE_EXPONENTS: [f64; 8] = [1.0, 8.0, 16.0, 32.0, 64.0, 128.0, 256.0, 512.0];

/// Its `f32` paths: the batch kernel and how far each `f32` evaluation may stray.
impl ModelF32 for SchlickMod {
    fn with_kernel<F: WithKernel>(&self, f: F) -> F::Output {
        with_squarings!(self.squarings(), K => f.call(self.kernel::<K>()))
    }

    fn bounds(&self, _n: f64) -> F32Bounds {
        // One fused rounding in the denominator, as Schlick's.
        F32Bounds::EXACT
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn power_follows_the_thesis_table() {
        let power = |n: f64| 1u32 << SchlickMod::new(Exponent::new(n)).squarings;
        assert_eq!(power(1.0), 1);
        assert_eq!(power(7.999), 1);
        assert_eq!(power(8.0), 2);
        assert_eq!(power(15.9), 2);
        assert_eq!(power(16.0), 4);
        assert_eq!(power(100.0), 16);
        assert_eq!(power(512.0), 128);
        assert_eq!(power(1000.0), 128);
    }
}
