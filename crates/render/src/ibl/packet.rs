//! The estimator of `trace.rs` for the scene's own materials, run over packets of
//! samples in `f32`: what Mitsuba 3's LLVM backend does with wide vectors, arranged so that
//! the expensive parts vectorise or vanish.
//!
//! A packet is up to [`LANES`] samples of one surface point (one view, one frame, one `wo`).
//! The estimator is the same as `trace.rs`'s, one environment draw and one BRDF draw
//! combined by the power heuristic; what differs is how it is computed:
//! - the lobe is evaluated **once per direction**, for all the packet's directions in one
//!   call of its SIMD kernel ([`specula::Lobe::eval_batch`]), and that one value gives both
//!   the BRDF and (over the lobe's integral) the sampler's density, where the `f64` path
//!   evaluates it twice;
//! - the environment is drawn by **alias** in constant time, a run of pixels ahead
//!   (`ahead.rs`: the texels this packet takes), and looked up once per BRDF direction for
//!   both its radiance and its density, in passes over the packet: first every lane's texel,
//!   then every texel's radiance and density (one 16-byte record, the density scaled by the
//!   Jacobian made on lanes), so that the reads of a map of megabytes overlap rather than
//!   wait one after another;
//! - the frame's tangents and the Phong axis's basis are built once per surface point, and
//!   closed-form lobes draw their cosines on SIMD lanes ([`specula::Lobe::tail_inverse_batch`]),
//!   tabulated lobes from their table in `f32` with a guide
//!   ([`specula::sampling::CosineTable32`]), where the `f64` path searches it;
//!   Newton-sampled lobes start Newton from that table's draw (the same root, in about half
//!   the iterations);
//! - each variant's directions, their texels and the combination of its two draws run on
//!   SIMD lanes (`lanes.rs`: 8 with AVX2 and FMA), the same on every level to `f32`
//!   roundings (tested).
//!
//! Random numbers come from [`specula::sampling::random_bits`] by (seed, draw, dimension),
//! two 32-bit numbers from each, so an image is the same on any number of threads. The
//! images agree with the `f64` path's within Monte Carlo noise (tested), not bit for bit:
//! the draws map the numbers to directions differently.

use core::f32::consts::FRAC_1_PI;

use glam::Vec3;
use specula::brdf::luminance;
use specula::lobe::Warp;
use specula::sampling::{random_bits, CosineTable32};
use specula::simd::{dispatch, Level, Prefetch};
use specula::{Geometry, Lobe};

use super::ahead::LightCells;
use super::draws::{Draws, SharedDraws};
use super::lane_geometry::{Columns3, LANES};
use super::lanes::{Brdf, Combine, Directions, Setting, SharedColumns, VariantColumns};
use super::{Environment, Strategy};
use crate::material::Material;

/// A scene material prepared for the packet estimator: `f = diffuse + specular lobe(t)`.
pub(super) struct PacketSurface {
    /// `kd C / pi`.
    diffuse: Vec3,
    /// `ks S N(n)`.
    specular: Vec3,
    /// The probability that a BRDF draw goes to the lobe rather than the cosine.
    share: f32,
    /// `1 / (2 pi int_0^1 lobe)`: the lobe's value to its sampler's density about its axis
    /// (for a lobe with a closed-form integral; see [`PacketSurface::density_per_value`]).
    value_to_density: f32,
    lobe: Lobe,
    geometry: Geometry,
    sampler: CosineSampler,
}

