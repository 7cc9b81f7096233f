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

use super::march::ray::{march_together, Highlights, Ray, Shade, HIGHLIGHTS};
use super::march::{Classification, PreparedVolume};
use super::transfer::TransferFunction;
use super::{Volume, VolumeError};
use crate::image::Image;
use crate::{Camera, Projection};

/// Where the volume is seen from: named by anatomy, as a radiologist names the side the
/// camera stands on, with parallel rays; or a perspective eye.
///
/// Front and back views have superior up; a view from above or below has anterior up. The
/// patient's left is on the image's right from the front (anterior) and from the feet
/// (inferior), as radiology displays a patient facing the viewer.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum View {
    /// From the front: the face, the patient's left on the image's right.
    Anterior,
    /// From behind: the back of the head, the patient's left on the image's left.
    Posterior,
    /// From the patient's left: anterior on the image's left.
    Left,
    /// From the patient's right: anterior on the image's right.
    Right,
    /// From above (the vertex), anterior up: the patient's right on the image's right.
    Superior,
    /// From the feet, anterior up: the patient's left on the image's right (an axial slice's
    /// orientation).
    Inferior,
    /// A perspective view from this world position towards the volume's centre, `z` up.
    Eye(Vec3),
}

impl View {
    /// The anatomical views, as the command line names them.
    pub const STANDARD: [View; 6] = [
        View::Anterior,
        View::Posterior,
        View::Left,
        View::Right,
        View::Superior,
        View::Inferior,
    ];

    /// The slice planes' names that earlier versions used, and the views they name.
    pub const ALIASES: [(&'static str, View); 3] = [
        ("coronal", View::Anterior),
        ("sagittal", View::Left),
        ("axial", View::Inferior),
    ];

    /// The view's name (`eye` for a perspective view).
    #[must_use]
    pub fn id(self) -> &'static str {
        match self {
            View::Anterior => "anterior",
            View::Posterior => "posterior",
            View::Left => "left",
            View::Right => "right",
            View::Superior => "superior",
            View::Inferior => "inferior",
            View::Eye(_) => "eye",
        }
    }

    /// A view by name (or by an alias), or the reason naming the choices.
    pub fn parse(text: &str) -> Result<Self, String> {
        let name = text.trim().to_ascii_lowercase();
        Self::STANDARD
            .into_iter()
            .find(|view| view.id() == name)
            .or_else(|| {
                Self::ALIASES
                    .iter()
                    .find(|(alias, _)| *alias == name)
                    .map(|&(_, view)| view)
            })
            .ok_or_else(|| {
                let names = Self::STANDARD.map(View::id);
                format!(
                    "unknown view '{}'; views: {} (or coronal, sagittal, axial){}",
                    specula::excerpt(text),
                    names.join(", "),
                    specula::did_you_mean(text, names)
                )
            })
    }

