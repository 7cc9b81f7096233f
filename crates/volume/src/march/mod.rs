//! What makes the CPU ray marcher fast without changing what it computes.
//!
//! - **Gradients once per volume.** Central differences one voxel apart of the trilinear field
//!   are the trilinear interpolation of the voxels' own central differences (interpolation is
//!   linear in the data and commutes with a whole-voxel shift), so [`PreparedVolume`] stores
//!   each voxel's value and world gradient side by side (16 bytes, or 8 for a volume too
//!   large for that: [`Layout`]) and a sample reads 8 neighbours instead of 48. Only the last
//!   voxel layer differs: there the reference clamps the outer sample of the difference, the
//!   prepared field the voxel's.
//! - **Empty space skipped exactly.** The grid is cut into bricks of [`BRICK`]^3 cells with
//!   each brick's smallest and largest value; a render marks the bricks whose whole value
//!   range has no extinction and finds, for each, how far the empty space around it reaches
//!   (its chessboard distance to the nearest occupied brick, two raster passes). A ray in an
//!   empty brick jumps to its exit from the empty cube of bricks centred there, along its own
//!   lattice of segments, so every sample it still takes is one it would have taken.
//! - **Classification without a search.** A table over the volume's range finds the piece
//!   of the transfer function a value falls in, whose line then gives extinction and colour
//!   exactly as the function does.
//! - **Transparent cells not read.** In a brick that is not empty, a cell whose corners all
//!   lie where the transfer function has no extinction is marked ([`cells`]); a sample there
//!   is known to have none without reading a voxel.

use std::borrow::Cow;
use std::sync::{Arc, Mutex, MutexGuard, PoisonError};

use glam::{IVec3, Vec3, Vec4};
use rayon::prelude::*;
use specula::simd::{dispatch, Job, Lanes, Level};

use crate::samples::{Sample, Samples};
use crate::transfer::{ControlPoint, TransferFunction};
use crate::volume::{Volume, MAX_SIDE, MAX_VOXELS};

mod cells;
#[cfg(test)]
mod prepared_tests;
pub(super) mod ray;
#[cfg(test)]
mod tests;
mod voxels;

pub use voxels::Layout;
use voxels::Voxels;

/// The flag of a table entry within which a control point lies.
const HOLDS_A_BOUND: u16 = 1 << 15;

/// Cells along each side of a brick: `2^BRICK_SHIFT`.
pub const BRICK: usize = 1 << BRICK_SHIFT;

const BRICK_SHIFT: i32 = 2;

/// How far, in bricks, an empty brick's clearance is counted: a ray skips at most this many
/// bricks' worth of empty space at once.
const MOST_CLEARANCE: u8 = 16;

// Lanes compute voxel and brick indices in `i32`, and `PreparedVolume::cell_along`'s rounding
// holds for indices below 2^22: the grid's limits keep both true.
const _: () = assert!(MAX_VOXELS <= i32::MAX as usize && MAX_SIDE <= 1 << 22);

/// Entries of the table that finds a value's piece of the transfer function.
pub const CLASSIFICATION_ENTRIES: usize = 4096;

/// A volume laid out for marching: value and world gradient per voxel, and the bricks'
/// value ranges. Built once and shared by every frame of that volume.
#[derive(Clone, Debug)]
pub struct PreparedVolume {
    dims: [usize; 3],
    /// `(value, gradient in value per mm)` per voxel, four numbers each, `i` fastest: a
    /// voxel and its neighbour along `i` are eight numbers in a row ([`Layout`]).
    voxels: Voxels,
    /// The largest cell index along each axis (`dims - 2`).
    last_cell: IVec3,
    last_index: Vec3,
    bricks: [usize; 3],
    /// Smallest and largest value of each brick's voxels (its cells' corners).
    brick_ranges: Vec<(f32, f32)>,
    range: (f32, f32),
    last_classification: LastClassification,
}

