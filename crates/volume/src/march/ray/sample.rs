//! A turn's samples: each lane placed (skipped past empty bricks, or not read in a transparent
//! cell), then the voxels and the transfer function read for the lanes left reading.

// A lane loop reads and writes several arrays at the lane's index: written as one index, it
// is the shape the compiler vectorises.
#![allow(clippy::needless_range_loop)]

use glam::Vec3;
use specula::simd::Lanes;

use super::{Marching, Packet, Turn, LANES};
use crate::march::{whole_below, PreparedVolume};

impl<const FETCH: bool> Packet<'_, FETCH> {
    /// Every lane's sample at its segment: a skip where its brick is empty, nothing where its
    /// cell is transparent, else the voxels and the transfer function read. Its lanes skip in
    /// step with one another (a lane skipping brick after brick on its own would be one long
    /// chain of dependent instructions while the rest wait), side by side, and not at all in a
    /// turn with no lane in an empty brick.
    #[inline(always)]
    pub(super) fn samples<V: Lanes>(&self, lanes: V, marching: &mut Marching, turn: &mut Turn) {
        let mut bricks = [(0, false); LANES];
        for k in 0..LANES {
            bricks[k] = self.brick_state(turn, k);
        }
        let mut reading = [false; LANES];
        // A turn in which no lane is in an empty brick (most, inside dense tissue) computes no
        // skip.
        if (0..LANES).any(|k| marching.live[k] & (bricks[k].0 > 0)) {
            for k in 0..LANES {
                reading[k] = self.advance(marching, turn, k, bricks[k]);
            }
        } else {
            for k in 0..LANES {
                reading[k] = self.stay(marching, turn, k, bricks[k]);
            }
        }
        for k in 0..LANES {
            self.fetch_ahead(turn, k, reading[k]);
        }
        for k in 0..LANES {
            if reading[k] {
                self.interpolate(lanes, turn, k);
            }
        }
        for k in 0..LANES {
            if reading[k] {
                self.classify(turn, k);
            }
        }
    }

    /// Lane `k`'s sample at its segment (see [`Self::samples`]); an idle lane's is cleared.
    #[inline(always)]
    pub(super) fn sample<V: Lanes>(
        &self,
        lanes: V,
        marching: &mut Marching,
        turn: &mut Turn,
        k: usize,
    ) {
        if self.place(marching, turn, k) {
            self.interpolate(lanes, turn, k);
            self.classify(turn, k);
        }
    }

    /// Skips lane `k` past the empty bricks its segment lies in, or says whether it reads a
    /// sample there (see [`Self::advance`]).
    #[inline(always)]
    fn place(&self, marching: &mut Marching, turn: &mut Turn, k: usize) -> bool {
        let brick = self.brick_state(turn, k);
        let reading = self.advance(marching, turn, k, brick);
        self.fetch_ahead(turn, k, reading);
        reading
    }

    /// The clearance of lane `k`'s brick, and whether its cell is transparent.
    #[inline(always)]
    fn brick_state(&self, turn: &Turn, k: usize) -> (u8, bool) {
        let brick = turn.brick[k] as usize;
        let transparent = self.classification.transparent[brick] >> turn.bit[k] & 1 != 0;
        (self.classification.clearance[brick], transparent)
    }

    /// Skips lane `k` past the empty bricks its segment lies in, given its brick's
    /// `(clearance, transparent)`, or says whether it reads a sample there (not in a
    /// transparent cell, whose sample has no extinction); an idle lane's is cleared. Without
    /// a branch: every lane computes a skip, kept where it has one, so that the lanes are
    /// computed side by side and an unpredictable clearance costs no misprediction.
    #[inline(always)]
    fn advance(
        &self,
        marching: &mut Marching,
        turn: &mut Turn,
        k: usize,
        (clearance, transparent): (u8, bool),
    ) -> bool {
        let skipping = marching.live[k] & (clearance > 0);
        let steps = self.skip(marching, turn, k, clearance) * u32::from(skipping);
        let j = marching.j[k] + steps;
        let skipped = marching.lattice[k] + j as f32 * self.step;
        marching.j[k] = j;
        marching.t[k] = if steps > 0 { skipped } else { marching.t[k] };
        self.stay(marching, turn, k, (clearance, transparent))
    }

    /// [`Self::advance`] for a lane that does not skip.
    #[inline(always)]
    fn stay(
        &self,
        marching: &Marching,
        turn: &mut Turn,
        k: usize,
        (clearance, transparent): (u8, bool),
    ) -> bool {
        turn.sigma[k] = 0.0;
        turn.t_end[k] = marching.t[k];
        marching.live[k] & (clearance == 0) & !transparent
    }

    /// When the volume is fetched ahead, asks for the voxels lane `k` reads [`LOOKAHEAD`]
    /// steps on, if it reads now (a loop apart from [`Self::advance`]'s, which a call would
    /// keep from being vectorised).
    #[inline(always)]
    fn fetch_ahead(&self, turn: &Turn, k: usize, reading: bool) {
        if FETCH && reading {
            self.volume.prefetch(turn.ahead[k] as usize, self.prefetch);
        }
    }

    /// Lane `k`'s value and gradient at its midpoint.
    #[inline(always)]
    fn interpolate<V: Lanes>(&self, lanes: V, turn: &mut Turn, k: usize) {
        let fraction = Vec3::new(
            turn.fraction[0][k],
            turn.fraction[1][k],
            turn.fraction[2][k],
        );
        let sample = self
            .volume
            .sample_at(lanes, turn.voxel[k] as usize, fraction);
        turn.value[k] = sample.x;
        for c in 0..3 {
            turn.gradient[c][k] = sample[c + 1];
        }
    }

    /// The transfer function at lane `k`'s value.
    #[inline(always)]
    fn classify(&self, turn: &mut Turn, k: usize) {
        let classified = self.classification.at(turn.value[k]);
        turn.sigma[k] = classified.x;
        for c in 0..3 {
            turn.base[c][k] = classified[c + 1];
        }
    }

    /// The segments lane `k` skips when its midpoint lies in an empty brick whose empty
    /// surroundings reach `clearance` bricks (1 taken for 0): every sample whose midpoint lies
    /// before the ray leaves the empty cube of bricks centred there has no extinction (a
    /// margin keeps the one that rounding could place across its exit).
    #[inline(always)]
    fn skip(&self, marching: &Marching, turn: &Turn, k: usize, clearance: u8) -> u32 {
        let reach = i32::from(clearance.max(1));
        let mut exit = f32::INFINITY;
        for axis in 0..3 {
            let leaves = PreparedVolume::clear_exit_along(
                turn.cell[axis][k],
                reach,
                marching.origin[axis][k],
                marching.inverse_direction[axis][k],
            );
            exit = if leaves < exit { leaves } else { exit };
        }
        // At most 2^22 - 1 segments at once (whole_below's range): a shorter skip is still
        // exact, and no ray is that many segments long.
        let beyond =
            ((exit - marching.t[k]) * self.inverse_step - 0.5 - 1e-3).clamp(0.0, 4_194_303.0);
        // The ceiling: `whole` falls short by one where beyond is not whole, or where it is
        // an odd whole number (whole_below's rounding); the comparison makes it up.
        let whole = whole_below(beyond);
        whole as u32 + u32::from((whole as f32) < beyond)
    }
}