/// How a surface's lobe draws its cosine in the packet estimator.
enum CosineSampler {
    /// By the lobe's closed-form inverse, in `f32`.
    ClosedForm,
    /// By Newton on the lobe's own integral (a user's formula declares it for exact
    /// sampling), in `f64` to `f32` resolution, from the table's draw.
    Newton(CosineTable32),
    /// From the table, whose density is then the sampler's.
    Table(CosineTable32),
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
        let table = || CosineTable32::of(&material.lobe);
        let total = material.lobe.tail(0.0).unwrap_or(0.0);
        Self {
            diffuse: diffuse * FRAC_1_PI,
            specular: specular * scale,
            share: if d + s > 0.0 {
                (s / (d + s)) as f32
            } else {
                0.0
            },
            value_to_density: if total > 0.0 {
                (1.0 / (core::f64::consts::TAU * total)) as f32
            } else {
                0.0
            },
            lobe: material.lobe,
            geometry: material.geometry,
            sampler: match material.lobe.warp() {
                Warp::Analytic => CosineSampler::ClosedForm,
                Warp::Newton => CosineSampler::Newton(table()),
                Warp::Table => CosineSampler::Table(table()),
            },
        }
    }

    /// The lobe's value to its sampler's density about its axis, or `None` for a tabulated
    /// lobe, whose sampler's density is its table's.
    fn density_per_value(&self) -> Option<f32> {
        match self.sampler {
            CosineSampler::Table(_) => None,
            _ => Some(self.value_to_density),
        }
    }

    /// A tabulated lobe's table, whose density is its sampler's.
    fn density_table(&self) -> Option<&CosineTable32> {
        match &self.sampler {
            CosineSampler::Table(table) => Some(table),
            _ => None,
        }
    }

    /// The cosines drawn from the lobe for the uniforms `us`, into `drawn`, where `takes(k)`:
    /// a closed-form inverse on `level`'s lanes for every lane (cheaper than choosing; the
    /// lanes that take none discard theirs), Newton or the table lane by lane for the lanes
    /// that take one (0 elsewhere).
    fn draw_cosines(
        &self,
        level: Level,
        us: &[f32],
        takes: impl Fn(usize) -> bool,
        drawn: &mut [f32],
    ) {
        match &self.sampler {
            CosineSampler::ClosedForm => {
                self.lobe.tail_inverse_batch(level, us, drawn);
            }
            CosineSampler::Newton(start) => each_taken(us, takes, drawn, |u| {
                self.lobe
                    .tail_inverse_f32(f64::from(u), f64::from(start.sample(u)))
                    .map_or(1.0, |inverted| inverted.x as f32)
            }),
            CosineSampler::Table(table) => each_taken(us, takes, drawn, |u| table.sample(u)),
        }
    }
}

