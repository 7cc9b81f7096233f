//! An environment map: radiance arriving from infinitely far away, stored as an
//! equirectangular (latitude-longitude) image, looked up and importance sampled.
//!
//! **Mapping** (world `z` up): row `y` of `H` covers polar angles `theta` in
//! `[pi y / H, pi (y + 1) / H]` from the zenith, so the top row is the sky; column `x` of `W`
//! covers azimuths from `phi = 3 pi / 2 - 2 pi x / W` downwards, so the image's middle column
//! looks along `+y` (where the default cameras look) and its right half lies towards `+x`:
//! the panorama is seen from inside unmirrored, as the usual lat-long files are.
//!
//! **Sampling**: each pixel's weight is its luminance times `sin theta` (the solid angle of
//! its row), and a [`Distribution2D`] over those weights draws a pixel and a point within it.
//! The density over the unit square becomes one over solid angle by the Jacobian
//! `1 / (2 pi^2 sin theta)`. Radiance is constant over each pixel (nearest lookup), so the
//! sampled density is exactly proportional to `luminance(L) sin theta` on the square: bright
//! pixels (the sun) are drawn in proportion to the light they send.

use core::f64::consts::{PI, TAU};
use std::path::Path;
use std::sync::OnceLock;

use glam::{DVec3, Vec3};
use rayon::prelude::*;
use specula::sampling::{Distribution2D, GroupedAliasTable};
use specula::simd::Lanes;
use specula::simd::Prefetch;
use thiserror::Error;

use super::angles;
use super::lane_geometry::{acos, atan2, sin_cos_turns, V3};
use super::weights::{first_bad_channel, row_sines, row_weights, weight, weights_of};
use crate::image::{read_image, Image};
use crate::image_error::ImageError;

/// An environment that cannot be used, and why.
#[derive(Debug, Error)]
#[non_exhaustive]
pub enum EnvironmentError {
    /// The file could not be read or decoded.
    #[error(transparent)]
    Image(#[from] ImageError),
    /// A pixel is NaN, infinite or negative: radiance is finite and non-negative.
    #[error(
        "{name}: pixel ({x}, {y}) is {value}; an environment's radiance must be finite and \
        non-negative in every channel"
    )]
    BadPixel {
        /// The map's name (its path, or what built it).
        name: String,
        /// Column.
        x: u32,
        /// Row.
        y: u32,
        /// The offending value.
        value: f32,
    },
    /// The map is too small to be a panorama, or its weights overflow.
    #[error(
        "{name}: {width}x{height} pixels cannot be an equirectangular environment; it needs at \
        least 2x1 pixels whose radiances sum to a finite value"
    )]
    Shape {
        /// The map's name.
        name: String,
        /// Width in pixels.
        width: u32,
        /// Height in pixels.
        height: u32,
    },
}

/// A direction drawn from the environment.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EnvironmentSample {
    /// Unit direction towards the environment (world space).
    pub wi: DVec3,
    /// Density with respect to solid angle.
    pub pdf: f64,
    /// The radiance arriving from `wi`.
    pub radiance: Vec3,
}

/// An equirectangular environment map, ready to look up and sample.
#[derive(Clone, Debug)]
pub struct Environment {
    image: Image,
    distribution: OnceLock<Option<Distribution2D>>,
    /// The same distribution over texels for the `f32` renderer: drawn by alias in constant
    /// time, a row and then a texel of it ([`Environment::draw_texel`]).
    alias: GroupedAliasTable,
    /// Per texel, its radiance and its density on the unit square (its weight over the mean
    /// weight, as `distribution` gives it) side by side: what a draw or a look-up reads, one
    /// cache line's worth from a map of megabytes, not two.
    texels: Vec<[f32; 4]>,
}

