//! The packet estimator's per-variant arithmetic over SIMD lanes ([`specula::simd::Lanes`]:
//! 8 lanes with AVX2 and FMA where the CPU has them, one otherwise), so that what each lobe
//! adds to a packet costs vector instructions rather than a scalar pass per sample.
//!
//! Two jobs run per variant and packet, with scalar passes between them for what does not
//! vectorise (the lobe's cosine draws, the environment's texel reads):
//! - [`Directions`]: each environment draw's lobe cosine, each BRDF draw's direction (the
//!   lobe's cosine turned about its axis, or the shared cosine-weighted direction), and the
//!   texel that direction falls in;
//! - [`Combine`]: the BRDF and its density for both draws, the power heuristic, and the
//!   packet's sum.
//!
//! Lanes past the packet's draws hold no draw (`light_pdf = 0`, source [`Source::None`]), so
//! every job runs over all [`LANES`] lanes (a multiple of every level's width) and masks with
//! selects, never with a multiply by 0 (a masked lane may hold an infinity or a NaN).

use core::f32::consts::{FRAC_1_PI, PI, TAU};

use glam::Vec3;
use specula::simd::{Job, Lanes};
use specula::Geometry;

use super::angles::{ACOS, ATAN};
use super::packet::LANES;
use super::Strategy;

/// `LANES` values of one quantity.
pub(super) type Column = [f32; LANES];

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

    #[must_use]
    pub(super) fn get(&self, k: usize) -> Vec3 {
        Vec3::new(self.x[k], self.y[k], self.z[k])
    }
}

/// Where a lane's BRDF direction came from, as a lane value.
#[derive(Clone, Copy, PartialEq)]
pub(super) enum Source {
    /// No direction above the surface.
    None = 0,
    /// Drawn from the lobe.
    Lobe = 1,
    /// The shared cosine-weighted draw.
    Diffuse = 2,
}

impl Source {
    #[must_use]
    pub(super) fn of(lane: f32) -> Self {
        if lane == 1.0 {
            Source::Lobe
        } else if lane == 2.0 {
            Source::Diffuse
        } else {
            Source::None
        }
    }
}

/// A vector of 3-vectors.
#[derive(Clone, Copy)]
struct V3<V> {
    x: V,
    y: V,
    z: V,
}

impl<V: Lanes> V3<V> {
    #[inline(always)]
    fn load(lanes: V, columns: &Columns3, k: usize) -> Self {
        let w = V::WIDTH;
        Self {
            x: lanes.load(&columns.x[k..k + w]),
            y: lanes.load(&columns.y[k..k + w]),
            z: lanes.load(&columns.z[k..k + w]),
        }
    }

    #[inline(always)]
    fn store(self, columns: &mut Columns3, k: usize) {
        let w = V::WIDTH;
        self.x.store(&mut columns.x[k..k + w]);
        self.y.store(&mut columns.y[k..k + w]);
        self.z.store(&mut columns.z[k..k + w]);
    }

    #[inline(always)]
    fn splat(lanes: V, v: Vec3) -> Self {
        Self {
            x: lanes.splat(v.x),
            y: lanes.splat(v.y),
            z: lanes.splat(v.z),
        }
    }

    #[inline(always)]
    fn dot(self, other: Self) -> V {
        self.x
            .mul_add(other.x, self.y.mul_add(other.y, self.z * other.z))
    }

    /// `self * s + other`.
    #[inline(always)]
    fn scale_add(self, s: V, other: Self) -> Self {
        Self {
            x: self.x.mul_add(s, other.x),
            y: self.y.mul_add(s, other.y),
            z: self.z.mul_add(s, other.z),
        }
    }

    #[inline(always)]
    fn scale(self, s: V) -> Self {
        Self {
            x: self.x * s,
            y: self.y * s,
            z: self.z * s,
        }
    }

    #[inline(always)]
    fn add(self, other: Self) -> Self {
        Self {
            x: self.x + other.x,
            y: self.y + other.y,
            z: self.z + other.z,
        }
    }

