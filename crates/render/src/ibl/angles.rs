//! The angle functions of the packet estimator, in `f32`, inline and free of branches on
//! their arguments: the environment's mapping and the azimuth of a draw spend most of their
//! time in `libm`'s `sincosf`, `acosf` and `atan2f` otherwise, and a branch on the quadrant
//! of a random angle is mispredicted as often as not. Each is within `2e-6` (absolute) of
//! `libm` (tested), a thousandth of a texel of a 4096-wide map.

use core::f32::consts::{FRAC_PI_2, PI, TAU};

/// `(sin, cos)` of the angle `turns` full turns (`2 pi turns` radians), `turns` in
/// `(-1000, 1000)`: reduced exactly to within an eighth of a turn of a quarter, then Taylor
/// polynomials to the 9th and 8th power. (The nearest quarter is found by truncating a
/// positive number: `round` is a `libm` call on baseline x86-64.)
#[must_use]
#[inline]
pub fn sin_cos_turns(turns: f32) -> (f32, f32) {
    let quarter = ((turns * 4.0 + 4000.5) as i32 - 4000) as f32;
    let a = (turns - quarter * 0.25) * TAU;
    let a2 = a * a;
    let sine =
        a * (1.0 + a2 * (-1.0 / 6.0 + a2 * (1.0 / 120.0 + a2 * (-1.0 / 5040.0 + a2 / 362_880.0))));
    let cosine =
        1.0 + a2 * (-0.5 + a2 * (1.0 / 24.0 + a2 * (-1.0 / 720.0 + a2 * (1.0 / 40_320.0))));
    // Quarter q turns: (s, c), (c, -s), (-s, -c), (-c, s): swapped when q is odd, the
    // first negated when q & 2, the second when (q + 1) & 2.
    let q = (quarter as i64).rem_euclid(4) as u32;
    let odd = q & 1 == 1;
    let (first, second) = (pick(odd, cosine, sine), pick(odd, sine, cosine));
    (
        negated_if(q & 2 != 0, first),
        negated_if((q + 1) & 2 != 0, second),
    )
}

/// `if condition { a } else { b }` by bits, never a branch.
#[inline(always)]
fn pick(condition: bool, a: f32, b: f32) -> f32 {
    let mask = 0u32.wrapping_sub(u32::from(condition));
    f32::from_bits((a.to_bits() & mask) | (b.to_bits() & !mask))
}

/// `-x` if `condition`, else `x`, by its sign bit.
#[inline(always)]
fn negated_if(condition: bool, x: f32) -> f32 {
    f32::from_bits(x.to_bits() ^ (u32::from(condition) << 31))
}

/// The polynomial of [`acos`] in `|x|`, lowest power first.
pub(super) const ACOS: [f32; 8] = [
    FRAC_PI_2,
    -0.214_598_8,
    0.088_978_87,
    -0.050_174_3,
    0.030_891_88,
    -0.017_088_13,
    0.006_670_09,
    -0.001_262_491,
];

/// The polynomial of [`atan2`]'s arctangent on `[0, 1]` in `s^2`, lowest power first (times
/// `s`).
pub(super) const ATAN: [f32; 7] = [
    0.999_996_1,
    -0.333_173_7,
    0.198_078_2,
    -0.132_333_5,
    0.079_623_7,
    -0.033_604_2,
    0.006_811_779,
];

/// `sum coefficients[i] x^i` by Horner's rule, unfused.
#[inline(always)]
fn horner(x: f32, coefficients: &[f32]) -> f32 {
    coefficients.iter().rev().fold(0.0, |sum, &c| sum * x + c)
}

/// `acos(x)` for `x` in `[-1, 1]`: Abramowitz and Stegun's 4.4.46, `sqrt(1 - x)` times a
/// polynomial of degree 7 (error below `2e-8` radians in exact arithmetic).
#[must_use]
#[inline]
pub fn acos(x: f32) -> f32 {
    let a = x.abs().min(1.0);
    let r = (1.0 - a).sqrt() * horner(a, &ACOS);
    pick(x < 0.0, PI - r, r)
}

/// `atan2(y, x)` in `[-pi, pi]`: the arctangent of the smaller over the larger magnitude by
/// an odd polynomial of degree 13 fitted on `[0, 1]` (error `2.5e-7`), then the octant's
/// symmetries.
#[must_use]
#[inline]
pub fn atan2(y: f32, x: f32) -> f32 {
    let (ax, ay) = (x.abs(), y.abs());
    let (small, large) = (ax.min(ay), ax.max(ay));
    if large == 0.0 {
        return 0.0;
    }
    let s = small / large;
    let r = s * horner(s * s, &ATAN);
    let r = pick(ay > ax, FRAC_PI_2 - r, r);
    let r = pick(x < 0.0, PI - r, r);
    negated_if(y < 0.0, r)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn each_is_within_its_bound_of_libm() {
        let mut worst = [0.0_f64; 4];
        for i in -20_000..=20_000 {
            let turns = i as f32 / 79.19;
            let (s, c) = sin_cos_turns(turns);
            let exact = (f64::from(turns) * core::f64::consts::TAU).sin_cos();
            worst[0] = worst[0].max((f64::from(s) - exact.0).abs());
            worst[1] = worst[1].max((f64::from(c) - exact.1).abs());
            let x = i as f32 / 20_000.0;
            worst[2] = worst[2].max((f64::from(acos(x)) - f64::from(x).acos()).abs());
            let (py, px) = ((i as f32 * 0.37).sin(), (i as f32 * 0.91).cos());
            worst[3] =
                worst[3].max((f64::from(atan2(py, px)) - f64::from(py).atan2(f64::from(px))).abs());
        }
        for (name, error) in ["sin", "cos", "acos", "atan2"].iter().zip(worst) {
            assert!(error < 2e-6, "{name}: {error}");
        }
        assert_eq!(atan2(0.0, 0.0), 0.0);
        assert!((atan2(0.0, -1.0) - PI).abs() < 1e-6);
        assert!((acos(-1.0) - PI).abs() < 1e-6 && acos(1.0).abs() < 1e-6);
    }
}
