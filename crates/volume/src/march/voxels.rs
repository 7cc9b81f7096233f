//! The prepared voxels: each voxel's value and world gradient, in one of two layouts.
//!
//! - [`Layout::Exact`]: four `f32` (16 bytes), a voxel and its neighbour along `i` one
//!   256-bit read. Fastest while the march is bound by its instructions (measured on the real
//!   CT and MRI, about 7 million voxels each: the compact layout's conversions cost the MRI,
//!   nearly every sample shaded, 5-9 % a frame).
//! - [`Layout::Compact`]: integers with a scale and offset per component: the value (2
//!   bytes; for a scan of whole numbers within `i16`, a CT in Hounsfield units, the volume's
//!   own [`Samples::Whole`], shared, not copied) and the gradient (three `i16`, 6 bytes) in
//!   two arrays. Half the memory, and half the traffic once the volume outgrows the caches (a
//!   512 x 512 x 432 CT: 17 % faster frames; volume and prepared voxels 8 bytes a voxel
//!   where `f32` samples and exact voxels take 20). Gradients are spread over the integers
//!   by the steepest a central difference can be along each axis (half the value range
//!   through the grid's map), so each is within half a step
//!   ([`Voxels::quantisation_error`]). The integers are interpolated and scaled once: the
//!   interpolation is linear, so scaling the result is scaling the corners.
//!
//! [`Layout::for_voxels`] picks the compact layout above [`Layout::COMPACT_ABOVE`] voxels.

use std::borrow::Cow;
use std::sync::Arc;

use glam::{Mat3, Vec3, Vec4};
use rayon::prelude::*;

use specula::simd::{Lanes, Prefetch};

use crate::samples::{Sample, Samples};
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
    /// The values as integers (the volume's own when it holds them so, [`Samples::Whole`])
    /// and the gradients beside them, three integers a voxel and one voxel's more at the end
    /// (a pair's six integers are read eight at a time, with the values put in the last two).
    Compact {
        values: Arc<Vec<i16>>,
        gradients: Vec<[i16; 3]>,
        quantised: Quantised,
    },
}

impl Voxels {
    /// `volume`'s voxels in `layout`, gradients by central differences one voxel apart (the
    /// outer sample clamped to the grid), turned to world axes.
    pub(super) fn new(volume: &Volume, layout: Layout) -> Self {
        match volume.samples() {
            Samples::Whole(values) => Self::of(volume, values, layout),
            Samples::Float(values) => Self::of(volume, values, layout),
        }
    }

