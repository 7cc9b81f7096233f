//! Image differences: PSNR, the largest absolute error and FLIP; and, in linear radiance,
//! the RMS difference and mean that compare two Monte Carlo renders ([`rms_difference`],
//! [`mean_radiance`]).
//!
//! All three compare what a viewer sees: both images are taken through the same [`Display`]
//! (exposure, tone map, sRGB curve, 8 bits), exactly as a PNG stores them. FLIP is NVIDIA's
//! perceptual error (Andersson et al. 2020) computed by the reference implementation through the
//! `nv-flip` crate, at its default 67 pixels per degree (a 0.7 m viewing distance from a
//! 24-inch 4K monitor); its mean over the image is reported, with a per-pixel map for heatmaps.

use thiserror::Error;

use crate::image::{Display, Image};

/// The RMS over pixels of the difference of two linear images of one size (the length of
/// each pixel's RGB difference): two renders' disagreement, to hold against the same figure
/// between two seeds of one renderer (its noise).
#[must_use]
pub fn rms_difference(a: &Image, b: &Image) -> f64 {
    let sum: f64 = a
        .pixels()
        .iter()
        .zip(b.pixels())
        .map(|(p, q)| f64::from((*p - *q).length_squared()))
        .sum();
    (sum / a.pixels().len().max(1) as f64).sqrt()
}

/// The mean over pixels of `r + g + b`: a render's brightness, whose ratio between two
/// renders shows a bias.
#[must_use]
pub fn mean_radiance(image: &Image) -> f64 {
    image
        .pixels()
        .iter()
        .map(|p| f64::from(p.x + p.y + p.z))
        .sum::<f64>()
        / image.pixels().len().max(1) as f64
}

/// Two images that cannot be compared.
#[derive(Clone, Debug, Error, PartialEq)]
#[error(
    "the images differ in size: {0}x{1} and {2}x{3}; only images of the same size can be compared"
)]
pub struct SizeMismatch(pub u32, pub u32, pub u32, pub u32);

/// How two images differ.
#[derive(Clone, Debug, PartialEq)]
pub struct Difference {
    /// Peak signal-to-noise ratio in dB over the sRGB values in `[0, 1]` (infinite when equal).
    pub psnr_db: f64,
    /// The largest absolute difference of an sRGB value in `[0, 1]`.
    pub max_abs_error: f64,
    /// The mean FLIP error in `[0, 1]`.
    pub mean_flip: f64,
    /// The per-pixel FLIP error, row-major.
    pub flip_map: Vec<f32>,
    /// Width of the images.
    pub width: u32,
    /// Height of the images.
    pub height: u32,
}

/// Compares `test` with `reference` as displayed through `display`.
pub fn compare(
    reference: &Image,
    test: &Image,
    display: Display,
) -> Result<Difference, SizeMismatch> {
    let (width, height) = (reference.width(), reference.height());
    if (width, height) != (test.width(), test.height()) {
        return Err(SizeMismatch(width, height, test.width(), test.height()));
    }
    let (a, b) = (reference.to_srgb8(display), test.to_srgb8(display));
    Ok(compare_srgb8(width, height, &a, &b))
}

/// Compares two 8-bit sRGB images (three bytes per pixel) of the same size.
#[must_use]
pub fn compare_srgb8(width: u32, height: u32, reference: &[u8], test: &[u8]) -> Difference {
    let (mut squared, mut max_abs) = (0.0_f64, 0.0_f64);
    for (&x, &y) in reference.iter().zip(test) {
        let d = (f64::from(x) - f64::from(y)).abs() / 255.0;
        squared += d * d;
        max_abs = max_abs.max(d);
    }
    let mse = squared / reference.len().max(1) as f64;
    // An image against itself (a grid's reference column) is 0 everywhere, as FLIP's own
    // map is (tested), without FLIP's filters.
    let flip_map = if reference == test {
        vec![0.0; reference.len() / 3]
    } else {
        flip(width, height, reference, test)
    };
    let mean_flip =
        flip_map.iter().map(|&v| f64::from(v)).sum::<f64>() / flip_map.len().max(1) as f64;
    Difference {
        psnr_db: -10.0 * mse.log10(),
        max_abs_error: max_abs,
        mean_flip,
        flip_map,
        width,
        height,
    }
}

