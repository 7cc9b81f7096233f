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
use specula::simd::{dispatch, Job, Lanes, Level};

use super::lane_geometry::V3;
use super::Environment;
use crate::image::Image;

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

/// The ground's radiance.
const GROUND: Vec3 = Vec3::new(0.09, 0.08, 0.07);

/// The radiance from the unit directions `wi`, on lanes.
#[inline(always)]
fn radiance<V: Lanes>(wi: V3<V>, sun: Vec3) -> V3<V> {
    let lanes = wi.z;
    let zero = lanes.splat(0.0);
    let cos_gamma = wi.dot(V3::splat(lanes, sun));
    let mut glow = cos_gamma.max(zero);
    for _ in 0..5 {
        glow = glow * glow;
    }
    let horizon = Vec3::new(1.0, 0.95, 0.9);
    let zenith = Vec3::new(0.18, 0.35, 0.85);
    let sky = V3::splat(lanes, zenith - horizon).scale_add(
        wi.z.max(zero).sqrt(),
        V3::splat(lanes, 2.0 * Vec3::new(1.0, 0.9, 0.7)).scale_add(glow, V3::splat(lanes, horizon)),
    );
    sky.select(
        cos_gamma.lt(lanes.splat(SUN_RADIUS.cos())),
        V3::splat(lanes, SUN_RADIANCE),
    )
    .select(wi.z.gt(zero), V3::splat(lanes, GROUND))
}

/// Points per pixel along each axis.
const SUB: usize = 4;

/// A pixel's 4 x 4 points' coordinates, point `p` on sub-row `p / 4` and sub-column `p % 4`.
type Points = [f32; SUB * SUB];

/// One row of the sky's pixels, each the mean of its points' radiances, on lanes.
struct SkyRow<'a> {
    /// `sin theta` and `cos theta` of each point of the row's pixels.
    thetas: [Points; 2],
    /// `sin phi` and `cos phi` of each point, per pixel of the row.
    phis: &'a [[Points; 2]],
    sun: Vec3,
    pixels: &'a mut [Vec3],
}

impl Job for SkyRow<'_> {
    type Output = ();

    #[inline(always)]
    fn run<V: Lanes>(self, lanes: V) {
        let w = V::WIDTH;
        let [sines, cosines] = &self.thetas;
        for (pixel, [sin_phis, cos_phis]) in self.pixels.iter_mut().zip(self.phis) {
            let mut sum = V3::splat(lanes, Vec3::ZERO);
            for k in (0..SUB * SUB).step_by(w) {
                let sine = lanes.load(&sines[k..k + w]);
                let wi = V3 {
                    x: sine * lanes.load(&cos_phis[k..k + w]),
                    y: sine * lanes.load(&sin_phis[k..k + w]),
                    z: lanes.load(&cosines[k..k + w]),
                };
                sum = sum.add(radiance(wi, self.sun));
            }
            *pixel = sum.sum_lanes() / (SUB * SUB) as f32;
        }
    }
}

