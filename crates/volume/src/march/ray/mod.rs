//! Rays marched as a packet: [`LANES`] rays side by side in structure-of-arrays form, every
//! lane advanced by one segment per turn of the loop.
//!
//! A turn has three phases. Where each lane's segment lies and which voxel cell its midpoint
//! falls in is lane-wise arithmetic on arrays (which the compiler vectorises). Then each lane is
//! placed: its brick's clearance and cell mask read lane by lane, the skips of lanes in empty
//! bricks computed side by side without a branch, and the lanes left reading (not skipping, not
//! in a transparent cell) interpolate the voxels and the transfer function in loops of their
//! own, since each lane reads elsewhere. Opacity, lighting and compositing are written in the
//! core's vectors ([`Lanes`]), with no branch on a sample's value (whether a noisy sample faces
//! the light is a coin toss that a branch would mispredict). The turns are software-pipelined:
//! the next turn's segments are placed before this turn is composited, and its samples read
//! after. A lane whose ray ends takes the next ray of the list, so the packet stays full until
//! the list runs out. Highlights are gathered across lanes and their lobe evaluated together by
//! the lobe's vector kernel ([`specula::Lobe::eval_batch`]).
//!
//! Every ray gets exactly the samples of a march on its own, front to back; only the order in
//! which its highlights are summed differs.

// A lane loop reads and writes several arrays at the lane's index: written as one index, it
// is the shape the compiler vectorises.
#![allow(clippy::needless_range_loop)]

mod composite;
mod sample;

use composite::Highlights;

use glam::Vec3;
use specula::simd::{dispatch, Job, Lanes, Level, Prefetch};

use super::cells::cell_bit;
use super::{Classification, PreparedVolume};
use crate::lighting::{Lighting, RayView};

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

/// Rays a packet marches side by side: one AVX2 vector of `f32` (a multiple of every
/// level's width).
pub(crate) const LANES: usize = 8;

/// Steps ahead of each sample that a volume larger than the caches is fetched into them: the
/// march otherwise waits on memory at every sample (a clinical-size CT: frames 15 % faster
/// with it; on the real CT, whose voxels the caches hold, the extra work made frames 4 %
/// slower with a cell's first rows asked for, 10 % with the whole cell, so it is left out
/// there).
const LOOKAHEAD: usize = 3;

/// Highlights gathered before their lobe is evaluated together.
const HIGHLIGHTS: usize = 64;

type Lane<T> = [T; LANES];

/// A ray's result: the colour it gathered and the light it let through.
pub(crate) type Marched = (Vec3, f32);

/// How the rays' samples are lit: the render's lighting, each ray's view of it, and the
/// lobes whose highlights the march adds, one image each.
#[derive(Clone, Copy)]
pub(crate) struct Lit<'a> {
    pub lighting: &'a Lighting,
    /// `views[r]` is ray `r`'s.
    pub views: &'a [RayView],
    /// One per image: every image has the same samples, their colours and opacities, and
    /// differs only in its highlights' lobe.
    pub highlights: &'a [Highlight],
}

/// One image's highlight: its lobe, and `ks N(n)` ([`Lighting::highlight_scale`]).
#[derive(Clone, Copy, Debug)]
pub(crate) struct Highlight {
    pub lobe: specula::Lobe,
    pub scale: f32,
}

impl Highlight {
    /// `lighting`'s own lobe's.
    pub(crate) fn of(lighting: &Lighting) -> Self {
        Self {
            lobe: lighting.shading.lobe,
            scale: lighting.highlight_scale(&lighting.shading.lobe),
        }
    }
}

/// Marches `rays` (with `lit`, or emission and absorption only) through `volume`, writing ray
/// `r`'s result to `out[r]`, compiled for `level`.
///
/// # Panics
/// If `out` (or `lit`'s views) and `rays` differ in length.
#[allow(clippy::too_many_arguments)]
pub(crate) fn march_rays(
    level: Level,
    volume: &PreparedVolume,
    classification: &Classification,
    lit: Option<Lit<'_>>,
    rays: &[Ray],
    step: f32,
    opacity_cutoff: f32,
    out: &mut [Marched],
) {
    let images = lit.map_or(1, |lit| lit.highlights.len());
    assert_eq!(
        rays.len() * images,
        out.len(),
        "march_rays: one result per ray and image"
    );
    if let Some(lit) = lit {
        assert_eq!(rays.len(), lit.views.len(), "march_rays: one view per ray");
    }
    let lookahead = LOOKAHEAD as f32 * step;
    macro_rules! packet {
        ($fetch:literal) => {
            Packet::<$fetch> {
                volume,
                classification,
                lit,
                rays,
                step,
                inverse_step: 1.0 / step,
                opacity_cutoff,
                prefetch: Prefetch::new(),
                lookahead,
                images,
                out,
            }
        };
    }
    if volume.outgrows_caches() {
        dispatch(level, packet!(true));
    } else {
        dispatch(level, packet!(false));
    }
}