    /// The direction the camera looks along and the image's up, in RAS world axes (an eye's
    /// are found from its position: [`RayCamera::new`]).
    fn axes(self) -> (Vec3, Vec3) {
        match self {
            View::Anterior => (Vec3::NEG_Y, Vec3::Z),
            View::Posterior => (Vec3::Y, Vec3::Z),
            View::Left => (Vec3::X, Vec3::Z),
            View::Right => (Vec3::NEG_X, Vec3::Z),
            View::Superior => (Vec3::NEG_Z, Vec3::Y),
            View::Inferior | View::Eye(_) => (Vec3::Z, Vec3::Y),
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
            anatomical => anatomical.axes(),
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

    /// The ray through the centre of pixel `(x, y)` of a `width x height` image: its origin
    /// and unit direction in the world.
    #[must_use]
    pub fn ray(&self, x: u32, y: u32, width: u32, height: u32) -> (Vec3, Vec3) {
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
    /// Where the light is.
    pub light: Light,
    /// Whether a sample fades to its unshaded colour as its gradient weakens (below 2 % of the
    /// value range per voxel), since a normal means little inside uniform tissue; without it
    /// every sample with a gradient is fully shaded, as VTK's ray casters shade.
    pub fade_weak_gradients: bool,
}

/// Where a volume's light is.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Light {
    /// At the eye, offset up and to the left (the default: surfaces facing the viewer keep
    /// some modelling).
    Key,
    /// Along the view direction, as a viewer's headlight (VTK's default light).
    Headlight,
}

impl Light {
    /// Both lights.
    pub const ALL: [Light; 2] = [Light::Key, Light::Headlight];

    /// The name the command line uses.
    #[must_use]
    pub fn id(self) -> &'static str {
        match self {
            Light::Key => "key",
            Light::Headlight => "headlight",
        }
    }
}

impl Shading {
    /// `lobe` with the weights every volume view uses: ambient 0.25, diffuse 0.7, specular
    /// 0.5, so that a highlight on a lit surface saturates only near its peak; the key light;
    /// weak gradients faded.
    #[must_use]
    pub fn new(lobe: Lobe, geometry: Geometry, normalisation: Normalisation) -> Self {
        Self {
            lobe,
            geometry,
            normalisation,
            ka: 0.25,
            kd: 0.7,
            ks: 0.5,
            light: Light::Key,
            fade_weak_gradients: true,
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
    let classification = Classification::new(prepared, transfer, step);
    let arch = pulp::Arch::new();
    let mut pixels = vec![settings.background; width as usize * height as usize];
    // Bands of TILE rows, drawn tile by tile: a tile's rays cross the same few columns of
    // voxels, which then stay in cache from one ray to the next.
    let band = TILE * width as usize;
    pixels
        .par_chunks_mut(band)
        .enumerate()
        .for_each(|(index, band)| {
            let rows = band.len() / width as usize;
            let mut buffers = [Highlights::EMPTY; TOGETHER];
            for x0 in (0..width as usize).step_by(TILE) {
                for row in 0..rows {
                    let y = (index * TILE + row) as u32;
                    let line = &mut band[row * width as usize..(row + 1) * width as usize];
                    let tile = &mut line[x0..(x0 + TILE).min(width as usize)];
                    for (group, pixels) in tile.chunks_mut(TOGETHER).enumerate() {
                        let first = x0 + group * TOGETHER;
                        let rays: [Option<(Ray, Vec3)>; TOGETHER] = core::array::from_fn(|k| {
                            if k >= pixels.len() {
                                return None;
                            }
                            let x = (first + k) as u32;
                            let (origin, direction) = camera.ray(x, y, width, height);
                            let (grid_origin, grid_direction) =
                                (volume.index(origin), volume.index_direction(direction));
                            let (start, end) = inside_grid(volume, grid_origin, grid_direction)?;
                            // The first segment's length varies from pixel to pixel, so the
                            // steps do not line up with a sharp boundary in the same way
                            // across the image (which draws wood-grain rings); the segments
                            // still sum to the ray's length exactly.
                            let ray = Ray {
                                origin: grid_origin,
                                direction: grid_direction,
                                start,
                                end,
                                first: step * pixel_jitter(x, y),
                            };
                            Some((ray, direction))
                        });
                        let lits = rays.map(|ray| {
                            let (_, direction) = ray?;
                            lighting.as_ref().map(|lighting| Lit {
                                lighting,
                                view: RayView::new(lighting, -direction),
                            })
                        });
                        let marched = march_together::<_, TOGETHER>(
                            arch,
                            prepared,
                            &classification,
                            core::array::from_fn(|k| {
                                rays[k].map(|(ray, _)| (ray, lits[k].as_ref()))
                            }),
                            step,
                            settings.opacity_cutoff,
                            &mut buffers,
                        );
                        for (pixel, marched) in pixels.iter_mut().zip(marched) {
                            if let Some((colour, transmittance)) = marched {
                                *pixel = colour + transmittance * settings.background;
                            }
                        }
                    }
                }
            }
            for _ in 0..rows {
                progress();
            }
        });
    Image::from_pixels(width, height, pixels)
        .ok_or_else(|| VolumeError("the image could not be assembled".into()))
}

/// Neighbouring rays marched side by side (see [`march_together`]).
const TOGETHER: usize = 4;

/// Pixels along each side of the square tiles drawn one at a time.
const TILE: usize = 8;

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
    /// Its reciprocal (infinite without the fade).
    per_gradient_reference: f32,
}

impl Lighting {
    fn new(shading: Shading, volume: &Volume, light: Vec3) -> Self {
        let (lo, hi) = volume.range();
        let voxel = volume.spacing().min_element();
        // Without the fade, any gradient shades fully (the GPU reads the same field).
        let gradient_reference = if shading.fade_weak_gradients {
            (0.02 * (hi - lo) / voxel).max(f32::MIN_POSITIVE)
        } else {
            f32::MIN_POSITIVE
        };
        Self {
            shading,
            normalisation: shading.normalisation.constant_for(&shading.lobe) as f32,
            light,
            gradient_reference,
            per_gradient_reference: 1.0 / gradient_reference,
        }
    }

