//! The exp2 unit: `2^-x` for an unsigned `x`, by a table of `2^-f` on the fraction and a
//! shift by the integer part.
//!
//! For `x = i + f` (`i` the integer bits, `f` in `[0, 1)` the fraction bits),
//! `2^-x = 2^-f >> i`. The table holds `2^k + 1` samples of `2^-f` in `[1/2, 1]`, linearly
//! interpolated between them by one multiplier (error about `0.12 / 4^k`, relative, plus
//! rounding); a barrel shifter applies `i`. Past `i = F_t + 1` (the table's fraction bits plus
//! its integer bit) every bit has been shifted out and the result is 0.
//!
//! Both baselines need only the negative exponent: the exact power is `2^-(n (-log2 t))` and
//! the spherical Gaussian `2^-(r (1 - t))`, with the negated argument non-negative.

use serde::Serialize;

use crate::fixed::{FixedPoint, Rounding};
use crate::log2::split;

/// The guard bits the table keeps beyond the unit's output fraction.
pub const EXP2_GUARD_BITS: u32 = 2;

/// A `2^-x` unit with `2^segments_log2` interpolated segments.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize)]
pub struct Exp2Unit {
    /// `k`: the table has `2^k + 1` entries.
    pub segments_log2: u32,
}

impl Exp2Unit {
    /// A short name: `table-64`.
    #[must_use]
    pub fn name(self) -> String {
        format!("table-{}", 1 << self.segments_log2)
    }

    /// The fraction bits of the table's entries (and the unit's exact result) for an output
    /// with `out_frac` bits.
    #[must_use]
    pub fn frac_bits(out_frac: u32) -> u32 {
        out_frac + EXP2_GUARD_BITS
    }

    /// The table, `2^(-i / 2^k)` for `i` in `0..=2^k`, rounded to `frac` bits.
    #[must_use]
    pub fn table(self, frac: u32) -> Vec<i64> {
        let segments = 1_u32 << self.segments_log2;
        (0..=segments)
            .map(|i| {
                let x = -f64::from(i) / f64::from(segments);
                FixedPoint::unsigned(1, frac).quantize(x.exp2(), Rounding::HalfEven)
            })
            .collect()
    }

    /// The largest shift that can leave a bit: beyond it the result is 0.
    #[must_use]
    pub fn last_shift(out_frac: u32) -> i64 {
        i64::from(Self::frac_bits(out_frac)) + 1
    }

    /// `2^-x` of `raw` in format `input` (unsigned), exactly as the hardware computes it,
    /// with `table` ([`Exp2Unit::table`] at [`Exp2Unit::frac_bits`]) built by the caller:
    /// `(raw, frac_bits)` of the result before its final resize.
    #[must_use]
    pub fn eval_with_table(
        self,
        table: &[i64],
        raw: i64,
        input: FixedPoint,
        out_frac: u32,
    ) -> (i128, u32) {
        debug_assert!(!input.signed);
        let frac = Self::frac_bits(out_frac);
        let raw = raw.max(0);
        let shift = raw >> input.frac_bits;
        if shift > Self::last_shift(out_frac) {
            return (0, frac);
        }
        let fraction = raw & ((1_i64 << input.frac_bits) - 1);
        let (index, within, within_bits) = split(fraction, input.frac_bits, self.segments_log2);
        let (high, low) = (table[index], table[index + 1]);
        // 2^-f falls across the segment: the start minus the drop times the position.
        let interpolated = high - (((high - low) * within) >> within_bits);
        (i128::from(interpolated >> shift), frac)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn exp2_neg(unit: Exp2Unit, x: f64, input: FixedPoint, out_frac: u32) -> f64 {
        let raw = input.quantize(x, Rounding::HalfEven);
        let table = unit.table(Exp2Unit::frac_bits(out_frac));
        let (value, frac) = unit.eval_with_table(&table, raw, input, out_frac);
        value as f64 / f64::from(frac).exp2()
    }

    /// Integers are exact: the table's first entry is 1 and the shift is the whole answer.
    #[test]
    fn integers_are_exact() {
        let input = FixedPoint::unsigned(6, 12);
        let unit = Exp2Unit { segments_log2: 4 };
        for i in 0..=18 {
            let expected = (-f64::from(i)).exp2();
            assert_eq!(exp2_neg(unit, f64::from(i), input, 16), expected, "2^-{i}");
        }
    }

    /// The error is the linear interpolation bound `h^2 / 8 max |(2^-f)''|` with
    /// `h = 2^-k`, `(2^-f)'' = (ln 2)^2 2^-f <= (ln 2)^2`, plus the table's and the shift's
    /// rounding.
    #[test]
    fn error_matches_the_interpolation_bound() {
        let input = FixedPoint::unsigned(3, 14);
        let unit = Exp2Unit { segments_log2: 4 };
        let out_frac = 20;
        let mut worst = 0.0_f64;
        for raw in 0..=input.max_raw() {
            let x = input.to_f64(raw);
            worst = worst.max((exp2_neg(unit, x, input, out_frac) - (-x).exp2()).abs());
        }
        let interpolation = core::f64::consts::LN_2.powi(2) / 8.0 / 256.0;
        let rounding = 2.0 * f64::from(Exp2Unit::frac_bits(out_frac)).exp2().recip();
        assert!(worst < interpolation + rounding, "{worst}");
        assert!(
            worst > interpolation / 4.0,
            "the error is interpolation, not zero"
        );
    }

    /// Past the last shift every bit is gone.
    #[test]
    fn large_arguments_give_zero() {
        let input = FixedPoint::unsigned(6, 8);
        let unit = Exp2Unit { segments_log2: 3 };
        let out_frac = 10;
        let beyond = Exp2Unit::last_shift(out_frac) as f64 + 1.0;
        assert_eq!(exp2_neg(unit, beyond, input, out_frac), 0.0);
        assert_eq!(exp2_neg(unit, 63.0, input, out_frac), 0.0);
    }
}
