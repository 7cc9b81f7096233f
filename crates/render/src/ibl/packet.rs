//! The estimator of [`super::trace`] for the scene's own materials, run over packets of
//! samples in `f32`: what Mitsuba 3's LLVM backend does with wide vectors, arranged so that
//! the expensive parts vectorise or vanish.
//!
//! A packet is up to [`LANES`] samples of one surface point (one view, one frame, one `wo`).
//! The estimator is the same as [`super::trace`]'s, one environment draw and one BRDF draw
//! combined by the power heuristic; what differs is how it is computed:
//! - the lobe is evaluated **once per direction**, for all the packet's directions in one
//!   call of its SIMD kernel ([`specula::Lobe::eval_batch`]), and that one value gives both
//!   the BRDF and (over the lobe's integral) the sampler's density, where the `f64` path
//!   evaluates it twice;
//! - the environment is drawn by **alias** in constant time ([`Environment::draw`]) and looked
//!   up once per BRDF direction for both its radiance and its density
//!   ([`Environment::look_up`]), in passes over the packet: first every lane's texel, then
//!   every texel's radiance and density (one 16-byte record), so that the reads of a map of
//!   megabytes overlap rather than wait one after another;
//! - the frame's tangents and the Phong axis's basis are built once per surface point, and
//!   closed-form lobes draw their cosine in `f32`, tabulated lobes from their table in `f32`
//!   with a guide ([`specula::sampling::CosineTable32`]), where the `f64` path searches it.
//!
//! Random numbers come from [`specula::sampling::random_bits`] by (seed, draw, dimension),
//! two 32-bit numbers from each, so an image is the same on any number of threads. The
//! images agree with the `f64` path's within Monte Carlo noise (tested), not bit for bit:
//! the draws map the numbers to directions differently.

use core::f32::consts::FRAC_1_PI;

use glam::Vec3;
use specula::brdf::luminance;
use specula::lobe::Warp;
use specula::sampling::{random_bits, unit_f32, CosineTable32};
use specula::{Geometry, Lobe};

use super::angles::sin_cos_turns;
use super::{Environment, Strategy};
use crate::Material;

/// Samples per packet: enough for the lobe's kernel to run at full width, few enough to live
/// on the stack.
pub(super) const LANES: usize = 64;

/// A scene material prepared for the packet estimator: `f = diffuse + specular lobe(t)`.
pub(super) struct PacketSurface {
    /// `kd C / pi`.
    diffuse: Vec3,
    /// `ks S N(n)`.
    specular: Vec3,
    /// The probability that a BRDF draw goes to the lobe rather than the cosine.
    share: f32,
    /// `1 / (2 pi int_0^1 lobe)`: the lobe's value to its sampler's density about its axis
    /// (for a lobe with a closed-form integral).
    density_per_value: f32,
    lobe: Lobe,
    geometry: Geometry,
    warp: Warp,
    /// A tabulated lobe's table, drawn and read in `f32`.
    table: Option<CosineTable32>,
}

impl PacketSurface {
    pub(super) fn new(material: &Material) -> Self {
        let diffuse = material.kd * material.colour;
        let specular = material.ks * material.specular_colour;
        let (d, s) = (
            luminance(diffuse.as_dvec3()),
            luminance(specular.as_dvec3()),
        );
        let scale = material.normalisation.constant_for(&material.lobe) as f32;
        let warp = material.lobe.warp();
        let total = material.lobe.tail(0.0).unwrap_or(0.0);
        Self {
            diffuse: diffuse * FRAC_1_PI,
            specular: specular * scale,
            share: if d + s > 0.0 {
                (s / (d + s)) as f32
            } else {
                0.0
            },
            density_per_value: if total > 0.0 {
                (1.0 / (core::f64::consts::TAU * total)) as f32
            } else {
                0.0
            },
            lobe: material.lobe,
            geometry: material.geometry,
            warp,
            table: (warp == Warp::Table).then(|| CosineTable32::of(&material.lobe)),
        }
    }

    /// The lobe's cosine `t` for `wi` (local), and for Blinn `wo . h` (the Jacobian's);
    /// `t = 0` where the half vector is undefined.
    fn cosine(&self, wo: Vec3, wi: Vec3) -> (f32, f32) {
        match self.geometry {
            Geometry::Phong => (Vec3::new(-wo.x, -wo.y, wo.z).dot(wi), 1.0),
            Geometry::Blinn => {
                let sum = wo + wi;
                let length_squared = sum.length_squared();
                if length_squared > 0.0 {
                    let h = sum / length_squared.sqrt();
                    (h.z, wo.dot(h))
                } else {
                    (0.0, 1.0)
                }
            }
        }
    }