    /// A sample's colour `base` lit by the classic model, with its `gradient` (value per mm)
    /// as the normal, seen along `wo`.
    #[must_use]
    pub fn shade(&self, gradient: Vec3, base: Vec3, wo: Vec3) -> Vec3 {
        let lit = self.light(gradient, base, &RayView::new(self, wo));
        lit.colour + Vec3::splat(lit.highlight * self.shading.lobe.eval(lit.t))
    }

    /// [`Lighting::shade`] in parts, the lobe left unevaluated (a ray gathers its cosines
    /// and evaluates them together).
    #[inline(always)]
    #[must_use]
    pub fn light(&self, gradient: Vec3, base: Vec3, view: &RayView) -> LitSample {
        let squared = gradient.length_squared();
        if !(squared > 0.0 && squared.is_finite()) {
            return LitSample {
                colour: base,
                highlight: 0.0,
                t: 0.0,
            };
        }
        let inverse = squared.sqrt().recip();
        // The normal is the gradient's opposite turned to face the viewer: `k g` with
        // `|k| = 1 / |g|`, so its dot products are those of the gradient, scaled.
        let towards_viewer = gradient.dot(view.wo);
        let k = if towards_viewer > 0.0 {
            inverse
        } else {
            -inverse
        };
        let shading = &self.shading;
        let along_light = k * gradient.dot(self.light);
        let diffuse = along_light.max(0.0);
        let t = match shading.geometry {
            Geometry::Phong => 2.0 * along_light * (k * towards_viewer) - view.wi_dot_wo,
            Geometry::Blinn => k * gradient.dot(view.half),
        };
        // base.lerp(lit, weight), the highlight's share kept apart.
        let weight = (squared * inverse * self.per_gradient_reference).min(1.0);
        LitSample {
            colour: base * (1.0 + weight * (shading.ka + shading.kd * diffuse - 1.0)),
            highlight: weight * shading.ks * self.normalisation,
            t,
        }
    }
}

/// A sample lit, its highlight apart: the sample is `colour + highlight * lobe(t)` in every
/// channel (the highlight is white).
#[derive(Clone, Copy, Debug)]
pub struct LitSample {
    /// Ambient and diffuse.
    pub colour: Vec3,
    /// The lobe's weight.
    pub highlight: f32,
    /// The lobe's cosine.
    pub t: f32,
}

/// What one ray's samples share: the view direction and, for Blinn, the half vector.
#[derive(Clone, Copy, Debug)]
pub struct RayView {
    wo: Vec3,
    half: Vec3,
    wi_dot_wo: f32,
}

impl RayView {
    /// The view `wo` under `lighting`'s light.
    #[must_use]
    pub fn new(lighting: &Lighting, wo: Vec3) -> Self {
        let sum = lighting.light + wo;
        let length = sum.length();
        Self {
            wo,
            // Light and view opposite: no half vector, and Blinn's cosine is 0.
            half: if length > 0.0 {
                sum / length
            } else {
                Vec3::ZERO
            },
            wi_dot_wo: lighting.light.dot(wo),
        }
    }
}

/// The lighting as one ray sees it.
struct Lit<'a> {
    lighting: &'a Lighting,
    view: RayView,
}

impl Shade for Lit<'_> {
    #[inline(always)]
    fn light(&self, gradient: Vec3, base: Vec3) -> LitSample {
        self.lighting.light(gradient, base, &self.view)
    }

    fn highlights(&self, ts: &[f32], weights: &[f32]) -> f32 {
        let mut lobes = [0.0_f32; HIGHLIGHTS];
        let lobes = &mut lobes[..ts.len()];
        self.lighting.shading.lobe.eval_batch(ts, lobes);
        lobes.iter().zip(weights).map(|(l, w)| l * w).sum()
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