/// The classification a prepared volume was last asked for, with its transfer function.
#[derive(Debug, Default)]
struct LastClassification(Mutex<Option<(TransferFunction, Arc<Classification>)>>);

impl Clone for LastClassification {
    fn clone(&self) -> Self {
        Self(Mutex::new(self.kept().clone()))
    }
}

impl LastClassification {
    fn kept(&self) -> MutexGuard<'_, Option<(TransferFunction, Arc<Classification>)>> {
        // A render that panicked left a whole classification or none: the value stays good.
        self.0.lock().unwrap_or_else(PoisonError::into_inner)
    }
}

impl PreparedVolume {
    /// Computes the gradients and the bricks' ranges (in parallel over slices), in the layout
    /// [`Layout::for_voxels`] picks for the volume's size.
    #[must_use]
    pub fn new(volume: &Volume) -> Self {
        Self::with_layout(volume, Layout::for_voxels(volume.samples().len()))
    }

    /// [`PreparedVolume::new`] in a chosen layout.
    #[must_use]
    pub fn with_layout(volume: &Volume, layout: Layout) -> Self {
        let dims = volume.dims();
        let voxels = Voxels::new(volume, layout);
        let bricks = dims.map(|d| (d - 1).div_ceil(BRICK));
        let brick_ranges = match volume.samples() {
            Samples::Whole(values) => brick_ranges(values, dims, bricks),
            Samples::Float(values) => brick_ranges(values, dims, bricks),
        };
        Self {
            dims,
            voxels,
            last_cell: IVec3::from(dims.map(|d| (d - 2) as i32)),
            last_index: volume.last_index(),
            bricks,
            brick_ranges,
            range: volume.range(),
            last_classification: LastClassification::default(),
        }
    }

    /// `transfer` arranged for this volume ([`Classification::new`]). The last one asked for
    /// is kept: a view re-rendered with one transfer function, frame after frame, arranges it
    /// once (a clinical-size CT's bricks take about 15 ms), as VTK's mapper keeps its
    /// space-leaping flags until the function changes.
    #[must_use]
    pub fn classification(&self, transfer: &TransferFunction) -> Arc<Classification> {
        let mut kept = self.last_classification.kept();
        if let Some((function, classification)) = kept.as_ref() {
            if function == transfer {
                return Arc::clone(classification);
            }
        }
        let classification = Arc::new(Classification::new(self, transfer));
        *kept = Some((transfer.clone(), Arc::clone(&classification)));
        classification
    }

    /// The grid's size.
    #[must_use]
    pub fn dims(&self) -> [usize; 3] {
        self.dims
    }