    /// A cosine drawn from the lobe for the uniform `u`.
    fn draw_cosine(&self, u: f32) -> f32 {
        match (self.warp, &self.table) {
            (_, Some(table)) => table.sample(u),
            (Warp::Analytic, None) => self.lobe.closed_form_sampling(u).map_or(1.0, |(t, _)| t),
            // Newton on the lobe's own integral (a user's formula declares it for exact
            // sampling), in `f64`.
            _ => self
                .lobe
                .tail_inverse(f64::from(u))
                .map_or(1.0, |inverted| inverted.x as f32),
        }
    }

    /// The BRDF and the BRDF strategy's density at `wi` (local, above the surface), from the
    /// lobe's value `value` at its cosine `t` (and `wo . h` for Blinn).
    fn f_and_pdf(&self, wi: Vec3, t: f32, half_cosine: f32, value: f32) -> (Vec3, f32) {
        let density = match &self.table {
            Some(table) => table.density(t) * (0.5 * FRAC_1_PI),
            None => value * self.density_per_value,
        };
        let lobe_pdf = match self.geometry {
            Geometry::Phong => density,
            Geometry::Blinn if half_cosine > 0.0 => density / (4.0 * half_cosine),
            Geometry::Blinn => 0.0,
        };
        (
            self.diffuse + self.specular * value,
            (1.0 - self.share) * wi.z * FRAC_1_PI + self.share * lobe_pdf,
        )
    }
}

/// An orthonormal frame about a unit normal, in `f32`.
#[derive(Clone, Copy)]
pub(super) struct Frame32 {
    tangent: Vec3,
    bitangent: Vec3,
    normal: Vec3,
}

impl Frame32 {
    pub(super) fn new(tangent: Vec3, bitangent: Vec3, normal: Vec3) -> Self {
        Self {
            tangent,
            bitangent,
            normal,
        }
    }

    fn to_local(self, v: Vec3) -> Vec3 {
        Vec3::new(
            v.dot(self.tangent),
            v.dot(self.bitangent),
            v.dot(self.normal),
        )
    }

    fn to_world(self, v: Vec3) -> Vec3 {
        self.tangent * v.x + self.bitangent * v.y + self.normal * v.z
    }
}

/// The environment's draw of one sample (local), its density and radiance, and the texel it
/// came from: the same for every variant of the surface.
#[derive(Clone, Copy, Default)]
struct LightDraw {
    /// The draw's index in the stream.
    draw: u64,
    texel: Option<usize>,
    within: [f32; 2],
    /// `pdf` 0 when there is no draw above the surface.
    wi: Vec3,
    pdf: f32,
    radiance: Vec3,
}

/// The BRDF's uniform numbers for one sample, and the cosine-weighted direction they give
/// with what the environment sends along it: shared by every variant that draws the cosine.
#[derive(Clone, Copy, Default)]
struct BrdfDraw {
    choice: f32,
    u1: f32,
    sin_phi: f32,
    cos_phi: f32,
    diffuse_wi: Vec3,
    diffuse_texel: usize,
    diffuse_sine: f32,
    diffuse_radiance: Vec3,
    diffuse_light_pdf: f32,
}

/// A packet's draws that every variant shares.
struct SharedDraws {
    lights: [LightDraw; LANES],
    brdfs: [BrdfDraw; LANES],
}

/// One sample's BRDF direction for one variant (local), its half-vector cosine, and what the
/// environment sends along it with the density it would have drawn it with.
#[derive(Clone, Copy, Default)]
struct Lane {
    light_half_cosine: f32,
    brdf_wi: Vec3,
    /// `true` when above the surface.
    brdf_ok: bool,
    brdf_half_cosine: f32,
    brdf_texel: usize,
    brdf_sine: f32,
    brdf_radiance: Vec3,
    brdf_light_pdf: f32,
}

/// A surface point, prepared once for all its samples: one surface per variant of the
/// image (one lobe each, when every lobe is rendered under the same light).
pub(super) struct Point<'a> {
    pub(super) surfaces: &'a [PacketSurface],
    pub(super) frame: Frame32,
    /// Towards the viewer, local, above the surface.
    pub(super) wo: Vec3,
}

