//! Direct volume rendering: rays marched through the volume, emission and absorption
//! composited front to back, each sample shaded with the chosen lobe as its specular term.
//!
//! Along a ray, the volume is cut into segments of `step` millimetres (the last one shorter,
//! ending at the grid's boundary) and sampled at each segment's midpoint. A segment of length
//! `s` at extinction `sigma` is opaque by `1 - exp(-sigma s)`, so a constant medium gives
//! Beer-Lambert's `exp(-sigma d)` exactly whatever the step. A sample's colour is shaded as
//! the classic model does a surface, with the gradient as its normal (the crate's
//! `lighting.rs`, which the marcher lights with too):
//! `C (ka + kd max(0, N.L)) + ks N(n) lobe(t)`, by default blended with the unshaded colour
//! by the gradient's strength (`|grad| / g_ref`, at most 1, `g_ref` = 2 % of the value range
//! per voxel), since a normal is meaningless inside uniform tissue. Normals face the viewer
//! (two-sided). Rays stop once 99 % opaque (early ray termination). `view.rs` names the views
//! and frames their rays; `march` is how the CPU computes all this fast.

mod view;

use glam::Vec3;
use rayon::prelude::*;
use specula_render::{Image, MAX_PIXELS};

pub use crate::lighting::{Light, Lighting, RayView, Shading};
pub use view::{surface_camera, RayCamera, View};

use crate::march::ray::{march_rays, Highlight, Lit, Ray};
use crate::march::PreparedVolume;
use crate::transfer::TransferFunction;
use crate::volume::{Volume, VolumeError};

/// What to render.
#[derive(Clone, Copy, Debug)]
pub struct DvrSettings {
    /// Image width in pixels.
    pub width: u32,
    /// Image height in pixels.
    pub height: u32,
    /// The view.
    pub view: View,
    /// Segment length as a fraction of the smallest voxel spacing (`(0, 4]`).
    pub step_fraction: f32,
    /// Stop a ray once this opaque (`1` never stops early).
    pub opacity_cutoff: f32,
    /// Shading, or none (emission and absorption only).
    pub shading: Option<Shading>,
    /// Seen where rays leave the volume with light to spare.
    pub background: Vec3,
}

impl DvrSettings {
    /// `width x height` from `view`, the step half a voxel, rays stopped at 99 % opacity.
    #[must_use]
    pub fn new(width: u32, height: u32, view: View, shading: Option<Shading>) -> Self {
        Self {
            width,
            height,
            view,
            step_fraction: 0.5,
            opacity_cutoff: 0.99,
            shading,
            background: Vec3::ZERO,
        }
    }
}

/// Where a ray (in grid coordinates, advancing `direction` per millimetre) is inside the grid.
pub(super) fn inside_grid(volume: &Volume, origin: Vec3, direction: Vec3) -> Option<(f32, f32)> {
    let high = volume.last_index();
    let (mut near, mut far) = (0.0_f32, f32::INFINITY);
    for axis in 0..3 {
        let (o, d, h) = (origin[axis], direction[axis], high[axis]);
        if d.abs() < 1e-12 {
            if o < 0.0 || o > h {
                return None;
            }
            continue;
        }
        let (a, b) = ((0.0 - o) / d, (h - o) / d);
        near = near.max(a.min(b));
        far = far.min(a.max(b));
    }
    (near < far).then_some((near, far))
}

/// What a render fixes before its first ray, so that another backend can march the same rays.
#[derive(Clone, Copy, Debug)]
pub struct DvrPlan {
    /// The rays.
    pub camera: RayCamera,
    /// Segment length in millimetres.
    pub step: f32,
    /// The prepared shading, if any.
    pub lighting: Option<Lighting>,
}

