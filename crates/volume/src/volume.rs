//! The volume: a scalar field on a regular grid, placed in the patient's world.
//!
//! A [`Volume`] holds samples on an `nx x ny x nz` grid (`i` fastest; whole numbers as `i16`,
//! others as `f32`: [`Samples`]), and the affine
//! map from grid indices to world millimetres in the patient's RAS frame, as NIfTI counts it
//! (`+x` towards the patient's Right, `+y` Anterior, `+z` Superior). Sampling is trilinear;
//! gradients are central differences of the trilinear
//! field, one voxel apart, taken to world units by the inverse transpose of the map.

use glam::{Mat3, Vec3};
use thiserror::Error;

use crate::samples::Samples;

/// The most voxels a volume may hold: 2^28 (a 1 GiB `f32` grid, 512 x 512 x 1024).
pub const MAX_VOXELS: usize = 1 << 28;

/// The most voxels along one axis.
pub const MAX_SIDE: usize = 4096;

/// Why a volume could not be built or read.
#[derive(Clone, Debug, Error, PartialEq)]
#[error("{0}")]
pub struct VolumeError(pub String);

/// A scalar volume on a regular grid, placed in world space.
#[derive(Clone, Debug, PartialEq)]
pub struct Volume {
    dims: [usize; 3],
    /// Grid index to world: `world = to_world * index + origin`.
    to_world: Mat3,
    origin: Vec3,
    to_index: Mat3,
    samples: Samples,
    units: Units,
    /// The smallest and largest sample, found once: every render's transfer function and
    /// lighting read it.
    range: (f32, f32),
}

/// What a volume's values mean.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Units {
    /// CT numbers (Hounsfield units: air -1000, water 0, bone several hundred and up).
    Hounsfield,
    /// Values without a fixed scale (MR, phantoms): transfer functions read them relative to
    /// the volume's range.
    #[default]
    Arbitrary,
}

impl Units {
    /// What a volume's values are when its file does not say: Hounsfield units when the
    /// smallest value is that of air or of a scanner's padding outside its field of view
    /// (-3100 to -900: air is -1000 HU, padding -1024, -2048 or -3024) and at least 1 % of
    /// the voxels are air (within 100 of -1000); otherwise arbitrary. MR magnitudes and the
    /// built-in volumes are never negative, so they are never taken for CT.
    #[must_use]
    pub fn from_values(samples: &Samples) -> Self {
        let smallest = samples.iter().fold(f32::INFINITY, f32::min);
        if !(-3100.0..=-900.0).contains(&smallest) {
            return Units::Arbitrary;
        }
        let air = samples
            .iter()
            .filter(|v| (-1100.0..=-900.0).contains(v))
            .count();
        if air * 100 >= samples.len() {
            Units::Hounsfield
        } else {
            Units::Arbitrary
        }
    }
}

impl Volume {
    /// Checks a grid's size before anything is allocated: every side in `[2, MAX_SIDE]` and at
    /// most [`MAX_VOXELS`] voxels.
    pub fn check_dims(dims: [usize; 3]) -> Result<usize, VolumeError> {
        if dims.iter().any(|&d| !(2..=MAX_SIDE).contains(&d)) {
            return Err(VolumeError(format!(
                "a volume of {} x {} x {} voxels: every side must be 2 to {MAX_SIDE}",
                dims[0], dims[1], dims[2]
            )));
        }
        let voxels = dims[0] * dims[1] * dims[2];
        if voxels > MAX_VOXELS {
            return Err(VolumeError(format!(
                "a volume of {} x {} x {} voxels ({voxels}) is over the limit of {MAX_VOXELS} \
                    voxels (1 GiB of f32)",
                dims[0], dims[1], dims[2]
            )));
        }
        Ok(voxels)
    }

    /// A volume of `samples` (`i` fastest) whose index `(i, j, k)` lies at world position
    /// `origin + to_world * (i, j, k)`: `to_world`'s columns are the steps along `i`, `j`
    /// and `k`, in millimetres. Refused when the grid is out of bounds, the sample count
    /// differs, a sample is not finite, or the map is singular or not finite.
    pub fn try_new(
        dims: [usize; 3],
        to_world: Mat3,
        origin: Vec3,
        samples: Vec<f32>,
        units: Units,
    ) -> Result<Self, VolumeError> {
        Self::from_samples(dims, to_world, origin, Samples::new(samples), units)
    }

