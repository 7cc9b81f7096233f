//! Fixed-point formats: `Q` numbers with an explicit rounding and saturation on every resize.
//!
//! A value is a raw integer and a [`FixedPoint`]: `value = raw / 2^frac_bits`, with `int_bits`
//! integer bits and a sign bit when signed (two's complement), so a format is `width()` bits
//! wide. Every operation computes its exact result first (a sum at the finer of the two
//! fraction widths, a product at the sum of both) and then [`FixedPoint::resize`]s it into the
//! destination: drop fraction bits by [`Rounding`], then saturate to the destination's range.
//! That is what a hardware datapath does, and it is what the Verilog emitter writes.
//!
//! [`Q`] is the same arithmetic with the format in the type (const generics), for code whose
//! widths are fixed; the datapaths, whose widths are swept at run time, use [`FixedPoint`] and raw
//! integers directly.

use serde::Serialize;

/// How fraction bits are dropped.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum Rounding {
    /// Towards minus infinity: the dropped bits are simply discarded (two's complement).
    Truncate,
    /// To the nearest, ties to the even neighbour (no bias over many operations).
    #[default]
    HalfEven,
}

/// A fixed-point format: sign, integer bits and fraction bits.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize)]
pub struct FixedPoint {
    /// Two's complement when true.
    pub signed: bool,
    /// Integer bits (not counting the sign).
    pub int_bits: u32,
    /// Fraction bits.
    pub frac_bits: u32,
}

/// The widest format the models handle: raw values, products and alignments stay within
/// `i128` with room to spare, and the Verilog's 64-bit intermediates hold every exact result.
pub const MAX_WIDTH: u32 = 36;

impl FixedPoint {
    /// Unsigned `UQ int.frac`.
    #[must_use]
    pub const fn unsigned(int_bits: u32, frac_bits: u32) -> Self {
        Self {
            signed: false,
            int_bits,
            frac_bits,
        }
    }

    /// Signed `SQ int.frac` (plus a sign bit).
    #[must_use]
    pub const fn signed(int_bits: u32, frac_bits: u32) -> Self {
        Self {
            signed: true,
            int_bits,
            frac_bits,
        }
    }

    /// Bits in a register of this format.
    #[must_use]
    pub const fn width(self) -> u32 {
        self.int_bits + self.frac_bits + self.signed as u32
    }

    /// The smallest raw value.
    #[must_use]
    pub const fn min_raw(self) -> i64 {
        if self.signed {
            -(1 << (self.int_bits + self.frac_bits))
        } else {
            0
        }
    }

    /// The largest raw value.
    #[must_use]
    pub const fn max_raw(self) -> i64 {
        (1 << (self.int_bits + self.frac_bits)) - 1
    }

    /// The raw value of `x`, rounded and saturated (NaN gives 0).
    #[must_use]
    pub fn quantize(self, x: f64, rounding: Rounding) -> i64 {
        let scaled = x * (self.frac_bits as f64).exp2();
        let rounded = match rounding {
            Rounding::Truncate => scaled.floor(),
            Rounding::HalfEven => scaled.round_ties_even(),
        };
        if rounded.is_nan() {
            return 0;
        }
        (rounded.clamp(self.min_raw() as f64, self.max_raw() as f64)) as i64
    }

    /// The value of `raw`.
    #[must_use]
    pub fn to_f64(self, raw: i64) -> f64 {
        raw as f64 / (self.frac_bits as f64).exp2()
    }

    /// Whether `raw` is a value of this format.
    #[must_use]
    pub fn holds(self, raw: i64) -> bool {
        (self.min_raw()..=self.max_raw()).contains(&raw)
    }

    /// An exact value `raw / 2^frac_bits` brought into this format: fraction bits dropped by
    /// `rounding` (or zeros appended), then saturated to the range.
    #[must_use]
    pub fn resize(self, raw: i128, frac_bits: u32, rounding: Rounding) -> i64 {
        let aligned = if frac_bits > self.frac_bits {
            let shift = frac_bits - self.frac_bits;
            let floor = raw >> shift;
            let remainder = raw - (floor << shift);
            let half = 1_i128 << (shift - 1);
            let up = rounding == Rounding::HalfEven
                && (remainder > half || (remainder == half && floor & 1 == 1));
            floor + i128::from(up)
        } else {
            raw << (self.frac_bits - frac_bits)
        };
        aligned.clamp(i128::from(self.min_raw()), i128::from(self.max_raw())) as i64
    }

    /// `SQ` or `UQ` `int.frac`, as datasheets write it.
    #[must_use]
    pub fn name(self) -> String {
        let sign = if self.signed { "SQ" } else { "UQ" };
        format!("{sign}{}.{}", self.int_bits, self.frac_bits)
    }
}