impl DvrPlan {
    /// Checks `settings` against `volume` and prepares the render.
    pub fn new(volume: &Volume, settings: &DvrSettings) -> Result<Self, VolumeError> {
        let (width, height) = (settings.width, settings.height);
        if width == 0 || height == 0 || u64::from(width) * u64::from(height) > MAX_PIXELS {
            return Err(VolumeError(format!(
                "an image of {width} x {height}: width and height must be at least 1 and the image \
                    at most {MAX_PIXELS} pixels"
            )));
        }
        if !(settings.step_fraction > 0.0 && settings.step_fraction <= 4.0) {
            return Err(VolumeError("the step must be in (0, 4] voxels".into()));
        }
        if !(settings.opacity_cutoff > 0.0 && settings.opacity_cutoff <= 1.0) {
            return Err(VolumeError(format!(
                "an opacity cutoff of {}: it must be in (0, 1] (1 never stops a ray early)",
                settings.opacity_cutoff
            )));
        }
        let camera = RayCamera::new(settings.view, volume)?;
        Ok(Self {
            camera,
            step: settings.step_fraction * volume.spacing().min_element(),
            lighting: settings.shading.map(|shading| {
                let light = match shading.light {
                    Light::Key => camera.light(),
                    Light::Headlight => -camera.forward,
                };
                Lighting::new(shading, volume, light)
            }),
        })
    }
}

/// Renders `volume` through `transfer` (already in the volume's values: see
/// [`TransferFunction::for_volume`]). `progress` is called once per finished row.
pub fn render_dvr(
    volume: &Volume,
    transfer: &TransferFunction,
    settings: &DvrSettings,
    progress: &(dyn Fn() + Sync),
) -> Result<Image, VolumeError> {
    // A request the plan refuses is refused before the volume is prepared (16 bytes a voxel).
    DvrPlan::new(volume, settings)?;
    let prepared = PreparedVolume::new(volume);
    render_dvr_prepared(volume, &prepared, transfer, settings, progress)
}

/// [`render_dvr`] with the volume's gradients and bricks computed beforehand (once for every
/// frame of one volume). `prepared` must be `volume`'s.
pub fn render_dvr_prepared(
    volume: &Volume,
    prepared: &PreparedVolume,
    transfer: &TransferFunction,
    settings: &DvrSettings,
    progress: &(dyn Fn() + Sync),
) -> Result<Image, VolumeError> {
    let mut images = render_images(volume, prepared, transfer, settings, None, progress)?;
    Ok(images.remove(0))
}

/// [`render_dvr_prepared`] once for each of `lobes`, the settings' shading with its lobe
/// replaced by each in turn, in one march: the rays' samples, their colours and opacities do
/// not depend on the lobe, so only the highlights are computed per lobe. Each image is, bit
/// for bit, the one [`render_dvr_prepared`] draws for its lobe alone.
///
/// # Errors
/// As [`render_dvr_prepared`]; and when the settings are unshaded (no lobe to replace).
pub fn render_dvr_lobes(
    volume: &Volume,
    prepared: &PreparedVolume,
    transfer: &TransferFunction,
    settings: &DvrSettings,
    lobes: &[specula::Lobe],
    progress: &(dyn Fn() + Sync),
) -> Result<Vec<Image>, VolumeError> {
    if settings.shading.is_none() {
        return Err(VolumeError(
            "an unshaded render has no lobe to vary: give it a shading".into(),
        ));
    }
    if lobes.is_empty() {
        return Ok(Vec::new());
    }
    render_images(volume, prepared, transfer, settings, Some(lobes), progress)
}