impl Environment {
    /// The environment of a linear-radiance lat-long `image`, or why it cannot be one.
    pub fn from_image(image: Image, name: &str) -> Result<Self, EnvironmentError> {
        let (width, height) = (image.width(), image.height());
        if let Some((index, value)) = first_bad_channel(&image) {
            return Err(EnvironmentError::BadPixel {
                name: name.to_owned(),
                x: index as u32 % width,
                y: index as u32 / width,
                value,
            });
        }
        let shape = || EnvironmentError::Shape {
            name: name.to_owned(),
            width,
            height,
        };
        if width < 2 {
            return Err(shape());
        }
        // The weights are made a row at a time, for the row's alias table and again for its
        // texels' densities: never the whole map's at once (4 MB at 1024 x 512).
        let (row_length, sines) = (width as usize, row_sines(height));
        let alias = GroupedAliasTable::from_groups(height as usize, row_length, |row, weights| {
            row_weights(
                &image.pixels()[row * row_length..][..row_length],
                sines[row],
                weights,
            );
        })
        .ok_or_else(shape)?;
        let (total, cells) = (alias.total(), image.pixels().len() as f64);
        let mut texels = vec![[0.0; 4]; image.pixels().len()];
        texels
            .par_chunks_mut(row_length)
            .zip(image.pixels().par_chunks(row_length))
            .zip(sines.par_iter())
            .for_each(|((texels, pixels), &sine)| {
                for (texel, radiance) in texels.iter_mut().zip(pixels) {
                    let density = if total > 0.0 {
                        (weight(*radiance, sine) * cells / total) as f32
                    } else {
                        1.0
                    };
                    *texel = [radiance.x, radiance.y, radiance.z, density];
                }
            });
        Ok(Self {
            image,
            distribution: OnceLock::new(),
            alias,
            texels,
        })
    }

    /// The distribution [`Environment::sample`] draws from, made on first use: the `f32`
    /// renderer draws by alias and never needs it (on 2 threads it took 6 ms of the 27 a
    /// 1024 x 512 map took to prepare).
    /// Its weights are those [`Environment::from_image`] checked and the alias table took,
    /// which it takes too, so it is never `None` (were it, the `f64` path would draw
    /// nothing: black, not a panic).
    fn distribution(&self) -> Option<&Distribution2D> {
        let distribution = self
            .distribution
            .get_or_init(|| {
                Distribution2D::new(&weights_of(&self.image), self.image.width() as usize)
            })
            .as_ref();
        debug_assert!(distribution.is_some(), "the alias table took these weights");
        distribution
    }

    /// Reads an environment from a `.hdr` (Radiance), `.exr` or `.png` (sRGB decoded) file:
    /// a regular file within the input limit and the image size limit.
    pub fn load(path: &Path) -> Result<Self, EnvironmentError> {
        Self::from_image(read_image(path)?, &path.display().to_string())
    }

    /// The environment `name` gives: `sky` (the built-in sky at [`super::SKY_WIDTH`]) or
    /// an image file ([`Environment::load`]).
    pub fn named(name: &Path) -> Result<Self, EnvironmentError> {
        if name.as_os_str() == "sky" {
            return Ok(Self::sky(super::SKY_WIDTH));
        }
        Self::load(name)
    }

    /// A constant environment: `radiance` from every direction (a white furnace when 1).
    #[must_use]
    pub fn constant(radiance: Vec3) -> Self {
        let image = Image::new(2, 1, radiance.max(Vec3::ZERO));
        Self::from_image(image, "constant").expect("a finite constant map is valid")
    }

    /// The image the environment is stored in.
    #[must_use]
    pub fn image(&self) -> &Image {
        &self.image
    }

    /// The radiance arriving from the unit direction `wi` (world space).
    #[must_use]
    pub fn radiance(&self, wi: DVec3) -> Vec3 {
        let [x, y] = to_square(wi);
        let (width, height) = (self.image.width(), self.image.height());
        let column = ((x * f64::from(width)) as u32).min(width - 1);
        let row = ((y * f64::from(height)) as u32).min(height - 1);
        self.image.get(column, row)
    }

