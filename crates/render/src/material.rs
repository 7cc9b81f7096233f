//! Materials, lights and the shading function the rasterizer calls.
//!
//! Both illumination models of SPEC section 6 share one shape,
//! `ambient + sum_lights E_i (D max(0, N.wi) + S lobe(t) [max(0, N.wi)])`:
//! - **classic**: `D = kd colour`, `S = ks specular_colour N(n)`, no cosine on the specular
//!   term, light intensity used as is (the thesis's formula; with normalisation `none`,
//!   `N(n) = 1`);
//! - **physical**: `D = kd colour / pi`, `S = ks specular_colour N(n)`, both terms times the
//!   cosine, and a point light's intensity falls off as `1 / d^2`.
//!
//! Arithmetic is `f32`; [`Shader::shade`] evaluates the lobe on the core's scalar fast path, and
//! the pipeline's Phong path feeds [`Shader::cosines`] to the batch path instead; the normalisation
//! constant is computed once per material in `f64`.

use glam::Vec3;
use serde::{Deserialize, Serialize};
use specula::{Geometry, Lobe, Normalisation};

/// The physical model's inverse square stops growing inside this squared distance (1e-4
/// scene units): a point light on the surface would otherwise send infinite radiance (a
/// subnormal distance squared in `f32`); renderers clamp it likewise.
pub const MIN_DISTANCE_SQUARED: f32 = 1e-8;

/// Where lighting is computed.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Shading {
    /// One normal per face: lighting once per triangle, at its centroid.
    Flat,
    /// Lighting at the vertices, colour interpolated.
    Gouraud,
    /// Normal (and position) interpolated, renormalised, lighting per pixel.
    #[default]
    Phong,
}

impl Shading {
    /// Every method.
    pub const ALL: [Shading; 3] = [Shading::Flat, Shading::Gouraud, Shading::Phong];

    /// The name in scenes and on the command line.
    #[must_use]
    pub fn id(self) -> &'static str {
        match self {
            Shading::Flat => "flat",
            Shading::Gouraud => "gouraud",
            Shading::Phong => "phong",
        }
    }
}

/// Which illumination model turns lights into radiance (SPEC section 6).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum IlluminationModel {
    /// `I = ka Ia + sum Ii (kd max(0, N.L) + ks N(n) lobe(t))`.
    #[default]
    Classic,
    /// `Lo = ka Ia + sum Ei (kd / pi + ks N(n) lobe(t)) max(0, N.L)`.
    Physical,
}

impl IlluminationModel {
    /// Both models.
    pub const ALL: [IlluminationModel; 2] =
        [IlluminationModel::Classic, IlluminationModel::Physical];

    /// The name in scenes and on the command line.
    #[must_use]
    pub fn id(self) -> &'static str {
        match self {
            IlluminationModel::Classic => "classic",
            IlluminationModel::Physical => "physical",
        }
    }
}

/// A light source with an RGB intensity.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Light {
    /// Parallel light arriving from `towards` (a unit vector pointing at the light).
    Directional {
        /// Unit direction from the surface towards the light.
        towards: Vec3,
        /// RGB intensity (irradiance at normal incidence, in the physical model).
        intensity: Vec3,
    },
    /// A point light.
    Point {
        /// World position.
        position: Vec3,
        /// RGB intensity (radiant intensity, in the physical model).
        intensity: Vec3,
    },
}

/// A surface's reflectance: the classic coefficients and the specular lobe.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Material {
    /// Ambient coefficient.
    pub ka: f32,
    /// Diffuse coefficient.
    pub kd: f32,
    /// Specular coefficient.
    pub ks: f32,
    /// Linear RGB colour of the ambient and diffuse terms.
    pub colour: Vec3,
    /// Linear RGB colour of the specular term (white for plastics, the colour for metals).
    pub specular_colour: Vec3,
    /// The specular lobe, prepared for its exponent.
    pub lobe: Lobe,
    /// Phong (`R.V`) or Blinn (`N.H`).
    pub geometry: Geometry,
    /// The lobe's scale `N(n)`.
    pub normalisation: Normalisation,
}

/// A material prepared for one illumination model: the coefficients both renderers (this
/// crate's and the GPU's) upload, computed in one place.
#[derive(Clone, Copy, Debug)]
pub struct Shader {
    ambient: Vec3,
    diffuse: Vec3,
    specular: Vec3,
    lobe: Lobe,
    geometry: Geometry,
    model: IlluminationModel,
}

