//! 3-vectors and angles on SIMD lanes ([`specula::simd::Lanes`]), for the packet
//! estimator's per-variant jobs (`lanes.rs`) and the map's texels
//! ([`super::Environment::texel_lanes`]): a packet's quantities stored by component in
//! [`LANES`]-long columns, loaded a vector at a time. `acos` and `atan2` evaluate the scalar
//! functions' polynomials ([`super::angles`]), fused.

use core::f32::consts::{PI, TAU};

use glam::Vec3;
use specula::simd::Lanes;
use specula::Geometry;

use super::angles::{ACOS, ATAN};

/// `LANES` values of one quantity.
/// Samples per packet (`packet.rs`): enough for the lobe's kernel to run at full
/// width, few enough to live on the stack.
pub(super) const LANES: usize = 64;

pub(super) type Column = [f32; LANES];

/// Lanes in the widest vector a level has (AVX2's 8; room for AVX-512's 16).
const WIDEST: usize = 16;

// Every level's vectors tile a packet (1 or 8 lanes).
const _: () = assert!(LANES.is_multiple_of(8));

/// `LANES` vectors, by component.
#[derive(Clone, Copy)]
pub(super) struct Columns3 {
    pub(super) x: Column,
    pub(super) y: Column,
    pub(super) z: Column,
}

impl Columns3 {
    pub(super) const ZERO: Self = Self {
        x: [0.0; LANES],
        y: [0.0; LANES],
        z: [0.0; LANES],
    };

    pub(super) fn set(&mut self, k: usize, v: Vec3) {
        (self.x[k], self.y[k], self.z[k]) = (v.x, v.y, v.z);
    }
}

/// A vector of 3-vectors.
#[derive(Clone, Copy)]
pub(super) struct V3<V> {
    pub(super) x: V,
    pub(super) y: V,
    pub(super) z: V,
}

impl<V: Lanes> V3<V> {
    #[inline(always)]
    pub(super) fn load(lanes: V, columns: &Columns3, k: usize) -> Self {
        let w = V::WIDTH;
        Self {
            x: lanes.load(&columns.x[k..k + w]),
            y: lanes.load(&columns.y[k..k + w]),
            z: lanes.load(&columns.z[k..k + w]),
        }
    }

    #[inline(always)]
    pub(super) fn store(self, columns: &mut Columns3, k: usize) {
        let w = V::WIDTH;
        self.x.store(&mut columns.x[k..k + w]);
        self.y.store(&mut columns.y[k..k + w]);
        self.z.store(&mut columns.z[k..k + w]);
    }

    #[inline(always)]
    pub(super) fn splat(lanes: V, v: Vec3) -> Self {
        Self {
            x: lanes.splat(v.x),
            y: lanes.splat(v.y),
            z: lanes.splat(v.z),
        }
    }

    #[inline(always)]
    pub(super) fn dot(self, other: Self) -> V {
        self.x
            .mul_add(other.x, self.y.mul_add(other.y, self.z * other.z))
    }

    /// `self * s + other`.
    #[inline(always)]
    pub(super) fn scale_add(self, s: V, other: Self) -> Self {
        Self {
            x: self.x.mul_add(s, other.x),
            y: self.y.mul_add(s, other.y),
            z: self.z.mul_add(s, other.z),
        }
    }

    #[inline(always)]
    pub(super) fn scale(self, s: V) -> Self {
        Self {
            x: self.x * s,
            y: self.y * s,
            z: self.z * s,
        }
    }

    #[inline(always)]
    pub(super) fn add(self, other: Self) -> Self {
        Self {
            x: self.x + other.x,
            y: self.y + other.y,
            z: self.z + other.z,
        }
    }

    /// Componentwise.
    #[inline(always)]
    pub(super) fn mul(self, other: Self) -> Self {
        Self {
            x: self.x * other.x,
            y: self.y * other.y,
            z: self.z * other.z,
        }
    }

    #[inline(always)]
    pub(super) fn sub(self, other: Self) -> Self {
        Self {
            x: self.x - other.x,
            y: self.y - other.y,
            z: self.z - other.z,
        }
    }

    #[inline(always)]
    pub(super) fn normalize(self) -> Self {
        let one = self.x.splat(1.0);
        self.scale(one / self.dot(self).sqrt())
    }

    #[inline(always)]
    pub(super) fn select(self, mask: V::Mask, other: Self) -> Self {
        Self {
            x: self.x.select(mask, other.x),
            y: self.y.select(mask, other.y),
            z: self.z.select(mask, other.z),
        }
    }

