//! The scalar type every lobe is written against.
//!
//! Each model's formula exists once, generic over [`Real`]. Instantiated with `f64` it is the
//! reference; with `f32` it is the fast path; with `Counted` (`ops.rs`) it counts
//! the operations of one evaluation, so the cost table is read off the implementation rather
//! than typed by hand. Anything a formula needs (a squaring, a `log2`, a comparison) is a
//! method here so that the counting type sees it.

use core::ops::{Add, Div, Mul, Neg, Sub};

/// A real number type a lobe can be evaluated in.
///
/// Constants enter through [`Real::from_f64`]: models keep their per-material constants in
/// `f64` and convert at use, which a compiler hoists out of any loop.
pub trait Real:
    Copy
    + PartialOrd
    + Add<Output = Self>
    + Sub<Output = Self>
    + Mul<Output = Self>
    + Div<Output = Self>
    + Neg<Output = Self>
{
    /// Converts an `f64` constant (rounding to nearest for narrower types).
    fn from_f64(x: f64) -> Self;
    /// A per-material constant the model prepared from `n`, by name (`n`, `slope`, ...): the
    /// number itself, except to a recorded expression, which keeps the name so that a target
    /// can expose it as an input (`Node::Parameter`, `expression/mod.rs`).
    #[inline(always)]
    fn parameter(_name: &'static str, value: f64) -> Self {
        Self::from_f64(value)
    }
    /// Widens to `f64` (exact for `f32` and `f64`).
    fn to_f64(self) -> f64;
    /// `self * self`, counted as a squaring rather than a general multiply.
    #[must_use]
    fn square(self) -> Self;
    /// Square root.
    #[must_use]
    fn sqrt(self) -> Self;
    /// Base-2 logarithm.
    #[must_use]
    fn log2(self) -> Self;
    /// Base-2 exponential.
    #[must_use]
    fn exp2(self) -> Self;
    /// Arc cosine, in radians.
    #[must_use]
    fn acos(self) -> Self;
    /// `e^self`.
    #[must_use]
    fn exp(self) -> Self;
    /// `ln(1 + self)`, exact near 0 (sampling's tail inverses).
    #[must_use]
    fn ln_1p(self) -> Self;
    /// `e^self - 1`, exact near 0 (sampling's tail inverses).
    #[must_use]
    fn exp_m1(self) -> Self;
    /// Cosine of an angle in radians.
    #[must_use]
    fn cos(self) -> Self;
    /// Sine of an angle in radians.
    #[must_use]
    fn sin(self) -> Self;
    /// `self` raised to a real power (the reference `t^n`).
    #[must_use]
    fn powf(self, exponent: Self) -> Self;
    /// The larger of two values (a comparison and a select).
    #[must_use]
    fn max(self, other: Self) -> Self;
    /// The smaller of two values (a comparison and a select).
    #[must_use]
    fn min(self, other: Self) -> Self;
    /// The smallest integer not below `self` (in hardware, the integer field: free but for
    /// the rounding).
    #[must_use]
    fn ceil(self) -> Self;
    /// `self * 2^k` for an integer-valued `k <= 0` (in hardware, a shift); 0 once `2^k`
    /// underflows the format.
    #[must_use]
    fn shift(self, k: Self) -> Self;
    /// `(m, e)` with `self = m 2^e`, `m` in `[1/2, 1)`, for `self > 0` (C's `frexp`): read
    /// off the float's exponent and mantissa fields, no arithmetic (in hardware, wiring).
    #[must_use]
    fn frexp(self) -> (Self, Self);
    /// The float whose bit pattern, read as a number with 23 fraction bits, is `self + 127`:
    /// `2^floor(x) (1 + x - floor(x))`, the piecewise-linear `2^x` of the IEEE bit trick
    /// (Schraudolph 1999); 0 at or below -127. In `f32` it is what the trick computes (one
    /// multiply-add and a float-to-int conversion, so the result lies on a grid of `2^-17`
    /// relative steps); in `f64` it is the exact piecewise-linear function.
    #[must_use]
    fn bits_exp2(self) -> Self;
    /// `then` where `self < bound`, else `otherwise` (a comparison and a select; false for
    /// NaN). Models choose with this rather than an `if`, so that a recorded expression
    /// (`expression/mod.rs`) keeps both sides and a target evaluates the choice itself.
    #[must_use]
    fn select_less(self, bound: Self, then: Self, otherwise: Self) -> Self;
    /// [`Real::select_less`] of two sides computed on demand: a float computes only the
    /// side it takes (for a scalar solver that evaluates a model many times); a recording
    /// or a count computes both, as `select_less` does.
    #[must_use]
    #[inline(always)]
    fn branch_less(
        self,
        bound: Self,
        then: impl FnOnce() -> Self,
        otherwise: impl FnOnce() -> Self,
    ) -> Self {
        self.select_less(bound, then(), otherwise())
    }
}

