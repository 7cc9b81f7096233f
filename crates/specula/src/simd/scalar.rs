//! [`Lanes`] with one lane: plain `f32` arithmetic, multiply-adds unfused (a fused one is a
//! library call on targets without FMA). The baseline level and the plain loop use it.

use core::ops::{Add, Div, Mul, Sub};

use super::Lanes;

/// One `f32` lane.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Scalar(pub f32);

macro_rules! binary {
    ($trait:ident, $method:ident, $op:tt) => {
        impl $trait for Scalar {
            type Output = Self;
            #[inline(always)]
            fn $method(self, other: Self) -> Self {
                Scalar(self.0 $op other.0)
            }
        }
    };
}

binary!(Add, add, +);
binary!(Sub, sub, -);
binary!(Mul, mul, *);
binary!(Div, div, /);

impl Lanes for Scalar {
    type Mask = bool;
    const WIDTH: usize = 1;

    #[inline(always)]
    fn splat(self, value: f32) -> Self {
        Scalar(value)
    }

    #[inline(always)]
    fn load(self, src: &[f32]) -> Self {
        Scalar(src[0])
    }

    #[inline(always)]
    fn store(self, dst: &mut [f32]) {
        dst[0] = self.0;
    }

    #[inline(always)]
    fn mul_add(self, b: Self, c: Self) -> Self {
        Scalar(self.0 * b.0 + c.0)
    }

    #[inline(always)]
    fn neg_mul_add(self, b: Self, c: Self) -> Self {
        Scalar(c.0 - self.0 * b.0)
    }

    #[inline(always)]
    fn sqrt(self) -> Self {
        Scalar(self.0.sqrt())
    }

    #[inline(always)]
    fn min(self, other: Self) -> Self {
        if self.0 < other.0 {
            self
        } else {
            other
        }
    }

    #[inline(always)]
    fn max(self, other: Self) -> Self {
        if self.0 > other.0 {
            self
        } else {
            other
        }
    }

    #[inline(always)]
    fn lt(self, other: Self) -> bool {
        self.0 < other.0
    }

    #[inline(always)]
    fn gt(self, other: Self) -> bool {
        self.0 > other.0
    }

    #[inline(always)]
    fn select(self, mask: bool, other: Self) -> Self {
        if mask {
            self
        } else {
            other
        }
    }

    #[inline(always)]
    fn keep(self, mask: bool) -> Self {
        if mask {
            self
        } else {
            Scalar(0.0)
        }
    }

    #[inline(always)]
    fn bits_and(self, bits: u32) -> Self {
        Scalar(f32::from_bits(self.0.to_bits() & bits))
    }

    #[inline(always)]
    fn bits_add(self, bits: u32) -> Self {
        Scalar(f32::from_bits(self.0.to_bits().wrapping_add(bits)))
    }

    #[inline(always)]
    fn bits_shl<const S: i32>(self) -> Self {
        Scalar(f32::from_bits(self.0.to_bits() << S))
    }

    #[inline(always)]
    fn bits_shr_signed<const S: i32>(self) -> Self {
        Scalar(f32::from_bits(((self.0.to_bits() as i32) >> S) as u32))
    }

    #[inline(always)]
    fn int_to_float(self) -> Self {
        Scalar(self.0.to_bits() as i32 as f32)
    }

    #[inline(always)]
    fn float_to_int(self) -> Self {
        // In range by the caller's clamp, where `as` is the hardware's truncation.
        Scalar(f32::from_bits(self.0 as i32 as u32))
    }
}
