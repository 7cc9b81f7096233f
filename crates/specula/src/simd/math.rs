//! Branch-free `log2`, `exp2` and `acos` over [`Lanes`]: the kernels' elementary functions.
//!
//! Cephes polynomials (S. Moshier, public domain) on reduced ranges, with the reduction done
//! on the bit patterns. Measured against `f64` over every `f32` the lobes can see (tests
//! below): [`log2`] within 2 ULP of the result or `2e-8` absolute near 1 (positive normal
//! inputs); [`exp2`] within 2 ULP on `[-126, 0]` and 0 at or below `-127`; [`acos`] within
//! `2.5e-7` radians on `[0, 1]`.
//!
//! Also the IEEE bit tricks' two halves, [`frexp`] and [`bits_exp2`] (the bit-trick lobes'
//! `log2` and `exp2`, exact by construction: field moves and one multiply-add).
//!
//! Instruction counts per vector are stated beside each function and checked by the tests.

use super::tally::{Class, Instructions};
use super::Lanes;

/// `log2 x` for a positive, finite, normal `x` (the caller guarantees it).
///
/// Writing `x = 2^k m` with `m` in `[sqrt(1/2), sqrt(2))`: subtracting the bits of
/// `sqrt(1/2)` puts `k` in the exponent field and `m`'s offset in the mantissa field (the
/// reduction of musl's `logf`), five integer-side instructions and no compare.
#[inline(always)]
pub(crate) fn log2<V: Lanes>(x: V) -> V {
    const SQRT_HALF_BITS: u32 = 0x3f35_04f3;
    let offset = x.bits_add(SQRT_HALF_BITS.wrapping_neg());
    let k = offset.bits_shr_signed::<23>().int_to_float();
    let m = offset.bits_and(0x007f_ffff).bits_add(SQRT_HALF_BITS);
    let z = m - x.splat(1.0);
    // Cephes logf: ln(1 + z) = z - z^2/2 + z^3 P(z), with P (degree 8, coefficients p0..p8)
    // by Estrin's scheme: four multiply-adds deep instead of Horner's eight, so that fewer
    // vectors wait on latency.
    let c = |value: f32| x.splat(value);
    let z2 = z * z;
    let z4 = z2 * z2;
    let p01 = c(-2.499_999_4e-1).mul_add(z, c(3.333_333e-1));
    let p23 = c(-1.666_805_8e-1).mul_add(z, c(2.000_071_4e-1));
    let p45 = c(-1.242_014_1e-1).mul_add(z, c(1.424_932_3e-1));
    let p67 = c(-1.151_461_1e-1).mul_add(z, c(1.167_699_9e-1));
    let low = p23.mul_add(z2, p01);
    let high = p67.mul_add(z2, p45);
    let p = c(7.037_683_6e-2).mul_add(z4, high).mul_add(z4, low);
    let ln = (z2 * z).mul_add(p, c(-0.5).mul_add(z2, z));
    ln.mul_add(c(core::f32::consts::LOG2_E), k)
}

/// [`log2`]'s instructions.
pub(crate) const LOG2: Instructions = Instructions::of(&[
    (Class::IntAdd, 2),
    (Class::Shift, 1),
    (Class::Convert, 1),
    (Class::Logic, 1),
    (Class::Add, 1),
    (Class::Fma, 11),
    (Class::Mul, 3),
]);

/// `2^x` for `x` in `[-126, 0]`; 0 at or below `-127` (the lobes' range: they underflow there).
#[inline(always)]
pub(crate) fn exp2<V: Lanes>(x: V) -> V {
    // Adding 1.5 * 2^23 rounds to an integer k, which then sits in the low mantissa bits;
    // shifted up by 23 those bits are k's exponent field (the magic's own bits shift out),
    // and k = -127 gives a zero scale.
    const MAGIC: f32 = 12_582_912.0;
    let clamped = x.max(x.splat(-127.0));
    let shifted = clamped + x.splat(MAGIC);
    let k = shifted - x.splat(MAGIC);
    let f = clamped - k;
    // Cephes exp2f: 2^f = 1 + f P(f), f in [-1/2, 1/2], P (degree 5) by Estrin's scheme.
    let c = |value: f32| x.splat(value);
    let f2 = f * f;
    let p01 = c(2.402_264_8e-1).mul_add(f, c(6.931_472e-1));
    let p23 = c(9.618_437e-3).mul_add(f, c(5.550_332_5e-2));
    let p45 = c(1.535_336_2e-4).mul_add(f, c(1.339_887_4e-3));
    let p = p45.mul_add(f2 * f2, p23.mul_add(f2, p01));
    let value = f.mul_add(p, c(1.0));
    let scale = shifted.bits_shl::<23>().bits_add(0x3f80_0000);
    value * scale
}

