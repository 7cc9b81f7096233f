//! The log2 unit: a leading-one detector for the integer part, and an approximation of
//! `log2(1 + f)` on the mantissa's fraction `f` in `[0, 1)`.
//!
//! For an unsigned input `x` with `F` fraction bits, let `p` be the position of its leading
//! one: `x = 2^(p - F) (1 + f)`, so `log2 x = (p - F) + log2(1 + f)`. The fraction `f` is the
//! bits below the leading one, shifted up to the top of a `W - 1`-bit field (`W` the input
//! width). Two units approximate `log2(1 + f)`:
//! - [`Log2Unit::Mitchell`]: `f` itself (Mitchell, 1962): no table, no multiplier, error up
//!   to 0.086;
//! - [`Log2Unit::Table`]: `2^k + 1` samples of `log2(1 + f)` with linear interpolation between
//!   them: a small ROM and one multiplier, error about `0.09 / 4^k` plus rounding.
//!
//! A zero input has no logarithm; the unit saturates to its output format's minimum, which the
//! datapaths turn into a lobe value of 0 (as every lobe gives for `t <= 0`).

use serde::Serialize;

use crate::fixed::{FixedPoint, Rounding};

/// How the unit approximates `log2(1 + f)`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum Log2Unit {
    /// `log2(1 + f) ~ f`.
    Mitchell,
    /// `2^segments_log2` segments of a table, linearly interpolated.
    Table {
        /// `k`: the table has `2^k + 1` entries.
        segments_log2: u32,
    },
}

/// Guard bits the table keeps beyond the unit's output fraction.
pub const TABLE_GUARD_BITS: u32 = 2;

impl Log2Unit {
    /// A short name: `mitchell` or `table-16`.
    #[must_use]
    pub fn name(self) -> String {
        match self {
            Log2Unit::Mitchell => "mitchell".to_owned(),
            Log2Unit::Table { segments_log2 } => format!("table-{}", 1 << segments_log2),
        }
    }

    /// The fraction bits of the table's entries, for an output with `out_frac` bits.
    #[must_use]
    pub fn table_frac_bits(out_frac: u32) -> u32 {
        out_frac + TABLE_GUARD_BITS
    }

    /// The fraction bits of the unit's exact result for an input of format `input`.
    #[must_use]
    pub fn frac_bits(self, input: FixedPoint, out_frac: u32) -> u32 {
        match self {
            Log2Unit::Mitchell => input.width() - 1,
            Log2Unit::Table { .. } => Self::table_frac_bits(out_frac),
        }
    }

    /// The table, `log2(1 + i / 2^k)` for `i` in `0..=2^k`, rounded to `frac` bits; empty for
    /// Mitchell's unit.
    #[must_use]
    pub fn table(self, frac: u32) -> Vec<i64> {
        match self {
            Log2Unit::Mitchell => Vec::new(),
            Log2Unit::Table { segments_log2 } => {
                let segments = 1_u32 << segments_log2;
                (0..=segments)
                    .map(|i| {
                        let x = 1.0 + f64::from(i) / f64::from(segments);
                        FixedPoint::unsigned(1, frac).quantize(x.log2(), Rounding::HalfEven)
                    })
                    .collect()
            }
        }
    }

    /// `log2` of `raw` in format `input` (unsigned), exactly as the hardware computes it:
    /// `(raw, frac_bits)` of the result before its final resize.
    #[must_use]
    pub fn eval(self, raw: i64, input: FixedPoint, out_frac: u32, out: FixedPoint) -> (i128, u32) {
        let table = self.table(Self::table_frac_bits(out_frac));
        self.eval_with_table(&table, raw, input, out_frac, out)
    }