    /// Componentwise.
    #[inline(always)]
    fn mul(self, other: Self) -> Self {
        Self {
            x: self.x * other.x,
            y: self.y * other.y,
            z: self.z * other.z,
        }
    }

    #[inline(always)]
    fn sub(self, other: Self) -> Self {
        Self {
            x: self.x - other.x,
            y: self.y - other.y,
            z: self.z - other.z,
        }
    }

    #[inline(always)]
    fn normalize(self) -> Self {
        let one = self.x.splat(1.0);
        self.scale(one / self.dot(self).sqrt())
    }

    #[inline(always)]
    fn select(self, mask: V::Mask, other: Self) -> Self {
        Self {
            x: self.x.select(mask, other.x),
            y: self.y.select(mask, other.y),
            z: self.z.select(mask, other.z),
        }
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

/// [`super::angles::acos`] on every lane.
#[inline(always)]
fn acos<V: Lanes>(x: V) -> V {
    let (zero, one) = (x.splat(0.0), x.splat(1.0));
    let a = abs(x).min(one);
    let r = (one - a).sqrt() * horner(a, &ACOS);
    (x.splat(PI) - r).select(x.lt(zero), r)
}

/// [`super::angles::atan2`] on every lane.
#[inline(always)]
fn atan2<V: Lanes>(y: V, x: V) -> V {
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

/// The lobe's cosine `t` for `wi` and, for Blinn, `wo . h` (1 for Phong); `t = 0` where the
/// half vector is undefined ([`super::packet`]'s scalar rule, on lanes).
#[inline(always)]
fn cosine<V: Lanes>(geometry: Geometry, wo: V3<V>, wi: V3<V>) -> (V, V) {
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

/// What the environment's draws and the shared BRDF numbers of a packet hold.
pub(super) struct SharedColumns {
    pub(super) light_wi: Columns3,
    /// 0 where there is no environment draw above the surface.
    pub(super) light_pdf: Column,
    pub(super) light_radiance: Columns3,
    pub(super) choice: Column,
    pub(super) sin_phi: Column,
    pub(super) cos_phi: Column,
    /// Zero where the cosine-weighted draw is not taken or not above the surface.
    pub(super) diffuse_wi: Columns3,
    pub(super) diffuse_radiance: Columns3,
    pub(super) diffuse_light_pdf: Column,
}

/// One variant's per-lane results.
pub(super) struct VariantColumns {
    /// The lobe's cosine drawn for each lane that draws from the lobe.
    pub(super) drawn: Column,
    pub(super) light_cosine: Column,
    pub(super) light_half_cosine: Column,
    /// The lobe's values at `light_cosine` and `brdf_cosine`.
    pub(super) light_value: Column,
    pub(super) brdf_value: Column,
    /// A tabulated lobe's sampler's densities there, per unit cosine.
    pub(super) light_density: Column,
    pub(super) brdf_density: Column,
    pub(super) brdf_wi: Columns3,
    pub(super) brdf_cosine: Column,
    pub(super) brdf_half_cosine: Column,
    /// [`Source`] as a lane value.
    pub(super) source: Column,
    /// The texel of a lobe-drawn direction: its column and row, and `sin theta` there.
    pub(super) texel_column: Column,
    pub(super) texel_row: Column,
    pub(super) texel_sine: Column,
    pub(super) brdf_radiance: Columns3,
    pub(super) brdf_light_pdf: Column,
}

impl VariantColumns {
    pub(super) const ZERO: Self = Self {
        drawn: [0.0; LANES],
        light_cosine: [0.0; LANES],
        light_half_cosine: [0.0; LANES],
        light_value: [0.0; LANES],
        brdf_value: [0.0; LANES],
        light_density: [0.0; LANES],
        brdf_density: [0.0; LANES],
        brdf_wi: Columns3::ZERO,
        brdf_cosine: [0.0; LANES],
        brdf_half_cosine: [0.0; LANES],
        source: [0.0; LANES],
        texel_column: [0.0; LANES],
        texel_row: [0.0; LANES],
        texel_sine: [0.0; LANES],
        brdf_radiance: Columns3::ZERO,
        brdf_light_pdf: [0.0; LANES],
    };
}

/// A surface point's frame and a variant's geometry, as the jobs need them.
#[derive(Clone, Copy)]
pub(super) struct Setting {
    pub(super) geometry: Geometry,
    pub(super) strategy: Strategy,
    /// Towards the viewer, local.
    pub(super) wo: Vec3,
    /// The frame's axes in world space.
    pub(super) frame: [Vec3; 3],
    /// The axis the lobe's draws turn about, and two directions across it.
    pub(super) axis: [Vec3; 3],
    /// The probability that a BRDF draw goes to the lobe.
    pub(super) share: f32,
    /// The environment map's width and height in texels.
    pub(super) texels: (u32, u32),
}

/// One variant's cosines, BRDF directions and their texels (see the module docs).
pub(super) struct Directions<'a> {
    pub(super) setting: Setting,
    pub(super) shared: &'a SharedColumns,
    pub(super) variant: &'a mut VariantColumns,
}

impl Job for Directions<'_> {
    type Output = ();

    #[inline(always)]
    fn run<V: Lanes>(self, lanes: V) {
        let Setting {
            geometry,
            strategy,
            wo,
            frame,
            axis,
            share,
            texels: (width, height),
        } = self.setting;
        let (shared, variant) = (self.shared, self.variant);
        let (zero, one) = (lanes.splat(0.0), lanes.splat(1.0));
        let wo = V3::splat(lanes, wo);
        let w = V::WIDTH;
        for k in (0..LANES).step_by(w) {
            let light = V3::load(lanes, &shared.light_wi, k);
            let has_light = lanes.load(&shared.light_pdf[k..k + w]).gt(zero);
            let (t, half_cosine) = cosine(geometry, wo, light);
            t.keep(has_light).store(&mut variant.light_cosine[k..k + w]);
            half_cosine.store(&mut variant.light_half_cosine[k..k + w]);
            if strategy == Strategy::Environment {
                zero.store(&mut variant.source[k..k + w]);
                zero.store(&mut variant.brdf_cosine[k..k + w]);
                continue;
            }
            // The lobe's draw: its cosine about the axis, turned by the shared azimuth.
            let t = lanes.load(&variant.drawn[k..k + w]);
            let sine = t.neg_mul_add(t, one).max(zero).sqrt();
            let (cos_phi, sin_phi) = (
                lanes.load(&shared.cos_phi[k..k + w]),
                lanes.load(&shared.sin_phi[k..k + w]),
            );
            let across = V3::splat(lanes, axis[1])
                .scale_add(cos_phi, V3::splat(lanes, axis[2]).scale(sin_phi));
            let direction = V3::splat(lanes, axis[0])
                .scale_add(t, across.scale(sine))
                .normalize();
            let (lobe_wi, lobe_t, lobe_half) = match geometry {
                Geometry::Phong => (direction, t, one),
                Geometry::Blinn => {
                    let half = wo.dot(direction);
                    let wi = direction.scale(half + half).sub(wo).normalize();
                    (wi, t.keep(half.gt(zero)), half)
                }
            };
            let diffuse_wi = V3::load(lanes, &shared.diffuse_wi, k);
            let (diffuse_t, diffuse_half) = cosine(geometry, wo, diffuse_wi);
            let from_lobe = lanes.load(&shared.choice[k..k + w]).lt(lanes.splat(share));
            let wi = lobe_wi.select(from_lobe, diffuse_wi);
            let t = lobe_t.select(from_lobe, diffuse_t);
            let half = lobe_half.select(from_lobe, diffuse_half);
            // Above the surface with a defined half vector (false for NaN in either).
            let above = half.keep(wi.z.gt(zero)).gt(zero);
            let source = lanes
                .splat(Source::Lobe as u8 as f32)
                .select(from_lobe, lanes.splat(Source::Diffuse as u8 as f32))
                .keep(above);
            source.store(&mut variant.source[k..k + w]);
            wi.store(&mut variant.brdf_wi, k);
            t.keep(above).store(&mut variant.brdf_cosine[k..k + w]);
            half.store(&mut variant.brdf_half_cosine[k..k + w]);
            // The texel a lobe-drawn direction falls in ([`super::Environment::texel_of`]).
            let world = V3::splat(lanes, frame[0]).scale_add(
                wi.x,
                V3::splat(lanes, frame[1]).scale_add(wi.y, V3::splat(lanes, frame[2]).scale(wi.z)),
            );
            let z = world.z.max(lanes.splat(-1.0)).min(one);
            let y = acos(z) * lanes.splat(FRAC_1_PI);
            let x = atan2(world.y, world.x).neg_mul_add(lanes.splat(1.0 / TAU), lanes.splat(0.75));
            let x = x.select(x.lt(one), x - one);
            let (w_f, h_f) = (width as f32, height as f32);
            let column = (x * lanes.splat(w_f)).min(lanes.splat(w_f - 1.0)).max(zero);
            let row = (y * lanes.splat(h_f)).min(lanes.splat(h_f - 1.0)).max(zero);
            column
                .float_to_int()
                .int_to_float()
                .store(&mut variant.texel_column[k..k + w]);
            row.float_to_int()
                .int_to_float()
                .store(&mut variant.texel_row[k..k + w]);
            z.neg_mul_add(z, one)
                .max(zero)
                .sqrt()
                .store(&mut variant.texel_sine[k..k + w]);
        }
    }
}

/// A variant's BRDF as the combination needs it.
#[derive(Clone, Copy)]
pub(super) struct Brdf {
    pub(super) geometry: Geometry,
    pub(super) strategy: Strategy,
    /// `kd C / pi`.
    pub(super) diffuse: Vec3,
    /// `ks S N(n)`.
    pub(super) specular: Vec3,
    pub(super) share: f32,
    /// The lobe's value to its sampler's density, or `None` where the densities are the
    /// table's, in [`VariantColumns::light_density`] and [`VariantColumns::brdf_density`].
    pub(super) density_per_value: Option<f32>,
}

/// One variant's estimates over a packet, summed (see the module docs).
pub(super) struct Combine<'a> {
    pub(super) brdf: Brdf,
    pub(super) shared: &'a SharedColumns,
    pub(super) variant: &'a VariantColumns,
}

impl Combine<'_> {
    /// `f` and the BRDF strategy's density at `wi`, from the lobe's value and density there.
    #[inline(always)]
    fn f_and_pdf<V: Lanes>(&self, wi_z: V, half: V, value: V, density: V) -> (V3<V>, V) {
        let brdf = self.brdf;
        let zero = value.splat(0.0);
        let lobe_pdf = match brdf.geometry {
            Geometry::Phong => density,
            Geometry::Blinn => (density / (half * value.splat(4.0))).keep(half.gt(zero)),
        };
        let f = V3::splat(value, brdf.specular).scale_add(value, V3::splat(value, brdf.diffuse));
        let pdf = wi_z.mul_add(
            value.splat((1.0 - brdf.share) * FRAC_1_PI),
            lobe_pdf * value.splat(brdf.share),
        );
        (f, pdf)
    }