fn flip(width: u32, height: u32, reference: &[u8], test: &[u8]) -> Vec<f32> {
    let image = |bytes: &[u8]| nv_flip::FlipImageRgb8::with_data(width, height, bytes);
    nv_flip::flip(
        image(reference),
        image(test),
        nv_flip::DEFAULT_PIXELS_PER_DEGREE,
    )
    .to_vec()
}

impl Difference {
    /// The FLIP map coloured with FLIP's magma map, as 8-bit sRGB bytes.
    #[must_use]
    pub fn heatmap_srgb8(&self) -> Vec<u8> {
        magma_srgb8(&self.flip_map)
    }

    /// The FLIP map over `scale` (the FLIP value drawn at the map's bright end; values above
    /// it drawn there too), in FLIP's magma map: a scale below 1 shows small differences that
    /// FLIP's own scale leaves black.
    #[must_use]
    pub fn heatmap_srgb8_scaled(&self, scale: f32) -> Vec<u8> {
        let scaled: Vec<f32> = self.flip_map.iter().map(|&v| v / scale).collect();
        magma_srgb8(&scaled)
    }
}

/// Each value in `[0, 1]` (clamped) in FLIP's magma colour map, as 8-bit sRGB bytes.
#[must_use]
pub fn magma_srgb8(values: &[f32]) -> Vec<u8> {
    let lut = nv_flip::magma_lut().to_vec();
    values
        .iter()
        .flat_map(|&v| {
            let k = 3 * (v.clamp(0.0, 1.0) * 255.0).round() as usize;
            [lut[k], lut[k + 1], lut[k + 2]]
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use glam::Vec3;

    use super::*;

    #[test]
    fn identical_images_have_infinite_psnr_and_zero_flip() {
        let image = Image::from_pixels(2, 2, vec![Vec3::new(0.2, 0.5, 0.9); 4]).unwrap();
        let d = compare(&image, &image, Display::default()).unwrap();
        assert!(d.psnr_db.is_infinite() && d.max_abs_error == 0.0 && d.mean_flip == 0.0);
    }

    /// FLIP's own map of a textured image against itself is 0 everywhere, as
    /// `compare_srgb8` gives without running it.
    #[test]
    fn flip_of_an_image_against_itself_is_zero() {
        let bytes: Vec<u8> = (0..3 * 48 * 40_u32)
            .map(|i| (i.wrapping_mul(2_654_435_761) >> 24) as u8)
            .collect();
        assert!(flip(48, 40, &bytes, &bytes).iter().all(|&v| v == 0.0));
        let d = compare_srgb8(48, 40, &bytes, &bytes);
        assert!(d.flip_map.len() == 48 * 40 && d.mean_flip == 0.0 && d.psnr_db.is_infinite());
    }

    #[test]
    fn psnr_of_a_uniform_offset_is_its_closed_form() {
        // Every value off by 10/255: MSE = (10/255)^2, PSNR = 20 log10(255/10).
        let a = vec![100_u8; 3 * 64 * 64];
        let b = vec![110_u8; 3 * 64 * 64];
        let d = compare_srgb8(64, 64, &a, &b);
        assert!((d.psnr_db - 20.0 * (25.5_f64).log10()).abs() < 1e-9);
        assert!((d.max_abs_error - 10.0 / 255.0).abs() < 1e-12);
    }

    #[test]
    fn flip_grows_with_the_difference_and_maps_black_to_white_near_one() {
        let black = vec![0_u8; 3 * 32 * 32];
        let grey = vec![40_u8; 3 * 32 * 32];
        let white = vec![255_u8; 3 * 32 * 32];
        let small = compare_srgb8(32, 32, &black, &grey).mean_flip;
        let large = compare_srgb8(32, 32, &black, &white).mean_flip;
        assert!(
            0.0 < small && small < large && large <= 1.0,
            "{small} {large}"
        );
        assert!(
            large > 0.9,
            "black against white is FLIP's maximal colour difference: {large}"
        );
    }

    #[test]
    fn size_mismatch_is_an_error_naming_both_sizes() {
        let error = compare(
            &Image::new(2, 2, Vec3::ZERO),
            &Image::new(3, 2, Vec3::ZERO),
            Display::default(),
        )
        .unwrap_err();
        assert!(error.to_string().contains("2x2 and 3x2"));
    }
}