    /// A direction for the uniform numbers `u`, drawn in proportion to luminance times
    /// solid angle; `None` on the poles' measure-zero lines, where the Jacobian vanishes.
    #[must_use]
    pub fn sample(&self, u: [f64; 2]) -> Option<EnvironmentSample> {
        let draw = self.distribution()?.sample(u);
        let (wi, sine) = from_square(draw.point);
        if sine <= 0.0 {
            return None;
        }
        Some(EnvironmentSample {
            wi,
            pdf: draw.pdf / (2.0 * PI * PI * sine),
            radiance: self.radiance(wi),
        })
    }

    /// The density of the unit direction `wi` under [`Environment::sample`], per solid angle.
    #[must_use]
    pub fn pdf(&self, wi: DVec3) -> f64 {
        let sine = (1.0 - wi.z * wi.z).max(0.0).sqrt();
        if sine <= 0.0 {
            return 0.0;
        }
        self.distribution()
            .map_or(0.0, |distribution| distribution.pdf(to_square(wi)))
            / (2.0 * PI * PI * sine)
    }
}

impl Environment {
    /// [`Environment::sample`]'s distribution for the `f32` renderer, drawn by alias: the
    /// texel for 64 random bits (then [`Environment::draw_in`]).
    #[must_use]
    #[inline]
    pub fn draw_texel(&self, bits: u64) -> usize {
        self.alias.sample(bits)
    }

    /// The column of [`Environment::draw_texel`]'s texel, given the row
    /// [`Environment::prefetch_draw`] drew for these bits.
    #[must_use]
    #[inline]
    pub(super) fn draw_column(&self, row: u32, bits: u64) -> u32 {
        self.alias.place_in(row as usize, bits) as u32
    }

    /// The texel at `row` and `column`.
    #[must_use]
    #[inline]
    pub(super) fn texel(&self, row: u32, column: u32) -> usize {
        row as usize * self.image.width() as usize + column as usize
    }

    /// [`Environment::draw_in`]'s direction on SIMD lanes: the point `within` (two columns
    /// of uniform numbers) the texels at `column` and `row` (whole numbers, as floats),
    /// turned to a unit direction (world space), and its `sin theta`.
    #[inline(always)]
    pub(super) fn direction_lanes<V: Lanes>(
        &self,
        (column, row): (V, V),
        within: (V, V),
    ) -> (V3<V>, V) {
        let (width, height) = (self.image.width() as f32, self.image.height() as f32);
        let x = (column + within.0) * column.splat(1.0 / width);
        let y = (row + within.1) * row.splat(1.0 / height);
        let (sine, cosine) = sin_cos_turns(y * y.splat(0.5));
        // phi = 3 pi / 2 - 2 pi x, in turns.
        let (sin_phi, cos_phi) = sin_cos_turns(x.splat(0.75) - x);
        let wi = V3 {
            x: sine * cos_phi,
            y: sine * sin_phi,
            z: cosine,
        };
        (wi, sine)
    }

    /// The row [`Environment::draw_texel`] draws for these bits, having asked for what it
    /// will read in the row ([`Environment::draw_column`] draws the texel there).
    #[inline]
    pub(super) fn prefetch_draw(&self, bits: u64, prefetch: Prefetch) -> u32 {
        let row = self.alias.group_of(bits);
        self.alias.prefetch(row, bits, prefetch);
        row as u32
    }

    /// Asks for what a look-up of `texel` will read ([`Environment::look_up_jacobian`],
    /// [`Environment::look_up_texel`], [`Environment::draw_in`]).
    #[inline]
    pub(super) fn prefetch_texel(&self, texel: usize, prefetch: Prefetch) {
        if let Some(record) = self.texels.get(texel) {
            prefetch.line(record);
        }
    }

    /// The point `within` the drawn `texel`: the unit direction, its density per solid angle
    /// and the radiance there; `None` on the poles.
    #[must_use]
    #[inline]
    pub fn draw_in(&self, texel: usize, within: [f32; 2]) -> Option<(Vec3, f32, Vec3)> {
        let width = self.image.width() as usize;
        let (column, row) = ((texel % width) as f32, (texel / width) as f32);
        let x = (column + within[0]) / width as f32;
        let y = (row + within[1]) / self.image.height() as f32;
        let (sine, cosine) = angles::sin_cos_turns(0.5 * y);
        if sine <= 0.0 {
            return None;
        }
        // phi = 3 pi / 2 - 2 pi x, in turns.
        let (sin_phi, cos_phi) = angles::sin_cos_turns(0.75 - x);
        let wi = Vec3::new(sine * cos_phi, sine * sin_phi, cosine);
        let (radiance, pdf) = self.look_up_jacobian(texel, jacobian(sine));
        Some((wi, pdf, radiance))
    }

