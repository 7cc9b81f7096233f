//! A scene ready to render: camera, lights, objects in world space with their materials, and
//! the render settings. Scenes are usually read from TOML ([`Scene::from_toml`], format in
//! `description/` and docs/renderer.md); [`DEFAULT_SCENE`] is embedded.

use glam::Vec3;
use specula::{Exponent, Geometry, Lobe, LobeKind, Normalisation};

use crate::camera::Camera;
use crate::image::Display;
use crate::material::{IlluminationModel, Light, Material, Shading};
use crate::mesh::Mesh;

/// The embedded default scene: a row of spheres with `n` = 4 ... 1000 and a teapot.
pub const DEFAULT_SCENE: &str = include_str!("../data/default-scene.toml");

/// The embedded environment-lighting scene: a sphere and the teapot, no lights, the physical
/// model (what `specula render --env` draws when given no scene file).
pub const IBL_SCENE: &str = include_str!("../data/ibl-scene.toml");

/// How to render: image size, supersampling, shading method and illumination model.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Settings {
    /// Image width in pixels.
    pub width: u32,
    /// Image height in pixels.
    pub height: u32,
    /// Supersampling: `samples x samples` samples per pixel, box filtered.
    pub samples: u32,
    /// Flat, Gouraud or Phong.
    pub shading: Shading,
    /// Classic or physically based.
    pub model: IlluminationModel,
    /// Drop triangles that face away from the camera.
    pub cull_back_faces: bool,
    /// Linear radiance where nothing is drawn.
    pub background: Vec3,
}

impl Default for Settings {
    fn default() -> Self {
        Self {
            width: 960,
            height: 540,
            samples: 1,
            shading: Shading::Phong,
            model: IlluminationModel::Classic,
            cull_back_faces: true,
            background: Vec3::ZERO,
        }
    }
}

/// A mesh in world space and its material.
#[derive(Clone, Debug, PartialEq)]
pub struct Object {
    /// The geometry, already transformed to world space.
    pub mesh: Mesh,
    /// The exact shape the mesh tessellates, where it has one: what a ray tracer given the
    /// scene (`write_mitsuba_scene`) draws instead of the triangles.
    pub analytic: Option<Analytic>,
    /// The material.
    pub material: Material,
}

/// An exact shape, in world space.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Analytic {
    /// A sphere.
    Sphere {
        /// Its centre.
        centre: Vec3,
        /// Its radius.
        radius: f32,
    },
}

/// Everything a render needs.
#[derive(Clone, Debug, PartialEq)]
pub struct Scene {
    /// The camera.
    pub camera: Camera,
    /// The lights.
    pub lights: Vec<Light>,
    /// Ambient light intensity `Ia`.
    pub ambient: Vec3,
    /// The objects, drawn in this order.
    pub objects: Vec<Object>,
    /// Render settings.
    pub settings: Settings,
    /// How radiance becomes display values when written to an 8-bit file.
    pub display: Display,
}

/// Changes applied to a whole scene (the command line's `--lobe`, `--n`, ...): `None` keeps
/// the scene's own value.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Overrides {
    /// Every material's lobe model (its exponent kept unless `n` is given too).
    pub lobe: Option<LobeKind>,
    /// Every material's exponent.
    pub n: Option<Exponent>,
    /// Every material's geometry.
    pub geometry: Option<Geometry>,
    /// Every material's normalisation.
    pub normalisation: Option<Normalisation>,
    /// The shading method.
    pub shading: Option<Shading>,
    /// The illumination model.
    pub model: Option<IlluminationModel>,
    /// Image width.
    pub width: Option<u32>,
    /// Image height.
    pub height: Option<u32>,
    /// Supersampling factor.
    pub samples: Option<u32>,
}

impl Scene {
    /// Applies `overrides` to the settings and to every material.
    pub fn apply(&mut self, overrides: &Overrides) {
        let settings = &mut self.settings;
        settings.shading = overrides.shading.unwrap_or(settings.shading);
        settings.model = overrides.model.unwrap_or(settings.model);
        settings.width = overrides.width.unwrap_or(settings.width);
        settings.height = overrides.height.unwrap_or(settings.height);
        settings.samples = overrides.samples.unwrap_or(settings.samples);
        for object in &mut self.objects {
            let material = &mut object.material;
            let kind = overrides.lobe.unwrap_or(material.lobe.kind());
            let n = overrides.n.unwrap_or(material.lobe.exponent());
            if (kind, n) != (material.lobe.kind(), material.lobe.exponent()) {
                material.lobe = Lobe::new(kind, n);
            }
            material.geometry = overrides.geometry.unwrap_or(material.geometry);
            material.normalisation = overrides.normalisation.unwrap_or(material.normalisation);
        }
    }

    /// Refuses a user's lobe (after overrides) whose formula is not a lobe at its material's
    /// `n` ([`specula::Lobe::checked`]).
    pub fn check_lobes(&self) -> Result<(), String> {
        for object in &self.objects {
            let lobe = object.material.lobe;
            Lobe::checked(lobe.kind(), lobe.exponent()).map_err(|e| e.to_string())?;
        }
        Ok(())
    }

    /// The embedded default scene.
    #[must_use]
    pub fn default_scene() -> Scene {
        Scene::from_toml(DEFAULT_SCENE, "<default scene>", None)
            .expect("the embedded default scene is valid (tested)")
            .scene
    }

    /// The embedded environment-lighting scene.
    #[must_use]
    pub fn ibl_scene() -> Scene {
        Scene::from_toml(IBL_SCENE, "<environment scene>", None)
            .expect("the embedded environment scene is valid (tested)")
            .scene
    }
}
