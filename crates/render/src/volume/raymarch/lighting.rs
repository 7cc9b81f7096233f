//! How a volume's samples are lit: the material, the light, and each sample's colour and
//! highlight.

use glam::Vec3;
use specula::{Geometry, Lobe, Normalisation};

use crate::volume::Volume;

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
    pub(super) fn new(shading: Shading, volume: &Volume, light: Vec3) -> Self {
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
        let parts = self.lit_parts(gradient, view.wo, view.half, view.wi_dot_wo);
        LitSample {
            colour: base * parts.colour_scale,
            highlight: parts.highlight,
            t: parts.t,
        }
    }

    /// [`Lighting::light`] without a branch on the sample (the ray marcher lights several
    /// rays' samples at once, lane by lane): the view is `wo`, its `half` vector and
    /// `wi . wo`.
    #[inline(always)]
    pub(crate) fn lit_parts(
        &self,
        gradient: Vec3,
        wo: Vec3,
        half: Vec3,
        wi_dot_wo: f32,
    ) -> LitParts {
        let squared = gradient.length_squared();
        // No gradient (or an infinite one): unlit, as a sample inside uniform tissue.
        let lit = squared > 0.0 && squared < f32::INFINITY;
        let inverse = if lit { squared } else { 1.0 }.sqrt().recip();
        // The normal is the gradient's opposite turned to face the viewer: `k g` with
        // `|k| = 1 / |g|`, so its dot products are those of the gradient, scaled.
        let towards_viewer = gradient.dot(wo);
        let k = if towards_viewer > 0.0 {
            inverse
        } else {
            -inverse
        };
        let shading = &self.shading;
        let along_light = k * gradient.dot(self.light);
        let diffuse = along_light.max(0.0);
        let t = match shading.geometry {
            Geometry::Phong => 2.0 * along_light * (k * towards_viewer) - wi_dot_wo,
            Geometry::Blinn => k * gradient.dot(half),
        };
        // base.lerp(lit, weight), the highlight's share kept apart.
        let weight = (squared * inverse * self.per_gradient_reference).min(1.0);
        LitParts {
            colour_scale: if lit {
                1.0 + weight * (shading.ka + shading.kd * diffuse - 1.0)
            } else {
                1.0
            },
            highlight: if lit {
                weight * shading.ks * self.normalisation
            } else {
                0.0
            },
            t: if lit { t } else { 0.0 },
        }
    }
}

/// A sample's lighting, its colour apart: the sample is `colour_scale * base + highlight *
/// lobe(t)` in every channel.
#[derive(Clone, Copy, Debug)]
pub(crate) struct LitParts {
    pub colour_scale: f32,
    pub highlight: f32,
    pub t: f32,
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
    pub(crate) wo: Vec3,
    pub(crate) half: Vec3,
    pub(crate) wi_dot_wo: f32,
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