    /// [`Environment::draw_texel`] then [`Environment::draw_in`].
    #[must_use]
    #[inline]
    pub fn draw(&self, bits: u64, within: [f32; 2]) -> Option<(Vec3, f32, Vec3)> {
        self.draw_in(self.draw_texel(bits), within)
    }

    /// The texel the unit direction `wi` falls in, and `sin theta` there (then
    /// [`Environment::look_up_texel`]).
    #[must_use]
    #[inline]
    pub fn texel_of(&self, wi: Vec3) -> (usize, f32) {
        let z = wi.z.clamp(-1.0, 1.0);
        let y = angles::acos(z) * core::f32::consts::FRAC_1_PI;
        let x = 0.75 - angles::atan2(wi.y, wi.x) * (0.5 * core::f32::consts::FRAC_1_PI);
        let x = if x >= 1.0 { x - 1.0 } else { x };
        let (width, height) = (self.image.width(), self.image.height());
        let column = ((x * width as f32) as u32).min(width - 1);
        let row = ((y * height as f32) as u32).min(height - 1);
        (
            (row * width + column) as usize,
            (1.0 - z * z).max(0.0).sqrt(),
        )
    }

    /// [`Environment::texel_of`] on SIMD lanes: each lane's column and row (as `i32` bit
    /// patterns, for [`Environment::texel_of_bits`]: converted back to integers lane by lane, a
    /// float costs a saturating conversion each) and `sin theta`, for unit directions `wi`.
    #[inline(always)]
    pub(super) fn texel_lanes<V: Lanes>(&self, wi: V3<V>) -> (V, V, V) {
        let (zero, one) = (wi.z.splat(0.0), wi.z.splat(1.0));
        let z = wi.z.max(wi.z.splat(-1.0)).min(one);
        let y = acos(z) * z.splat(core::f32::consts::FRAC_1_PI);
        let x = atan2(wi.y, wi.x).neg_mul_add(z.splat(1.0 / core::f32::consts::TAU), z.splat(0.75));
        let x = x.select(x.lt(one), x - one);
        let (width, height) = (self.image.width() as f32, self.image.height() as f32);
        // Clamped before the conversion, which a NaN also leaves in range.
        let column = (x * z.splat(width)).min(z.splat(width - 1.0)).max(zero);
        let row = (y * z.splat(height)).min(z.splat(height - 1.0)).max(zero);
        (
            column.float_to_int(),
            row.float_to_int(),
            z.neg_mul_add(z, one).max(zero).sqrt(),
        )
    }

    /// The texel at the row and column [`Environment::texel_lanes`] stored (`i32` bit
    /// patterns of numbers it clamped to the map).
    #[must_use]
    #[inline]
    pub(super) fn texel_of_bits(&self, row: f32, column: f32) -> usize {
        self.texel(row.to_bits(), column.to_bits())
    }

    /// The radiance of `texel` and the density per solid angle of a draw there, where
    /// `jacobian` is [`jacobian`]'s (or [`jacobian_lanes`]'s) for its `sin theta`.
    #[must_use]
    #[inline]
    pub(super) fn look_up_jacobian(&self, texel: usize, jacobian: f32) -> (Vec3, f32) {
        let [r, g, b, density] = self.texels[texel];
        (Vec3::new(r, g, b), density * jacobian)
    }

    /// The radiance of `texel` and the density per solid angle [`Environment::draw`] draws a
    /// direction there with, where `sine` is its `sin theta`.
    #[must_use]
    #[inline]
    pub fn look_up_texel(&self, texel: usize, sine: f32) -> (Vec3, f32) {
        self.look_up_jacobian(texel, jacobian(sine))
    }

