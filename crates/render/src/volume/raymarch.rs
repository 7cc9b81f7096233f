//! Direct volume rendering: rays marched through the volume, emission and absorption
//! composited front to back, each sample shaded with the chosen lobe as its specular term.
//!
//! Along a ray, the volume is cut into segments of `step` millimetres (the last one shorter,
//! ending at the grid's boundary) and sampled at each segment's midpoint. A segment of length
//! `s` at extinction `sigma` is opaque by `1 - exp(-sigma s)`, so a constant medium gives
//! Beer-Lambert's `exp(-sigma d)` exactly whatever the step. A sample's colour is shaded as
//! the classic model does a surface, with the gradient as its normal and a light at the eye,
//! offset up and to the left:
//! `C (ka + kd max(0, N.L)) + ks N(n) lobe(t)`,
//! blended with the unshaded colour by the gradient's strength (`|grad| / g_ref`, at most 1,
//! `g_ref` = 2 % of the value range per voxel), since a normal is meaningless inside uniform
//! tissue. Normals face the viewer (two-sided). Rays stop once 99 % opaque (early ray
//! termination).

use glam::Vec3;
use rayon::prelude::*;
use specula::{Geometry, Lobe, Normalisation};

use super::transfer::TransferFunction;
use super::{Volume, VolumeError};
use crate::image::Image;
use crate::{Camera, Projection};

/// Where the volume is seen from.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum View {
    /// From the feet, anterior up (radiological convention: the patient's left on the right).
    Axial,
    /// From the patient's left, superior up (anterior on the left).
    Sagittal,
    /// From the front, superior up (the patient's left on the right).
    Coronal,
    /// A perspective view from this world position towards the volume's centre, `z` up.
    Eye(Vec3),
}

impl View {
    /// The standard views, as the command line names them.
    pub const STANDARD: [View; 3] = [View::Axial, View::Sagittal, View::Coronal];

    /// The view's name (`eye` for a perspective view).
    #[must_use]
    pub fn id(self) -> &'static str {
        match self {
            View::Axial => "axial",
            View::Sagittal => "sagittal",
            View::Coronal => "coronal",
            View::Eye(_) => "eye",
        }
    }
}

/// A view's rays: parallel ones from a plane, or a pinhole's from the eye.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RayCamera {
    /// The eye (pinhole), or the centre of the plane the parallel rays start from.
    pub eye: Vec3,
    /// The view direction.
    pub forward: Vec3,
    /// The image's `+x` in the world.
    pub right: Vec3,
    /// The image's `+y` in the world.
    pub up: Vec3,
    /// Half the view's height: in millimetres (parallel) or as `tan(fov / 2)` (pinhole).
    pub half_height: f32,
    /// Parallel rays (the standard views) or a pinhole (`--eye`).
    pub parallel: bool,
}

impl RayCamera {
    /// The rays that frame `volume` from `view`.
    pub fn new(view: View, volume: &Volume) -> Result<Self, VolumeError> {
        let corners = volume.corners();
        let centre = corners.iter().copied().sum::<Vec3>() / 8.0;
        let radius = corners
            .iter()
            .map(|c| c.distance(centre))
            .fold(0.0, f32::max);
        let (forward, up) = match view {
            View::Axial => (Vec3::Z, Vec3::Y),
            View::Sagittal => (Vec3::X, Vec3::Z),
            View::Coronal => (Vec3::NEG_Y, Vec3::Z),
            View::Eye(eye) => {
                let distance = eye.distance(centre);
                if !(eye.is_finite() && distance > 1.01 * radius) {
                    return Err(VolumeError(format!(
                        "--eye must be a finite point outside the volume's bounding sphere (centre {centre}, radius {radius:.1} mm)"
                    )));
                }
                let forward = (centre - eye) / distance;
                let up = if forward.cross(Vec3::Z).length() > 1e-3 {
                    Vec3::Z
                } else {
                    Vec3::Y
                };
                let right = forward.cross(up).normalize();
                return Ok(Self {
                    eye,
                    forward,
                    right,
                    up: right.cross(forward),
                    half_height: 1.05 * (radius / distance).asin().tan(),
                    parallel: false,
                });
            }
        };
        let right = forward.cross(up);
        // The view fits the grid's projected extent (the image's aspect is applied per ray,
        // so the width is framed by the larger of the two).
        let half = |axis: Vec3| {
            corners
                .iter()
                .map(|c| (*c - centre).dot(axis).abs())
                .fold(0.0, f32::max)
        };
        Ok(Self {
            eye: centre - 2.0 * radius * forward,
            forward,
            right,
            up,
            half_height: 1.05 * half(up).max(half(right)),
            parallel: true,
        })
    }

