//! Rays marched as a packet: [`LANES`] rays side by side in structure-of-arrays form, every
//! lane advanced by one segment per turn of the loop.
//!
//! Each turn has three phases. Where the lanes' segments lie and which voxel cell each
//! midpoint falls in is lane-wise arithmetic on arrays, which the compiler turns into vector
//! instructions; reading the voxels and the tables is a loop over the lanes (the loads differ
//! per lane); lighting and compositing are lane-wise arithmetic again, with no branch on a
//! sample's value (whether a noisy sample faces the light is a coin toss a branch would
//! mispredict). A lane whose ray ends takes the next ray of the list, so the packet stays full
//! until the list runs out. Highlights are gathered across lanes and their lobe evaluated
//! together by the lobe's vector kernel ([`specula::Lobe::eval_batch`]).
//!
//! Every ray gets exactly the samples, opacities and lighting of a march on its own, front to
//! back; only the order in which its highlights are summed differs.

// A lane loop reads and writes several arrays at the lane's index: written as one index, it
// is the shape the compiler vectorises.
#![allow(clippy::needless_range_loop)]

use glam::{IVec3, Vec3};
use specula::simd::exp2_nonpositive;

use super::{Classification, PreparedVolume};
use crate::volume::raymarch::{Lighting, RayView};

/// One ray's march, in grid units: `origin + direction * t` for `t` (mm) in `[start, end]`.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Ray {
    pub origin: Vec3,
    pub direction: Vec3,
    pub start: f32,
    pub end: f32,
    /// The first segment's length (a per-pixel fraction of a step).
    pub first: f32,
}

/// Rays a packet marches side by side: one 256-bit vector of `f32`.
pub(crate) const LANES: usize = 8;

/// Highlights gathered before their lobe is evaluated together.
const HIGHLIGHTS: usize = 64;

type Lane<T> = [T; LANES];

/// A ray's result: the colour it gathered and the light it let through.
pub(crate) type Marched = (Vec3, f32);

/// How the rays' samples are lit: the render's lighting and each ray's view of it.
#[derive(Clone, Copy)]
pub(crate) struct Lit<'a> {
    pub lighting: &'a Lighting,
    /// `views[r]` is ray `r`'s.
    pub views: &'a [RayView],
}

/// Marches `rays` (with `lit`, or emission and absorption only) through `volume`, writing ray
/// `r`'s result to `out[r]`.
///
/// The loop is compiled for the best instruction set the CPU has (`arch` dispatches it), with
/// everything it calls inlined into it.
///
/// # Panics
/// If `out` (or `lit`'s views) and `rays` differ in length.
#[allow(clippy::too_many_arguments)]
pub(crate) fn march_rays(
    arch: pulp::Arch,
    volume: &PreparedVolume,
    classification: &Classification,
    lit: Option<Lit<'_>>,
    rays: &[Ray],
    step: f32,
    opacity_cutoff: f32,
    out: &mut [Marched],
) {
    assert_eq!(rays.len(), out.len(), "march_rays: one result per ray");
    if let Some(lit) = lit {
        assert_eq!(rays.len(), lit.views.len(), "march_rays: one view per ray");
    }
    arch.dispatch(Packet {
        volume,
        classification,
        lit,
        rays,
        step,
        opacity_cutoff,
        out,
    });
}

/// [`march_rays`]'s work, as the instruction-set dispatch takes it.
struct Packet<'a> {
    volume: &'a PreparedVolume,
    classification: &'a Classification,
    lit: Option<Lit<'a>>,
    rays: &'a [Ray],
    step: f32,
    opacity_cutoff: f32,
    out: &'a mut [Marched],
}