    /// The radiance from the unit direction `wi` and its density under
    /// [`Environment::draw`] (per solid angle), in `f32`.
    #[must_use]
    #[inline]
    pub fn look_up(&self, wi: Vec3) -> (Vec3, f32) {
        let (texel, sine) = self.texel_of(wi);
        self.look_up_texel(texel, sine)
    }
}

/// The unit square's density to one per solid angle, `1 / (2 pi^2 sin theta)`, and 0 where
/// `sin theta` is not positive (no draw: a density of 0). The `f32` paths' one Jacobian, made
/// once so that a look-up multiplies.
#[must_use]
#[inline]
pub(super) fn jacobian(sine: f32) -> f32 {
    if sine > 0.0 {
        1.0 / (sine * (2.0 * core::f32::consts::PI * core::f32::consts::PI))
    } else {
        0.0
    }
}

/// [`jacobian`] on lanes of `sin theta` (the same operations).
#[inline(always)]
pub(super) fn jacobian_lanes<V: Lanes>(sine: V) -> V {
    let scale = sine.splat(2.0 * core::f32::consts::PI * core::f32::consts::PI);
    (sine.splat(1.0) / (sine * scale)).keep(sine.gt(sine.splat(0.0)))
}

/// The point of the unit square a unit direction maps to.
fn to_square(wi: DVec3) -> [f64; 2] {
    let theta = wi.z.clamp(-1.0, 1.0).acos();
    let phi = wi.y.atan2(wi.x);
    let x = (0.75 - phi / TAU).rem_euclid(1.0);
    [
        x.min(1.0 - f64::EPSILON),
        (theta / PI).min(1.0 - f64::EPSILON),
    ]
}

/// The unit direction of a point of the unit square, and `sin theta` there.
fn from_square([x, y]: [f64; 2]) -> (DVec3, f64) {
    let (sine, cosine) = theta_of_square(y);
    let (sin_phi, cos_phi) = phi_of_square(x);
    (DVec3::new(sine * cos_phi, sine * sin_phi, cosine), sine)
}

/// `(sin theta, cos theta)` of the square's row coordinate `y`.
pub(super) fn theta_of_square(y: f64) -> (f64, f64) {
    (PI * y).sin_cos()
}