    /// The ray through the centre of pixel `(x, y)` of a `width x height` image.
    fn ray(&self, x: u32, y: u32, width: u32, height: u32) -> (Vec3, Vec3) {
        let aspect = width as f32 / height as f32;
        let sx = ((x as f32 + 0.5) / width as f32 * 2.0 - 1.0) * aspect * self.half_height;
        let sy = (1.0 - (y as f32 + 0.5) / height as f32 * 2.0) * self.half_height;
        if self.parallel {
            (self.eye + sx * self.right + sy * self.up, self.forward)
        } else {
            let direction = (self.forward + sx * self.right + sy * self.up).normalize();
            (self.eye, direction)
        }
    }

    /// The light: at the eye, offset up and to the left.
    #[must_use]
    pub fn light(&self) -> Vec3 {
        (-self.forward + 0.35 * self.up - 0.35 * self.right).normalize()
    }
}

/// The rasterizer's camera for `view` of `volume`, framed as the ray marcher frames it, and
/// the direction towards the light.
pub fn surface_camera(view: View, volume: &Volume) -> Result<(Camera, Vec3), VolumeError> {
    let rays = RayCamera::new(view, volume)?;
    let corners = volume.corners();
    let reach = corners
        .iter()
        .map(|c| c.distance(rays.eye))
        .fold(0.0, f32::max);
    let projection = if rays.parallel {
        Projection::Orthographic {
            height: 2.0 * rays.half_height,
        }
    } else {
        Projection::Perspective {
            fov_y_degrees: (2.0 * rays.half_height.atan()).to_degrees(),
        }
    };
    let camera = Camera::try_new(
        rays.eye,
        rays.eye + rays.forward,
        rays.up,
        projection,
        1e-3 * reach,
        1.01 * reach,
    )
    .map_err(|e| VolumeError(e.to_string()))?;
    Ok((camera, rays.light()))
}

/// The specular material every sample shares.
#[derive(Clone, Copy, Debug)]
pub struct Shading {
    /// The lobe (with its exponent).
    pub lobe: Lobe,
    /// How the lobe's cosine is formed.
    pub geometry: Geometry,
    /// The specular normalisation.
    pub normalisation: Normalisation,
    /// Ambient weight.
    pub ka: f32,
    /// Diffuse weight.
    pub kd: f32,
    /// Specular weight.
    pub ks: f32,
}

