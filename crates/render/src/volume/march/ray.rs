//! One ray's march through a [`PreparedVolume`], and rays marched side by side.

use glam::Vec3;
use specula::simd::exp2_nonpositive;

use super::{Classification, PreparedVolume};
use crate::volume::raymarch::LitSample;

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

/// Highlights a ray gathers before evaluating their lobe together.
pub(crate) const HIGHLIGHTS: usize = 64;

/// How a ray's samples are lit.
pub(crate) trait Shade {
    /// A sample of colour `base` and `gradient`, lit, its highlight apart.
    fn light(&self, gradient: Vec3, base: Vec3) -> LitSample;
    /// `sum of weights[k] lobe(ts[k])`, for at most [`HIGHLIGHTS`] cosines.
    fn highlights(&self, ts: &[f32], weights: &[f32]) -> f32;
}

/// A ray partway through its march.
struct Marching {
    ray: Ray,
    inverse_direction: Vec3,
    /// Segment 0 is the first (a fraction of a step); segment `j > 0` ends at
    /// `lattice + (j + 1) step`, computed from `j` so that a skip lands on the very positions
    /// the march would have reached.
    lattice: f32,
    per_step: f32,
    j: u32,
    t: f32,
    colour: Vec3,
    transmittance: f32,
    /// Highlights in the ray's [`Highlights`] buffer, and the sum of those evaluated.
    gathered: usize,
    highlight: f32,
}

/// A ray's highlights: their cosines and weights, evaluated together when the buffer fills
/// (the lobes' vector kernels) and added at the end; each is white, so the sum is one number.
/// Kept apart from [`Marching`] and reused from ray to ray, so that starting a ray moves and
/// clears nothing.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Highlights {
    ts: [f32; HIGHLIGHTS],
    weights: [f32; HIGHLIGHTS],
}

impl Highlights {
    /// An empty buffer.
    pub(crate) const EMPTY: Self = Self {
        ts: [0.0; HIGHLIGHTS],
        weights: [0.0; HIGHLIGHTS],
    };
}

impl Marching {
    #[inline(always)]
    fn new(ray: Ray, step: f32) -> Self {
        // A direction along a grid plane never leaves a brick across it: a huge inverse keeps
        // that axis's exit out of the minimum (and away from 0 * infinity).
        let inverse_direction = Vec3::select(
            ray.direction.abs().cmplt(Vec3::splat(1e-12)),
            Vec3::splat(1e30),
            ray.direction.recip(),
        );
        Self {
            inverse_direction,
            lattice: ray.start + ray.first - step,
            per_step: step.recip(),
            j: 0,
            t: ray.start,
            ray,
            colour: Vec3::ZERO,
            transmittance: 1.0,
            gathered: 0,
            highlight: 0.0,
        }
    }

    /// Whether the ray has segments left and light to carry.
    #[inline(always)]
    fn going(&self, opacity_cutoff: f32) -> bool {
        self.t < self.ray.end && 1.0 - self.transmittance < opacity_cutoff
    }

