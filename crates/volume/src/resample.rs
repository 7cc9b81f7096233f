//! A volume resampled onto another grid over the same extent: how a clinical-size scan is
//! made from a smaller real one for benchmarks (`specula volume-convert --resample`), the
//! way a scanner's reconstruction at a finer spacing would place it.

use glam::{Mat3, Vec3};
use rayon::prelude::*;

use crate::volume::{Volume, VolumeError};

impl Volume {
    /// The volume on a grid of `dims` spanning the same extent (the first and last voxels'
    /// centres where this grid's are), each sample the trilinear interpolation of this
    /// volume there, rounded to a whole number when every sample here is one (a CT's
    /// Hounsfield units stay integers). Refused as [`Volume::check_dims`] refuses a grid.
    pub fn resampled(&self, dims: [usize; 3]) -> Result<Volume, VolumeError> {
        let voxels = Self::check_dims(dims)?;
        let old = self.dims();
        // Index along each axis of the new grid to index of this one.
        let step =
            Vec3::from_array([0, 1, 2].map(|a| (old[a] - 1) as f32 / (dims[a] - 1).max(1) as f32));
        let whole = self.whole_numbers();
        let mut samples = vec![0.0_f32; voxels];
        samples
            .par_chunks_mut(dims[0] * dims[1])
            .enumerate()
            .for_each(|(k, slice)| {
                for (index, value) in slice.iter_mut().enumerate() {
                    let (i, j) = (index % dims[0], index / dims[0]);
                    let at = Vec3::new(i as f32, j as f32, k as f32) * step;
                    let sample = self.sample(at);
                    *value = if whole { sample.round() } else { sample };
                }
            });
        let to_world = self.to_world() * Mat3::from_diagonal(step);
        Volume::try_new(dims, to_world, self.origin(), samples, self.units())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::volume::Units;

    /// A linear field on a sheared grid.
    fn linear(dims: [usize; 3], value: impl Fn(Vec3) -> f32) -> Volume {
        let to_world = Mat3::from_cols(
            Vec3::new(0.8, 0.0, 0.0),
            Vec3::new(0.3, 1.1, 0.0),
            Vec3::new(0.0, 0.2, 2.5),
        );
        let origin = Vec3::new(-3.0, 1.0, 4.0);
        let mut samples = Vec::new();
        for k in 0..dims[2] {
            for j in 0..dims[1] {
                for i in 0..dims[0] {
                    let index = Vec3::new(i as f32, j as f32, k as f32);
                    samples.push(value(origin + to_world * index));
                }
            }
        }
        Volume::try_new(dims, to_world, origin, samples, Units::Arbitrary).unwrap()
    }

    /// Trilinear interpolation reproduces a linear field, so the resampled volume holds the
    /// field at its own voxels' world positions, over the same corners.
    #[test]
    fn a_linear_field_resamples_to_itself() {
        let field = |p: Vec3| 0.7 * p.x - 1.3 * p.y + 0.25 * p.z + 0.1;
        let original = linear([6, 5, 4], field);
        let resampled = original.resampled([11, 7, 9]).unwrap();
        assert_eq!(resampled.dims(), [11, 7, 9]);
        for (a, b) in resampled.corners().iter().zip(original.corners()) {
            assert!((*a - b).length() < 1e-4, "{a} {b}");
        }
        for (n, value) in resampled.samples().iter().enumerate() {
            let index = Vec3::new((n % 11) as f32, (n / 11 % 7) as f32, (n / 77) as f32);
            let expected = field(resampled.world(index));
            assert!((value - expected).abs() < 1e-4, "{n}: {value} {expected}");
        }
    }

    /// Whole-numbered scans stay whole; the same grid gives the same samples; a grid out of
    /// bounds is refused.
    #[test]
    fn whole_numbers_stay_whole_and_bad_grids_are_refused() {
        let original = linear([5, 4, 3], |p| (3.0 * p.x).round());
        let resampled = original.resampled([9, 9, 9]).unwrap();
        assert!(resampled.samples().iter().all(|v| v == v.trunc()));
        assert_eq!(
            original.resampled([5, 4, 3]).unwrap().samples(),
            original.samples()
        );
        assert!(original.resampled([1, 4, 3]).is_err());
    }
}