    /// [`Voxels::new`] over the volume's `samples`.
    fn of<T: Sample>(volume: &Volume, samples: &[T], layout: Layout) -> Self {
        let range = volume.range();
        let to_world_gradient = volume.to_index().transpose();
        let dims = volume.dims();
        match layout {
            Layout::Exact => {
                let mut voxels = vec![[0.0; 4]; samples.len()];
                fill_gradients(samples, dims, to_world_gradient, &mut voxels, |value, g| {
                    [value, g.x, g.y, g.z]
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
                let held = match volume.samples() {
                    Samples::Whole(values) => Some(values),
                    Samples::Float(_) => None,
                };
                let quantised = Quantised::new(held.is_some(), range, steepest);
                let values = held.map_or_else(
                    || {
                        let encoded = samples
                            .par_iter()
                            .map(|&v| quantised.encode_value(v.into()))
                            .collect();
                        Arc::new(encoded)
                    },
                    Arc::clone,
                );
                let mut gradients = vec![[0_i16; 3]; samples.len() + 1];
                fill_gradients(
                    samples,
                    dims,
                    to_world_gradient,
                    &mut gradients[..samples.len()],
                    |_, g| quantised.encode_gradient(g),
                );
                Voxels::Compact {
                    values,
                    gradients,
                    quantised,
                }
            }
        }
    }

    /// The trilinear value and gradient at `f` in the cell whose first voxel is `at`, on a
    /// grid `nx` voxels wide with `nxy` to a slice. The cell's corners are four pairs of
    /// neighbours along `i`, each pair eight numbers in a row: they are interpolated pairwise
    /// along `y`, then `z` (in `lanes`, eight numbers to a 256-bit vector), and the pair's two
    /// ends along `x` last.
    #[inline(always)]
    pub(super) fn trilinear<V: Lanes>(
        &self,
        lanes: V,
        at: usize,
        f: Vec3,
        nx: usize,
        nxy: usize,
    ) -> Vec4 {
        match self {
            Voxels::Exact(voxels) => {
                let ends = trilinear_lanes(lanes, at, nx, nxy, f, |voxel| {
                    *voxels[voxel..]
                        .as_flattened()
                        .first_chunk()
                        .expect("a cell's corners lie inside the grid")
                });
                let low = Vec4::from_slice(&ends[..4]);
                let high = Vec4::from_slice(&ends[4..]);
                low + (high - low) * f.x
            }
            Voxels::Compact {
                values,
                gradients,
                quantised,
            } => {
                // Lanes `[x0, y0, z0, x1, y1, z1, v0, v1]`: one 16-byte read of the pair's
                // gradients (and two integers past them), its last two lanes the values.
                let lanes = trilinear_lanes(lanes, at, nx, nxy, f, |voxel| {
                    let mut pair = *gradients[voxel..]
                        .as_flattened()
                        .first_chunk::<8>()
                        .expect("a cell's corners lie inside the grid");
                    let [v0, v1] = *values[voxel..]
                        .first_chunk()
                        .expect("a cell's corners lie inside the grid");
                    pair[6] = v0;
                    pair[7] = v1;
                    pair.map(f32::from)
                });
                let low = Vec4::new(lanes[6], lanes[0], lanes[1], lanes[2]);
                let high = Vec4::new(lanes[7], lanes[3], lanes[4], lanes[5]);
                quantised.decode(low + (high - low) * f.x)
            }
        }
    }

    /// Voxel `voxel`'s value, as the interpolation reads it.
    pub(super) fn value(&self, voxel: usize) -> f32 {
        match self {
            Voxels::Exact(voxels) => voxels[voxel][0],
            Voxels::Compact {
                values, quantised, ..
            } => {
                quantised
                    .decode(Vec4::new(f32::from(values[voxel]), 0.0, 0.0, 0.0))
                    .x
            }
        }
    }

    /// The layout.
    pub(super) fn layout(&self) -> Layout {
        match self {
            Voxels::Exact(_) => Layout::Exact,
            Voxels::Compact { .. } => Layout::Compact,
        }
    }

    /// Asks for the cache lines of the cell whose first voxel is `at` (on a grid `nx` voxels
    /// wide with `nxy` to a slice): each of its four rows' pair of voxels, the pair's end too
    /// where it may lie on the next line. Every row, not only the first of each slice: a ray
    /// along `j` reaches the next row a step later, yet asking for it as well made the
    /// clinical-size CT's frames 2-3 % faster (and the pairs' ends another 4 %).
    #[inline(always)]
    pub(super) fn prefetch(&self, at: usize, nx: usize, nxy: usize, prefetch: Prefetch) {
        for row in [at, at + nx, at + nxy, at + nxy + nx] {
            match self {
                Voxels::Exact(voxels) => {
                    prefetch.line(&voxels[row]);
                    prefetch.line(&voxels[row + 1]);
                }
                Voxels::Compact {
                    values, gradients, ..
                } => {
                    prefetch.line(&values[row]);
                    prefetch.line(&gradients[row]);
                    prefetch.line(&gradients[row + 2]);
                }
            }
        }
    }

    /// Every voxel's `(value, world gradient)` as `f32`.
    pub(super) fn exact(&self) -> Cow<'_, [[f32; 4]]> {
        match self {
            Voxels::Exact(voxels) => Cow::Borrowed(voxels),
            Voxels::Compact {
                values,
                gradients,
                quantised,
            } => Cow::Owned(
                values
                    .iter()
                    .zip(gradients)
                    .map(|(&value, &[x, y, z])| {
                        quantised
                            .decode(Vec4::from_array([value, x, y, z].map(f32::from)))
                            .to_array()
                    })
                    .collect(),
            ),
        }
    }

    /// The largest difference between a stored value and the volume's, and between a stored
    /// gradient's components and the exact ones: 0 for the exact layout, half a step for
    /// the compact one (0 for values it reads from the volume's own integers).
    pub(super) fn quantisation_error(&self) -> (f32, Vec3) {
        match self {
            Voxels::Exact(_) => (0.0, Vec3::ZERO),
            Voxels::Compact { quantised, .. } => {
                let [value, x, y, z] = quantised.scale;
                let value = if quantised.exact_values {
                    0.0
                } else {
                    0.5 * value
                };
                (value, 0.5 * Vec3::new(x, y, z))
            }
        }
    }
}

/// Sets `out[v]` to `voxel(value, gradient)` for every voxel `v` of `samples` (a grid of
/// `dims`), the gradient by central differences one voxel apart (the outer sample clamped to
/// the grid) turned to world axes by `to_world_gradient`. Row by row, in parallel over
/// slices: a row and its four neighbours along `j` and `k` are read side by side, with no
/// index arithmetic per voxel (against a closure over `(i, j, k)`: a clinical-size CT's
/// compact voxels 1.6 -> 0.49 s, the real CT's exact ones 47 -> 31 ms).
fn fill_gradients<T: Sample, O: Send>(
    samples: &[T],
    [nx, ny, nz]: [usize; 3],
    to_world_gradient: Mat3,
    out: &mut [O],
    voxel: impl Fn(f32, Vec3) -> O + Sync,
) {
    let row = |j: usize, k: usize| &samples[nx * (j + ny * k)..][..nx];
    out.par_chunks_mut(nx * ny)
        .enumerate()
        .for_each(|(k, slice)| {
            let (k0, k1) = (k.saturating_sub(1), (k + 1).min(nz - 1));
            for (j, out) in slice.chunks_exact_mut(nx).enumerate() {
                let (j0, j1) = (j.saturating_sub(1), (j + 1).min(ny - 1));
                let (here, before_j, after_j, before_k, after_k) =
                    (row(j, k), row(j0, k), row(j1, k), row(j, k0), row(j, k1));
                for (i, out) in out.iter_mut().enumerate() {
                    let (i0, i1) = (i.saturating_sub(1), (i + 1).min(nx - 1));
                    let difference = |a: T, b: T| 0.5 * (a.into() - b.into());
                    let along_index = Vec3::new(
                        difference(here[i1], here[i0]),
                        difference(after_j[i], before_j[i]),
                        difference(after_k[i], before_k[i]),
                    );
                    *out = voxel(here[i].into(), to_world_gradient * along_index);
                }
            }
        });
}

/// The cell's four pairs read by `pair`, interpolated along `y` and `z` in `lanes`: what is
/// left is the pair's two ends along `x`.
#[inline(always)]
fn trilinear_lanes<V: Lanes>(
    lanes: V,
    at: usize,
    nx: usize,
    nxy: usize,
    f: Vec3,
    pair: impl Fn(usize) -> [f32; 8],
) -> [f32; 8] {
    let corners = [pair(at), pair(at + nx), pair(at + nxy), pair(at + nxy + nx)];
    let (fy, fz) = (lanes.splat(f.y), lanes.splat(f.z));
    let lerp = |a: V, b: V, t: V| a + (b - a) * t;
    let mut ends = [0.0; 8];
    for at in (0..8).step_by(V::WIDTH) {
        let [a, b, c, d] = corners.map(|corner| lanes.load(&corner[at..at + V::WIDTH]));
        lerp(lerp(a, b, fy), lerp(c, d, fy), fz).store(&mut ends[at..at + V::WIDTH]);
    }
    ends
}

/// How the compact layout holds a voxel's value and gradient: `stored * scale + offset`
/// per component (value, gradient x, y, z).
#[derive(Clone, Copy, Debug)]
pub(super) struct Quantised {
    scale: [f32; 4],
    inverse_scale: [f32; 4],
    offset: [f32; 4],
    /// Whether the stored values are the volume's own (its integers, or its one value).
    exact_values: bool,
}

impl Quantised {
    const LARGEST: f32 = 32_767.0;