    /// `(value, world gradient)` per voxel, `i` fastest, as `f32`: what the GPU's marcher
    /// uploads, so that it reads a sample's 8 corners, not the 48 of six differenced samples.
    #[must_use]
    pub fn voxels(&self) -> Cow<'_, [[f32; 4]]> {
        self.voxels.exact()
    }

    /// The largest difference between a stored value and the volume's, and between a stored
    /// gradient's world components and the exact ones (0 in the exact layout).
    #[must_use]
    pub fn quantisation_error(&self) -> (f32, Vec3) {
        self.voxels.quantisation_error()
    }

    /// How far a sample's interpolated value may stray from the range of its cell's corners
    /// (as [`Self::voxels`] gives them): the rounding of three nested `a + (b - a) t`, each
    /// within about 2.5 units in the last place of the largest value (the difference, the
    /// product and the sum rounded once each, unfused), so 7.5 in all, taken twice over; and,
    /// for values stored as integers scaled, half a step.
    fn value_margin(&self) -> f32 {
        let largest = self.range.0.abs().max(self.range.1.abs());
        largest * f32::EPSILON * 16.0 + f32::MIN_POSITIVE + self.quantisation_error().0
    }

    /// Bricks along each axis ([`BRICK`]^3 cells each, the last ones possibly partial).
    #[must_use]
    pub fn bricks(&self) -> [usize; 3] {
        self.bricks
    }

    /// The cell holding grid index `p` (already within the grid), and `p`'s place in it.
    #[inline(always)]
    fn cell(&self, p: Vec3) -> (IVec3, Vec3) {
        let [(x, fx), (y, fy), (z, fz)] =
            [0, 1, 2].map(|axis| Self::cell_along(p[axis], self.last_cell[axis]));
        (IVec3::new(x, y, z), Vec3::new(fx, fy, fz))
    }

    /// [`Self::cell`] along one axis whose last cell is `last_cell`: [`whole_below`] of p,
    /// whose cell then holds p at its far corner (f = 1) where p is an odd whole number. The
    /// last layer of voxels belongs to the last cell.
    #[inline(always)]
    fn cell_along(p: f32, last_cell: i32) -> (i32, f32) {
        let cell = whole_below(p).min(last_cell);
        (cell, p - cell as f32)
    }

    /// Value and world gradient at grid index `p` (clamped to the grid), interpolated
    /// trilinearly.
    #[inline(always)]
    #[must_use]
    pub fn sample(&self, p: Vec3) -> Vec4 {
        struct Sample<'a>(&'a PreparedVolume, Vec3);
        impl Job for Sample<'_> {
            type Output = Vec4;
            fn run<V: Lanes>(self, lanes: V) -> Vec4 {
                let Sample(volume, p) = self;
                let (cell, f) = volume.cell(p.clamp(Vec3::ZERO, volume.last_index));
                volume.sample_at(lanes, volume.voxel(cell.to_array()) as usize, f)
            }
        }
        dispatch(Level::Baseline, Sample(self, p))
    }

    /// The first voxel of `cell` (its corner of smallest indices). Plain `i32` arithmetic (a
    /// grid holds at most `MAX_VOXELS`, 2^28, voxels), so that lanes compute it side by side.
    #[inline(always)]
    fn voxel(&self, cell: [i32; 3]) -> i32 {
        let [nx, ny, _] = self.dims.map(|d| d as i32);
        cell[0] + nx * (cell[1] + ny * cell[2])
    }

    /// The trilinear value and gradient at `f` in the cell whose first voxel is `at`.
    #[inline(always)]
    fn sample_at<V: Lanes>(&self, lanes: V, at: usize, f: Vec3) -> Vec4 {
        let (nx, nxy) = (self.dims[0], self.dims[0] * self.dims[1]);
        self.voxels.trilinear(lanes, at, f, nx, nxy)
    }

    /// Whether the voxels are too many for the caches (held in the compact layout), so that
    /// the march fetches them ahead of its samples.
    #[must_use]
    fn outgrows_caches(&self) -> bool {
        self.voxels.layout() == Layout::Compact
    }

    /// Asks for the cache lines of the cell whose first voxel is `at` (within the grid).
    #[inline(always)]
    fn prefetch(&self, at: usize, prefetch: specula::simd::Prefetch) {
        let nxy = self.dims[0] * self.dims[1];
        self.voxels.prefetch(at, self.dims[0], nxy, prefetch);
    }

    /// The index of the brick holding `cell` (`i32` arithmetic, as [`Self::voxel`]).
    #[inline(always)]
    fn brick(&self, cell: [i32; 3]) -> i32 {
        let [bx, by, _] = self.bricks.map(|b| b as i32);
        (cell[0] >> BRICK_SHIFT) + bx * ((cell[1] >> BRICK_SHIFT) + by * (cell[2] >> BRICK_SHIFT))
    }

    /// Where a ray (grid index `origin + direction * t`, one axis of it) leaves, along that
    /// axis, the cube of bricks within `reach - 1` bricks of the one holding `cell` (that
    /// brick alone for a reach of 1): the ray leaves the cube at the least of the three.
    #[inline(always)]
    fn clear_exit_along(cell: i32, reach: i32, origin: f32, inverse_direction: f32) -> f32 {
        let brick = cell >> BRICK_SHIFT;
        let low = ((brick - (reach - 1)) << BRICK_SHIFT) as f32;
        let high = ((brick + reach) << BRICK_SHIFT) as f32;
        let a = (low - origin) * inverse_direction;
        let c = (high - origin) * inverse_direction;
        if a > c {
            a
        } else {
            c
        }
    }
}