/// The march behind both: one image per lobe of `lobes`, or the settings' own.
fn render_images(
    volume: &Volume,
    prepared: &PreparedVolume,
    transfer: &TransferFunction,
    settings: &DvrSettings,
    lobes: Option<&[specula::Lobe]>,
    progress: &(dyn Fn() + Sync),
) -> Result<Vec<Image>, VolumeError> {
    if prepared.dims() != volume.dims() {
        return Err(VolumeError(
            "the prepared volume is another volume's (its grid differs)".into(),
        ));
    }
    let (width, height) = (settings.width, settings.height);
    let DvrPlan {
        camera,
        step,
        lighting,
    } = DvrPlan::new(volume, settings)?;
    let classification = prepared.classification(transfer);
    let level = specula::simd::Level::detect();
    let highlights: Vec<Highlight> = match (&lighting, lobes) {
        (None, _) => Vec::new(),
        (Some(lighting), None) => vec![Highlight::of(lighting)],
        (Some(lighting), Some(lobes)) => lobes
            .iter()
            .map(|lobe| Highlight {
                lobe: *lobe,
                scale: lighting.highlight_scale(lobe),
            })
            .collect(),
    };
    let images = highlights.len().max(1);
    // Pixel `p` of image `i` at `pixels[p * images + i]`.
    let mut pixels = vec![settings.background; width as usize * height as usize * images];
    // Bands of TILE rows, drawn tile by tile: a tile's rays cross the same few columns of
    // voxels, which then stay in cache from one ray to the next. The bands are handed out in
    // order, so that the threads draw neighbouring bands at once and share the slices the
    // shared cache holds (split in halves, as an indexed parallel iterator is, they drew far
    // apart: a clinical-size CT's frames 84-87 -> 78-80 ms on 2 threads, with 8-pixel tiles).
    let band = TILE * width as usize * images;
    pixels
        .chunks_mut(band)
        .enumerate()
        .par_bridge()
        .for_each(|(index, band)| {
            let rows = band.len() / (width as usize * images);
            let mut rays = Vec::with_capacity(TILE * TILE);
            let mut views = Vec::with_capacity(TILE * TILE);
            let mut places = Vec::with_capacity(TILE * TILE);
            let mut marched = Vec::with_capacity(TILE * TILE);
            for x0 in (0..width as usize).step_by(TILE) {
                rays.clear();
                views.clear();
                places.clear();
                for row in 0..rows {
                    let y = (index * TILE + row) as u32;
                    for x in x0..(x0 + TILE).min(width as usize) {
                        let (origin, direction) = camera.ray(x as u32, y, width, height);
                        let (grid_origin, grid_direction) =
                            (volume.index(origin), volume.index_direction(direction));
                        let Some((start, end)) = inside_grid(volume, grid_origin, grid_direction)
                        else {
                            continue;
                        };
                        // The first segment's length varies from pixel to pixel, so the steps
                        // do not line up with a sharp boundary in the same way across the
                        // image (which draws wood-grain rings); the segments still sum to the
                        // ray's length exactly.
                        rays.push(Ray {
                            origin: grid_origin,
                            direction: grid_direction,
                            start,
                            end,
                            first: step * pixel_jitter(x as u32, y),
                        });
                        if let Some(lighting) = &lighting {
                            views.push(RayView::new(lighting, -direction));
                        }
                        places.push(row * width as usize + x);
                    }
                }
                marched.clear();
                marched.resize(rays.len() * images, (Vec3::ZERO, 1.0));
                march_rays(
                    level,
                    prepared,
                    &classification,
                    lighting.as_ref().map(|lighting| Lit {
                        lighting,
                        views: &views,
                        highlights: &highlights,
                    }),
                    &rays,
                    step,
                    settings.opacity_cutoff,
                    &mut marched,
                );
                for (&place, results) in places.iter().zip(marched.chunks_exact(images)) {
                    for (image, &(colour, transmittance)) in results.iter().enumerate() {
                        band[place * images + image] = colour + transmittance * settings.background;
                    }
                }
            }
            for _ in 0..rows {
                progress();
            }
        });
    if images == 1 {
        return Ok(vec![Image::from_pixels(width, height, pixels).ok_or_else(
            || VolumeError("the image could not be assembled".into()),
        )?]);
    }
    (0..images)
        .map(|image| {
            let own = pixels.iter().skip(image).step_by(images).copied().collect();
            Image::from_pixels(width, height, own)
                .ok_or_else(|| VolumeError("the image could not be assembled".into()))
        })
        .collect()
}

/// Pixels along each side of the square tiles drawn one at a time (and rows in a band).
/// Measured with the bands handed out in order, on 2 threads: 4 against 8, the clinical-size
/// CT's frames 81 -> 76 ms and the real CT's 68 -> 63 ms; 2 and 3 were slower than 8 (a tile
/// shorter than a packet of lanes leaves lanes idle), 16 no faster; 4 rows with 8, 16 or 32
/// columns within noise of 4.
const TILE: usize = 4;

