//! The scene file's shape as serde reads it: every key, its type and its default. Values are
//! kept `Spanned` where a later check must point at them; `build.rs` turns this into a
//! [`Scene`](crate::scene::Scene).

use glam::Vec3;
use serde::Deserialize;
use toml::Spanned;

use crate::image::{Display, ToneMap};
use crate::material::{IlluminationModel, Shading};
use crate::scene::Settings;

/// Three numbers, exactly. serde's arrays stop after their length, so a `[f32; 3]` would take
/// `[0, 0, 5, 7]` as `[0, 0, 5]`; this refuses the extra element.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub(super) struct Triple(pub(super) [f32; 3]);

impl<'de> Deserialize<'de> for Triple {
    fn deserialize<D: serde::Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        let values = Vec::<f32>::deserialize(deserializer)?;
        <[f32; 3]>::try_from(values.as_slice())
            .map(Triple)
            .map_err(|_| serde::de::Error::invalid_length(values.len(), &"exactly 3 numbers"))
    }
}

impl From<Triple> for Vec3 {
    fn from(triple: Triple) -> Self {
        Vec3::from_array(triple.0)
    }
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct SceneDescription {
    #[serde(default)]
    pub(super) ambient: Option<Spanned<Triple>>,
    pub(super) camera: Spanned<CameraDescription>,
    #[serde(default)]
    pub(super) render: RenderDescription,
    #[serde(default)]
    pub(super) lights: Vec<Spanned<LightDescription>>,
    #[serde(default)]
    pub(super) objects: Vec<Spanned<ObjectDescription>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct CameraDescription {
    pub(super) eye: Triple,
    pub(super) target: Triple,
    #[serde(default = "z_up")]
    pub(super) up: Triple,
    pub(super) fov: Option<f32>,
    pub(super) orthographic: Option<f32>,
    #[serde(default = "default_near")]
    pub(super) near: f32,
    #[serde(default = "default_far")]
    pub(super) far: f32,
}

fn z_up() -> Triple {
    Triple([0.0, 0.0, 1.0])
}
fn default_near() -> f32 {
    0.1
}
fn default_far() -> f32 {
    1000.0
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields, default)]
pub(super) struct RenderDescription {
    pub(super) width: u32,
    pub(super) height: u32,
    pub(super) samples: u32,
    pub(super) shading: Shading,
    pub(super) model: IlluminationModel,
    pub(super) cull_back_faces: bool,
    pub(super) background: Spanned<Triple>,
    pub(super) exposure: Spanned<f32>,
    pub(super) tonemap: ToneMap,
}

impl Default for RenderDescription {
    fn default() -> Self {
        let settings = Settings::default();
        Self {
            width: settings.width,
            height: settings.height,
            samples: settings.samples,
            shading: settings.shading,
            model: settings.model,
            cull_back_faces: settings.cull_back_faces,
            background: Spanned::new(0..0, Triple(settings.background.to_array())),
            exposure: Spanned::new(0..0, Display::default().exposure),
            tonemap: Display::default().tonemap,
        }
    }
}

#[derive(Clone, Copy, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub(super) enum LightKind {
    Directional,
    Point,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct LightDescription {
    pub(super) kind: LightKind,
    pub(super) towards: Option<Triple>,
    pub(super) position: Option<Triple>,
    #[serde(default = "white")]
    pub(super) intensity: Triple,
}

fn white() -> Triple {
    Triple([1.0; 3])
}

#[derive(Clone, Copy, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub(super) enum ShapeKind {
    Sphere,
    Torus,
    Plane,
    Teapot,
    Mesh,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct ObjectDescription {
    pub(super) shape: ShapeKind,
    pub(super) radius: Option<Spanned<f32>>,
    pub(super) segments: Option<Spanned<u32>>,
    pub(super) rings: Option<Spanned<u32>>,
    pub(super) major: Option<Spanned<f32>>,
    pub(super) minor: Option<Spanned<f32>>,
    pub(super) sides: Option<Spanned<u32>>,
    pub(super) size: Option<Spanned<f32>>,
    pub(super) level: Option<Spanned<u32>>,
    pub(super) path: Option<Spanned<String>>,
    #[serde(default)]
    pub(super) translate: Triple,
    #[serde(default)]
    pub(super) rotate: Triple,
    #[serde(default = "one")]
    pub(super) scale: Spanned<f32>,
    #[serde(default)]
    pub(super) material: MaterialDescription,
}

fn one() -> Spanned<f32> {
    Spanned::new(0..0, 1.0)
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields, default)]
pub(super) struct MaterialDescription {
    pub(super) ka: Spanned<f32>,
    pub(super) kd: Spanned<f32>,
    pub(super) ks: Spanned<f32>,
    pub(super) colour: Spanned<Triple>,
    pub(super) specular_colour: Spanned<Triple>,
    pub(super) lobe: Spanned<String>,
    pub(super) n: Spanned<f64>,
    pub(super) geometry: Spanned<String>,
    pub(super) normalisation: Spanned<String>,
}

impl Default for MaterialDescription {
    fn default() -> Self {
        let unspanned = |v| Spanned::new(0..0, v);
        Self {
            ka: unspanned(0.1),
            kd: unspanned(0.6),
            ks: unspanned(0.4),
            colour: Spanned::new(0..0, Triple([0.8; 3])),
            specular_colour: Spanned::new(0..0, Triple([1.0; 3])),
            lobe: Spanned::new(0..0, "pow".to_owned()),
            n: Spanned::new(0..0, 32.0),
            geometry: Spanned::new(0..0, "phong".to_owned()),
            normalisation: Spanned::new(0..0, "none".to_owned()),
        }
    }
}