/// `a + b` exactly, at the finer fraction width: `(raw, frac_bits)`.
#[must_use]
pub fn exact_add(a: i64, fa: FixedPoint, b: i64, fb: FixedPoint) -> (i128, u32) {
    let frac = fa.frac_bits.max(fb.frac_bits);
    let widen = |raw: i64, f: FixedPoint| i128::from(raw) << (frac - f.frac_bits);
    (widen(a, fa) + widen(b, fb), frac)
}

/// `a * b` exactly: `(raw, frac_bits)`.
#[must_use]
pub fn exact_mul(a: i64, fa: FixedPoint, b: i64, fb: FixedPoint) -> (i128, u32) {
    (i128::from(a) * i128::from(b), fa.frac_bits + fb.frac_bits)
}

/// A fixed-point number with its format in the type: `SIGNED`, `INT` integer bits, `FRAC`
/// fraction bits. Operations name their result type and rounding; the result saturates.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct Q<const SIGNED: bool, const INT: u32, const FRAC: u32> {
    raw: i64,
}

/// Unsigned `UQ INT.FRAC`.
pub type UQ<const INT: u32, const FRAC: u32> = Q<false, INT, FRAC>;
/// Signed `SQ INT.FRAC`.
pub type SQ<const INT: u32, const FRAC: u32> = Q<true, INT, FRAC>;

impl<const SIGNED: bool, const INT: u32, const FRAC: u32> Q<SIGNED, INT, FRAC> {
    /// The runtime description of this type's format.
    pub const FORMAT: FixedPoint = FixedPoint {
        signed: SIGNED,
        int_bits: INT,
        frac_bits: FRAC,
    };

    /// The number with this raw value, if the format holds it.
    #[must_use]
    pub fn try_from_raw(raw: i64) -> Option<Self> {
        Self::FORMAT.holds(raw).then_some(Self { raw })
    }

    /// The number nearest `raw`'s value within the range (saturated).
    #[must_use]
    pub fn from_raw_saturating(raw: i64) -> Self {
        Self {
            raw: raw.clamp(Self::FORMAT.min_raw(), Self::FORMAT.max_raw()),
        }
    }

    /// `x` rounded and saturated.
    #[must_use]
    pub fn from_f64(x: f64, rounding: Rounding) -> Self {
        Self {
            raw: Self::FORMAT.quantize(x, rounding),
        }
    }

    /// The raw integer.
    #[must_use]
    pub fn raw(self) -> i64 {
        self.raw
    }

    /// The value.
    #[must_use]
    pub fn to_f64(self) -> f64 {
        Self::FORMAT.to_f64(self.raw)
    }

    /// The exact value `raw / 2^frac` rounded and saturated into this format.
    fn from_exact((raw, frac): (i128, u32), rounding: Rounding) -> Self {
        Self {
            raw: Self::FORMAT.resize(raw, frac, rounding),
        }
    }

    /// This number in another format.
    #[must_use]
    pub fn resize<const S: bool, const I: u32, const F: u32>(
        self,
        rounding: Rounding,
    ) -> Q<S, I, F> {
        Q::from_exact((i128::from(self.raw), FRAC), rounding)
    }

    /// `self + rhs` in the result's format.
    #[must_use]
    pub fn add<
        const S2: bool,
        const I2: u32,
        const F2: u32,
        const S: bool,
        const I: u32,
        const F: u32,
    >(
        self,
        rhs: Q<S2, I2, F2>,
        rounding: Rounding,
    ) -> Q<S, I, F> {
        Q::from_exact(
            exact_add(self.raw, Self::FORMAT, rhs.raw, Q::<S2, I2, F2>::FORMAT),
            rounding,
        )
    }

    /// `self - rhs` in the result's format.
    #[must_use]
    pub fn sub<
        const S2: bool,
        const I2: u32,
        const F2: u32,
        const S: bool,
        const I: u32,
        const F: u32,
    >(
        self,
        rhs: Q<S2, I2, F2>,
        rounding: Rounding,
    ) -> Q<S, I, F> {
        Q::from_exact(
            exact_add(self.raw, Self::FORMAT, -rhs.raw, Q::<S2, I2, F2>::FORMAT),
            rounding,
        )
    }