/// The lanes' rays partway through their marches.
struct Lanes {
    /// The ray each lane marches (an index into the list), or none.
    ray: Lane<Option<usize>>,
    origin: [Lane<f32>; 3],
    direction: [Lane<f32>; 3],
    /// Per axis, `1 / direction` (huge along a grid plane), for leaving empty bricks.
    inverse_direction: Lane<Vec3>,
    end: Lane<f32>,
    /// Where the first segment ends.
    first_end: Lane<f32>,
    /// Segment `j > 0` ends at `lattice + (j + 1) step`, computed from `j` so that a skip lands
    /// on the very positions the march would have reached.
    lattice: Lane<f32>,
    j: Lane<u32>,
    t: Lane<f32>,
    colour: [Lane<f32>; 3],
    transmittance: Lane<f32>,
    /// The ray's view: `wo`, the half vector, `wi . wo`.
    wo: [Lane<f32>; 3],
    half: [Lane<f32>; 3],
    wi_dot_wo: Lane<f32>,
}

/// One turn's samples, lane by lane.
struct Samples {
    /// The extinction there (0 where a lane took no sample).
    sigma: Lane<f32>,
    /// The transfer function's colour there.
    base: [Lane<f32>; 3],
    /// The field's gradient there (world, value per mm).
    gradient: [Lane<f32>; 3],
}

/// Highlights waiting for their lobe: cosine, weight and the ray they belong to.
struct Highlights {
    ts: [f32; HIGHLIGHTS],
    weights: [f32; HIGHLIGHTS],
    rays: [usize; HIGHLIGHTS],
    gathered: usize,
}

impl Highlights {
    /// Evaluates the gathered highlights' lobe and adds each, white, to its ray's colour.
    #[inline(always)]
    fn flush(&mut self, lighting: &Lighting, out: &mut [Marched]) {
        let n = self.gathered;
        let mut lobes = [0.0_f32; HIGHLIGHTS];
        lighting
            .shading
            .lobe
            .eval_batch(&self.ts[..n], &mut lobes[..n]);
        for i in 0..n {
            out[self.rays[i]].0 += Vec3::splat(self.weights[i] * lobes[i]);
        }
        self.gathered = 0;
    }
}

impl Lanes {
    /// Lane `k` takes ray `r` of `rays` (or none), its result in `out[r]` cleared.
    #[inline(always)]
    fn start(&mut self, k: usize, r: Option<usize>, packet: &mut Packet<'_>) {
        self.ray[k] = r;
        let Some(r) = r else {
            // An idle lane: no segment left, no light to carry.
            self.end[k] = f32::NEG_INFINITY;
            self.t[k] = 0.0;
            self.transmittance[k] = 0.0;
            return;
        };
        let ray = packet.rays[r];
        for axis in 0..3 {
            self.origin[axis][k] = ray.origin[axis];
            self.direction[axis][k] = ray.direction[axis];
        }
        // A direction along a grid plane never leaves a brick across it: a huge inverse keeps
        // that axis's exit out of the minimum (and away from 0 * infinity).
        self.inverse_direction[k] = Vec3::select(
            ray.direction.abs().cmplt(Vec3::splat(1e-12)),
            Vec3::splat(1e30),
            ray.direction.recip(),
        );
        self.end[k] = ray.end;
        self.first_end[k] = ray.start + ray.first;
        self.lattice[k] = ray.start + ray.first - packet.step;
        self.j[k] = 0;
        self.t[k] = ray.start;
        self.transmittance[k] = 1.0;
        for c in 0..3 {
            self.colour[c][k] = 0.0;
        }
        if let Some(lit) = packet.lit {
            let view = lit.views[r];
            for axis in 0..3 {
                self.wo[axis][k] = view.wo[axis];
                self.half[axis][k] = view.half[axis];
            }
            self.wi_dot_wo[k] = view.wi_dot_wo;
        }
        packet.out[r] = (Vec3::ZERO, 1.0);
    }
}