/// [`exp2`]'s instructions.
pub(crate) const EXP2: Instructions = Instructions::of(&[
    (Class::MinMax, 1),
    (Class::Add, 3),
    (Class::Fma, 6),
    (Class::Shift, 1),
    (Class::IntAdd, 1),
    (Class::Mul, 3),
]);

/// `acos x` for `x` in `[0, 1]`.
///
/// One polynomial for both halves: above 1/2, `acos x = 2 asin(sqrt((1 - x) / 2))`; below,
/// `pi/2 - asin x`; the inputs and the final multiply-add are selected, not both computed.
#[inline(always)]
pub(crate) fn acos<V: Lanes>(x: V) -> V {
    let c = |value: f32| x.splat(value);
    let high = x.gt(c(0.5));
    let half = x.neg_mul_add(c(0.5), c(0.5));
    let z = half.select(high, x * x);
    let y = z.sqrt().select(high, x);
    // Cephes asinf: asin(y) = y + y^3 P(y^2) for |y| <= 1/2.
    let p = c(4.216_32e-2).mul_add(z, c(2.418_131e-2));
    let p = p.mul_add(z, c(4.547_002_6e-2));
    let p = p.mul_add(z, c(7.495_300_3e-2));
    let p = p.mul_add(z, c(1.666_675_2e-1));
    let asin = (y * z).mul_add(p, y);
    let scale = c(2.0).select(high, c(-1.0));
    let offset = c(0.0).select(high, c(core::f32::consts::FRAC_PI_2));
    asin.mul_add(scale, offset)
}

/// [`acos`]'s instructions.
pub(crate) const ACOS: Instructions = Instructions::of(&[
    (Class::Compare, 1),
    (Class::Fma, 7),
    (Class::Mul, 2),
    (Class::Blend, 4),
    (Class::Sqrt, 1),
]);

/// `(t's mantissa in [1/2, 1), t's exponent)` as vector lanes, from the bits: the
/// [`Real::frexp`](crate::Real::frexp) of the kernels, for `t >= 0`.
#[inline(always)]
pub(crate) fn frexp<V: Lanes>(t: V) -> (V, V) {
    let mantissa = t.bits_and(0x007f_ffff).bits_add(0x3f00_0000);
    let exponent = t.bits_shr_signed::<23>().bits_add(126_u32.wrapping_neg());
    (mantissa, exponent.int_to_float())
}

/// [`frexp`]'s instructions.
pub(crate) const FREXP: Instructions = Instructions::of(&[
    (Class::Logic, 1),
    (Class::IntAdd, 2),
    (Class::Shift, 1),
    (Class::Convert, 1),
]);

/// [`Real::bits_exp2`](crate::Real::bits_exp2) on vector lanes: `(x + 127) 2^23` truncated is the
/// bit pattern.
#[inline(always)]
pub(crate) fn bits_exp2<V: Lanes>(x: V) -> V {
    x.max(x.splat(-127.0))
        .mul_add(x.splat(8_388_608.0), x.splat(1_065_353_216.0))
        .float_to_int()
}

/// [`bits_exp2`]'s instructions.
pub(crate) const BITS_EXP2: Instructions =
    Instructions::of(&[(Class::MinMax, 1), (Class::Fma, 1), (Class::Convert, 1)]);

#[cfg(test)]
mod tests {
    use super::super::tally::count;
    use super::super::{dispatch, BatchLoop, Drive, Kernel, Level};
    use super::*;

    #[derive(Clone, Copy)]
    enum Function {
        Log2,
        Exp2,
        Acos,
    }

    impl Kernel for Function {
        fn eval_lanes<V: Lanes>(self, x: V) -> V {
            match self {
                Function::Log2 => log2(x),
                Function::Exp2 => exp2(x),
                Function::Acos => acos(x),
            }
        }
    }

    /// `function` at every `x`, at every level and as the plain loop: each result set, named.
    fn everywhere(function: Function, xs: &[f32]) -> Vec<(String, Vec<f32>)> {
        let mut results = Vec::new();
        for level in Level::available() {
            for batch_loop in [BatchLoop::Explicit, BatchLoop::Plain] {
                let mut out = vec![0.0; xs.len()];
                dispatch(
                    level,
                    Drive {
                        kernel: function,
                        ts: xs,
                        out: &mut out,
                        batch_loop,
                    },
                );
                results.push((format!("{} {batch_loop:?}", level.name()), out));
            }
        }
        results
    }

