//! [`Lanes`] on AVX2 + FMA: 8 lanes in a `ymm` register, each method one instruction (named
//! beside it), through `pulp`'s safe intrinsics (the token proves the features are enabled).

use core::arch::x86_64::{__m256, __m256i, _CMP_GT_OQ, _CMP_LT_OQ};
use core::ops::{Add, Div, Mul, Sub};

use pulp::bytemuck::cast;
use pulp::x86::V3;

use super::{Job, Lanes};

/// Eight `f32` lanes and the token that proves AVX2 + FMA.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Avx2(V3, __m256);

impl Avx2 {
    #[inline(always)]
    fn with(self, value: __m256) -> Self {
        Self(self.0, value)
    }

    #[inline(always)]
    fn int(self) -> __m256i {
        self.0.avx._mm256_castps_si256(self.1)
    }

    #[inline(always)]
    fn with_int(self, value: __m256i) -> Self {
        self.with(self.0.avx._mm256_castsi256_ps(value))
    }

    #[inline(always)]
    fn int_splat(self, bits: u32) -> __m256i {
        self.0.avx._mm256_set1_epi32(bits as i32)
    }
}

macro_rules! binary {
    ($trait:ident, $method:ident, $intrinsic:ident) => {
        impl $trait for Avx2 {
            type Output = Self;
            #[inline(always)]
            fn $method(self, other: Self) -> Self {
                self.with(self.0.avx.$intrinsic(self.1, other.1))
            }
        }
    };
}

binary!(Add, add, _mm256_add_ps); // vaddps
binary!(Sub, sub, _mm256_sub_ps); // vsubps
binary!(Mul, mul, _mm256_mul_ps); // vmulps
binary!(Div, div, _mm256_div_ps); // vdivps

impl Lanes for Avx2 {
    type Mask = __m256;
    const WIDTH: usize = 8;

    #[inline(always)]
    fn splat(self, value: f32) -> Self {
        self.with(self.0.avx._mm256_set1_ps(value))
    }

    #[inline(always)]
    fn load(self, src: &[f32]) -> Self {
        let array: [f32; 8] = src.try_into().expect("a load takes 8 floats");
        self.with(cast(array)) // vmovups
    }

    #[inline(always)]
    fn store(self, dst: &mut [f32]) {
        dst.copy_from_slice(&cast::<__m256, [f32; 8]>(self.1)); // vmovups
    }

    #[inline(always)]
    fn mul_add(self, b: Self, c: Self) -> Self {
        self.with(self.0.fma._mm256_fmadd_ps(self.1, b.1, c.1)) // vfmadd
    }

    #[inline(always)]
    fn neg_mul_add(self, b: Self, c: Self) -> Self {
        self.with(self.0.fma._mm256_fnmadd_ps(self.1, b.1, c.1)) // vfnmadd
    }

    #[inline(always)]
    fn sqrt(self) -> Self {
        self.with(self.0.avx._mm256_sqrt_ps(self.1)) // vsqrtps
    }

    #[inline(always)]
    fn min(self, other: Self) -> Self {
        self.with(self.0.avx._mm256_min_ps(self.1, other.1)) // vminps
    }

    #[inline(always)]
    fn max(self, other: Self) -> Self {
        self.with(self.0.avx._mm256_max_ps(self.1, other.1)) // vmaxps
    }

    #[inline(always)]
    fn lt(self, other: Self) -> __m256 {
        self.0.avx._mm256_cmp_ps::<_CMP_LT_OQ>(self.1, other.1) // vcmpps
    }

    #[inline(always)]
    fn gt(self, other: Self) -> __m256 {
        self.0.avx._mm256_cmp_ps::<_CMP_GT_OQ>(self.1, other.1) // vcmpps
    }

    #[inline(always)]
    fn select(self, mask: __m256, other: Self) -> Self {
        self.with(self.0.avx._mm256_blendv_ps(other.1, self.1, mask)) // vblendvps
    }

    #[inline(always)]
    fn keep(self, mask: __m256) -> Self {
        self.with(self.0.avx._mm256_and_ps(self.1, mask)) // vandps
    }

    #[inline(always)]
    fn bits_and(self, bits: u32) -> Self {
        let mask = self.0.avx._mm256_castsi256_ps(self.int_splat(bits));
        self.with(self.0.avx._mm256_and_ps(self.1, mask)) // vandps
    }

    #[inline(always)]
    fn bits_add(self, bits: u32) -> Self {
        let sum = self
            .0
            .avx2
            ._mm256_add_epi32(self.int(), self.int_splat(bits));
        self.with_int(sum) // vpaddd
    }

    #[inline(always)]
    fn bits_shl<const S: i32>(self) -> Self {
        self.with_int(self.0.avx2._mm256_slli_epi32::<S>(self.int())) // vpslld
    }

    #[inline(always)]
    fn bits_shr_signed<const S: i32>(self) -> Self {
        self.with_int(self.0.avx2._mm256_srai_epi32::<S>(self.int())) // vpsrad
    }

    #[inline(always)]
    fn int_to_float(self) -> Self {
        self.with(self.0.avx._mm256_cvtepi32_ps(self.int())) // vcvtdq2ps
    }

    #[inline(always)]
    fn float_to_int(self) -> Self {
        self.with_int(self.0.avx._mm256_cvttps_epi32(self.1)) // vcvttps2dq
    }
}

/// A [`Job`] as `pulp` runs it: `with_simd` is inlined into the function compiled with the
/// AVX2 + FMA features, and so is everything the job calls (all `#[inline(always)]`).
pub(crate) struct Avx2Job<J>(pub V3, pub J);

impl<J: Job> pulp::WithSimd for Avx2Job<J> {
    type Output = J::Output;

    #[inline(always)]
    fn with_simd<S: pulp::Simd>(self, _: S) -> J::Output {
        let Avx2Job(simd, job) = self;
        job.run(Avx2(simd, simd.avx._mm256_setzero_ps()))
    }
}