impl pulp::WithSimd for Packet<'_> {
    type Output = ();

    #[inline(always)]
    fn with_simd<Level: pulp::Simd>(mut self, _: Level) -> Self::Output {
        let zeros = [0.0_f32; LANES];
        let mut lanes = Lanes {
            ray: [None; LANES],
            origin: [zeros; 3],
            direction: [zeros; 3],
            inverse_direction: [Vec3::ZERO; LANES],
            end: zeros,
            first_end: zeros,
            lattice: zeros,
            j: [0; LANES],
            t: zeros,
            colour: [zeros; 3],
            transmittance: zeros,
            wo: [zeros; 3],
            half: [zeros; 3],
            wi_dot_wo: zeros,
        };
        let mut highlights = Highlights {
            ts: [0.0; HIGHLIGHTS],
            weights: [0.0; HIGHLIGHTS],
            rays: [0; HIGHLIGHTS],
            gathered: 0,
        };
        let mut next = 0;
        for k in 0..LANES {
            let r = (next < self.rays.len()).then_some(next);
            next += usize::from(r.is_some());
            lanes.start(k, r, &mut self);
        }
        while lanes.ray.iter().any(Option::is_some) {
            let (cells, fractions, lengths) = self.segments(&mut lanes);
            let samples = self.sample(&mut lanes, &cells, &fractions);
            self.composite(&mut lanes, &samples, &lengths, &mut highlights);
            for k in 0..LANES {
                let Some(r) = lanes.ray[k] else { continue };
                if lanes.t[k] < lanes.end[k] && 1.0 - lanes.transmittance[k] < self.opacity_cutoff {
                    continue;
                }
                let colour = Vec3::new(lanes.colour[0][k], lanes.colour[1][k], lanes.colour[2][k]);
                self.out[r].0 += colour;
                self.out[r].1 = lanes.transmittance[k];
                let taken = (next < self.rays.len()).then_some(next);
                next += usize::from(taken.is_some());
                lanes.start(k, taken, &mut self);
            }
        }
        if let Some(lit) = self.lit {
            highlights.flush(lit.lighting, self.out);
        }
    }
}