    /// Each component's lanes summed in order (a packet's estimates, without a column
    /// of [`LANES`] to fill and read back).
    #[inline(always)]
    pub(super) fn sum_lanes(self) -> Vec3 {
        let sum = |v: V| {
            let mut lanes = [0.0; WIDEST];
            v.store(&mut lanes[..V::WIDTH]);
            lanes[..V::WIDTH].iter().sum::<f32>()
        };
        Vec3::new(sum(self.x), sum(self.y), sum(self.z))
    }
}

/// `sum coefficients[i] x^i` by Horner's rule, fused.
#[inline(always)]
fn horner<V: Lanes>(x: V, coefficients: &[f32]) -> V {
    let mut sum = x.splat(0.0);
    for &c in coefficients.iter().rev() {
        sum = sum.mul_add(x, x.splat(c));
    }
    sum
}

/// `|x|`.
#[inline(always)]
fn abs<V: Lanes>(x: V) -> V {
    x.bits_and(0x7fff_ffff)
}

/// The Taylor polynomials of [`sin_cos_turns`] in `a^2`, lowest power first: `sin a / a`
/// and `cos a` (those of [`super::angles::sin_cos_turns`]).
const SIN: [f32; 5] = [1.0, -1.0 / 6.0, 1.0 / 120.0, -1.0 / 5040.0, 1.0 / 362_880.0];
const COS: [f32; 5] = [1.0, -0.5, 1.0 / 24.0, -1.0 / 720.0, 1.0 / 40_320.0];

/// [`super::angles::sin_cos_turns`] on every lane, `turns` in `(-1000, 1000)`: the same
/// reduction to within an eighth of a turn of a quarter and the same polynomials (fused), the
/// quarter's symmetries chosen by masks.
#[inline(always)]
pub(super) fn sin_cos_turns<V: Lanes>(turns: V) -> (V, V) {
    let s = |value: f32| turns.splat(value);
    let zero = s(0.0);
    let whole = |x: V| x.float_to_int().int_to_float();
    // The nearest quarter, by truncating a positive number, and that number of quarters
    // modulo 4 (a whole number from 0 to 3).
    let positive = whole(turns.mul_add(s(4.0), s(4000.5)));
    let quarter = positive - s(4000.0);
    let a = quarter.neg_mul_add(s(0.25), turns) * s(TAU);
    let a2 = a * a;
    let (sine, cosine) = (a * horner(a2, &SIN), horner(a2, &COS));
    let q = whole(positive * s(0.25)).neg_mul_add(s(4.0), positive);
    // Quarter q: (s, c), (c, -s), (-s, -c), (-c, s): swapped where q is odd, the first
    // negated where q is 2 or 3, the second where it is 1 or 2.
    let odd = whole(q * s(0.5)).neg_mul_add(s(2.0), q).gt(s(0.5));
    let (first, second) = (cosine.select(odd, sine), sine.select(odd, cosine));
    (
        (zero - first).select(q.gt(s(1.5)), first),
        (zero - second).select(abs(q - s(1.5)).lt(s(1.0)), second),
    )
}

/// [`super::angles::acos`] on every lane.
#[inline(always)]
pub(super) fn acos<V: Lanes>(x: V) -> V {
    let (zero, one) = (x.splat(0.0), x.splat(1.0));
    let a = abs(x).min(one);
    let r = (one - a).sqrt() * horner(a, &ACOS);
    (x.splat(PI) - r).select(x.lt(zero), r)
}

/// [`super::angles::atan2`] on every lane.
#[inline(always)]
pub(super) fn atan2<V: Lanes>(y: V, x: V) -> V {
    let zero = x.splat(0.0);
    let (ax, ay) = (abs(x), abs(y));
    let (small, large) = (ax.min(ay), ax.max(ay));
    let s = small / large;
    let r = s * horner(s * s, &ATAN);
    let r = (x.splat(core::f32::consts::FRAC_PI_2) - r).select(ay.gt(ax), r);
    let r = (x.splat(PI) - r).select(x.lt(zero), r);
    let r = (zero - r).select(y.lt(zero), r);
    r.keep(large.gt(zero))
}

/// The lobe's cosine `t` for `wi` (local) and, for Blinn, `wo . h` (1 for Phong): Phong's
/// `t` is `wi` against `wo` mirrored about the normal, Blinn's the half vector's `z`; where
/// `wo + wi` vanishes the half vector is undefined, and `t = 0`, `wo . h = 1`.
#[inline(always)]
pub(super) fn cosine<V: Lanes>(geometry: Geometry, wo: V3<V>, wi: V3<V>) -> (V, V) {
    let (zero, one) = (wi.x.splat(0.0), wi.x.splat(1.0));
    match geometry {
        Geometry::Phong => {
            let mirror = V3 {
                x: zero - wo.x,
                y: zero - wo.y,
                z: wo.z,
            };
            (mirror.dot(wi), one)
        }
        Geometry::Blinn => {
            let sum = V3 {
                x: wo.x + wi.x,
                y: wo.y + wi.y,
                z: wo.z + wi.z,
            };
            let length_squared = sum.dot(sum);
            let defined = length_squared.gt(zero);
            let h = sum.scale(one / length_squared.sqrt());
            (h.z.keep(defined), wo.dot(h).select(defined, one))
        }
    }
}