    /// [`Volume::try_new`] with samples already in their form (integers read from a file).
    pub fn from_samples(
        dims: [usize; 3],
        to_world: Mat3,
        origin: Vec3,
        samples: Samples,
        units: Units,
    ) -> Result<Self, VolumeError> {
        let voxels = Self::check_dims(dims)?;
        if samples.len() != voxels {
            return Err(VolumeError(format!(
                "{} samples for a {} x {} x {} grid ({voxels} expected)",
                samples.len(),
                dims[0],
                dims[1],
                dims[2]
            )));
        }
        // Integers are always finite: only `f32` samples need looking at.
        if let Samples::Float(values) = &samples {
            if let Some(at) = values.iter().position(|v| !v.is_finite()) {
                return Err(VolumeError(format!(
                    "voxel {at} is {}; every sample must be finite",
                    values[at]
                )));
            }
        }
        let determinant = to_world.determinant();
        if !(to_world.is_finite() && origin.is_finite() && determinant.abs() > 1e-12) {
            return Err(VolumeError(
                "the voxel spacing and orientation must be finite and non-degenerate (a zero \
                    spacing or parallel axes cannot place the voxels)"
                    .into(),
            ));
        }
        let range = samples
            .iter()
            .fold((f32::INFINITY, f32::NEG_INFINITY), |(lo, hi), v| {
                (lo.min(v), hi.max(v))
            });
        Ok(Self {
            dims,
            to_world,
            origin,
            to_index: to_world.inverse(),
            samples,
            units,
            range,
        })
    }

    /// An axis-aligned volume with `spacing` millimetres between voxels, centred on the origin.
    pub fn centred(
        dims: [usize; 3],
        spacing: Vec3,
        samples: Vec<f32>,
        units: Units,
    ) -> Result<Self, VolumeError> {
        let extent = Vec3::new(
            (dims[0] - 1) as f32,
            (dims[1] - 1) as f32,
            (dims[2] - 1) as f32,
        ) * spacing;
        Self::try_new(
            dims,
            Mat3::from_diagonal(spacing),
            -0.5 * extent,
            samples,
            units,
        )
    }

    /// Whether every sample is a whole number (a CT in Hounsfield units, an integer MRI), so
    /// that integers can hold the volume exactly.
    #[must_use]
    pub fn whole_numbers(&self) -> bool {
        match &self.samples {
            Samples::Whole(_) => true,
            Samples::Float(values) => values.iter().all(|&v| v == v.trunc()),
        }
    }

    /// The grid's size.
    #[must_use]
    pub fn dims(&self) -> [usize; 3] {
        self.dims
    }

    /// The samples, `i` fastest.
    #[must_use]
    pub fn samples(&self) -> &Samples {
        &self.samples
    }

    /// What the values mean.
    #[must_use]
    pub fn units(&self) -> Units {
        self.units
    }

    /// Grid index to world (millimetres): the map's linear part.
    #[must_use]
    pub fn to_world(&self) -> Mat3 {
        self.to_world
    }

    /// World to grid index: the inverse of [`Volume::to_world`], computed once.
    #[must_use]
    pub fn to_index(&self) -> Mat3 {
        self.to_index
    }

    /// The world position of voxel `(0, 0, 0)`.
    #[must_use]
    pub fn origin(&self) -> Vec3 {
        self.origin
    }

    /// The distance between neighbouring voxels along each grid axis, in millimetres.
    #[must_use]
    pub fn spacing(&self) -> Vec3 {
        Vec3::new(
            self.to_world.x_axis.length(),
            self.to_world.y_axis.length(),
            self.to_world.z_axis.length(),
        )
    }

    /// The world position of a (fractional) grid index.
    #[must_use]
    pub fn world(&self, index: Vec3) -> Vec3 {
        self.to_world * index + self.origin
    }

    /// The (fractional) grid index of a world position.
    #[must_use]
    pub fn index(&self, world: Vec3) -> Vec3 {
        self.index_direction(world - self.origin)
    }

    /// The largest grid index along each axis: the grid spans `[0, last_index]`.
    #[must_use]
    pub fn last_index(&self) -> Vec3 {
        Vec3::new(
            (self.dims[0] - 1) as f32,
            (self.dims[1] - 1) as f32,
            (self.dims[2] - 1) as f32,
        )
    }

    /// A world direction (or displacement) in grid index units.
    #[must_use]
    pub fn index_direction(&self, world: Vec3) -> Vec3 {
        self.to_index * world
    }

    /// The eight corners of the grid in world space.
    #[must_use]
    pub fn corners(&self) -> [Vec3; 8] {
        let top = self.last_index();
        core::array::from_fn(|c| {
            let pick = |bit: usize, high: f32| if c >> bit & 1 == 1 { high } else { 0.0 };
            self.world(Vec3::new(pick(0, top.x), pick(1, top.y), pick(2, top.z)))
        })
    }

    /// The smallest and largest sample.
    #[must_use]
    pub fn range(&self) -> (f32, f32) {
        self.range
    }

