//! The draws every variant of a packet shares, on SIMD lanes: each environment draw's
//! direction (the point drawn within its texel, turned to a direction in the surface's
//! frame) and each cosine-weighted BRDF draw's direction with the texel it falls in, and
//! the azimuth every BRDF draw turns by. What stays scalar around it (`packet.rs`): the
//! random numbers and the alias table's draws before it, the texels' records after (reads at
//! random places of the map). Scalar, these were the packet's most costly part: three
//! sines and cosines, an arccosine and an arctangent per sample.

use glam::Vec3;
use specula::simd::{Job, Lanes};

use super::lane_geometry::{sin_cos_turns, Column, LANES, V3};
use super::lanes::SharedColumns;
use super::Environment;

/// A packet's shared random numbers, by lane, and the texels its draws fall in.
pub(super) struct Draws {
    /// The environment draw's texel (whole numbers, as floats) and the point within it.
    pub(super) light_column: Column,
    pub(super) light_row: Column,
    pub(super) within_x: Column,
    pub(super) within_y: Column,
    /// The BRDF draw's uniform number for the cosine, and its azimuth in turns. A lane that
    /// makes no cosine-weighted draw holds 1 (whose cosine, 0, is not above the surface).
    pub(super) u1: Column,
    pub(super) azimuth: Column,
    /// `sin theta` of the environment's direction: 0 where the lane has no environment draw
    /// (or its direction is on a pole or below the surface), so that its density is 0.
    pub(super) light_sine: Column,
    /// The cosine-weighted direction's texel and `sin theta` there (0 where the lane makes
    /// no such draw).
    pub(super) diffuse_column: Column,
    pub(super) diffuse_row: Column,
    pub(super) diffuse_sine: Column,
}

impl Draws {
    pub(super) const ZERO: Self = Self {
        light_column: [0.0; LANES],
        light_row: [0.0; LANES],
        within_x: [0.0; LANES],
        within_y: [0.0; LANES],
        u1: [0.0; LANES],
        azimuth: [0.0; LANES],
        light_sine: [0.0; LANES],
        diffuse_column: [0.0; LANES],
        diffuse_row: [0.0; LANES],
        diffuse_sine: [0.0; LANES],
    };
}

/// The shared directions of a packet's `used` lanes (see the module docs).
pub(super) struct SharedDraws<'a> {
    /// The surface's tangent, bitangent and normal in world space.
    pub(super) frame: [Vec3; 3],
    /// Whether the lanes draw from the environment.
    pub(super) light: bool,
    /// The smallest share of BRDF draws any variant's lobe takes: a lane whose choice is at
    /// least this makes the cosine-weighted draw.
    pub(super) fewest_lobe_draws: f32,
    /// The lanes to run: the packet's draws rounded up to the level's width.
    pub(super) used: usize,
    pub(super) environment: &'a Environment,
    pub(super) draws: &'a mut Draws,
    pub(super) shared: &'a mut SharedColumns,
}

impl Job for SharedDraws<'_> {
    type Output = ();

    #[inline(always)]
    fn run<V: Lanes>(self, lanes: V) {
        let (draws, shared, environment) = (self.draws, self.shared, self.environment);
        let (zero, one) = (lanes.splat(0.0), lanes.splat(1.0));
        let [tangent, bitangent, normal] = self.frame.map(|axis| V3::splat(lanes, axis));
        let w = V::WIDTH;
        for k in (0..self.used).step_by(w) {
            let column = |values: &[f32]| lanes.load(&values[k..k + w]);
            // The environment's draw, in the surface's frame.
            let (world, sine) = environment.direction_lanes(
                (column(&draws.light_column), column(&draws.light_row)),
                (column(&draws.within_x), column(&draws.within_y)),
            );
            let local = V3 {
                x: world.dot(tangent),
                y: world.dot(bitangent),
                z: world.dot(normal),
            };
            local.store(&mut shared.light_wi, k);
            let sine = if self.light { sine } else { zero };
            sine.keep(local.z.gt(zero))
                .store(&mut draws.light_sine[k..k + w]);
            // The BRDF draw's azimuth, and the cosine-weighted direction where it is taken.
            let (sin_phi, cos_phi) = sin_cos_turns(column(&draws.azimuth));
            sin_phi.store(&mut shared.sin_phi[k..k + w]);
            cos_phi.store(&mut shared.cos_phi[k..k + w]);
            let u1 = column(&draws.u1);
            let (sine, cosine) = (u1.sqrt(), (one - u1).max(zero).sqrt());
            // Taken where the choice is not below every lobe's share, and above the surface.
            let taken = zero.select(
                column(&shared.choice).lt(lanes.splat(self.fewest_lobe_draws)),
                one,
            );
            let above = (cosine * taken).gt(zero);
            let diffuse = V3 {
                x: sine * cos_phi,
                y: sine * sin_phi,
                z: cosine,
            }
            .select(above, V3::splat(lanes, Vec3::ZERO));
            diffuse.store(&mut shared.diffuse_wi, k);
            let world = tangent.scale_add(
                diffuse.x,
                bitangent.scale_add(diffuse.y, normal.scale(diffuse.z)),
            );
            let (texel_column, texel_row, texel_sine) = environment.texel_lanes(world);
            texel_column.store(&mut draws.diffuse_column[k..k + w]);
            texel_row.store(&mut draws.diffuse_row[k..k + w]);
            texel_sine
                .keep(above)
                .store(&mut draws.diffuse_sine[k..k + w]);
        }
    }
}