#[cfg(test)]
mod tests {
    use specula::simd::{dispatch, Job, Level};

    use super::*;

    /// `sin_cos_turns` on lanes, at every level this CPU has, is within `2e-6` of `libm`'s in
    /// `f64` over a thousand turns either way, every quarter included.
    #[test]
    fn the_lane_sines_are_libms() {
        struct Turns<'a>(&'a [f32; LANES], &'a mut [[f32; LANES]; 2]);
        impl Job for Turns<'_> {
            type Output = ();
            #[inline(always)]
            fn run<V: Lanes>(self, lanes: V) {
                for k in (0..LANES).step_by(V::WIDTH) {
                    let (sine, cosine) = sin_cos_turns(lanes.load(&self.0[k..k + V::WIDTH]));
                    sine.store(&mut self.1[0][k..k + V::WIDTH]);
                    cosine.store(&mut self.1[1][k..k + V::WIDTH]);
                }
            }
        }
        for level in Level::available() {
            for round in 0..400 {
                let turns: [f32; LANES] = core::array::from_fn(|k| {
                    ((round * LANES + k) as f32 * 0.618_034).fract() * 1999.0 - 999.5
                });
                let mut out = [[0.0; LANES]; 2];
                dispatch(level, Turns(&turns, &mut out));
                for (k, &t) in turns.iter().enumerate() {
                    let exact = (f64::from(t) * core::f64::consts::TAU).sin_cos();
                    let (sine, cosine) = (f64::from(out[0][k]), f64::from(out[1][k]));
                    assert!(
                        (sine - exact.0).abs() <= 2e-6 && (cosine - exact.1).abs() <= 2e-6,
                        "{level:?} {t} turns: ({sine}, {cosine}) against {exact:?}"
                    );
                }
            }
        }
    }

    /// `acos` and `atan2` on lanes, at every level this CPU has, are within `2e-6` of
    /// `libm`'s in `f64` (the bound of the scalar polynomials they share, a thousandth of a
    /// texel of a 4096-wide map), and `atan2(0, 0)` is 0.
    #[test]
    fn the_lane_angles_are_libms() {
        struct Angles<'a>(
            &'a [f32; LANES],
            &'a [f32; LANES],
            &'a mut [[f32; LANES]; 2],
        );
        impl Job for Angles<'_> {
            type Output = ();
            #[inline(always)]
            fn run<V: Lanes>(self, lanes: V) {
                for k in (0..LANES).step_by(V::WIDTH) {
                    let (x, y) = (
                        lanes.load(&self.0[k..k + V::WIDTH]),
                        lanes.load(&self.1[k..k + V::WIDTH]),
                    );
                    acos(x).store(&mut self.2[0][k..k + V::WIDTH]);
                    atan2(y, x).store(&mut self.2[1][k..k + V::WIDTH]);
                }
            }
        }
        for level in Level::available() {
            for round in 0..200 {
                let xs: [f32; LANES] = core::array::from_fn(|k| {
                    ((round * LANES + k) as f32 * 0.618_034).fract() * 2.0 - 1.0
                });
                let ys: [f32; LANES] =
                    core::array::from_fn(|k| (k as f32 * 0.37 + round as f32).sin());
                let mut out = [[0.0; LANES]; 2];
                dispatch(level, Angles(&xs, &ys, &mut out));
                for k in 0..LANES {
                    let (x, y) = (f64::from(xs[k]), f64::from(ys[k]));
                    let (acos, atan2) = (f64::from(out[0][k]), f64::from(out[1][k]));
                    assert!(
                        (acos - x.acos()).abs() <= 2e-6,
                        "{level:?} acos({x}): {acos} against {}",
                        x.acos()
                    );
                    assert!(
                        (atan2 - y.atan2(x)).abs() <= 2e-6,
                        "{level:?} atan2({y}, {x}): {atan2} against {}",
                        y.atan2(x)
                    );
                }
            }
            let zero = [0.0; LANES];
            let mut out = [[1.0; LANES]; 2];
            dispatch(level, Angles(&zero, &zero, &mut out));
            assert!(out[1].iter().all(|&a| a == 0.0), "atan2(0, 0) on {level:?}");
        }
    }
}