    /// Integers for values in `[lo, hi]` (the volume's own when `integers`: scale 1, offset
    /// 0) and for gradients up to `steepest` along each world axis.
    fn new(integers: bool, (lo, hi): (f32, f32), steepest: Vec3) -> Self {
        let (value_scale, value_offset) = if integers {
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
            exact_values: integers || hi <= lo,
        }
    }

    /// A value as an integer: the nearest, rounded by adding and taking away `1.5 * 2^23`
    /// (the sum's spacing is 1), which needs no library call on a baseline CPU where
    /// `f32::round` does.
    #[inline(always)]
    fn encode_value(&self, value: f32) -> i16 {
        self.encode(0, value)
    }

    /// A world gradient as integers ([`Quantised::encode_value`]'s rounding).
    #[inline(always)]
    fn encode_gradient(&self, gradient: Vec3) -> [i16; 3] {
        [
            self.encode(1, gradient.x),
            self.encode(2, gradient.y),
            self.encode(3, gradient.z),
        ]
    }

    /// Component `c`'s `number` as its nearest integer.
    #[inline(always)]
    fn encode(&self, c: usize, number: f32) -> i16 {
        const ROUND: f32 = 12_582_912.0;
        let scaled = ((number - self.offset[c]) * self.inverse_scale[c])
            .clamp(-Self::LARGEST, Self::LARGEST);
        ((scaled + ROUND) - ROUND) as i16
    }

    /// A voxel's (or an interpolation of voxels') value and gradient from its integers.
    #[inline(always)]
    fn decode(&self, stored: Vec4) -> Vec4 {
        stored * Vec4::from_array(self.scale) + Vec4::from_array(self.offset)
    }
}