/// `draw(u)` into `drawn` for each uniform `u` of `us` whose lane `takes`, 0 elsewhere.
fn each_taken(
    us: &[f32],
    takes: impl Fn(usize) -> bool,
    drawn: &mut [f32],
    draw: impl Fn(f32) -> f32,
) {
    for (k, (drawn, &u)) in drawn.iter_mut().zip(us).enumerate() {
        *drawn = if takes(k) { draw(u) } else { 0.0 };
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
}

/// The columns a packet's passes write and read: made once per thread and reused for every
/// pixel (filling some 20 kB with zeros per pixel cost more than a sample). Every pass
/// writes the lanes it runs before any reads them, so what a pixel leaves behind is never
/// read by the next.
pub(super) struct Scratch {
    /// The texel each environment draw drew.
    light_texel: [usize; LANES],
    numbers: Draws,
    shared: SharedColumns,
    variant: VariantColumns,
}

impl Scratch {
    pub(super) fn new() -> Box<Self> {
        Box::new(Self {
            light_texel: [0; LANES],
            numbers: Draws::ZERO,
            shared: SharedColumns {
                light_wi: Columns3::ZERO,
                light_pdf: [0.0; LANES],
                light_radiance: Columns3::ZERO,
                choice: [0.0; LANES],
                sin_phi: [0.0; LANES],
                cos_phi: [0.0; LANES],
                diffuse_wi: Columns3::ZERO,
            },
            variant: VariantColumns::ZERO,
        })
    }
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
/// `seed`) at `point` with its surface `v`, their environment draws' texels taken from
/// `cells` (where they were pushed in the same order). The random numbers do not depend on
/// the surface, so every variant's environment draws, and the cosine-weighted BRDF draws of
/// every variant that makes one, are computed once; each variant's sums are the ones it
/// would have alone, bit for bit.
///
/// `level` is where the per-variant arithmetic runs ([`Level::detect`]'s, but for tests).
pub(super) fn shade(
    point: &Point,
    environment: &Environment,
    (strategy, level): (Strategy, Level),
    seed: u64,
    mut draws: impl ExactSizeIterator<Item = u64>,
    (cells, scratch, sums): (&mut LightCells, &mut Scratch, &mut [glam::DVec3]),
) {
    let fewest_lobe_draws = point
        .surfaces
        .iter()
        .map(|s| s.share)
        .fold(f32::INFINITY, f32::min);
    let prefetch = Prefetch::new();
    let Scratch {
        light_texel,
        numbers,
        shared,
        variant,
    } = scratch;
    let (light, brdf) = (
        strategy != Strategy::Brdf,
        strategy != Strategy::Environment,
    );
    while draws.len() > 0 {
        // In passes over the packet rather than lane by lane: each pass's reads of the map
        // (megabytes, mostly out of cache) are asked for a pass before they are made (the
        // environment draws', a run of pixels before), and are independent of one another,
        // so they overlap.
        let count = draws.len().min(LANES);
        let (rows, columns) = cells.take(count);
        // The lanes the jobs run: the draws rounded up to the level's width, so that a pixel
        // of 16 samples pays for 16 lanes, not 64.
        let used = count.next_multiple_of(level.lanes());
        // The drawn texels, and the bits of the points within them and of the BRDF's numbers
        // (made uniform numbers on lanes). The lanes past the draws draw nothing
        // (`SharedDraws` masks them); they read texel 0.
        for k in 0..used {
            let (row, column, [within, choice, more]) = match draws.next() {
                Some(draw) => {
                    debug_assert_eq!(
                        environment.texel(rows[k], columns[k]),
                        environment.draw_texel(random_bits(seed, draw, 0)),
                        "draw {draw} took the texel pushed for another"
                    );
                    let bits = [1, 2, 3].map(|dimension| random_bits(seed, draw, dimension));
                    (rows[k], columns[k], bits)
                }
                None => (0, 0, [0; 3]),
            };
            light_texel[k] = environment.texel(row, column);
            (numbers.light_row[k], numbers.light_column[k]) = (row as f32, column as f32);
            let bits = |bits: u64| f32::from_bits(bits as u32);
            numbers.within_x[k] = bits(within);
            numbers.within_y[k] = bits(within >> 32);
            numbers.choice[k] = bits(choice);
            numbers.u1_bits[k] = bits(choice >> 32);
            numbers.azimuth[k] = bits(more);
        }
        // The environment's directions and the cosine-weighted ones on lanes.
        dispatch(
            level,
            SharedDraws {
                frame: [
                    point.frame.tangent,
                    point.frame.bitangent,
                    point.frame.normal,
                ],
                light,
                brdf,
                fewest_lobe_draws,
                count,
                used,
                environment,
                draws: numbers,
                shared,
            },
        );
        // The environment draws' radiances and densities: a lane without a draw (its
        // Jacobian 0) gets density 0.
        for (k, &texel) in light_texel[..used].iter().enumerate() {
            let (radiance, pdf) = environment.look_up_jacobian(texel, numbers.light_jacobian[k]);
            shared.light_pdf[k] = pdf;
            shared.light_radiance.set(k, radiance);
        }
        let packet = Packet {
            point,
            environment,
            strategy,
            level,
            shared,
            u1: &numbers.u1,
            count,
            used,
            prefetch,
        };
        for (surface, sum) in point.surfaces.iter().zip(sums.iter_mut()) {
            *sum += shade_variant(packet, surface, variant).as_dvec3();
        }
    }
}

/// A packet's shared draws, as every variant reads them.
#[derive(Clone, Copy)]
struct Packet<'a> {
    point: &'a Point<'a>,
    environment: &'a Environment,
    strategy: Strategy,
    level: Level,
    shared: &'a SharedColumns,
    /// The uniform number each lane's lobe draw takes.
    u1: &'a [f32; LANES],
    /// The packet's draws (its first lanes).
    count: usize,
    /// The lanes the jobs run (`lanes.rs`).
    used: usize,
    prefetch: Prefetch,
}

/// One variant's estimates over a packet of `count` draws, summed: its lobe's cosine draws,
/// then its directions and their texels on lanes, the lobe's values (its SIMD kernel) and a
/// table's densities while the texels are asked for, the texels' reads, and the combination
/// on lanes.
fn shade_variant(packet: Packet, surface: &PacketSurface, variant: &mut VariantColumns) -> Vec3 {
    let Packet {
        point,
        environment,
        strategy,
        level,
        shared,
        u1,
        count,
        used,
        prefetch,
    } = packet;
    let draws_lobe = strategy != Strategy::Environment;
    surface.draw_cosines(
        level,
        &u1[..used],
        |k| k < count && draws_lobe && shared.choice[k] < surface.share,
        &mut variant.drawn[..used],
    );
    let wo = point.wo;
    // The basis the lobe's directions are drawn in: about the mirror direction (Phong) or
    // the normal (Blinn's half vector).
    let axis = match surface.geometry {
        Geometry::Phong => Vec3::new(-wo.x, -wo.y, wo.z),
        Geometry::Blinn => Vec3::Z,
    };
    let (b1, b2) = axis.any_orthonormal_pair();
    let Frame32 {
        tangent,
        bitangent,
        normal,
    } = point.frame;
    dispatch(
        level,
        Directions {
            used,
            setting: Setting {
                geometry: surface.geometry,
                strategy,
                wo,
                frame: [tangent, bitangent, normal],
                axis: [axis, b1, b2],
                share: surface.share,
            },
            environment,
            shared,
            variant: &mut *variant,
        },
    );
    let brdf_texel = |variant: &VariantColumns, k: usize| {
        environment.texel_of_bits(variant.texel_row[k], variant.texel_column[k])
    };
    let has_brdf_direction = |variant: &VariantColumns, k: usize| variant.brdf_taken[k] > 0.0;
    for k in 0..count {
        if has_brdf_direction(variant, k) {
            environment.prefetch_texel(brdf_texel(variant, k), prefetch);
        }
    }
    surface.lobe.eval_batch(
        &variant.light_cosine[..count],
        &mut variant.light_value[..count],
    );
    surface.lobe.eval_batch(
        &variant.brdf_cosine[..count],
        &mut variant.brdf_value[..count],
    );
    if let Some(table) = surface.density_table() {
        table.density_batch(
            &variant.light_cosine[..count],
            &mut variant.light_density[..count],
        );
        table.density_batch(
            &variant.brdf_cosine[..count],
            &mut variant.brdf_density[..count],
        );
    }
    // The texels' reads last: the lobe's values above do not need them, and give the reads
    // asked for the time to arrive.
    for k in 0..count {
        let (radiance, light_pdf) = if has_brdf_direction(variant, k) {
            environment.look_up_jacobian(brdf_texel(variant, k), variant.texel_jacobian[k])
        } else {
            (Vec3::ZERO, 0.0)
        };
        variant.brdf_radiance.set(k, radiance);
        variant.brdf_light_pdf[k] = light_pdf;
    }
    dispatch(
        level,
        Combine {
            used,
            brdf: Brdf {
                geometry: surface.geometry,
                strategy,
                diffuse: surface.diffuse,
                specular: surface.specular,
                share: surface.share,
                density_per_value: surface.density_per_value(),
            },
            shared,
            variant,
        },
    )
}

#[cfg(test)]
mod tests {
    use glam::DVec3;
    use specula::{Exponent, LobeKind, Normalisation};

    use super::*;

    /// The packet estimator's sums are the same, to `f32` roundings, wherever its lanes run:
    /// at the baseline level (one lane, unfused) and at the best this CPU has, for a lobe of
    /// each sampler (closed form, Newton, table), Phong and Blinn, under each strategy.
    #[test]
    fn every_level_shades_the_same() {
        let environment = Environment::sky(256);
        let surfaces: Vec<PacketSurface> = [LobeKind::Pow, LobeKind::Schlick, LobeKind::Cheb2]
            .into_iter()
            .flat_map(|kind| {
                [Geometry::Phong, Geometry::Blinn].map(|geometry| {
                    PacketSurface::new(&Material {
                        ka: 0.0,
                        kd: 0.4,
                        ks: 0.6,
                        colour: Vec3::new(0.8, 0.5, 0.3),
                        specular_colour: Vec3::ONE,
                        lobe: Lobe::new(kind, Exponent::new(40.0)),
                        geometry,
                        normalisation: Normalisation::Lobe,
                    })
                })
            })
            .collect();
        let tilt = Vec3::new(0.3, -0.2, 1.0).normalize();
        let (tangent, bitangent) = tilt.any_orthonormal_pair();
        let point = Point {
            surfaces: &surfaces,
            frame: Frame32::new(tangent, bitangent, tilt),
            wo: Vec3::new(0.4, 0.1, 0.8).normalize(),
        };
        for strategy in [Strategy::Mis, Strategy::Brdf, Strategy::Environment] {
            let sums_at = |level| {
                let mut sums = vec![DVec3::ZERO; surfaces.len()];
                let mut cells = LightCells::default();
                let draws = || (0..1000_u32).map(u64::from);
                cells.push(&environment, 7, draws());
                cells.resolve(&environment);
                shade(
                    &point,
                    &environment,
                    (strategy, level),
                    7,
                    draws(),
                    (&mut cells, &mut Scratch::new(), &mut sums),
                );
                sums
            };
            let baseline = sums_at(Level::Baseline);
            for level in Level::available() {
                for (v, (a, b)) in sums_at(level).iter().zip(&baseline).enumerate() {
                    assert!(
                        a.cmpgt(DVec3::ZERO).all()
                            && (*a - *b).abs().max_element() <= 1e-4 * b.max_element(),
                        "{strategy:?} {level:?} variant {v}: {a} against {b}"
                    );
                }
            }
        }
    }
}
