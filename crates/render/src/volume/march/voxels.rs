//! The prepared voxels: each voxel's value and world gradient, in one of two layouts.
//!
//! - [`Layout::Exact`]: four `f32` (16 bytes), a voxel and its neighbour along `i` one
//!   256-bit read. Fastest while the march is bound by its instructions (measured on the real
//!   CT and MRI, about 7 million voxels each: the compact layout's conversions cost the MRI,
//!   nearly every sample shaded, 5-9 % a frame).
//! - [`Layout::Compact`]: four `i16` (8 bytes) with a scale and offset per component. Half
//!   the memory, and half the traffic once the volume outgrows the caches (a 512 x 512 x 432
//!   CT: 17 % faster frames, peak 2.3 -> 1.4 GB). A scan of whole numbers within `i16` (a CT
//!   in Hounsfield units, an 8-bit MRI) keeps its values exactly; gradients are spread over
//!   the integers by the steepest a central difference can be along each axis (half the
//!   value range through the grid's map), so each is within half a step
//!   ([`Voxels::quantisation_error`]). The integers are interpolated and scaled once: the
//!   interpolation is linear, so scaling the result is scaling the corners.
//!
//! [`Layout::for_voxels`] picks the compact layout above [`Layout::COMPACT_ABOVE`] voxels.

use std::borrow::Cow;

use glam::{Vec3, Vec4};
use rayon::prelude::*;

use crate::volume::Volume;

/// How the prepared voxels are held (see the module docs).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Layout {
    /// Four `f32` per voxel.
    Exact,
    /// Four `i16` per voxel, scaled.
    Compact,
}

impl Layout {
    /// Above this many voxels (512 MiB of exact voxels) the compact layout is used.
    pub const COMPACT_ABOVE: usize = 1 << 25;

    /// The layout for a volume of `voxels` voxels.
    #[must_use]
    pub fn for_voxels(voxels: usize) -> Self {
        if voxels > Self::COMPACT_ABOVE {
            Layout::Compact
        } else {
            Layout::Exact
        }
    }
}

/// The voxels in their layout.
#[derive(Clone, Debug)]
pub(super) enum Voxels {
    Exact(Vec<[f32; 4]>),
    Compact(Vec<[i16; 4]>, Quantised),
}

impl Voxels {
    /// `volume`'s voxels in `layout`, gradients by central differences one voxel apart (the
    /// outer sample clamped to the grid), turned to world axes.
    pub(super) fn new(volume: &Volume, layout: Layout) -> Self {
        let (samples, range) = (volume.samples(), volume.range());
        let to_world_gradient = volume.to_index().transpose();
        let [nx, ny, nz] = volume.dims();
        let at = |i: usize, j: usize, k: usize| samples[i + nx * (j + ny * k)];
        let gradient = |i: usize, j: usize, k: usize| {
            let (i0, i1) = (i.saturating_sub(1), (i + 1).min(nx - 1));
            let (j0, j1) = (j.saturating_sub(1), (j + 1).min(ny - 1));
            let (k0, k1) = (k.saturating_sub(1), (k + 1).min(nz - 1));
            let along_index = 0.5
                * Vec3::new(
                    at(i1, j, k) - at(i0, j, k),
                    at(i, j1, k) - at(i, j0, k),
                    at(i, j, k1) - at(i, j, k0),
                );
            to_world_gradient * along_index
        };
        match layout {
            Layout::Exact => {
                let mut voxels = vec![[0.0; 4]; samples.len()];
                fill(&mut voxels, nx * ny, nx, |i, j, k| {
                    let g = gradient(i, j, k);
                    [at(i, j, k), g.x, g.y, g.z]
                });
                Voxels::Exact(voxels)
            }
            Layout::Compact => {
                // The steepest a central difference can be along each world axis: half the
                // range along each grid axis, through the map's rows (a bound, not a search,
                // which would cost a second pass over the volume).
                let half_range = 0.5 * (range.1 - range.0);
                let rows = to_world_gradient.transpose();
                let steepest = Vec3::new(
                    rows.x_axis.abs().element_sum(),
                    rows.y_axis.abs().element_sum(),
                    rows.z_axis.abs().element_sum(),
                ) * half_range;
                let quantised = Quantised::new(volume.whole_numbers(), range, steepest);
                let mut voxels = vec![[0_i16; 4]; samples.len()];
                fill(&mut voxels, nx * ny, nx, |i, j, k| {
                    quantised.encode(at(i, j, k), gradient(i, j, k))
                });
                Voxels::Compact(voxels, quantised)
            }
        }
    }

    /// The trilinear value and gradient at `f` in the cell whose first voxel is `at`, on a
    /// grid `nx` voxels wide with `nxy` to a slice. The cell's corners are four pairs of
    /// neighbours along `i`, each pair eight numbers in a row: they are interpolated pairwise
    /// along `y`, then `z` (eight lanes at a time), and the pair's two ends along `x` last.
    #[inline(always)]
    pub(super) fn trilinear(&self, at: usize, f: Vec3, nx: usize, nxy: usize) -> Vec4 {
        match self {
            Voxels::Exact(voxels) => trilinear(at, f, nx, nxy, |voxel| {
                *voxels[voxel..]
                    .as_flattened()
                    .first_chunk()
                    .expect("a cell's corners lie inside the grid")
            }),
            Voxels::Compact(voxels, quantised) => {
                let stored = trilinear(at, f, nx, nxy, |voxel| {
                    let pair: &[i16; 8] = voxels[voxel..]
                        .as_flattened()
                        .first_chunk()
                        .expect("a cell's corners lie inside the grid");
                    pair.map(f32::from)
                });
                quantised.decode(stored)
            }
        }
    }