impl Environment {
    /// The procedural sky at `width x width / 2` pixels (`width` at least 2).
    #[must_use]
    pub fn sky(width: u32) -> Environment {
        let width = width.max(2) as usize;
        let height = (width / 2).max(1);
        let sun = sun_direction();
        // The directions are separable: a sub-row fixes theta, a sub-column phi, so each
        // sine and cosine is computed once per sub-row or sub-column, not per point.
        let at = |index: usize, count: usize| (index as f64 + 0.5) / count as f64;
        // A pixel's points' sines and cosines, point `p` taking the angle `place(p)` from
        // `first`.
        let points = |angles: &[(f64, f64)], first: usize, place: fn(usize) -> usize| {
            let angle = |p: usize| angles[first + place(p)];
            [
                core::array::from_fn(|p| angle(p).0 as f32),
                core::array::from_fn(|p| angle(p).1 as f32),
            ]
        };
        let thetas: Vec<(f64, f64)> = (0..height * SUB)
            .map(|y| super::environment::theta_of_square(at(y, height * SUB)))
            .collect();
        let phis: Vec<(f64, f64)> = (0..width * SUB)
            .map(|x| super::environment::phi_of_square(at(x, width * SUB)))
            .collect();
        let columns: Vec<[Points; 2]> = (0..width)
            .map(|x| points(&phis, x * SUB, |p| p % SUB))
            .collect();
        let level = Level::detect();
        let row = |y: usize, pixels: &mut [Vec3]| {
            let thetas = points(&thetas, y * SUB, |p| p / SUB);
            dispatch(
                level,
                SkyRow {
                    thetas,
                    phis: &columns,
                    sun,
                    pixels,
                },
            );
        };
        // The rows whose every point lies below the horizon are all ground, one value:
        // half the map.
        let ground_from = (0..height)
            .find(|&y| thetas[y * SUB].1 as f32 <= 0.0)
            .unwrap_or(height);
        let mut pixels = crate::buffers::filled(GROUND, width * height);
        pixels[..ground_from * width]
            .par_chunks_mut(width)
            .enumerate()
            .for_each(|(y, pixels)| row(y, pixels));
        let image =
            Image::from_pixels(width as u32, height as u32, pixels).expect("width x height pixels");
        Environment::from_image(image, "sky").expect("the sky is finite and non-negative")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every pixel is the mean of its 4 x 4 points' radiances, the formulas of the module's
    /// documentation written again in `f64` here, to `f32` roundings: but where a point lies
    /// so near the sun's rim that a rounding may put it either side.
    #[test]
    fn pixels_are_the_means_of_their_points() {
        let (width, height) = (256, 128);
        let sky = Environment::sky(width);
        let sun = sun_direction().as_dvec3();
        let rim = f64::from(SUN_RADIUS).cos();
        let radiance = |wi: glam::DVec3| -> Option<glam::DVec3> {
            if wi.z <= 0.0 {
                return Some(glam::DVec3::new(0.09, 0.08, 0.07));
            }
            let cos_gamma = wi.dot(sun);
            if (cos_gamma - rim).abs() < 1e-5 {
                return None;
            }
            if cos_gamma >= rim {
                return Some(SUN_RADIANCE.as_dvec3());
            }
            let horizon = glam::DVec3::new(1.0, 0.95, 0.9);
            let zenith = glam::DVec3::new(0.18, 0.35, 0.85);
            let glow = 2.0 * glam::DVec3::new(1.0, 0.9, 0.7) * cos_gamma.max(0.0).powi(32);
            Some(horizon + (zenith - horizon) * wi.z.sqrt() + glow)
        };
        let mut checked = 0;
        for y in 0..height {
            for x in 0..width {
                let mean = (0..16).try_fold(glam::DVec3::ZERO, |sum, p| {
                    let (u, v) = (
                        (f64::from(x * 4 + p % 4) + 0.5) / f64::from(width * 4),
                        (f64::from(y * 4 + p / 4) + 0.5) / f64::from(height * 4),
                    );
                    let theta = core::f64::consts::PI * v;
                    let phi = 1.5 * core::f64::consts::PI - core::f64::consts::TAU * u;
                    let wi = glam::DVec3::new(
                        theta.sin() * phi.cos(),
                        theta.sin() * phi.sin(),
                        theta.cos(),
                    );
                    Some(sum + radiance(wi)? / 16.0)
                });
                let Some(mean) = mean else { continue };
                let pixel = sky.image().get(x, y).as_dvec3();
                assert!(
                    (pixel - mean).abs().max_element() <= 1e-5 * mean.max_element(),
                    "pixel ({x}, {y}): {pixel} against {mean}"
                );
                checked += 1;
            }
        }
        assert!(
            checked > width * height * 99 / 100,
            "{checked} pixels checked"
        );
    }

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