/// [`march_rays`]'s work, as the instruction-set dispatch takes it; `FETCH`: with the voxels
/// fetched into the cache [`LOOKAHEAD`] steps ahead of each sample (a parameter, so that each
/// form is compiled apart: a test per lane would keep the segment loop from vectorising).
struct Packet<'a, const FETCH: bool> {
    volume: &'a PreparedVolume,
    classification: &'a Classification,
    lit: Option<Lit<'a>>,
    rays: &'a [Ray],
    step: f32,
    /// `1 / step`.
    inverse_step: f32,
    opacity_cutoff: f32,
    prefetch: Prefetch,
    /// How far ahead of each sample (mm along the ray) the voxels are fetched when `FETCH`.
    lookahead: f32,
    /// Results per ray: ray `r`'s for image `i` is `out[r * images + i]`.
    images: usize,
    out: &'a mut [Marched],
}

/// The lanes' rays partway through their marches.
#[derive(Clone, Copy)]
struct Marching {
    /// The ray each lane marches (an index into the list); `live` says whether it has one.
    ray: Lane<usize>,
    live: Lane<bool>,
    origin: [Lane<f32>; 3],
    direction: [Lane<f32>; 3],
    /// Per axis, `1 / direction` (huge along a grid plane), for leaving empty bricks.
    inverse_direction: [Lane<f32>; 3],
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
    /// The rays' views: `wo`, the half vector and `wi . wo`.
    wo: [Lane<f32>; 3],
    half: [Lane<f32>; 3],
    wi_dot_wo: Lane<f32>,
}

/// One turn's segments and samples, lane by lane.
#[derive(Clone, Copy)]
struct Turn {
    cell: [Lane<i32>; 3],
    /// The cell's first voxel, and the brick holding it.
    voxel: Lane<i32>,
    /// Where the cell [`LOOKAHEAD`] steps further on starts, when the volume is prefetched.
    ahead: Lane<i32>,
    brick: Lane<i32>,
    /// The cell's bit in its brick's mask of transparent cells.
    bit: Lane<u32>,
    /// The midpoint's place in its cell.
    fraction: [Lane<f32>; 3],
    length: Lane<f32>,
    /// The field's value at the midpoint.
    value: Lane<f32>,
    /// The extinction at the midpoint (0 where a lane took no sample).
    sigma: Lane<f32>,
    /// The transfer function's colour there.
    base: [Lane<f32>; 3],
    /// The field's gradient there (world, value per mm).
    gradient: [Lane<f32>; 3],
    /// Where the lane's march stands after this turn (past its segment or a skip).
    t_end: Lane<f32>,
}

impl Marching {
    /// Every lane without a ray.
    const IDLE: Self = Self {
        ray: [0; LANES],
        live: [false; LANES],
        origin: [[0.0; LANES]; 3],
        direction: [[0.0; LANES]; 3],
        inverse_direction: [[0.0; LANES]; 3],
        end: [0.0; LANES],
        first_end: [0.0; LANES],
        lattice: [0.0; LANES],
        j: [0; LANES],
        t: [0.0; LANES],
        colour: [[0.0; LANES]; 3],
        transmittance: [0.0; LANES],
        wo: [[0.0; LANES]; 3],
        half: [[0.0; LANES]; 3],
        wi_dot_wo: [0.0; LANES],
    };
}

impl Turn {
    const EMPTY: Self = Self {
        cell: [[0; LANES]; 3],
        voxel: [0; LANES],
        ahead: [0; LANES],
        brick: [0; LANES],
        bit: [0; LANES],
        fraction: [[0.0; LANES]; 3],
        length: [0.0; LANES],
        value: [0.0; LANES],
        sigma: [0.0; LANES],
        base: [[0.0; LANES]; 3],
        gradient: [[0.0; LANES]; 3],
        t_end: [0.0; LANES],
    };
}

impl<const FETCH: bool> Job for Packet<'_, FETCH> {
    type Output = ();

    #[inline(always)]
    fn run<V: Lanes>(mut self, lanes: V) {
        let mut marching = Marching::IDLE;
        let mut highlights = Highlights::EMPTY;
        let mut next = 0;
        for k in 0..LANES {
            self.start(&mut marching, k, &mut next);
        }
        // Software-pipelined: the next turn's segments are placed before this turn is
        // composited and its samples read after, so that the vector loads of a turn's lanes
        // find them stored a whole phase earlier (a vector load of values just stored lane by
        // lane cannot be forwarded from the stores and waits for all of them), and the
        // composite's arithmetic stands between the segments' and the reads' (measured: 5 %
        // off the real CT's frame, against reading the samples before compositing). A lane
        // whose ray ends has its read-ahead sample replaced by its next ray's first.
        let (mut current, mut ahead) = (Turn::EMPTY, Turn::EMPTY);
        self.segments(&mut marching, &mut current);
        self.samples(lanes, &mut marching, &mut current);
        while marching.live.contains(&true) {
            self.segments(&mut marching, &mut ahead);
            // A turn in which no lane took a sample with extinction composites nothing
            // (common where a packet's rays cross air or tissue the transfer function hides).
            if current.sigma.iter().any(|&sigma| sigma > 0.0) {
                self.composite(lanes, &mut marching, &current, &mut highlights);
            }
            self.samples(lanes, &mut marching, &mut ahead);
            let mut ended = [false; LANES];
            for k in 0..LANES {
                let going = current.t_end[k] < marching.end[k]
                    && 1.0 - marching.transmittance[k] < self.opacity_cutoff;
                ended[k] = marching.live[k] & !going;
            }
            if ended.contains(&true) {
                for k in (0..LANES).filter(|&k| ended[k]) {
                    let r = marching.ray[k];
                    let colour = Vec3::new(
                        marching.colour[0][k],
                        marching.colour[1][k],
                        marching.colour[2][k],
                    );
                    for marched in &mut self.out[r * self.images..(r + 1) * self.images] {
                        marched.0 += colour;
                        marched.1 = marching.transmittance[k];
                    }
                    self.start(&mut marching, k, &mut next);
                    // The read-ahead sample was the ended ray's: the lane's next ray takes its
                    // first segment instead, and an idle lane's sample is cleared (composited,
                    // it would add light to a ray already written out).
                    if marching.live[k] {
                        self.segment(&mut marching, &mut ahead, k);
                    }
                    self.sample(lanes, &mut marching, &mut ahead, k);
                }
            }
            core::mem::swap(&mut current, &mut ahead);
        }
        if let Some(lit) = self.lit {
            highlights.flush(lit.highlights, self.out);
        }
    }
}

