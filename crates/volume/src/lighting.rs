//! How a volume's samples are lit: the material, the light, and each sample's colour and
//! highlight.

use glam::Vec3;
use specula::simd::Lanes;
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
    /// Whether a sample with no gradient keeps its ambient term alone (VTK's GPU ray caster,
    /// whose normal there is 0, so that only `ambient * colour` is left) rather than its full
    /// colour, unlit, as specula and VTK's CPU caster keep it.
    pub ambient_where_flat: bool,
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
            ambient_where_flat: false,
        }
    }
}

/// What every shaded sample of one render shares, prepared once.
#[derive(Clone, Copy, Debug)]
pub struct Lighting {
    /// The material.
    pub shading: Shading,
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
            light,
            gradient_reference,
            per_gradient_reference: 1.0 / gradient_reference,
        }
    }

    /// What the highlight of `lobe` is scaled by: `ks N(n)`, this lighting's normalisation's
    /// constant for `lobe` (a march may light several lobes' images at once).
    #[must_use]
    pub fn highlight_scale(&self, lobe: &specula::Lobe) -> f32 {
        self.shading.ks * self.shading.normalisation.constant_for(lobe) as f32
    }

    /// Samples lit by the classic model, a vector of them at once (the ray marcher lights
    /// several rays' samples together): lane `k` has the `gradient` (value per mm) whose
    /// opposite, turned to face the viewer, is its normal, and the view `wo`, `half` vector
    /// and `wi . wo` of its own ray. Lane-wise, with no branch on a sample.
    #[inline(always)]
    pub(crate) fn light_lanes<V: Lanes>(
        &self,
        gradient: [V; 3],
        view: &LanesView<V>,
    ) -> LitLanes<V> {
        let shading = &self.shading;
        let [gx, gy, gz] = gradient;
        let (zero, one) = (gx.splat(0.0), gx.splat(1.0));
        let dot = |v: [V; 3]| gx * v[0] + gy * v[1] + gz * v[2];
        let squared = dot(gradient);
        // No gradient (or an infinite one): unlit, as a sample inside uniform tissue.
        let finite = squared.keep(squared.lt(gx.splat(f32::INFINITY)));
        let shaded = finite.gt(zero);
        let inverse = one / finite.select(shaded, one).sqrt();
        // The normal is the gradient's opposite turned to face the viewer: `k g` with
        // `|k| = 1 / |g|`, so its dot products are those of the gradient, scaled.
        let towards_viewer = dot(view.wo);
        let k = inverse.select(towards_viewer.gt(zero), zero - inverse);
        let light = self.light;
        let along_light = k * dot([gx.splat(light.x), gx.splat(light.y), gx.splat(light.z)]);
        let diffuse = along_light.max(zero);
        let t = match shading.geometry {
            Geometry::Phong => gx.splat(2.0) * along_light * (k * towards_viewer) - view.wi_dot_wo,
            Geometry::Blinn => k * dot(view.half),
        };
        // base.lerp(lit, weight), the highlight's share kept apart.
        let weight = (squared * inverse * gx.splat(self.per_gradient_reference)).min(one);
        let lit = one + weight * (gx.splat(shading.ka) + gx.splat(shading.kd) * diffuse - one);
        let flat = if shading.ambient_where_flat {
            gx.splat(shading.ka)
        } else {
            one
        };
        LitLanes {
            colour_scale: lit.select(shaded, flat),
            fade: weight.keep(shaded),
            t: t.keep(shaded),
        }
    }
}

/// Rays' views, lane by lane (see [`RayView`]).
#[derive(Clone, Copy, Debug)]
pub(crate) struct LanesView<V> {
    pub wo: [V; 3],
    pub half: [V; 3],
    pub wi_dot_wo: V,
}

/// Samples' lighting, their colours apart: a sample is `colour_scale * base + fade * scale *
/// lobe(t)` in every channel (the highlight is white), `scale` the lobe's `ks N(n)`
/// ([`Lighting::highlight_scale`]).
#[derive(Clone, Copy, Debug)]
pub(crate) struct LitLanes<V> {
    pub colour_scale: V,
    /// The highlight's share of the sample's shading (weak gradients faded; 0 unshaded).
    pub fade: V,
    pub t: V,
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