/// Adds to `sums[v]` the sum of the estimates of `draws` (each a draw index of the stream
/// `seed`) at `point` with its surface `v`. The random numbers do not depend on the surface,
/// so every variant's environment draws, and the cosine-weighted BRDF draws of every
/// variant that makes one, are computed once; each variant's sums are the ones it would
/// have alone, bit for bit.
pub(super) fn shade(
    point: &Point,
    environment: &Environment,
    strategy: Strategy,
    seed: u64,
    draws: impl Iterator<Item = u64>,
    sums: &mut [glam::DVec3],
) {
    let fewest_lobe_draws = point
        .surfaces
        .iter()
        .map(|s| s.share)
        .fold(f32::INFINITY, f32::min);
    let mut draws = draws.peekable();
    let mut shared = SharedDraws {
        lights: [LightDraw::default(); LANES],
        brdfs: [BrdfDraw::default(); LANES],
    };
    let mut lanes = [Lane::default(); LANES];
    let mut cosines = [0.0_f32; 2 * LANES];
    let mut values = [0.0_f32; 2 * LANES];
    while draws.peek().is_some() {
        // In passes over the packet rather than lane by lane: each pass's reads of the map
        // (megabytes, mostly out of cache) are independent of one another and overlap.
        let mut count = 0;
        let SharedDraws { lights, brdfs } = &mut shared;
        // The environment's draws: random numbers and the alias table's texels.
        for (k, draw) in draws.by_ref().take(LANES).enumerate() {
            count = k + 1;
            let light = &mut lights[k];
            *light = LightDraw {
                draw,
                ..LightDraw::default()
            };
            if strategy != Strategy::Brdf {
                let bits = random_bits(seed, draw, 0);
                let within = random_bits(seed, draw, 1);
                light.texel =
                    Some(environment.draw_texel(bits as u32, unit_f32((bits >> 32) as u32)));
                light.within = [unit_f32(within as u32), unit_f32((within >> 32) as u32)];
            }
        }
        // The BRDF's numbers, and the cosine-weighted directions' texels.
        if strategy != Strategy::Environment {
            for (light, brdf) in lights[..count].iter().zip(brdfs.iter_mut()) {
                let bits = random_bits(seed, light.draw, 2);
                let more = random_bits(seed, light.draw, 3);
                brdf.choice = unit_f32(bits as u32);
                brdf.u1 = unit_f32((bits >> 32) as u32);
                (brdf.sin_phi, brdf.cos_phi) = sin_cos_turns(unit_f32(more as u32));
                brdf.diffuse_wi = Vec3::ZERO;
                if brdf.choice >= fewest_lobe_draws {
                    let (sine, cosine) = (brdf.u1.sqrt(), (1.0 - brdf.u1).max(0.0).sqrt());
                    let wi = Vec3::new(sine * brdf.cos_phi, sine * brdf.sin_phi, cosine);
                    if wi.z > 0.0 {
                        brdf.diffuse_wi = wi;
                        (brdf.diffuse_texel, brdf.diffuse_sine) =
                            environment.texel_of(point.frame.to_world(wi));
                    }
                }
            }
        }
        // The texels' radiances and densities.
        for (light, brdf) in lights[..count].iter_mut().zip(brdfs.iter_mut()) {
            if let Some(texel) = light.texel {
                if let Some((wi, pdf, radiance)) = environment.draw_in(texel, light.within) {
                    let wi = point.frame.to_local(wi);
                    if wi.z > 0.0 {
                        (light.wi, light.pdf, light.radiance) = (wi, pdf, radiance);
                    }
                }
            }
            if brdf.diffuse_wi.z > 0.0 {
                (brdf.diffuse_radiance, brdf.diffuse_light_pdf) =
                    environment.look_up_texel(brdf.diffuse_texel, brdf.diffuse_sine);
            }
        }
        for (surface, sum) in point.surfaces.iter().zip(sums.iter_mut()) {
            let lanes = &mut lanes[..count];
            variant_directions(
                point,
                environment,
                surface,
                strategy,
                &shared,
                lanes,
                &mut cosines,
            );
            for lane in lanes
                .iter_mut()
                .filter(|lane| lane.brdf_texel != usize::MAX)
            {
                (lane.brdf_radiance, lane.brdf_light_pdf) =
                    environment.look_up_texel(lane.brdf_texel, lane.brdf_sine);
            }
            // The light's cosines then the BRDF's, `count` each: a packet of a pixel's
            // position may be short of LANES.
            surface
                .lobe
                .eval_batch(&cosines[..2 * count], &mut values[..2 * count]);
            *sum += combine(surface, strategy, &shared.lights, lanes, &cosines, &values).as_dvec3();
        }
    }
}