    /// The lobe sampler's density about its axis, per solid angle, where its value is
    /// `value`: the value's share of the lobe's integral, or the table's density per unit
    /// cosine over `2 pi`.
    #[inline(always)]
    fn density<V: Lanes>(&self, value: V, table: &Column, k: usize) -> V {
        match self.brdf.density_per_value {
            Some(per_value) => value * value.splat(per_value),
            None => value.load(&table[k..k + V::WIDTH]) * value.splat(0.5 * FRAC_1_PI),
        }
    }

    /// The weight of a draw of density `pdf` against the other strategy's `other`: Veach's
    /// power heuristic under MIS ([`specula::sampling::power_heuristic`]'s rules for zero and
    /// infinite densities), 1 otherwise. Squared in `f32` (one division; the ratio form
    /// takes two, 4 % of the environment grid's time): a density whose square overflows
    /// (above `1.8e19`) weighs as an infinite one, one whose square vanishes (below `1e-22`)
    /// as 0.
    #[inline(always)]
    fn weight<V: Lanes>(&self, pdf: V, other: V) -> V {
        let one = pdf.splat(1.0);
        if self.brdf.strategy != Strategy::Mis {
            return one;
        }
        let (zero, infinity) = (pdf.splat(0.0), pdf.splat(f32::INFINITY));
        let (a, b) = (pdf * pdf, other * other);
        (a / (a + b))
            .select(a.lt(infinity), one)
            .keep(b.lt(infinity))
            .keep(a.gt(zero))
    }
}