/// A fraction in `(0, 1]` that is fixed per pixel (a hash of its coordinates).
#[must_use]
pub fn pixel_jitter(x: u32, y: u32) -> f32 {
    let mut h = x.wrapping_mul(0x9E37_79B9) ^ y.wrapping_mul(0x85EB_CA6B);
    h ^= h >> 15;
    h = h.wrapping_mul(0x2C1B_3C6D);
    h ^= h >> 12;
    ((h >> 8) as f32 + 1.0) / (1 << 24) as f32
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::transfer::{ControlPoint, Scale};
    use crate::volume::Units;

    fn constant(dims: [usize; 3], spacing: Vec3, value: f32) -> Volume {
        Volume::centred(
            dims,
            spacing,
            vec![value; dims[0] * dims[1] * dims[2]],
            Units::Arbitrary,
        )
        .unwrap()
    }

    fn flat(sigma: f32, colour: Vec3) -> TransferFunction {
        TransferFunction::try_new(
            vec![ControlPoint {
                value: 0.0,
                sigma,
                colour,
            }],
            Scale::Absolute,
        )
        .unwrap()
    }

    /// A constant slab seen along `z`: every ray inside the grid crosses its whole thickness
    /// `d`, so the pixel is `c (1 - exp(-sigma d)) + background exp(-sigma d)` (Beer-Lambert),
    /// for any step.
    #[test]
    fn a_constant_slab_obeys_beer_lambert() {
        let (colour, background) = (Vec3::new(0.9, 0.5, 0.2), Vec3::new(0.0, 0.1, 0.3));
        // 40 x 40 x 11 voxels of 2 x 2 x 3 mm: 30 mm thick along z.
        let volume = constant([40, 40, 11], Vec3::new(2.0, 2.0, 3.0), 1.0);
        for (sigma, step_fraction) in [(0.01, 0.5), (0.05, 0.37), (0.2, 1.3)] {
            let mut settings = DvrSettings::new(32, 32, View::Inferior, None);
            settings.step_fraction = step_fraction;
            settings.opacity_cutoff = 1.0;
            settings.background = background;
            let image = render_dvr(&volume, &flat(sigma, colour), &settings, &|| {}).unwrap();
            let kept = (-sigma * 30.0_f32).exp();
            let expected = colour * (1.0 - kept) + background * kept;
            let centre = image.get(16, 16);
            assert!(
                (centre - expected).length() < 1e-4,
                "sigma {sigma}: {centre} against {expected}"
            );
        }
    }

    #[test]
    fn early_termination_stops_within_its_cutoff() {
        let volume = constant([20, 20, 20], Vec3::ONE, 1.0);
        let settings = DvrSettings::new(8, 8, View::Anterior, None);
        let image = render_dvr(&volume, &flat(0.5, Vec3::ONE), &settings, &|| {}).unwrap();
        let centre = image.get(4, 4).x;
        assert!((0.99..=1.0).contains(&centre), "{centre}");
    }

    #[test]
    fn rays_that_miss_see_the_background_and_views_frame_the_volume() {
        let volume = constant([10, 10, 10], Vec3::ONE, 1.0);
        for view in [
            View::Inferior,
            View::Left,
            View::Anterior,
            View::Eye(Vec3::new(40.0, -30.0, 20.0)),
        ] {
            let mut settings = DvrSettings::new(40, 40, view, None);
            settings.background = Vec3::new(0.0, 0.0, 1.0);
            let image = render_dvr(&volume, &flat(1.0, Vec3::X), &settings, &|| {}).unwrap();
            assert_eq!(image.get(0, 0), Vec3::Z, "{view:?}: a corner misses");
            assert!(image.get(20, 20).x > 0.99, "{view:?}: the centre is inside");
        }
    }

    #[test]
    fn an_opacity_cutoff_outside_its_range_is_refused() {
        let volume = constant([10, 10, 10], Vec3::ONE, 1.0);
        for cutoff in [0.0, -1.0, 1.5, f32::NAN] {
            let mut settings = DvrSettings::new(8, 8, View::Anterior, None);
            settings.opacity_cutoff = cutoff;
            let refused = render_dvr(&volume, &flat(1.0, Vec3::X), &settings, &|| {}).unwrap_err();
            assert!(refused.0.contains("opacity cutoff"), "{cutoff}: {refused}");
        }
    }

    #[test]
    fn an_eye_inside_the_volume_is_refused() {
        let volume = constant([10, 10, 10], Vec3::ONE, 1.0);
        let settings = DvrSettings::new(8, 8, View::Eye(Vec3::ZERO), None);
        let refused = render_dvr(&volume, &flat(1.0, Vec3::X), &settings, &|| {}).unwrap_err();
        assert!(
            refused.0.contains("outside the volume's bounding sphere"),
            "{refused}"
        );
    }
}