    /// The sample at a whole index, clamped to the grid.
    #[must_use]
    pub fn at(&self, i: isize, j: isize, k: isize) -> f32 {
        let clamp = |v: isize, d: usize| v.clamp(0, d as isize - 1) as usize;
        let (i, j, k) = (
            clamp(i, self.dims[0]),
            clamp(j, self.dims[1]),
            clamp(k, self.dims[2]),
        );
        self.samples.get(i + self.dims[0] * (j + self.dims[1] * k))
    }

    /// The trilinear interpolation at a fractional grid index (clamped to the grid).
    #[must_use]
    pub fn sample(&self, index: Vec3) -> f32 {
        let p = index.clamp(Vec3::ZERO, self.last_index());
        let base = p.floor();
        let f = p - base;
        let (i, j, k) = (base.x as isize, base.y as isize, base.z as isize);
        let lerp = |a: f32, b: f32, t: f32| a + (b - a) * t;
        let row = |j: isize, k: isize| lerp(self.at(i, j, k), self.at(i + 1, j, k), f.x);
        let plane = |k: isize| lerp(row(j, k), row(j + 1, k), f.y);
        lerp(plane(k), plane(k + 1), f.z)
    }

    /// The gradient at a fractional grid index, in value per millimetre: central differences
    /// of the trilinear field one voxel apart along each grid axis, then to world axes (within
    /// a voxel of the boundary the outer sample is clamped to the grid).
    #[must_use]
    pub fn gradient(&self, index: Vec3) -> Vec3 {
        let difference = |axis: Vec3| 0.5 * (self.sample(index + axis) - self.sample(index - axis));
        let along_index = Vec3::new(
            difference(Vec3::X),
            difference(Vec3::Y),
            difference(Vec3::Z),
        );
        self.to_index.transpose() * along_index
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A linear field `a . world + b` on a sheared, scaled grid.
    fn linear(a: Vec3, b: f32) -> Volume {
        let to_world = Mat3::from_cols(
            Vec3::new(0.8, 0.0, 0.0),
            Vec3::new(0.3, 1.1, 0.0),
            Vec3::new(0.0, 0.2, 2.5),
        );
        let origin = Vec3::new(-3.0, 1.0, 4.0);
        let dims = [6, 5, 4];
        let mut samples = Vec::new();
        for k in 0..dims[2] {
            for j in 0..dims[1] {
                for i in 0..dims[0] {
                    let world = to_world * Vec3::new(i as f32, j as f32, k as f32) + origin;
                    samples.push(a.dot(world) + b);
                }
            }
        }
        Volume::try_new(dims, to_world, origin, samples, Units::Arbitrary).unwrap()
    }

    #[test]
    fn trilinear_sampling_and_gradients_are_exact_on_a_linear_field() {
        let a = Vec3::new(0.5, -1.5, 2.0);
        let volume = linear(a, 3.0);
        for index in [
            Vec3::new(1.5, 2.25, 1.75),
            Vec3::new(3.1, 1.9, 1.6),
            Vec3::new(2.0, 2.0, 1.0),
        ] {
            let world = volume.world(index);
            assert!((volume.sample(index) - (a.dot(world) + 3.0)).abs() < 1e-4);
            assert!((volume.gradient(index) - a).length() < 1e-4);
            assert!((volume.index(world) - index).length() < 1e-5);
        }
    }

    #[test]
    fn sizes_are_refused_before_allocation() {
        let refused = Volume::check_dims([100_000, 100_000, 100_000]).unwrap_err();
        assert!(
            refused.0.contains("every side must be 2 to 4096"),
            "{refused}"
        );
        let refused = Volume::check_dims([4096, 4096, 4096]).unwrap_err();
        assert!(refused.0.contains("over the limit"), "{refused}");
        assert!(Volume::check_dims([1, 4, 4]).is_err());
    }

    #[test]
    fn bad_grids_are_refused_with_the_reason() {
        let refused =
            Volume::centred([2, 2, 2], Vec3::ONE, vec![0.0; 7], Units::Arbitrary).unwrap_err();
        assert!(refused.0.contains("7 samples"), "{refused}");
        let mut samples = vec![0.0; 8];
        samples[5] = f32::NAN;
        let refused = Volume::centred([2, 2, 2], Vec3::ONE, samples, Units::Arbitrary).unwrap_err();
        assert!(refused.0.contains("voxel 5"), "{refused}");
        let refused = Volume::centred(
            [2, 2, 2],
            Vec3::new(1.0, 0.0, 1.0),
            vec![0.0; 8],
            Units::Arbitrary,
        )
        .unwrap_err();
        assert!(refused.0.contains("non-degenerate"), "{refused}");
    }
}