impl Job for Combine<'_> {
    type Output = Vec3;

    #[inline(always)]
    fn run<V: Lanes>(self, lanes: V) -> Vec3 {
        let (shared, variant) = (self.shared, self.variant);
        let zero = lanes.splat(0.0);
        let nothing = V3::splat(lanes, Vec3::ZERO);
        let w = V::WIDTH;
        let mut sum = nothing;
        for k in (0..LANES).step_by(w) {
            // The environment's draw.
            let light_pdf = lanes.load(&shared.light_pdf[k..k + w]);
            let light = V3::load(lanes, &shared.light_wi, k);
            let value = lanes.load(&variant.light_value[k..k + w]);
            let (f, brdf_pdf) = self.f_and_pdf(
                light.z,
                lanes.load(&variant.light_half_cosine[k..k + w]),
                value,
                self.density(value, &variant.light_density, k),
            );
            let scale = light.z * self.weight(light_pdf, brdf_pdf) / light_pdf;
            let contribution = f
                .mul(V3::load(lanes, &shared.light_radiance, k))
                .scale(scale);
            sum = sum.add(contribution.select(light_pdf.gt(zero), nothing));
            // The BRDF's draw.
            let wi = V3::load(lanes, &variant.brdf_wi, k);
            let value = lanes.load(&variant.brdf_value[k..k + w]);
            let (f, pdf) = self.f_and_pdf(
                wi.z,
                lanes.load(&variant.brdf_half_cosine[k..k + w]),
                value,
                self.density(value, &variant.brdf_density, k),
            );
            let light_pdf = lanes.load(&variant.brdf_light_pdf[k..k + w]);
            let scale = wi.z * self.weight(pdf, light_pdf) / pdf;
            let contribution = f
                .mul(V3::load(lanes, &variant.brdf_radiance, k))
                .scale(scale);
            let taken = lanes.load(&variant.source[k..k + w]).gt(zero);
            sum = sum.add(contribution.select(pdf.keep(taken).gt(zero), nothing));
        }
        let mut columns = Columns3::ZERO;
        sum.store(&mut columns, 0);
        (0..w).fold(Vec3::ZERO, |total, k| total + columns.get(k))
    }
}

#[cfg(test)]
mod tests {
    use specula::simd::{dispatch, Level};

    use super::*;

    /// `acos` and `atan2` on lanes, at every level this CPU has, are the scalar ones of
    /// [`super::super::angles`] to a few `f32` roundings (the fused multiply-adds).
    #[test]
    fn the_lane_angles_are_the_scalar_ones() {
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
                    let (x, y) = (xs[k], ys[k]);
                    let acos = super::super::angles::acos(x);
                    let atan2 = super::super::angles::atan2(y, x);
                    assert!(
                        (out[0][k] - acos).abs() <= 1e-6,
                        "{level:?} acos({x}): {} against {acos}",
                        out[0][k]
                    );
                    assert!(
                        (out[1][k] - atan2).abs() <= 1e-6,
                        "{level:?} atan2({y}, {x}): {} against {atan2}",
                        out[1][k]
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