/// One variant's cosines (of the `count = lanes.len()` lanes: the environment's draws' in
/// `cosines[..count]`, the BRDF's in `cosines[count..2 count]`) and BRDF directions; a lane drawing from this variant's lobe leaves
/// the texel its direction falls in (`usize::MAX` where it reads nothing new).
fn variant_directions(
    point: &Point,
    environment: &Environment,
    surface: &PacketSurface,
    strategy: Strategy,
    shared: &SharedDraws,
    lanes: &mut [Lane],
    cosines: &mut [f32; 2 * LANES],
) {
    let (wo, count) = (point.wo, lanes.len());
    // The basis the lobe's directions are drawn in: about the mirror direction (Phong) or
    // the normal (Blinn's half vector).
    let axis = match surface.geometry {
        Geometry::Phong => Vec3::new(-wo.x, -wo.y, wo.z),
        Geometry::Blinn => Vec3::Z,
    };
    let (b1, b2) = axis.any_orthonormal_pair();
    for (k, lane) in lanes.iter_mut().enumerate() {
        *lane = Lane {
            brdf_texel: usize::MAX,
            ..Lane::default()
        };
        cosines[k] = 0.0;
        cosines[count + k] = 0.0;
        let light = &shared.lights[k];
        if light.pdf > 0.0 {
            let (t, half_cosine) = surface.cosine(wo, light.wi);
            lane.light_half_cosine = half_cosine;
            cosines[k] = t;
        }
        if strategy == Strategy::Environment {
            continue;
        }
        let brdf = &shared.brdfs[k];
        let (wi, t, half_cosine) = if brdf.choice < surface.share {
            let t = surface.draw_cosine(brdf.u1);
            let sine = (1.0 - t * t).max(0.0).sqrt();
            let direction = (t * axis + sine * (brdf.cos_phi * b1 + brdf.sin_phi * b2)).normalize();
            match surface.geometry {
                Geometry::Phong => (direction, t, 1.0),
                Geometry::Blinn => {
                    let half_cosine = wo.dot(direction);
                    let wi = (2.0 * half_cosine * direction - wo).normalize();
                    (wi, if half_cosine > 0.0 { t } else { 0.0 }, half_cosine)
                }
            }
        } else {
            let wi = brdf.diffuse_wi;
            let (t, half_cosine) = surface.cosine(wo, wi);
            (wi, t, half_cosine)
        };
        if wi.z > 0.0 && half_cosine > 0.0 {
            lane.brdf_wi = wi;
            lane.brdf_ok = true;
            lane.brdf_half_cosine = half_cosine;
            cosines[count + k] = t;
            if brdf.choice < surface.share {
                (lane.brdf_texel, lane.brdf_sine) = environment.texel_of(point.frame.to_world(wi));
            } else {
                (lane.brdf_radiance, lane.brdf_light_pdf) =
                    (brdf.diffuse_radiance, brdf.diffuse_light_pdf);
            }
        }
    }
}

/// One variant's estimates over the packet, summed: each lane's environment draw and BRDF
/// draw, combined by the power heuristic.
fn combine(
    surface: &PacketSurface,
    strategy: Strategy,
    lights: &[LightDraw; LANES],
    lanes: &[Lane],
    cosines: &[f32; 2 * LANES],
    values: &[f32; 2 * LANES],
) -> Vec3 {
    let count = lanes.len();
    let mut packet = Vec3::ZERO;
    for (k, lane) in lanes.iter().enumerate() {
        let light = &lights[k];
        if light.pdf > 0.0 {
            let (f, brdf_pdf) =
                surface.f_and_pdf(light.wi, cosines[k], lane.light_half_cosine, values[k]);
            let weight = match strategy {
                Strategy::Mis => power_heuristic(light.pdf, brdf_pdf),
                _ => 1.0,
            };
            packet += f * light.radiance * (light.wi.z * weight / light.pdf);
        }
        if lane.brdf_ok {
            let (f, pdf) = surface.f_and_pdf(
                lane.brdf_wi,
                cosines[count + k],
                lane.brdf_half_cosine,
                values[count + k],
            );
            if pdf > 0.0 {
                let weight = match strategy {
                    Strategy::Mis => power_heuristic(pdf, lane.brdf_light_pdf),
                    _ => 1.0,
                };
                packet += f * lane.brdf_radiance * (lane.brdf_wi.z * weight / pdf);
            }
        }
    }
    packet
}

/// Veach's power heuristic ([`specula::sampling::power_heuristic`], whose care for zero and
/// infinite densities it keeps) on `f32` densities.
fn power_heuristic(pdf: f32, other: f32) -> f32 {
    specula::sampling::power_heuristic(f64::from(pdf), f64::from(other)) as f32
}