    /// Marches one segment (or skips the empty ones of a brick).
    #[inline(always)]
    fn advance<S: Shade>(
        &mut self,
        volume: &PreparedVolume,
        classification: &Classification,
        step: f32,
        shade: Option<&S>,
        buffer: &mut Highlights,
    ) {
        let next = if self.j == 0 {
            self.ray.start + self.ray.first
        } else {
            self.lattice + (self.j + 1) as f32 * step
        };
        // Segments other than the first and the last are a whole step (their opacity is
        // tabulated).
        let whole = self.j > 0 && next <= self.ray.end;
        let length = next.min(self.ray.end) - self.t;
        let middle = self.t + 0.5 * length;
        let p =
            (self.ray.origin + self.ray.direction * middle).clamp(Vec3::ZERO, volume.last_index);
        let (cell, f) = volume.cell(p);
        self.t = next;
        self.j += 1;
        if !classification.occupied[volume.brick(cell)] {
            // Every sample whose midpoint lies in this brick has no extinction: skip the
            // segments whose midpoints come before its exit (a margin keeps the one that
            // rounding could place across it).
            // Out of the whole region when it is empty too.
            let exit = if classification.occupied_regions[volume.region(cell)] {
                volume.brick_exit(cell, self.ray.origin, self.inverse_direction)
            } else {
                volume.region_exit(cell, self.ray.origin, self.inverse_direction)
            };
            let beyond = (exit - self.t) * self.per_step - 0.5 - 1e-3;
            if beyond > 0.0 {
                // ceil without a library call (beyond > 0).
                let skipped = beyond as i32;
                self.j += skipped as u32 + u32::from((skipped as f32) < beyond);
                self.t = self.lattice + self.j as f32 * step;
            }
            return;
        }
        let sample = volume.sample_in(cell, f);
        let classified = classification.at(sample.x);
        let sigma = classified.x;
        if sigma <= 0.0 {
            return;
        }
        let alpha = if whole {
            classification.full_segment_opacity(sigma)
        } else {
            1.0 - exp2_nonpositive(-sigma * length * core::f32::consts::LOG2_E)
        };
        let base = Vec3::new(classified.y, classified.z, classified.w);
        let carried = self.transmittance * alpha;
        self.transmittance *= 1.0 - alpha;
        let Some(shade) = shade else {
            self.colour += carried * base;
            return;
        };
        let lit = shade.light(Vec3::new(sample.y, sample.z, sample.w), base);
        self.colour += carried * lit.colour;
        // Every lobe is 0 at a cosine of 0 or less.
        if lit.highlight > 0.0 && lit.t > 0.0 {
            buffer.ts[self.gathered] = lit.t;
            buffer.weights[self.gathered] = carried * lit.highlight;
            self.gathered += 1;
            if self.gathered == HIGHLIGHTS {
                self.highlight += shade.highlights(&buffer.ts, &buffer.weights);
                self.gathered = 0;
            }
        }
    }

    /// The colour gathered and the light let through.
    #[inline(always)]
    fn finish<S: Shade>(&self, shade: Option<&S>, buffer: &Highlights) -> (Vec3, f32) {
        let mut highlight = self.highlight;
        if let (Some(shade), true) = (shade, self.gathered > 0) {
            highlight += shade.highlights(
                &buffer.ts[..self.gathered],
                &buffer.weights[..self.gathered],
            );
        }
        (self.colour + Vec3::splat(highlight), self.transmittance)
    }
}

/// Rays marched side by side, one segment of each in turn: neighbouring rays read the same
/// voxels, and their independent steps overlap each other's memory latency. Each ray's
/// result is its own march's, front to back: the colour gathered and the light let through.
///
/// The loop is compiled for the best instruction set the CPU has (`arch` dispatches it:
/// fused multiply-adds, SSE4.1's `floor`), everything it calls being inlined into it.
pub(crate) fn march_together<S: Shade, const N: usize>(
    arch: pulp::Arch,
    volume: &PreparedVolume,
    classification: &Classification,
    rays: [Option<(Ray, Option<&S>)>; N],
    step: f32,
    opacity_cutoff: f32,
    buffers: &mut [Highlights; N],
) -> [Option<(Vec3, f32)>; N] {
    arch.dispatch(Together {
        volume,
        classification,
        rays,
        step,
        opacity_cutoff,
        buffers,
    })
}

/// [`march_together`]'s work, as the instruction-set dispatch takes it.
struct Together<'a, S, const N: usize> {
    volume: &'a PreparedVolume,
    classification: &'a Classification,
    rays: [Option<(Ray, Option<&'a S>)>; N],
    step: f32,
    opacity_cutoff: f32,
    buffers: &'a mut [Highlights; N],
}

impl<S: Shade, const N: usize> pulp::WithSimd for Together<'_, S, N> {
    type Output = [Option<(Vec3, f32)>; N];

    #[inline(always)]
    fn with_simd<Level: pulp::Simd>(self, _: Level) -> Self::Output {
        let Self {
            volume,
            classification,
            rays,
            step,
            opacity_cutoff,
            buffers,
        } = self;
        let mut marching: [Option<(Marching, Option<&S>)>; N] =
            rays.map(|ray| ray.map(|(ray, shade)| (Marching::new(ray, step), shade)));
        loop {
            let mut any = false;
            for (ray, buffer) in marching.iter_mut().zip(buffers.iter_mut()) {
                let Some((ray, shade)) = ray else { continue };
                if ray.going(opacity_cutoff) {
                    ray.advance(volume, classification, step, *shade, buffer);
                    any = true;
                }
            }
            if !any {
                break;
            }
        }
        core::array::from_fn(|k| {
            marching[k]
                .as_ref()
                .map(|(ray, shade)| ray.finish(*shade, &buffers[k]))
        })
    }
}
