//! The draws every variant of a packet shares, on SIMD lanes: each environment draw's
//! direction (the point drawn within its texel, turned to a direction in the surface's
//! frame), each cosine-weighted BRDF draw's direction, and the azimuth every BRDF draw turns
//! by. The texel a BRDF draw falls in is found with the variant's own directions
//! (`lanes.rs`), the cosine-weighted ones among them: finding it here too read the same
//! texel twice. What stays scalar around it: the alias table's draws (`ahead.rs`) and the
//! random bits before it (`packet.rs`), the texels' records after (reads at random places of
//! the map). Scalar, these were the packet's most costly part: sines, cosines, an arccosine
//! and an arctangent per sample.

use glam::Vec3;
use specula::simd::{Job, Lanes};

use super::environment::jacobian_lanes;
use super::lane_geometry::{sin_cos_turns, Column, LANES, V3};
use super::lanes::SharedColumns;
use super::Environment;

/// Each lane's index, to tell the lanes past a packet's draws.
const LANE_INDEX: Column = {
    let mut index = [0.0; LANES];
    let mut k = 0;
    while k < LANES {
        index[k] = k as f32;
        k += 1;
    }
    index
};

/// [`specula::sampling::unit_f32`] on lanes of random bits: their top 24 over `2^24`.
#[inline(always)]
fn unit_lanes<V: Lanes>(bits: V) -> V {
    bits.bits_shr_signed::<8>()
        .bits_and(0x00FF_FFFF)
        .int_to_float()
        * bits.splat(1.0 / (1u32 << 24) as f32)
}

/// A packet's shared random numbers by lane, and the texels its environment draws drew.
///
/// The random numbers come in as 32 random bits each (as the bit patterns of `f32`s), and
/// [`SharedDraws`] makes them uniform numbers on lanes ([`specula::sampling::unit_f32`]'s,
/// bit for bit), where a conversion lane by lane cost a tenth of a packet.
pub(super) struct Draws {
    /// The environment draw's texel (whole numbers, as floats) and the bits of the point
    /// within it.
    pub(super) light_column: Column,
    pub(super) light_row: Column,
    pub(super) within_x: Column,
    pub(super) within_y: Column,
    /// The bits of the BRDF draw's choice of term, of its uniform number for the cosine, and
    /// of its azimuth.
    pub(super) choice: Column,
    pub(super) u1_bits: Column,
    pub(super) azimuth: Column,
    /// The cosine's uniform number, made from `u1_bits`. A lane past the packet's draws, or
    /// without a BRDF draw, gets 1 (whose cosine, 0, is not above the surface).
    pub(super) u1: Column,
    /// `1 / (2 pi^2 sin theta)` of the environment's direction ([`jacobian_lanes`]): 0 where
    /// the lane has no environment draw (or its direction is on a pole or below the
    /// surface), so that its density is 0.
    pub(super) light_jacobian: Column,
}

impl Draws {
    pub(super) const ZERO: Self = Self {
        light_column: [0.0; LANES],
        light_row: [0.0; LANES],
        within_x: [0.0; LANES],
        within_y: [0.0; LANES],
        choice: [0.0; LANES],
        u1_bits: [0.0; LANES],
        azimuth: [0.0; LANES],
        u1: [0.0; LANES],
        light_jacobian: [0.0; LANES],
    };
}

/// The shared directions of a packet's `used` lanes (see the module docs).
pub(super) struct SharedDraws<'a> {
    /// The surface's tangent, bitangent and normal in world space.
    pub(super) frame: [Vec3; 3],
    /// Whether the lanes draw from the environment, and from the BRDF.
    pub(super) light: bool,
    pub(super) brdf: bool,
    /// The smallest share of BRDF draws any variant's lobe takes: a lane whose choice is at
    /// least this makes the cosine-weighted draw.
    pub(super) fewest_lobe_draws: f32,
    /// The packet's draws, and the lanes to run: the draws rounded up to the level's width.
    pub(super) count: usize,
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
            let unit = |bits: &[f32]| unit_lanes(column(bits));
            let drawn = column(&LANE_INDEX).lt(lanes.splat(self.count as f32));
            // The lanes past the draws choose no lobe (2 is above every share) and take the
            // cosine 0 in the cosine-weighted draw.
            let choice = unit(&draws.choice).select(drawn, lanes.splat(2.0));
            choice.store(&mut shared.choice[k..k + w]);
            let u1 = if self.brdf {
                unit(&draws.u1_bits).select(drawn, one)
            } else {
                one
            };
            u1.store(&mut draws.u1[k..k + w]);
            // The environment's draw, in the surface's frame.
            let (world, sine) = environment.direction_lanes(
                (column(&draws.light_column), column(&draws.light_row)),
                (unit(&draws.within_x), unit(&draws.within_y)),
            );
            let local = V3 {
                x: world.dot(tangent),
                y: world.dot(bitangent),
                z: world.dot(normal),
            };
            local.store(&mut shared.light_wi, k);
            let jacobian = if self.light {
                jacobian_lanes(sine)
            } else {
                zero
            };
            jacobian
                .keep(local.z.gt(zero))
                .keep(drawn)
                .store(&mut draws.light_jacobian[k..k + w]);
            // The BRDF draw's azimuth, and the cosine-weighted direction where it is taken.
            let (sin_phi, cos_phi) = sin_cos_turns(unit(&draws.azimuth));
            sin_phi.store(&mut shared.sin_phi[k..k + w]);
            cos_phi.store(&mut shared.cos_phi[k..k + w]);
            let (sine, cosine) = (u1.sqrt(), (one - u1).max(zero).sqrt());
            // Taken where the choice is not below every lobe's share, and above the surface.
            let taken = zero.select(choice.lt(lanes.splat(self.fewest_lobe_draws)), one);
            let above = (cosine * taken).gt(zero);
            let diffuse = V3 {
                x: sine * cos_phi,
                y: sine * sin_phi,
                z: cosine,
            }
            .select(above, V3::splat(lanes, Vec3::ZERO));
            diffuse.store(&mut shared.diffuse_wi, k);
        }
    }
}

#[cfg(test)]
mod tests {
    use specula::sampling::unit_f32;
    use specula::simd::{dispatch, Level};

    use super::*;

    /// Random bits made uniform numbers on lanes are `unit_f32`'s, bit for bit, at every
    /// level: the bits with the sign bit set too (a signed shift alone would smear it).
    #[test]
    fn units_on_lanes_are_unit_f32s() {
        struct Units<'a>(&'a [u32], &'a mut Vec<f32>);
        impl Job for Units<'_> {
            type Output = ();
            #[inline(always)]
            fn run<V: Lanes>(self, lanes: V) {
                for chunk in self.0.chunks_exact(V::WIDTH) {
                    let bits: Vec<f32> = chunk.iter().map(|&b| f32::from_bits(b)).collect();
                    let mut out = vec![0.0; V::WIDTH];
                    unit_lanes(lanes.load(&bits)).store(&mut out);
                    self.1.extend(out);
                }
            }
        }
        let bits: Vec<u32> = [0, 255, 256, 0x7FFF_FFFF, 0x8000_0000, 0xFFFF_FF00, u32::MAX]
            .into_iter()
            .chain((0..1017u32).map(|i| i.wrapping_mul(0x9E37_79B9)))
            .collect();
        for level in Level::available() {
            let mut units = Vec::new();
            dispatch(level, Units(&bits, &mut units));
            for (&b, &u) in bits.iter().zip(&units) {
                assert_eq!(u.to_bits(), unit_f32(b).to_bits(), "{level:?} bits {b:#x}");
            }
        }
    }
}