/// `x` (in `[0, 2^22)`) rounded down to a whole number, or to one less where `x` is an odd
/// whole number. Adding 1.5 * 2^23 to x - 1/2 rounds it to an integer held in the low
/// mantissa bits (the sum lies in [2^23, 2^24), where the spacing is 1), a tie to even: two
/// instructions a lane, where `as i32` (saturating, NaN to 0) takes several.
#[inline(always)]
fn whole_below(x: f32) -> i32 {
    const ROUND: f32 = 12_582_912.0;
    let rounded = (x - 0.5) + ROUND;
    rounded.to_bits() as i32 - ROUND.to_bits() as i32
}

/// The smallest and largest of `samples` (a grid of `dims`) over each of `bricks` bricks'
/// voxels (its cells' corners), in parallel over bricks.
fn brick_ranges<T: Sample>(samples: &[T], dims: [usize; 3], bricks: [usize; 3]) -> Vec<(f32, f32)> {
    let [nx, ny, nz] = dims;
    let at = |i: usize, j: usize, k: usize| -> f32 { samples[i + nx * (j + ny * k)].into() };
    (0..bricks[0] * bricks[1] * bricks[2])
        .into_par_iter()
        .map(|b| {
            let (bi, bj, bk) = (
                b % bricks[0],
                b / bricks[0] % bricks[1],
                b / (bricks[0] * bricks[1]),
            );
            let span = |brick: usize, d: usize| brick * BRICK..=((brick + 1) * BRICK).min(d - 1);
            let mut range = (f32::INFINITY, f32::NEG_INFINITY);
            for k in span(bk, nz) {
                for j in span(bj, ny) {
                    for i in span(bi, nx) {
                        let v = at(i, j, k);
                        range = (range.0.min(v), range.1.max(v));
                    }
                }
            }
            range
        })
        .collect()
}

/// A transfer function arranged for one volume: its pieces as `value -> (sigma, r, g, b)`
/// lines, a table that finds a value's piece, and the bricks it leaves empty.
#[derive(Clone, Debug)]
pub struct Classification {
    /// The control points' values: piece `s` holds the values in `(bounds[s - 1], bounds[s]]`
    /// (piece 0 those up to the first point, the last those beyond the last point).
    bounds: Vec<f32>,
    /// Per piece: where its line starts (a value), its `(sigma, r, g, b)` there, and its
    /// slope per unit of value.
    pieces: Vec<(f32, Vec4, Vec4)>,
    /// The piece of the smallest value each table entry can hold, with [`HOLDS_A_BOUND`] set
    /// when a control point lies within the entry (so that a value may be in a later piece).
    first_piece: Vec<u16>,
    lowest: f32,
    per_entry: f32,
    /// Per brick, 0 where it holds a value with extinction, else its chessboard distance in
    /// bricks to the nearest such brick (at most [`MOST_CLEARANCE`]): every brick less than
    /// that far from it is empty too.
    clearance: Vec<u8>,
    /// Per brick, a bit per cell ([`cells::cell_bit`]) set where no value in the cell has
    /// extinction (only in bricks whose clearance is 0).
    transparent: Vec<u64>,
}

