//! The built-in procedural sky (`--env sky`): an environment that needs no file, with a sun
//! small and bright enough to show a lobe's highlight and a sky broad enough to show its
//! bloom.
//!
//! In linear radiance, world `z` up:
//! - **sky** (`z > 0`): from a pale horizon `(1.0, 0.95, 0.9)` to a blue zenith
//!   `(0.18, 0.35, 0.85)` as `sqrt(z)`, plus a circumsolar glow `2 (1, 0.9, 0.7) cos^32(gamma)`
//!   (`gamma` the angle to the sun);
//! - **sun**: a disc of angular radius 2.5 degrees at elevation 35 degrees, radiance
//!   `800 (1, 0.93, 0.8)`: about 4 units of irradiance at normal incidence against the sky's
//!   2 or so, as on a clear day, and about 25 pixels across at the default size;
//! - **ground** (`z <= 0`): a constant dull brown `(0.09, 0.08, 0.07)`.
//!
//! Each pixel is the mean of 4 x 4 points within it, so the sun's edge is antialiased and its
//! energy does not depend on the map's size.

use glam::Vec3;
use rayon::prelude::*;

use super::Environment;
use crate::Image;

/// The default sky's width in pixels (height half of it).
pub const SKY_WIDTH: u32 = 1024;

/// The unit direction towards the sun.
#[must_use]
pub fn sun_direction() -> Vec3 {
    let elevation = 35f32.to_radians();
    let azimuth = Vec3::new(-0.45, -0.75, 0.0).normalize();
    azimuth * elevation.cos() + Vec3::Z * elevation.sin()
}

/// The sun's angular radius in radians.
pub const SUN_RADIUS: f32 = 2.5 * core::f32::consts::PI / 180.0;

/// The sun's radiance.
pub const SUN_RADIANCE: Vec3 = Vec3::new(800.0, 744.0, 640.0);

/// The radiance from the unit direction `wi`.
fn radiance(wi: Vec3, sun: Vec3) -> Vec3 {
    if wi.z <= 0.0 {
        return Vec3::new(0.09, 0.08, 0.07);
    }
    let cos_gamma = wi.dot(sun);
    if cos_gamma >= SUN_RADIUS.cos() {
        return SUN_RADIANCE;
    }
    let horizon = Vec3::new(1.0, 0.95, 0.9);
    let zenith = Vec3::new(0.18, 0.35, 0.85);
    let glow = 2.0 * Vec3::new(1.0, 0.9, 0.7) * cos_gamma.max(0.0).powi(32);
    horizon.lerp(zenith, wi.z.sqrt()) + glow
}

impl Environment {
    /// The procedural sky at `width x width / 2` pixels (`width` at least 2).
    #[must_use]
    pub fn sky(width: u32) -> Environment {
        let width = width.max(2);
        let height = (width / 2).max(1);
        let sun = sun_direction();
        const SUB: u32 = 4;
        // The directions are separable: a sub-row fixes theta, a sub-column phi, so each
        // sine and cosine is computed once per sub-row or sub-column, not per point.
        let at = |index: u32, count: u32| (f64::from(index) + 0.5) / f64::from(count);
        let thetas: Vec<(f64, f64)> = (0..height * SUB)
            .map(|y| super::environment::theta_of_square(at(y, height * SUB)))
            .collect();
        let phis: Vec<(f64, f64)> = (0..width * SUB)
            .map(|x| super::environment::phi_of_square(at(x, width * SUB)))
            .collect();
        let texel = |x: u32, y: u32| {
            let mut sum = Vec3::ZERO;
            for &(sine, cosine) in &thetas[(y * SUB) as usize..((y + 1) * SUB) as usize] {
                for &(sin_phi, cos_phi) in &phis[(x * SUB) as usize..((x + 1) * SUB) as usize] {
                    let wi = glam::DVec3::new(sine * cos_phi, sine * sin_phi, cosine);
                    sum += radiance(wi.as_vec3(), sun);
                }
            }
            sum / (SUB * SUB) as f32
        };
        // The rows whose every point lies below the horizon are all ground, one value made
        // once: half the map, and half the time it took.
        let ground_from = (0..height)
            .find(|&y| thetas[(y * SUB) as usize].1 as f32 <= 0.0)
            .unwrap_or(height);
        let ground = texel(0, ground_from.min(height - 1));
        let pixels: Vec<Vec3> = (0..width * height)
            .into_par_iter()
            .map(|index| {
                let (x, y) = (index % width, index / width);
                if y >= ground_from {
                    ground
                } else {
                    texel(x, y)
                }
            })
            .collect();
        let image = Image::from_pixels(width, height, pixels).expect("width x height pixels");
        Environment::from_image(image, "sky").expect("the sky is finite and non-negative")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The sun's disc holds the energy its size and radiance say (a cone of half-angle `r`
    /// subtends `2 pi (1 - cos r)`), whatever the map's resolution.
    #[test]
    fn the_sun_sends_its_closed_form_power() {
        let expected =
            SUN_RADIANCE.x as f64 * core::f64::consts::TAU * (1.0 - f64::from(SUN_RADIUS).cos());
        for width in [512, 1024] {
            let sky = Environment::sky(width);
            let image = sky.image();
            let (w, h) = (image.width(), image.height());
            let pixel_solid_angle = |y: u32| {
                let (t0, t1) = (
                    core::f64::consts::PI * f64::from(y) / f64::from(h),
                    core::f64::consts::PI * f64::from(y + 1) / f64::from(h),
                );
                core::f64::consts::TAU / f64::from(w) * (t0.cos() - t1.cos())
            };
            // The sun's pixels are those far above what the sky can give (< 4).
            let mut power = 0.0;
            for y in 0..h {
                for x in 0..w {
                    let red = f64::from(image.get(x, y).x);
                    if red > 10.0 {
                        power += red * pixel_solid_angle(y);
                    }
                }
            }
            assert!(
                (power / expected - 1.0).abs() < 0.03,
                "{width}: {power} against {expected}"
            );
        }
    }
}