    /// [`Log2Unit::eval`] with the unit's [`Log2Unit::table`] for `out_frac` built once by the
    /// caller.
    #[must_use]
    pub fn eval_with_table(
        self,
        table: &[i64],
        raw: i64,
        input: FixedPoint,
        out_frac: u32,
        out: FixedPoint,
    ) -> (i128, u32) {
        debug_assert!(!input.signed);
        let width = input.width();
        let mantissa_bits = width - 1;
        if raw <= 0 {
            // The output's minimum, at the unit's own fraction width.
            let frac = self.frac_bits(input, out_frac);
            let min = i128::from(out.min_raw());
            return if frac >= out.frac_bits {
                (min << (frac - out.frac_bits), frac)
            } else {
                (min >> (out.frac_bits - frac), frac)
            };
        }
        let leading = 63 - raw.leading_zeros();
        let exponent = i128::from(leading) - i128::from(input.frac_bits);
        // The bits below the leading one, at the top of a (width - 1)-bit fraction field.
        let normalised = (raw << (mantissa_bits - leading)) & ((1_i64 << mantissa_bits) - 1);
        match self {
            Log2Unit::Mitchell => (
                (exponent << mantissa_bits) + i128::from(normalised),
                mantissa_bits,
            ),
            Log2Unit::Table { segments_log2 } => {
                let frac = Self::table_frac_bits(out_frac);
                let (index, within, within_bits) = split(normalised, mantissa_bits, segments_log2);
                let (low, high) = (table[index], table[index + 1]);
                let interpolated = low + (((high - low) * within) >> within_bits);
                ((exponent << frac) + i128::from(interpolated), frac)
            }
        }
    }
}

/// A fraction of `bits` bits split into a table index (its top `k` bits) and the position
/// within the segment (the remaining bits, and how many there are): both table units' address.
pub(crate) fn split(fraction: i64, bits: u32, k: u32) -> (usize, i64, u32) {
    if bits >= k {
        let rest = bits - k;
        (
            (fraction >> rest) as usize,
            fraction & ((1 << rest) - 1),
            rest,
        )
    } else {
        ((fraction << (k - bits)) as usize, 0, 0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn log2_of(unit: Log2Unit, x: f64, input: FixedPoint) -> f64 {
        let out = FixedPoint::signed(5, 16);
        let raw = input.quantize(x, Rounding::HalfEven);
        let (value, frac) = unit.eval(raw, input, out.frac_bits, out);
        value as f64 / (frac as f64).exp2()
    }

    /// Powers of two are exact in both units: the leading-one position is the whole answer.
    #[test]
    fn powers_of_two_are_exact() {
        let input = FixedPoint::unsigned(3, 12);
        for unit in [Log2Unit::Mitchell, Log2Unit::Table { segments_log2: 4 }] {
            for e in -12..3 {
                let x = f64::from(e).exp2();
                assert_eq!(log2_of(unit, x, input), f64::from(e), "{unit:?} 2^{e}");
            }
        }
    }

    /// Mitchell's error is the known maximum of `log2(1 + f) - f`, 0.0861; a 16-segment
    /// table brings it to the interpolation bound `(ln 2)^-1 / 8 / 16^2` plus rounding.
    #[test]
    fn errors_match_the_known_bounds() {
        let input = FixedPoint::unsigned(2, 14);
        let mut worst = [0.0_f64; 2];
        for raw in 1..=input.max_raw() {
            let x = input.to_f64(raw);
            for (k, unit) in [Log2Unit::Mitchell, Log2Unit::Table { segments_log2: 4 }]
                .into_iter()
                .enumerate()
            {
                worst[k] = worst[k].max((log2_of(unit, x, input) - x.log2()).abs());
            }
        }
        let mitchell_max =
            (1.0 / core::f64::consts::LN_2).log2() - 1.0 / core::f64::consts::LN_2 + 1.0;
        assert!(
            (worst[0] - mitchell_max).abs() < 1e-3,
            "{worst:?} {mitchell_max}"
        );
        let interpolation = 1.0 / core::f64::consts::LN_2 / 8.0 / 256.0;
        assert!(
            worst[1] < interpolation + 3.0 * 2.0_f64.powi(-16),
            "{worst:?}"
        );
        assert!(
            worst[1] > interpolation / 4.0,
            "the table's error is interpolation, not zero"
        );
    }

    #[test]
    fn zero_saturates_to_the_most_negative_output() {
        let out = FixedPoint::signed(5, 10);
        let input = FixedPoint::unsigned(1, 7);
        for unit in [Log2Unit::Mitchell, Log2Unit::Table { segments_log2: 3 }] {
            let (raw, frac) = unit.eval(0, input, 10, out);
            assert_eq!(out.resize(raw, frac, Rounding::HalfEven), out.min_raw());
        }
    }
}
