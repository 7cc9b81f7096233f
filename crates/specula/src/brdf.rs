//! BRDFs and the classic illumination model (SPEC section 6).
//!
//! - [`Brdf`]: the physically based form `f(wo, wi) = kd/pi + ks N(n) lobe(t)`; the radiance
//!   it reflects is `Lo = sum f Ei max(0, N.wi)`.
//! - [`ClassicModel`]: the thesis's first formula,
//!   `I = ka Ia + sum Ii (kd max(0, N.L) + ks lobe(t))`, per RGB channel.
//!
//! Both work in the local shading frame (normal `+z`), with `wo` towards the viewer and `wi`
//! towards the light, unit length.

use glam::DVec3;

use crate::{Geometry, Lobe, Normalisation};

/// A linear RGB triple (reflectances, intensities, radiances).
pub type Rgb = DVec3;

/// The luminance of linear RGB (Rec. 709 primaries): how bright a colour looks.
#[must_use]
pub fn luminance(rgb: Rgb) -> f64 {
    rgb.dot(Rgb::new(0.2126, 0.7152, 0.0722))
}

/// The physically based specular + diffuse BRDF.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Brdf {
    /// Diffuse reflectance.
    pub kd: Rgb,
    /// Specular reflectance.
    pub ks: Rgb,
    lobe: Lobe,
    geometry: Geometry,
    normalisation: Normalisation,
    scale: f64,
}

impl Brdf {
    /// A BRDF; the normalisation constant is computed here, once.
    #[must_use]
    pub fn new(
        kd: Rgb,
        ks: Rgb,
        lobe: Lobe,
        geometry: Geometry,
        normalisation: Normalisation,
    ) -> Self {
        let scale = normalisation.constant_for(&lobe);
        Self {
            kd,
            ks,
            lobe,
            geometry,
            normalisation,
            scale,
        }
    }

    /// The lobe.
    #[must_use]
    pub fn lobe(&self) -> &Lobe {
        &self.lobe
    }

    /// The geometry.
    #[must_use]
    pub fn geometry(&self) -> Geometry {
        self.geometry
    }

    /// The normalisation.
    #[must_use]
    pub fn normalisation(&self) -> Normalisation {
        self.normalisation
    }

    /// The normalisation constant `N(n)` in use.
    #[must_use]
    pub fn normalisation_constant(&self) -> f64 {
        self.scale
    }

    /// The specular factor `N(n) lobe(t)` (per unit `ks`), for directions above the surface.
    #[must_use]
    pub fn specular(&self, wo: DVec3, wi: DVec3) -> f64 {
        self.scale * self.lobe.eval(self.geometry.cos_lobe_local(wo, wi))
    }

    /// `f(wo, wi)`; zero when either direction is at or below the horizon.
    #[must_use]
    pub fn f(&self, wo: DVec3, wi: DVec3) -> Rgb {
        if wo.z <= 0.0 || wi.z <= 0.0 {
            return Rgb::ZERO;
        }
        self.kd * core::f64::consts::FRAC_1_PI + self.ks * self.specular(wo, wi)
    }
}

/// A light as the classic model sees it: a direction and an RGB intensity.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Light {
    /// Unit direction towards the light (local frame).
    pub wi: DVec3,
    /// RGB intensity `Ii` (or irradiance `Ei` for the physically based form).
    pub intensity: Rgb,
}

/// The classic (Phong-style) illumination model, peak-1 lobe.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ClassicModel {
    /// Ambient reflectance.
    pub ka: Rgb,
    /// Diffuse reflectance.
    pub kd: Rgb,
    /// Specular reflectance.
    pub ks: Rgb,
    /// The lobe (used with peak 1, no normalisation).
    pub lobe: Lobe,
    /// The geometry.
    pub geometry: Geometry,
}

impl ClassicModel {
    /// `I = ka Ia + sum Ii (kd max(0, N.L) + ks lobe(t))`.
    #[must_use]
    pub fn intensity(&self, ambient: Rgb, wo: DVec3, lights: &[Light]) -> Rgb {
        lights.iter().fold(self.ka * ambient, |sum, light| {
            if wo.z <= 0.0 || light.wi.z <= 0.0 {
                return sum;
            }
            let t = self.geometry.cos_lobe_local(wo, light.wi);
            sum + light.intensity * (self.kd * light.wi.z + self.ks * self.lobe.eval(t))
        })
    }

    /// The BRDF the classic model implies when its intensities are read as irradiances:
    /// `kd + ks lobe(t) / cos(theta_i)` (its specular term lacks the cosine a BRDF's
    /// reflected radiance carries, so the implied BRDF divides by it, which is what breaks
    /// reciprocity).
    #[must_use]
    pub fn implied_brdf(&self, wo: DVec3, wi: DVec3) -> Rgb {
        if wo.z <= 0.0 || wi.z <= 0.0 {
            return Rgb::ZERO;
        }
        let t = self.geometry.cos_lobe_local(wo, wi);
        self.kd + self.ks * (self.lobe.eval(t) / wi.z)
    }
}

/// The physically based radiance `Lo = sum f(wo, wi) Ei max(0, N.wi)`.
#[must_use]
pub fn reflected_radiance(brdf: &Brdf, wo: DVec3, lights: &[Light]) -> Rgb {
    lights
        .iter()
        .map(|light| brdf.f(wo, light.wi) * light.intensity * light.wi.z.max(0.0))
        .sum()
}