impl Shader {
    /// Prepares `material` for `model` (the normalisation constant is computed here, once).
    #[must_use]
    pub fn new(material: &Material, model: IlluminationModel) -> Self {
        let scale = material.normalisation.constant_for(&material.lobe) as f32;
        let diffuse = material.kd * material.colour;
        Self {
            ambient: material.ka * material.colour,
            diffuse: match model {
                IlluminationModel::Classic => diffuse,
                IlluminationModel::Physical => diffuse * core::f32::consts::FRAC_1_PI,
            },
            specular: material.ks * scale * material.specular_colour,
            lobe: material.lobe,
            geometry: material.geometry,
            model,
        }
    }

    /// The ambient term for ambient intensity `ambient`.
    #[must_use]
    pub fn ambient(&self, ambient: Vec3) -> Vec3 {
        self.ambient * ambient
    }

    /// The prepared reflectances `(ambient, diffuse, specular)`: `ka C`, `kd C` (over `pi` in
    /// the physical model) and `ks S N(n)`.
    #[must_use]
    pub fn coefficients(&self) -> (Vec3, Vec3, Vec3) {
        (self.ambient, self.diffuse, self.specular)
    }

    /// The geometry and the illumination model.
    #[must_use]
    pub fn geometry_and_model(&self) -> (Geometry, IlluminationModel) {
        (self.geometry, self.model)
    }

    /// Whether the lobe matters: a material without a specular term (a matte floor) skips it,
    /// exactly, since the lobe is finite.
    #[must_use]
    pub fn has_specular(&self) -> bool {
        self.specular != Vec3::ZERO
    }

    /// The lobe.
    #[must_use]
    pub fn lobe(&self) -> &specula::Lobe {
        &self.lobe
    }

    /// What `light` sends to `position`: the unit direction towards it and the intensity that
    /// arrives, or `None` for a point light at the point itself (or a directional light with
    /// no direction).
    pub fn incoming(&self, light: &Light, position: Vec3) -> Option<(Vec3, Vec3)> {
        match *light {
            Light::Directional { towards, intensity } => {
                towards.try_normalize().map(|wi| (wi, intensity))
            }
            Light::Point {
                position: at,
                intensity,
            } => {
                let offset = at - position;
                let distance_squared = offset.length_squared();
                if distance_squared <= 0.0 {
                    return None;
                }
                let arriving = match self.model {
                    IlluminationModel::Classic => intensity,
                    IlluminationModel::Physical => {
                        intensity / distance_squared.max(MIN_DISTANCE_SQUARED)
                    }
                };
                Some((offset / distance_squared.sqrt(), arriving))
            }
        }
    }

    /// `(N.wi, t)` when the light reaches the visible side of the surface, else `None`.
    pub fn cosines(&self, normal: Vec3, wo: Vec3, wi: Vec3) -> Option<(f32, f32)> {
        let cos_in = normal.dot(wi);
        (normal.dot(wo) > 0.0 && cos_in > 0.0)
            .then(|| (cos_in, self.geometry.cos_lobe_f32(normal, wo, wi)))
    }

    /// One light's contribution from the arriving intensity, `N.wi` and the lobe's value.
    pub fn contribution(&self, intensity: Vec3, cos_in: f32, lobe: f32) -> Vec3 {
        intensity
            * match self.model {
                IlluminationModel::Classic => self.diffuse * cos_in + self.specular * lobe,
                IlluminationModel::Physical => (self.diffuse + self.specular * lobe) * cos_in,
            }
    }

    /// Radiance leaving `position` towards `wo`, for the surface `normal`. Both directions
    /// are normalised here; where one has no direction (zero, or too long for `f32`), only
    /// the ambient term remains.
    pub fn shade(
        &self,
        position: Vec3,
        normal: Vec3,
        wo: Vec3,
        lights: &[Light],
        ambient: Vec3,
    ) -> Vec3 {
        let mut radiance = self.ambient(ambient);
        let (Some(normal), Some(wo)) = (normal.try_normalize(), wo.try_normalize()) else {
            return radiance;
        };
        for light in lights {
            let Some((wi, intensity)) = self.incoming(light, position) else {
                continue;
            };
            let Some((cos_in, t)) = self.cosines(normal, wo, wi) else {
                continue;
            };
            let lobe = if self.has_specular() {
                self.lobe.eval(t)
            } else {
                0.0
            };
            radiance += self.contribution(intensity, cos_in, lobe);
        }
        radiance
    }
}

#[cfg(test)]
mod tests {
    use specula::{Brdf, ClassicModel, Exponent, LobeKind, Rgb};