impl Packet<'_> {
    /// Every lane's next segment: the cell its midpoint lies in, the place there, and its
    /// length. Advances the lanes past it.
    #[inline(always)]
    fn segments(&self, lanes: &mut Lanes) -> ([Lane<i32>; 3], [Lane<f32>; 3], Lane<f32>) {
        // See `PreparedVolume::cell`: adding 1.5 * 2^23 to p - 1/2 rounds it to an integer.
        const ROUND: f32 = 12_582_912.0;
        let step = self.step;
        let last_index = self.volume.last_index;
        let last_cell = self.volume.last_cell;
        let mut cells = [[0_i32; LANES]; 3];
        let mut fractions = [[0.0_f32; LANES]; 3];
        let mut lengths = [0.0_f32; LANES];
        for k in 0..LANES {
            let j = lanes.j[k];
            let next = if j == 0 {
                lanes.first_end[k]
            } else {
                lanes.lattice[k] + (j + 1) as f32 * step
            };
            let length = next.min(lanes.end[k]) - lanes.t[k];
            lengths[k] = length;
            let middle = lanes.t[k] + 0.5 * length;
            for axis in 0..3 {
                let p = (lanes.origin[axis][k] + lanes.direction[axis][k] * middle)
                    .max(0.0)
                    .min(last_index[axis]);
                let rounded = (p - 0.5) + ROUND;
                let cell = (rounded.to_bits() as i32 - ROUND.to_bits() as i32).min(last_cell[axis]);
                cells[axis][k] = cell;
                fractions[axis][k] = p - cell as f32;
            }
            lanes.t[k] = next;
            lanes.j[k] = j + 1;
        }
        (cells, fractions, lengths)
    }

    /// Each lane's sample, read lane by lane: lanes in empty bricks skip ahead instead.
    #[inline(always)]
    fn sample(
        &self,
        lanes: &mut Lanes,
        cells: &[Lane<i32>; 3],
        fractions: &[Lane<f32>; 3],
    ) -> Samples {
        let (volume, classification) = (self.volume, self.classification);
        let zeros = [0.0_f32; LANES];
        let mut samples = Samples {
            sigma: zeros,
            base: [zeros; 3],
            gradient: [zeros; 3],
        };
        for k in 0..LANES {
            if lanes.ray[k].is_none() {
                continue;
            }
            let cell = IVec3::new(cells[0][k], cells[1][k], cells[2][k]);
            if !classification.occupied[volume.brick(cell)] {
                self.skip(lanes, k, cell);
                continue;
            }
            let f = Vec3::new(fractions[0][k], fractions[1][k], fractions[2][k]);
            let sample = volume.sample_in(cell, f);
            let classified = classification.at(sample.x);
            samples.sigma[k] = classified.x;
            for c in 0..3 {
                samples.base[c][k] = classified[c + 1];
                samples.gradient[c][k] = sample[c + 1];
            }
        }
        samples
    }

    /// Lane `k`'s midpoint lies in the empty brick `cell` is in: every sample whose midpoint
    /// lies before the brick's exit has no extinction, so the lane skips those segments (a
    /// margin keeps the one that rounding could place across it); out of the whole region
    /// when it is empty too.
    #[inline(always)]
    fn skip(&self, lanes: &mut Lanes, k: usize, cell: IVec3) {
        let (volume, classification) = (self.volume, self.classification);
        let origin = Vec3::new(lanes.origin[0][k], lanes.origin[1][k], lanes.origin[2][k]);
        let inverse_direction = lanes.inverse_direction[k];
        let exit = if classification.occupied_regions[volume.region(cell)] {
            volume.brick_exit(cell, origin, inverse_direction)
        } else {
            volume.region_exit(cell, origin, inverse_direction)
        };
        let beyond = (exit - lanes.t[k]) / self.step - 0.5 - 1e-3;
        if beyond > 0.0 {
            // ceil without a library call (beyond > 0).
            let skipped = beyond as i32;
            lanes.j[k] += skipped as u32 + u32::from((skipped as f32) < beyond);
            lanes.t[k] = lanes.lattice[k] + lanes.j[k] as f32 * self.step;
        }
    }

    /// Composites each lane's sample front to back, lit, and gathers its highlight. A
    /// segment of `length` at extinction `sigma` is opaque by `1 - exp(-sigma length)`.
    #[inline(always)]
    fn composite(
        &mut self,
        lanes: &mut Lanes,
        samples: &Samples,
        lengths: &Lane<f32>,
        highlights: &mut Highlights,
    ) {
        let mut carried = [0.0_f32; LANES];
        let mut sampled = [false; LANES];
        for k in 0..LANES {
            let sigma = samples.sigma[k].max(0.0);
            let alpha = 1.0 - exp2_nonpositive(-sigma * lengths[k] * core::f32::consts::LOG2_E);
            carried[k] = lanes.transmittance[k] * alpha;
            lanes.transmittance[k] *= 1.0 - alpha;
            sampled[k] = sigma > 0.0;
        }
        let Some(lit) = self.lit else {
            for c in 0..3 {
                for k in 0..LANES {
                    lanes.colour[c][k] += carried[k] * samples.base[c][k];
                }
            }
            return;
        };
        let mut ts = [0.0_f32; LANES];
        let mut weights = [0.0_f32; LANES];
        let mut keep = [false; LANES];
        for k in 0..LANES {
            let parts = lit.lighting.lit_parts(
                Vec3::new(
                    samples.gradient[0][k],
                    samples.gradient[1][k],
                    samples.gradient[2][k],
                ),
                Vec3::new(lanes.wo[0][k], lanes.wo[1][k], lanes.wo[2][k]),
                Vec3::new(lanes.half[0][k], lanes.half[1][k], lanes.half[2][k]),
                lanes.wi_dot_wo[k],
            );
            for c in 0..3 {
                lanes.colour[c][k] += carried[k] * (samples.base[c][k] * parts.colour_scale);
            }
            ts[k] = parts.t;
            weights[k] = carried[k] * parts.highlight;
            // Every lobe is 0 at a cosine of 0 or less; a lane that took no sample carried
            // nothing.
            keep[k] = sampled[k] && parts.highlight > 0.0 && parts.t > 0.0;
        }
        for k in 0..LANES {
            let at = highlights.gathered;
            highlights.ts[at] = ts[k];
            highlights.weights[at] = weights[k];
            highlights.rays[at] = lanes.ray[k].unwrap_or(0);
            highlights.gathered += usize::from(keep[k]);
        }
        if highlights.gathered > HIGHLIGHTS - LANES {
            highlights.flush(lit.lighting, self.out);
        }
    }
}