impl Classification {
    /// Arranges `transfer` (in `volume`'s values).
    #[must_use]
    pub fn new(volume: &PreparedVolume, transfer: &TransferFunction) -> Self {
        let points = transfer.points();
        let bounds: Vec<f32> = points.iter().map(|p| p.value).collect();
        let entry = |p: &ControlPoint| Vec4::new(p.sigma, p.colour.x, p.colour.y, p.colour.z);
        let mut pieces = vec![(points[0].value, entry(&points[0]), Vec4::ZERO)];
        for pair in points.windows(2) {
            let (a, b) = (&pair[0], &pair[1]);
            let slope = (entry(b) - entry(a)) / (b.value - a.value);
            pieces.push((a.value, entry(a), slope));
        }
        let last = &points[points.len() - 1];
        pieces.push((last.value, entry(last), Vec4::ZERO));
        let (lowest, highest) = volume.range;
        let span = highest - lowest;
        let entries = CLASSIFICATION_ENTRIES;
        // A flat volume has one value: every lookup reads the first entry.
        let per_entry = if span > 0.0 {
            entries as f32 / span
        } else {
            0.0
        };
        // Half an entry below its start, so that rounding in the lookup never lands past
        // a value's piece; the march then steps forward over the bounds it passes.
        let below = |value: f32| bounds.iter().filter(|&&b| b < value).count() as u16;
        let first_piece = (0..entries)
            .map(|e| {
                let start = lowest + (e as f32 - 0.5) / per_entry.max(f32::MIN_POSITIVE);
                let end = lowest + (e as f32 + 1.5) / per_entry.max(f32::MIN_POSITIVE);
                let piece = below(start);
                if below(end) == piece && per_entry > 0.0 {
                    piece
                } else {
                    piece | HOLDS_A_BOUND
                }
            })
            .collect();
        let occupied: Vec<bool> = volume
            .brick_ranges
            .par_iter()
            .map(|&(lo, hi)| {
                transfer.at(lo).0 > 0.0
                    || transfer.at(hi).0 > 0.0
                    || points
                        .iter()
                        .any(|p| p.sigma > 0.0 && p.value > lo && p.value < hi)
            })
            .collect();
        let clearance = chessboard_distance(&occupied, volume.bricks);
        let transparent = cells::transparent_cells(volume, points, &occupied);
        Self {
            bounds,
            pieces,
            first_piece,
            lowest,
            per_entry,
            clearance,
            transparent,
        }
    }

    /// Per brick (`i` fastest, [`PreparedVolume::bricks`] of them), 0 where it holds a value
    /// with extinction, else how many bricks its empty surroundings reach: what the GPU's
    /// marcher skips by, as the CPU's does.
    #[must_use]
    pub fn clearance(&self) -> &[u8] {
        &self.clearance
    }

    /// The classification as flat tables, for a GPU to read as this does ([`Self::at`]).
    #[must_use]
    pub fn tables(&self) -> ClassificationTables {
        ClassificationTables {
            bounds: self.bounds.clone(),
            pieces: self
                .pieces
                .iter()
                .map(|&(start, at_start, slope)| (start, at_start.to_array(), slope.to_array()))
                .collect(),
            first_piece: self.first_piece.iter().map(|&e| u32::from(e)).collect(),
            lowest: self.lowest,
            per_entry: self.per_entry,
        }
    }

    /// Extinction and colour `(sigma, r, g, b)` at `value`: the transfer function's own
    /// interpolation.
    #[inline(always)]
    fn at(&self, value: f32) -> Vec4 {
        let x = ((value - self.lowest) * self.per_entry)
            .clamp(0.0, (CLASSIFICATION_ENTRIES - 1) as f32);
        let entry = self.first_piece[x as i32 as usize];
        let mut piece = usize::from(entry & !HOLDS_A_BOUND);
        if entry & HOLDS_A_BOUND != 0 {
            while piece < self.bounds.len() && value > self.bounds[piece] {
                piece += 1;
            }
        }
        let (start, at_start, slope) = self.pieces[piece];
        at_start + slope * (value - start)
    }
}