    use super::*;

    fn material(normalisation: Normalisation) -> Material {
        Material {
            ka: 0.1,
            kd: 0.5,
            ks: 0.4,
            colour: Vec3::new(0.9, 0.5, 0.2),
            specular_colour: Vec3::ONE,
            lobe: Lobe::new(LobeKind::SchlickMod, Exponent::new(40.0)),
            geometry: Geometry::Blinn,
            normalisation,
        }
    }

    /// In the local frame (normal +z) both models match the core's f64 definitions.
    #[test]
    fn both_models_agree_with_the_cores_reference_forms() {
        let (wo, wi) = (
            Vec3::new(0.2, -0.1, 0.97).normalize(),
            Vec3::new(-0.25, 0.1, 0.96).normalize(),
        );
        let intensity = Vec3::new(1.0, 0.8, 0.6);
        let lights = [Light::Directional {
            towards: wi,
            intensity,
        }];
        let ambient = Vec3::splat(0.2);
        let m = material(Normalisation::None);
        let classic = Shader::new(&m, IlluminationModel::Classic).shade(
            Vec3::ZERO,
            Vec3::Z,
            wo,
            &lights,
            ambient,
        );
        let reference = ClassicModel {
            ka: Rgb::splat(0.1) * m.colour.as_dvec3(),
            kd: Rgb::splat(0.5) * m.colour.as_dvec3(),
            ks: Rgb::splat(0.4),
            lobe: m.lobe,
            geometry: m.geometry,
        }
        .intensity(
            ambient.as_dvec3(),
            wo.as_dvec3(),
            &[specula::brdf::Light {
                wi: wi.as_dvec3(),
                intensity: intensity.as_dvec3(),
            }],
        );
        assert!(
            (classic.as_dvec3() - reference).abs().max_element() < 1e-5,
            "{classic} {reference}"
        );

        let m = material(Normalisation::Lobe);
        let physical = Shader::new(&m, IlluminationModel::Physical).shade(
            Vec3::ZERO,
            Vec3::Z,
            wo,
            &lights,
            Vec3::ZERO,
        );
        let brdf = Brdf::new(
            Rgb::splat(0.5) * m.colour.as_dvec3(),
            Rgb::splat(0.4),
            m.lobe,
            m.geometry,
            Normalisation::Lobe,
        );
        let reference = specula::brdf::reflected_radiance(
            &brdf,
            wo.as_dvec3(),
            &[specula::brdf::Light {
                wi: wi.as_dvec3(),
                intensity: intensity.as_dvec3(),
            }],
        );
        assert!(
            (physical.as_dvec3() - reference).abs().max_element() < 1e-4 * reference.max_element(),
            "{physical} {reference}"
        );
    }

    #[test]
    fn lights_below_the_horizon_and_hidden_normals_contribute_nothing() {
        let shader = Shader::new(&material(Normalisation::None), IlluminationModel::Classic);
        let below = [Light::Directional {
            towards: -Vec3::Z,
            intensity: Vec3::ONE,
        }];
        let ambient = Vec3::splat(0.5);
        let only_ambient = 0.1 * material(Normalisation::None).colour * ambient;
        assert_eq!(
            shader.shade(Vec3::ZERO, Vec3::Z, Vec3::Z, &below, ambient),
            only_ambient
        );
        let above = [Light::Directional {
            towards: Vec3::Z,
            intensity: Vec3::ONE,
        }];
        assert_eq!(
            shader.shade(Vec3::ZERO, Vec3::Z, -Vec3::Z, &above, ambient),
            only_ambient
        );
    }

    #[test]
    fn point_lights_fall_off_with_distance_only_in_the_physical_model() {
        let m = material(Normalisation::None);
        let light = |d: f32| {
            [Light::Point {
                position: Vec3::new(0.0, 0.0, d),
                intensity: Vec3::ONE,
            }]
        };
        for (model, ratio) in [
            (IlluminationModel::Classic, 1.0),
            (IlluminationModel::Physical, 4.0),
        ] {
            let shader = Shader::new(&m, model);
            let near = shader.shade(Vec3::ZERO, Vec3::Z, Vec3::Z, &light(1.0), Vec3::ZERO);
            let far = shader.shade(Vec3::ZERO, Vec3::Z, Vec3::Z, &light(2.0), Vec3::ZERO);
            assert!(((near / far) - Vec3::splat(ratio)).abs().max_element() < 1e-5);
        }
    }
}