    /// `self * rhs` in the result's format.
    #[must_use]
    pub fn mul<
        const S2: bool,
        const I2: u32,
        const F2: u32,
        const S: bool,
        const I: u32,
        const F: u32,
    >(
        self,
        rhs: Q<S2, I2, F2>,
        rounding: Rounding,
    ) -> Q<S, I, F> {
        Q::from_exact(
            exact_mul(self.raw, Self::FORMAT, rhs.raw, Q::<S2, I2, F2>::FORMAT),
            rounding,
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The reference: the exact rational `numerator / 2^shift` rounded with integer division
    /// and an explicit tie test, then clamped. Written independently of `FixedPoint::resize`.
    fn reference(numerator: i128, shift: i32, to: FixedPoint, rounding: Rounding) -> i64 {
        let value = if shift <= 0 {
            numerator * (1_i128 << -shift)
        } else {
            let divisor = 1_i128 << shift;
            let quotient = numerator.div_euclid(divisor);
            let remainder = numerator.rem_euclid(divisor);
            match rounding {
                Rounding::Truncate => quotient,
                Rounding::HalfEven => match (2 * remainder).cmp(&divisor) {
                    core::cmp::Ordering::Less => quotient,
                    core::cmp::Ordering::Greater => quotient + 1,
                    core::cmp::Ordering::Equal => quotient + (quotient % 2).abs(),
                },
            }
        };
        let (lo, hi) = if to.signed {
            (
                -(1_i128 << (to.int_bits + to.frac_bits)),
                (1 << (to.int_bits + to.frac_bits)) - 1,
            )
        } else {
            (0, (1_i128 << (to.int_bits + to.frac_bits)) - 1)
        };
        value.clamp(lo, hi) as i64
    }

    type A = SQ<1, 3>;
    type B = UQ<2, 2>;
    type Out = SQ<2, 1>;

    fn all<const S: bool, const I: u32, const F: u32>() -> Vec<Q<S, I, F>> {
        let f = Q::<S, I, F>::FORMAT;
        (f.min_raw()..=f.max_raw())
            .map(|raw| Q::try_from_raw(raw).expect("in range"))
            .collect()
    }

    /// Every pair of a 5-bit signed and a 4-bit unsigned operand, both roundings, into a
    /// narrower signed result: bits compared with the integer reference.
    #[test]
    fn add_sub_mul_match_integer_reference_exhaustively() {
        for rounding in [Rounding::Truncate, Rounding::HalfEven] {
            for a in all::<true, 1, 3>() {
                for b in all::<false, 2, 2>() {
                    let (ra, rb) = (i128::from(a.raw()), i128::from(b.raw()));
                    let out = Out::FORMAT;
                    // a has 3 fraction bits, b 2: the sum is at 3, the product at 5.
                    let sum: Out = a.add(b, rounding);
                    assert_eq!(sum.raw(), reference(ra + 2 * rb, 3 - 1, out, rounding));
                    let difference: Out = a.sub(b, rounding);
                    assert_eq!(
                        difference.raw(),
                        reference(ra - 2 * rb, 3 - 1, out, rounding)
                    );
                    let product: Out = a.mul(b, rounding);
                    assert_eq!(product.raw(), reference(ra * rb, 5 - 1, out, rounding));
                }
            }
        }
    }

    /// Every value of a 6-bit format resized into narrower, wider, signed and unsigned ones.
    #[test]
    fn resize_matches_integer_reference_exhaustively() {
        let targets = [
            FixedPoint::unsigned(1, 1),
            FixedPoint::signed(0, 2),
            FixedPoint::signed(3, 4),
            FixedPoint::unsigned(2, 0),
        ];
        for rounding in [Rounding::Truncate, Rounding::HalfEven] {
            for a in all::<true, 2, 3>() {
                for to in targets {
                    let got = to.resize(i128::from(a.raw()), 3, rounding);
                    let shift = 3 - to.frac_bits as i32;
                    assert_eq!(
                        got,
                        reference(i128::from(a.raw()), shift, to, rounding),
                        "{to:?}"
                    );
                }
            }
        }
    }

    #[test]
    fn ties_go_to_even_and_truncation_goes_down() {
        let half_even = |x: f64| B::from_f64(x, Rounding::HalfEven).to_f64();
        // Steps of 0.25: 0.125 lies between 0 and 0.25 (even raw 0), 0.375 between 0.25 and 0.5.
        assert_eq!(half_even(0.125), 0.0);
        assert_eq!(half_even(0.375), 0.5);
        let down: A = A::from_f64(-0.0625, Rounding::Truncate);
        assert_eq!(down.to_f64(), -0.125);
        // Saturation at both ends, and NaN to zero.
        assert_eq!(
            B::from_f64(1e9, Rounding::HalfEven).raw(),
            B::FORMAT.max_raw()
        );
        assert_eq!(
            A::from_f64(-1e9, Rounding::HalfEven).raw(),
            A::FORMAT.min_raw()
        );
        assert_eq!(A::from_f64(f64::NAN, Rounding::HalfEven).raw(), 0);
        assert_eq!(A::try_from_raw(16), None);
        assert_eq!(A::from_raw_saturating(16).raw(), 15);
    }
}