    fn ulps(value: f32, reference: f64) -> f64 {
        let spacing = f64::from(f32::EPSILON) * reference.abs().max(f64::from(f32::MIN_POSITIVE));
        (f64::from(value) - reference).abs() / spacing
    }

    /// Every 97th normal `f32` up to 4, and large values.
    #[test]
    fn log2_is_within_2_ulp_or_2e_8_absolute() {
        let mut xs: Vec<f32> = (f32::MIN_POSITIVE.to_bits()..4.0_f32.to_bits())
            .step_by(97)
            .map(f32::from_bits)
            .collect();
        xs.extend([1e10_f32, 3.4e38, 1.0, 0.5, 2.0, f32::MAX]);
        for (name, values) in everywhere(Function::Log2, &xs) {
            for (&x, &value) in xs.iter().zip(&values) {
                let reference = f64::from(x).log2();
                let error = (f64::from(value) - reference).abs();
                assert!(
                    ulps(value, reference) <= 2.0 || error <= 2e-8,
                    "{name}: log2({x:e}) = {value} vs {reference}"
                );
            }
        }
    }

    #[test]
    fn exp2_is_within_2_ulp_on_the_lobes_range_and_0_below() {
        let xs: Vec<f32> = (0..=126 * 1024)
            .map(|i| -(i as f32) / 1024.0 - f32::EPSILON * (i % 7) as f32)
            .filter(|&x| x >= -126.0)
            .chain([-127.0, -200.0, -1e30, 0.0])
            .collect();
        for (name, values) in everywhere(Function::Exp2, &xs) {
            for (&x, &value) in xs.iter().zip(&values) {
                if x <= -127.0 {
                    assert_eq!(value, 0.0, "{name}: exp2({x})");
                } else {
                    let reference = f64::from(x).exp2();
                    assert!(
                        ulps(value, reference) <= 2.0,
                        "{name}: exp2({x}) = {value} vs {reference}"
                    );
                }
            }
        }
    }

    /// `exp2_nonpositive` is `exp2` on its range and takes a positive argument or NaN as 0,
    /// on every level.
    #[test]
    fn exp2_nonpositive_takes_positive_arguments_and_nan_as_zero() {
        struct Run;
        impl super::super::Job for Run {
            type Output = Vec<f32>;
            fn run<V: Lanes>(self, lanes: V) -> Vec<f32> {
                let xs = [0.5, 100.0, f32::NAN, f32::INFINITY, -1.0, 0.0, -3.0, -200.0];
                let mut out = vec![0.0; xs.len()];
                for (x, o) in xs.chunks(V::WIDTH).zip(out.chunks_mut(V::WIDTH)) {
                    super::super::exp2_nonpositive(lanes.load(x)).store(o);
                }
                out
            }
        }
        for level in Level::available() {
            let expected = [1.0, 1.0, 1.0, 1.0, 0.5, 1.0, 0.125, 0.0];
            for (got, expected) in dispatch(level, Run).iter().zip(expected) {
                assert!(
                    (got - expected).abs() <= 2.0 * f32::EPSILON,
                    "{level:?}: {got} against {expected}"
                );
            }
        }
    }

    #[test]
    fn acos_is_within_2_5e_7_on_zero_one() {
        let mut xs: Vec<f32> = (0..=1_000_000).map(|k| k as f32 / 1e6).collect();
        // Near 1 the angle is small: checked relative to it too.
        xs.extend((1..=10_000).map(|k| 1.0 - k as f32 * f32::EPSILON / 2.0));
        for (name, values) in everywhere(Function::Acos, &xs) {
            for (&x, &value) in xs.iter().zip(&values) {
                let reference = f64::from(x).acos();
                let error = (f64::from(value) - reference).abs();
                assert!(error <= 2.5e-7, "{name}: acos({x}) off by {error:e}");
                if x >= 0.999 {
                    assert!(
                        error <= 4e-7 * reference + 1e-9,
                        "{name}: acos({x}) = {value} vs {reference}, relative"
                    );
                }
            }
        }
    }

    #[test]
    fn stated_instruction_counts_are_what_the_functions_execute() {
        for x in [0.1, 0.7, 1.0] {
            assert_eq!(count(Function::Log2, x), LOG2, "log2");
            assert_eq!(count(Function::Exp2, -x), EXP2, "exp2");
            assert_eq!(count(Function::Acos, x), ACOS, "acos");
        }
    }
}
