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
//! Lanes past the packet's draws hold no draw (`light_pdf = 0`, `brdf_taken = 0`), so
//! every job runs over the packet's draws rounded up to the level's width (`used`: a packet of
//! 16 draws costs 16 lanes, not [`LANES`]) and masks with selects, never with a multiply by 0
//! (a masked lane may hold an infinity or a NaN).

use core::f32::consts::FRAC_1_PI;

use glam::Vec3;
use specula::simd::{Job, Lanes};
use specula::Geometry;

use super::environment::jacobian_lanes;
use super::lane_geometry::{cosine, Column, Columns3, LANES, V3};
use super::{Environment, Strategy};

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
    /// 1 where the lane's BRDF draw (the lobe's or the cosine-weighted one) gives a direction
    /// above the surface, 0 elsewhere.
    pub(super) brdf_taken: Column,
    /// The texel of each lane's BRDF direction: its column and row (`i32` bit patterns, for
    /// [`Environment::texel_of_bits`]), and the Jacobian there ([`jacobian_lanes`]).
    pub(super) texel_column: Column,
    pub(super) texel_row: Column,
    pub(super) texel_jacobian: Column,
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
        brdf_taken: [0.0; LANES],
        texel_column: [0.0; LANES],
        texel_row: [0.0; LANES],
        texel_jacobian: [0.0; LANES],
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
}

/// One variant's cosines, BRDF directions and their texels (see the module docs).
pub(super) struct Directions<'a> {
    pub(super) setting: Setting,
    /// The lanes to run: the packet's draws rounded up to the level's width.
    pub(super) used: usize,
    pub(super) environment: &'a Environment,
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
        } = self.setting;
        let (environment, shared, variant) = (self.environment, self.shared, self.variant);
        let (zero, one) = (lanes.splat(0.0), lanes.splat(1.0));
        let wo = V3::splat(lanes, wo);
        let w = V::WIDTH;
        for k in (0..self.used).step_by(w) {
            let light = V3::load(lanes, &shared.light_wi, k);
            let has_light = lanes.load(&shared.light_pdf[k..k + w]).gt(zero);
            let (t, half_cosine) = cosine(geometry, wo, light);
            t.keep(has_light).store(&mut variant.light_cosine[k..k + w]);
            half_cosine.store(&mut variant.light_half_cosine[k..k + w]);
            if strategy == Strategy::Environment {
                zero.store(&mut variant.brdf_taken[k..k + w]);
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
            one.keep(above).store(&mut variant.brdf_taken[k..k + w]);
            wi.store(&mut variant.brdf_wi, k);
            t.keep(above).store(&mut variant.brdf_cosine[k..k + w]);
            half.store(&mut variant.brdf_half_cosine[k..k + w]);
            // The texel the BRDF direction falls in.
            let world = V3::splat(lanes, frame[0]).scale_add(
                wi.x,
                V3::splat(lanes, frame[1]).scale_add(wi.y, V3::splat(lanes, frame[2]).scale(wi.z)),
            );
            let (column, row, sine) = environment.texel_lanes(world);
            column.store(&mut variant.texel_column[k..k + w]);
            row.store(&mut variant.texel_row[k..k + w]);
            jacobian_lanes(sine).store(&mut variant.texel_jacobian[k..k + w]);
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
    /// The lanes to run: the packet's draws rounded up to the level's width.
    pub(super) used: usize,
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
        for k in (0..self.used).step_by(w) {
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
            let taken = lanes.load(&variant.brdf_taken[k..k + w]).gt(zero);
            sum = sum.add(contribution.select(pdf.keep(taken).gt(zero), nothing));
        }
        sum.sum_lanes()
    }
}