macro_rules! impl_real_for_float {
    ($float:ty) => {
        impl Real for $float {
            #[inline(always)]
            fn from_f64(x: f64) -> Self {
                x as $float
            }
            #[inline(always)]
            fn to_f64(self) -> f64 {
                f64::from(self)
            }
            #[inline(always)]
            fn square(self) -> Self {
                self * self
            }
            #[inline(always)]
            fn sqrt(self) -> Self {
                <$float>::sqrt(self)
            }
            #[inline(always)]
            fn log2(self) -> Self {
                <$float>::log2(self)
            }
            #[inline(always)]
            fn exp2(self) -> Self {
                <$float>::exp2(self)
            }
            #[inline(always)]
            fn acos(self) -> Self {
                <$float>::acos(self)
            }
            #[inline(always)]
            fn cos(self) -> Self {
                <$float>::cos(self)
            }
            #[inline(always)]
            fn sin(self) -> Self {
                <$float>::sin(self)
            }
            #[inline(always)]
            fn exp(self) -> Self {
                <$float>::exp(self)
            }
            #[inline(always)]
            fn ln_1p(self) -> Self {
                <$float>::ln_1p(self)
            }
            #[inline(always)]
            fn exp_m1(self) -> Self {
                <$float>::exp_m1(self)
            }
            #[inline(always)]
            fn powf(self, exponent: Self) -> Self {
                <$float>::powf(self, exponent)
            }
            #[inline(always)]
            fn max(self, other: Self) -> Self {
                <$float>::max(self, other)
            }
            #[inline(always)]
            fn min(self, other: Self) -> Self {
                <$float>::min(self, other)
            }
            #[inline(always)]
            fn ceil(self) -> Self {
                <$float>::ceil(self)
            }
            #[inline(always)]
            fn shift(self, k: Self) -> Self {
                // Build 2^k from its exponent field; below the normal range the result is 0,
                // which is also what a fixed-width shifter produces.
                let biased = k as i64 + <$float>::MAX_EXP as i64 - 1;
                if biased <= 0 {
                    0.0
                } else {
                    self * <$float>::from_bits(
                        ((biased as u64) << (<$float>::MANTISSA_DIGITS - 1)) as _,
                    )
                }
            }
            #[inline(always)]
            fn frexp(self) -> (Self, Self) {
                BitTricks::frexp_fields(self)
            }
            #[inline(always)]
            fn bits_exp2(self) -> Self {
                BitTricks::bits_exp2_fields(self)
            }
            #[inline(always)]
            fn select_less(self, bound: Self, then: Self, otherwise: Self) -> Self {
                if self < bound {
                    then
                } else {
                    otherwise
                }
            }
            #[inline(always)]
            fn branch_less(
                self,
                bound: Self,
                then: impl FnOnce() -> Self,
                otherwise: impl FnOnce() -> Self,
            ) -> Self {
                if self < bound {
                    then()
                } else {
                    otherwise()
                }
            }
        }
    };
}

impl_real_for_float!(f32);
impl_real_for_float!(f64);

impl BitTricks for f32 {
    #[inline(always)]
    fn frexp_fields(self) -> (Self, Self) {
        let bits = self.to_bits();
        let mantissa = f32::from_bits((bits & 0x007f_ffff) | 0x3f00_0000);
        (mantissa, ((bits >> 23) & 0xff) as f32 - 126.0)
    }
    #[inline(always)]
    fn bits_exp2_fields(self) -> Self {
        // As fastapprox writes it: (x + 127) 2^23, truncated, is the bit pattern.
        f32::from_bits((self.max(-127.0) * 8_388_608.0 + 1_065_353_216.0) as u32)
    }
}

impl BitTricks for f64 {
    #[inline(always)]
    fn frexp_fields(self) -> (Self, Self) {
        let bits = self.to_bits();
        let mantissa = f64::from_bits((bits & 0x000f_ffff_ffff_ffff) | 0x3fe0_0000_0000_0000);
        (mantissa, ((bits >> 52) & 0x7ff) as f64 - 1022.0)
    }
    #[inline(always)]
    fn bits_exp2_fields(self) -> Self {
        if self <= -127.0 {
            return 0.0;
        }
        let whole = self.floor();
        (1.0 + self - whole) * 2f64.powi(whole as i32)
    }
}

/// The bit-pattern operations behind [`Real::frexp`] and [`Real::bits_exp2`] for the float
/// types.
trait BitTricks: Sized {
    fn frexp_fields(self) -> (Self, Self);
    fn bits_exp2_fields(self) -> Self;
}