impl Shading {
    /// `lobe` with the weights every volume view uses: ambient 0.25, diffuse 0.7, specular
    /// 0.5, so that a highlight on a lit surface saturates only near its peak.
    #[must_use]
    pub fn new(lobe: Lobe, geometry: Geometry, normalisation: Normalisation) -> Self {
        Self {
            lobe,
            geometry,
            normalisation,
            ka: 0.25,
            kd: 0.7,
            ks: 0.5,
        }
    }
}

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
fn inside_grid(volume: &Volume, origin: Vec3, direction: Vec3) -> Option<(f32, f32)> {
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
        if width == 0 || height == 0 || u64::from(width) * u64::from(height) > crate::MAX_PIXELS {
            return Err(VolumeError(format!(
                "an image of {width} x {height}: width and height must be at least 1 and the image at most {} pixels",
                crate::MAX_PIXELS
            )));
        }
        if !(settings.step_fraction > 0.0 && settings.step_fraction <= 4.0) {
            return Err(VolumeError("the step must be in (0, 4] voxels".into()));
        }
        let camera = RayCamera::new(settings.view, volume)?;
        Ok(Self {
            camera,
            step: settings.step_fraction * volume.spacing().min_element(),
            lighting: settings
                .shading
                .map(|shading| Lighting::new(shading, volume, camera.light())),
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
    let (width, height) = (settings.width, settings.height);
    let DvrPlan {
        camera,
        step,
        lighting,
    } = DvrPlan::new(volume, settings)?;
    let mut pixels = vec![settings.background; width as usize * height as usize];
    pixels
        .par_chunks_mut(width as usize)
        .enumerate()
        .for_each(|(y, row)| {
            for (x, pixel) in row.iter_mut().enumerate() {
                let (origin, direction) = camera.ray(x as u32, y as u32, width, height);
                let wo = -direction;
                let (grid_origin, grid_direction) =
                    (volume.index(origin), volume.index_direction(direction));
                let Some((start, end)) = inside_grid(volume, grid_origin, grid_direction) else {
                    continue;
                };
                let (mut colour, mut transmittance) = (Vec3::ZERO, 1.0_f32);
                let mut t = start;
                // The first segment's length varies from pixel to pixel, so the steps do not
                // line up with a sharp boundary in the same way across the image (which draws
                // wood-grain rings); the segments still sum to the ray's length exactly.
                let mut segment = step * pixel_jitter(x as u32, y as u32);
                while t < end && 1.0 - transmittance < settings.opacity_cutoff {
                    segment = segment.min(end - t);
                    let index = grid_origin + grid_direction * (t + 0.5 * segment);
                    t += segment;
                    let length = segment;
                    segment = step;
                    let (sigma, base) = transfer.at(volume.sample(index));
                    if sigma <= 0.0 {
                        continue;
                    }
                    let alpha = 1.0 - (-sigma * length).exp();
                    let shaded = match &lighting {
                        None => base,
                        Some(lighting) => lighting.shade(volume, index, base, wo),
                    };
                    colour += transmittance * alpha * shaded;
                    transmittance *= 1.0 - alpha;
                }
                *pixel = colour + transmittance * settings.background;
            }
            progress();
        });
    Image::from_pixels(width, height, pixels)
        .ok_or_else(|| VolumeError("the image could not be assembled".into()))
}

/// A fraction in `(0, 1]` that is fixed per pixel (a hash of its coordinates).
#[must_use]
pub fn pixel_jitter(x: u32, y: u32) -> f32 {
    let mut h = x.wrapping_mul(0x9E37_79B9) ^ y.wrapping_mul(0x85EB_CA6B);
    h ^= h >> 15;
    h = h.wrapping_mul(0x2C1B_3C6D);
    h ^= h >> 12;
    ((h >> 8) as f32 + 1.0) / (1 << 24) as f32
}

/// What every shaded sample of one render shares, prepared once.
#[derive(Clone, Copy, Debug)]
pub struct Lighting {
    /// The material.
    pub shading: Shading,
    /// The normalisation's constant for the lobe.
    pub normalisation: f32,
    /// `wi`: towards the light.
    pub light: Vec3,
    /// The gradient magnitude at which a sample is fully shaded: 2 % of the value range per
    /// voxel.
    pub gradient_reference: f32,
}

impl Lighting {
    fn new(shading: Shading, volume: &Volume, light: Vec3) -> Self {
        let (lo, hi) = volume.range();
        let voxel = volume.spacing().min_element();
        Self {
            shading,
            normalisation: shading.normalisation.constant_for(&shading.lobe) as f32,
            light,
            gradient_reference: (0.02 * (hi - lo) / voxel).max(f32::MIN_POSITIVE),
        }
    }

    /// A sample's colour `base` lit by the classic model, with the gradient as the normal,
    /// seen along `wo`.
    fn shade(&self, volume: &Volume, index: Vec3, base: Vec3, wo: Vec3) -> Vec3 {
        let gradient = volume.gradient(index);
        let strength = gradient.length();
        if !(strength > 0.0 && strength.is_finite()) {
            return base;
        }
        let mut normal = -gradient / strength;
        if normal.dot(wo) < 0.0 {
            normal = -normal;
        }
        let (shading, wi) = (&self.shading, self.light);
        let diffuse = normal.dot(wi).max(0.0);
        let t = shading.geometry.cos_lobe_f32(normal, wo, wi);
        let specular = shading.ks * self.normalisation * shading.lobe.eval(t);
        let lit = base * (shading.ka + shading.kd * diffuse) + Vec3::splat(specular);
        base.lerp(lit, (strength / self.gradient_reference).min(1.0))
    }
}

#[cfg(test)]
mod tests {
    use super::super::transfer::{ControlPoint, Scale};
    use super::super::Units;
    use super::*;

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
            let mut settings = DvrSettings::new(32, 32, View::Axial, None);
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
        let settings = DvrSettings::new(8, 8, View::Coronal, None);
        let image = render_dvr(&volume, &flat(0.5, Vec3::ONE), &settings, &|| {}).unwrap();
        let centre = image.get(4, 4).x;
        assert!((0.99..=1.0).contains(&centre), "{centre}");
    }

    #[test]
    fn rays_that_miss_see_the_background_and_views_frame_the_volume() {
        let volume = constant([10, 10, 10], Vec3::ONE, 1.0);
        for view in [
            View::Axial,
            View::Sagittal,
            View::Coronal,
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