    /// Every voxel's `(value, world gradient)` as `f32`.
    pub(super) fn exact(&self) -> Cow<'_, [[f32; 4]]> {
        match self {
            Voxels::Exact(voxels) => Cow::Borrowed(voxels),
            Voxels::Compact(voxels, quantised) => Cow::Owned(
                voxels
                    .iter()
                    .map(|voxel| {
                        quantised
                            .decode(Vec4::from_array(voxel.map(f32::from)))
                            .to_array()
                    })
                    .collect(),
            ),
        }
    }

    /// The largest difference between a stored value and the volume's, and between a stored
    /// gradient's components and the exact ones: 0 for the exact layout, half a step for
    /// the compact one.
    pub(super) fn quantisation_error(&self) -> (f32, Vec3) {
        match self {
            Voxels::Exact(_) => (0.0, Vec3::ZERO),
            Voxels::Compact(_, quantised) => {
                let [value, x, y, z] = quantised.scale;
                (0.5 * value, 0.5 * Vec3::new(x, y, z))
            }
        }
    }
}

/// Sets every voxel of `voxels` (slices of `slice` voxels, rows of `nx`) to `voxel(i, j, k)`,
/// in parallel over slices.
fn fill<T: Send>(
    voxels: &mut [T],
    slice: usize,
    nx: usize,
    voxel: impl Fn(usize, usize, usize) -> T + Sync,
) {
    voxels
        .par_chunks_mut(slice)
        .enumerate()
        .for_each(|(k, voxels)| {
            for (j, row) in voxels.chunks_exact_mut(nx).enumerate() {
                for (i, out) in row.iter_mut().enumerate() {
                    *out = voxel(i, j, k);
                }
            }
        });
}

/// [`Voxels::trilinear`] over pairs read by `pair`.
#[inline(always)]
fn trilinear(at: usize, f: Vec3, nx: usize, nxy: usize, pair: impl Fn(usize) -> [f32; 8]) -> Vec4 {
    let near = lerp8(pair(at), pair(at + nx), f.y);
    let far = lerp8(pair(at + nxy), pair(at + nxy + nx), f.y);
    let ends = lerp8(near, far, f.z);
    let low = Vec4::from_slice(&ends[..4]);
    let high = Vec4::from_slice(&ends[4..]);
    low + (high - low) * f.x
}

/// `a + (b - a) t`, lane by lane.
#[inline(always)]
fn lerp8(a: [f32; 8], b: [f32; 8], t: f32) -> [f32; 8] {
    let mut out = a;
    for lane in 0..8 {
        out[lane] = a[lane] + (b[lane] - a[lane]) * t;
    }
    out
}

/// How the compact layout holds a voxel's value and gradient: `stored * scale + offset`
/// per component (value, gradient x, y, z).
#[derive(Clone, Copy, Debug)]
pub(super) struct Quantised {
    scale: [f32; 4],
    inverse_scale: [f32; 4],
    offset: [f32; 4],
}

impl Quantised {
    const LARGEST: f32 = 32_767.0;

    fn new(whole: bool, (lo, hi): (f32, f32), steepest: Vec3) -> Self {
        let (value_scale, value_offset) = if whole && lo >= -Self::LARGEST && hi <= Self::LARGEST {
            (1.0, 0.0)
        } else if hi > lo {
            ((hi - lo) / (2.0 * Self::LARGEST), 0.5 * (lo + hi))
        } else {
            (1.0, lo)
        };
        let step = |largest: f32| {
            if largest > 0.0 {
                largest / Self::LARGEST
            } else {
                1.0
            }
        };
        let scale = [
            value_scale,
            step(steepest.x),
            step(steepest.y),
            step(steepest.z),
        ];
        Self {
            scale,
            inverse_scale: scale.map(|s| 1.0 / s),
            offset: [value_offset, 0.0, 0.0, 0.0],
        }
    }

    /// A voxel's value and world gradient as integers: the nearest, rounded by adding and
    /// taking away `1.5 * 2^23` (the sum's spacing is 1), which needs no library call on a
    /// baseline CPU where `f32::round` does.
    #[inline(always)]
    fn encode(&self, value: f32, gradient: Vec3) -> [i16; 4] {
        const ROUND: f32 = 12_582_912.0;
        let numbers = [value, gradient.x, gradient.y, gradient.z];
        core::array::from_fn(|c| {
            let scaled = ((numbers[c] - self.offset[c]) * self.inverse_scale[c])
                .clamp(-Self::LARGEST, Self::LARGEST);
            ((scaled + ROUND) - ROUND) as i16
        })
    }

    /// A voxel's (or an interpolation of voxels') value and gradient from its integers.
    #[inline(always)]
    fn decode(&self, stored: Vec4) -> Vec4 {
        stored * Vec4::from_array(self.scale) + Vec4::from_array(self.offset)
    }
}
