//! The environment map's sampling weights: each texel's luminance times the solid angle of
//! its row (`sin theta`), made a row at a time (for the alias table's rows and the texels'
//! densities) or whole (for the `f64` distribution, on first use), and the check that a map's
//! radiance is finite and non-negative.

use core::f64::consts::PI;

use glam::Vec3;
use rayon::prelude::*;

use crate::image::Image;

/// Rec. 709 luminance weights: how bright a linear RGB radiance looks.
pub(super) const LUMINANCE: Vec3 = Vec3::new(0.2126, 0.7152, 0.0722);

/// Each pixel's weight for sampling: its luminance times `sin theta` at its row's middle,
/// row by row on every thread.
pub(super) fn weights_of(image: &Image) -> Vec<f64> {
    let (width, sines) = (image.width().max(1) as usize, row_sines(image.height()));
    let mut weights = vec![0.0; image.pixels().len()];
    weights
        .par_chunks_mut(width)
        .zip(image.pixels().par_chunks(width))
        .zip(sines.par_iter())
        .for_each(|((weights, pixels), &sine)| row_weights(pixels, sine, weights));
    weights
}

/// `sin theta` at the middle of each of `height` rows: the solid angle a row's texels span,
/// up to a constant.
pub(super) fn row_sines(height: u32) -> Vec<f64> {
    (0..height)
        .map(|row| (PI * (f64::from(row) + 0.5) / f64::from(height)).sin())
        .collect()
}

/// The sampling weight of a texel of `radiance` in a row of `sine`: its luminance times the
/// solid angle.
#[inline]
pub(super) fn weight(radiance: Vec3, sine: f64) -> f64 {
    f64::from(radiance.dot(LUMINANCE)) * sine
}

/// The weights of a row of `pixels` whose `sin theta` is `sine`, into `weights`.
pub(super) fn row_weights(pixels: &[Vec3], sine: f64, weights: &mut [f64]) {
    for (out, &pixel) in weights.iter_mut().zip(pixels) {
        *out = weight(pixel, sine);
    }
}

/// The first channel of `image` (its pixel's index and its value) that is NaN, infinite or
/// negative. Each row is tested without a branch per channel (a map of megabytes is almost
/// always clean), and only a row that fails is searched.
pub(super) fn first_bad_channel(image: &Image) -> Option<(usize, f32)> {
    let bad = |v: f32| !(0.0..f32::INFINITY).contains(&v);
    let width = image.width().max(1) as usize;
    let row = image.pixels().par_chunks(width).position_first(|pixels| {
        pixels
            .iter()
            .fold(false, |any, p| any | bad(p.x) | bad(p.y) | bad(p.z))
    })?;
    image.pixels()[row * width..]
        .iter()
        .enumerate()
        .find_map(|(index, pixel)| {
            let value = pixel.to_array().into_iter().find(|&v| bad(v))?;
            Some((row * width + index, value))
        })
}