/// `(sin phi, cos phi)` of the square's column coordinate `x`.
pub(super) fn phi_of_square(x: f64) -> (f64, f64) {
    (1.5 * PI - TAU * x).sin_cos()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_mapping_inverts_and_puts_plus_y_in_the_middle() {
        let [x, y] = to_square(DVec3::Y);
        assert!((x - 0.5).abs() < 1e-12 && (y - 0.5).abs() < 1e-12);
        let [x, _] = to_square(DVec3::X);
        assert!((x - 0.75).abs() < 1e-12, "+x is right of the middle");
        assert!(to_square(DVec3::Z)[1] < 1e-12, "the zenith is the top row");
        for i in 0..100 {
            let point = [(i as f64 * 0.618_034) % 1.0, (i as f64 + 0.5) / 100.0];
            let (wi, _) = from_square(point);
            let back = to_square(wi);
            assert!((back[0] - point[0]).abs() < 1e-9 && (back[1] - point[1]).abs() < 1e-9);
        }
    }

    /// The texel a direction falls in on SIMD lanes, at every level this CPU has, is the one
    /// the `f64` mapping (`to_square`) puts it in, but within a polynomial's error of a texel
    /// border (then a neighbour), and `sin theta` there is `f64`'s.
    #[test]
    fn texels_on_lanes_are_the_f64_mappings() {
        use specula::simd::{dispatch, Job, Level};

        struct Texels<'a>(&'a Environment, &'a [Vec3], &'a mut Vec<[f32; 3]>);
        impl Job for Texels<'_> {
            type Output = ();
            #[inline(always)]
            fn run<V: Lanes>(self, lanes: V) {
                let w = V::WIDTH;
                for chunk in self.1.chunks_exact(w) {
                    let column = |f: fn(&Vec3) -> f32| chunk.iter().map(f).collect::<Vec<f32>>();
                    let wi = V3 {
                        x: lanes.load(&column(|v| v.x)),
                        y: lanes.load(&column(|v| v.y)),
                        z: lanes.load(&column(|v| v.z)),
                    };
                    let (c, r, s) = self.0.texel_lanes(wi);
                    let (c, r) = (c.int_to_float(), r.int_to_float());
                    let mut out = [vec![0.0; w], vec![0.0; w], vec![0.0; w]];
                    c.store(&mut out[0]);
                    r.store(&mut out[1]);
                    s.store(&mut out[2]);
                    self.2
                        .extend((0..w).map(|k| [out[0][k], out[1][k], out[2][k]]));
                }
            }
        }
        let environment = Environment::from_image(Image::new(512, 256, Vec3::ONE), "m").unwrap();
        let (width, height) = (512.0, 256.0);
        // A golden spiral over the sphere, 4096 directions.
        let directions: Vec<Vec3> = (0..4096)
            .map(|i| {
                let z = 1.0 - (f64::from(i) + 0.5) / 2048.0;
                let phi = f64::from(i) * 2.399_963_229_728_653;
                let r = (1.0 - z * z).sqrt();
                DVec3::new(r * phi.cos(), r * phi.sin(), z).as_vec3()
            })
            .collect();
        for level in Level::available() {
            let mut texels = Vec::new();
            dispatch(level, Texels(&environment, &directions, &mut texels));
            let mut exact = 0;
            for (wi, &[column, row, sine]) in directions.iter().zip(&texels) {
                let [x, y] = to_square(wi.as_dvec3());
                let (expected_column, expected_row) = ((x * width).floor(), (y * height).floor());
                let off = |a: f32, b: f64, period: f64| {
                    let d = (f64::from(a) - b).abs();
                    d.min(period - d)
                };
                let (dc, dr) = (
                    off(column, expected_column, width),
                    off(row, expected_row, f64::INFINITY),
                );
                assert!(
                    dc <= 1.0 && dr <= 1.0,
                    "{level:?} {wi}: ({column}, {row}) against ({expected_column}, {expected_row})"
                );
                exact += usize::from(dc == 0.0 && dr == 0.0);
                let theta_sine = wi.as_dvec3().truncate().length();
                assert!(
                    (f64::from(sine) - theta_sine).abs() < 1e-6,
                    "{level:?} {wi}: sine {sine}"
                );
            }
            assert!(
                exact >= 4090,
                "{level:?}: only {exact} of 4096 in the f64 mapping's texel"
            );
        }
    }

    #[test]
    fn bad_maps_are_refused_by_name() {
        let mut image = Image::new(4, 2, Vec3::ONE);
        image.set(3, 1, Vec3::new(0.0, f32::NAN, 0.0));
        let error = Environment::from_image(image, "sky.exr")
            .unwrap_err()
            .to_string();
        assert!(
            error.contains("sky.exr") && error.contains("(3, 1)"),
            "{error}"
        );
        let error = Environment::from_image(Image::new(4, 2, -Vec3::ONE), "m").unwrap_err();
        assert!(error.to_string().contains("non-negative"), "{error}");
        // The first bad channel in reading order is named, whatever row each thread tests.
        let mut image = Image::new(8, 64, Vec3::ONE);
        image.set(5, 60, Vec3::new(f32::NAN, 0.0, 0.0));
        image.set(2, 40, Vec3::new(1.0, f32::INFINITY, -1.0));
        let error = Environment::from_image(image, "m").unwrap_err().to_string();
        assert!(error.contains("(2, 40) is inf"), "{error}");
        // Negative zero is not negative radiance.
        assert!(Environment::from_image(Image::new(4, 2, Vec3::splat(-0.0)), "m").is_ok());
        let error = Environment::from_image(Image::new(1, 1, Vec3::ONE), "m").unwrap_err();
        assert!(error.to_string().contains("at least 2x1"), "{error}");
    }
}
