//! The sRGB transfer function ([`srgb_encode`], [`srgb_decode`]), and 8-bit sRGB by tables:
//! exactly the bytes `(srgb_encode(x) * 255).round() as u8` gives and the values
//! `srgb_decode(b / 255)` gives, without a `powf` per channel (an image's encoding was a tenth
//! of the report's time).
//!
//! Encoding finds, for each byte `b`, the smallest `f32` whose byte exceeds `b` (by bisection
//! on the formula itself, which is monotonic), and, for each of the 32,512 groups of floats
//! in `(0, 1)` sharing their top 17 bits, the byte of the group's smallest float; a value's
//! byte is its group's, raised past the thresholds it reaches (at most one: a group spans
//! less than half a byte of output).

use std::sync::LazyLock;

/// The sRGB transfer function (IEC 61966-2-1) of a value in `[0, 1]`.
#[must_use]
pub fn srgb_encode(linear: f32) -> f32 {
    if linear <= 0.003_130_8 {
        12.92 * linear
    } else {
        1.055 * linear.powf(1.0 / 2.4) - 0.055
    }
}

/// The inverse of [`srgb_encode`].
#[must_use]
pub fn srgb_decode(encoded: f32) -> f32 {
    if encoded <= 0.040_45 {
        encoded / 12.92
    } else {
        ((encoded + 0.055) / 1.055).powf(2.4)
    }
}

/// Bits dropped from a float to find its group.
const SHIFT: u32 = 15;

/// The byte by the formula.
fn by_formula(x: f32) -> u8 {
    (srgb_encode(x) * 255.0).round() as u8
}

struct Encoder {
    /// `thresholds[b]`: the smallest float whose byte exceeds `b`.
    thresholds: [f32; 255],
    /// Per group of floats in `(0, 1)`, the byte of its smallest.
    start: Vec<u8>,
}

static ENCODER: LazyLock<Encoder> = LazyLock::new(|| {
    let one = 1.0_f32.to_bits();
    let mut thresholds = [1.0_f32; 255];
    for (b, threshold) in thresholds.iter_mut().enumerate() {
        // The smallest bit pattern in (0, 1] whose byte exceeds b.
        let (mut low, mut high) = (0_u32, one);
        while high - low > 1 {
            let middle = low + (high - low) / 2;
            if usize::from(by_formula(f32::from_bits(middle))) > b {
                high = middle;
            } else {
                low = middle;
            }
        }
        *threshold = f32::from_bits(high);
    }
    let start = (0..one >> SHIFT)
        .map(|group| by_formula(f32::from_bits(group << SHIFT)))
        .collect();
    Encoder { thresholds, start }
});

static DECODER: LazyLock<[f32; 256]> =
    LazyLock::new(|| core::array::from_fn(|b| srgb_decode(b as f32 / 255.0)));

/// `(srgb_encode(x) * 255).round() as u8`: 0 for NaN and below, 255 from 1 up.
#[inline]
#[must_use]
pub fn encode(x: f32) -> u8 {
    if x.is_nan() || x <= 0.0 {
        return 0;
    }
    if x >= 1.0 {
        return 255;
    }
    let encoder = &*ENCODER;
    let mut byte = encoder.start[(x.to_bits() >> SHIFT) as usize];
    while byte < 255 && x >= encoder.thresholds[usize::from(byte)] {
        byte += 1;
    }
    byte
}

/// `srgb_decode(b / 255)`.
#[inline]
#[must_use]
pub fn decode(b: u8) -> f32 {
    DECODER[usize::from(b)]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn srgb_curve_matches_its_definition_and_inverts() {
        // IEC 61966-2-1 reference points: 0.5 linear encodes to 0.7353569830524495.
        assert!((srgb_encode(0.5) - 0.735_357).abs() < 1e-6);
        assert!((srgb_encode(0.002) - 0.025_84).abs() < 1e-6);
        for k in 0..=255 {
            let v = k as f32 / 255.0;
            assert!((srgb_encode(srgb_decode(v)) - v).abs() < 1e-5);
        }
    }

    /// Every byte's threshold and its neighbours, and a stride through every float in
    /// `[0, 1]` (and beyond, and NaN), encode as the formula does.
    #[test]
    fn the_tables_are_the_formula() {
        let mut checked = 0_u64;
        let mut check = |x: f32| {
            assert_eq!(encode(x), by_formula(x), "{x} ({:#x})", x.to_bits());
            checked += 1;
        };
        for &threshold in &ENCODER.thresholds {
            let bits = threshold.to_bits();
            for around in bits.saturating_sub(4)..=bits + 4 {
                check(f32::from_bits(around));
            }
        }
        for bits in (0..=1.0_f32.to_bits()).step_by(997) {
            check(f32::from_bits(bits));
        }
        for x in [
            f32::NAN,
            -1.0,
            -0.0,
            0.0,
            1.0,
            1.5,
            f32::INFINITY,
            f32::MIN_POSITIVE,
        ] {
            check(x);
        }
        assert!(checked > 1_000_000, "{checked}");
    }

    /// Every byte survives decoding then encoding: an image written as 8-bit sRGB and read
    /// back compares as the bytes it was written from (the report's tables rest on this).
    #[test]
    fn every_byte_survives_decode_then_encode() {
        for b in 0..=255_u8 {
            assert_eq!(encode(decode(b)), b, "{b}");
        }
    }
}