impl<const FETCH: bool> Packet<'_, FETCH> {
    /// Lane `k` takes ray `next` of the list (its result cleared) and `next` moves on, or the
    /// lane idles when the list has run out.
    #[inline(always)]
    fn start(&mut self, marching: &mut Marching, k: usize, next: &mut usize) {
        let Some(&ray) = self.rays.get(*next) else {
            marching.live[k] = false;
            return;
        };
        let r = *next;
        *next += 1;
        marching.ray[k] = r;
        marching.live[k] = true;
        for axis in 0..3 {
            marching.origin[axis][k] = ray.origin[axis];
            marching.direction[axis][k] = ray.direction[axis];
        }
        // A direction along a grid plane never leaves a brick across it: a huge inverse keeps
        // that axis's exit out of the minimum (and away from 0 * infinity).
        let inverse = Vec3::select(
            ray.direction.abs().cmplt(Vec3::splat(1e-12)),
            Vec3::splat(1e30),
            ray.direction.recip(),
        );
        for axis in 0..3 {
            marching.inverse_direction[axis][k] = inverse[axis];
        }
        marching.end[k] = ray.end;
        marching.first_end[k] = ray.start + ray.first;
        marching.lattice[k] = ray.start + ray.first - self.step;
        marching.j[k] = 0;
        marching.t[k] = ray.start;
        marching.transmittance[k] = 1.0;
        for c in 0..3 {
            marching.colour[c][k] = 0.0;
        }
        if let Some(lit) = self.lit {
            let view = lit.views[r];
            for axis in 0..3 {
                marching.wo[axis][k] = view.wo[axis];
                marching.half[axis][k] = view.half[axis];
            }
            marching.wi_dot_wo[k] = view.wi_dot_wo;
        }
        self.out[r * self.images..(r + 1) * self.images].fill((Vec3::ZERO, 1.0));
    }

    /// Every lane's next segment (its length, the cell its midpoint lies in and the place
    /// there): arithmetic the compiler vectorises across lanes.
    #[inline(always)]
    fn segments(&self, marching: &mut Marching, turn: &mut Turn) {
        for k in 0..LANES {
            self.segment(marching, turn, k);
        }
    }

    /// Lane `k`'s next segment (see [`Self::segments`]).
    #[inline(always)]
    fn segment(&self, marching: &mut Marching, turn: &mut Turn, k: usize) {
        let volume = self.volume;
        let j = marching.j[k];
        let next = if j == 0 {
            marching.first_end[k]
        } else {
            marching.lattice[k] + (j + 1) as f32 * self.step
        };
        let length = next.min(marching.end[k]) - marching.t[k];
        turn.length[k] = length;
        let middle = marching.t[k] + 0.5 * length;
        let further = middle + self.lookahead;
        let mut ahead = [0; 3];
        for axis in 0..3 {
            let p = (marching.origin[axis][k] + marching.direction[axis][k] * middle)
                .max(0.0)
                .min(volume.last_index[axis]);
            let (cell, fraction) = PreparedVolume::cell_along(p, volume.last_cell[axis]);
            turn.cell[axis][k] = cell;
            turn.fraction[axis][k] = fraction;
            if FETCH {
                let q = (marching.origin[axis][k] + marching.direction[axis][k] * further)
                    .max(0.0)
                    .min(volume.last_index[axis]);
                ahead[axis] = PreparedVolume::cell_along(q, volume.last_cell[axis]).0;
            }
        }
        let cell = [turn.cell[0][k], turn.cell[1][k], turn.cell[2][k]];
        turn.voxel[k] = volume.voxel(cell);
        turn.brick[k] = volume.brick(cell);
        turn.bit[k] = cell_bit(cell);
        if FETCH {
            turn.ahead[k] = volume.voxel(ahead);
        }
        marching.t[k] = next;
        marching.j[k] = j + 1;
    }
}