/// [`Classification`] as flat tables ([`Classification::tables`]): a value's entry is
/// `first_piece[clamp((value - lowest) * per_entry, 0, CLASSIFICATION_ENTRIES - 1)]`, its
/// piece the entry's low 15 bits, then past every bound below the value when the entry's
/// bit 15 says a bound lies within it; the piece's line gives `(sigma, r, g, b)` as
/// `at_start + slope * (value - start)`.
#[derive(Clone, Debug)]
pub struct ClassificationTables {
    /// The control points' values.
    pub bounds: Vec<f32>,
    /// Per piece: `(start, at_start, slope)`.
    pub pieces: Vec<(f32, [f32; 4], [f32; 4])>,
    /// Per entry: the piece of its smallest value, bit 15 set when a bound lies within it.
    pub first_piece: Vec<u32>,
    /// The volume's smallest value.
    pub lowest: f32,
    /// Entries per unit of value.
    pub per_entry: f32,
}

/// Per brick of a `[nx, ny, nz]` grid, 0 where `occupied`, else the chessboard distance to
/// the nearest occupied brick (at most [`MOST_CLEARANCE`], also where none is). Two raster
/// passes over the 3 x 3 x 3 neighbourhood, forward then backward, give the chessboard
/// distance exactly (Rosenfeld and Pfaltz's sequential transform); the grid is padded by one
/// empty brick a side so that every neighbour exists, and each row takes the minimum over
/// the rows before it (lane-wise) before the sweep along itself.
fn chessboard_distance(occupied: &[bool], [nx, ny, nz]: [usize; 3]) -> Vec<u8> {
    let (px, py) = (nx + 2, ny + 2);
    let padded = |i: usize, j: usize, k: usize| (i + 1) + px * ((j + 1) + py * (k + 1));
    let mut distance = vec![MOST_CLEARANCE; px * py * (nz + 2)];
    // Row by row between the grid and its padding: no division per brick.
    let rows = (0..nz)
        .flat_map(|k| (0..ny).map(move |j| (j, k)))
        .map(|(j, k)| (nx * (j + ny * k), padded(0, j, k)));
    for (row, start) in rows.clone() {
        for (d, &o) in distance[start..start + nx]
            .iter_mut()
            .zip(&occupied[row..row + nx])
        {
            if o {
                *d = 0;
            }
        }
    }
    // The 12 neighbours in the slice and the row before a brick, as distances back from it
    // in the padded grid (the 13th, the brick before it in its row, is the sweep's).
    let (row, slice) = (px, px * py);
    let mut earlier = [0_usize; 12];
    for (n, (dj, di)) in (0..3)
        .flat_map(|dj| (0..3).map(move |di| (dj, di)))
        .enumerate()
    {
        earlier[n] = slice + dj * row + di - row - 1;
    }
    for di in 0..3 {
        earlier[9 + di] = row + di - 1;
    }
    let mut nearest = vec![0_u8; nx];
    for forward in [true, false] {
        for kk in 0..nz {
            for jj in 0..ny {
                let (j, k) = if forward {
                    (jj, kk)
                } else {
                    (ny - 1 - jj, nz - 1 - kk)
                };
                let start = padded(0, j, k);
                // Neighbour by neighbour, the whole row at once (bytes side by side in vectors).
                nearest.fill(MOST_CLEARANCE);
                for &back in &earlier {
                    let from = if forward { start - back } else { start + back };
                    for (nearest, &there) in nearest.iter_mut().zip(&distance[from..from + nx]) {
                        *nearest = (*nearest).min(there);
                    }
                }
                let mut before = MOST_CLEARANCE;
                for ii in 0..nx {
                    let i = if forward { ii } else { nx - 1 - ii };
                    let at = start + i;
                    let value = distance[at]
                        .min(nearest[i].saturating_add(1))
                        .min(before.saturating_add(1));
                    distance[at] = value;
                    before = value;
                }
            }
        }
    }
    let mut clearance = vec![0; nx * ny * nz];
    for (row, start) in rows {
        clearance[row..row + nx].copy_from_slice(&distance[start..start + nx]);
    }
    clearance
}
