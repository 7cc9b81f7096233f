//! The TOML scene format, and its translation into a [`Scene`].
//!
//! Every key is optional except the camera's `eye` and `target`; unknown keys are refused. A
//! problem is reported as `file:line:column: key: what is wrong (and the valid choices)`: syntax
//! and type errors with the position `toml` gives, value errors (an unknown lobe id, `n` out of
//! range, a key that does not apply to the shape) with the position of the offending value.

use std::ops::Range;
use std::path::{Path, PathBuf};

use glam::{EulerRot, Mat3, Vec3};

use crate::camera::MAX_COORDINATE;
use serde::Deserialize;
use specula::{Exponent, Geometry, Lobe, LobeKind, Normalisation};
use thiserror::Error;
use toml::Spanned;

use crate::camera::Projection;
use crate::load::load_mesh;
use crate::material::{IlluminationModel, Light, Material, Shading};
use crate::scene::{Object, Settings};
use crate::{plane, sphere, teapot, torus, Camera, Display, Mesh, Scene, ToneMap, TEAPOT_PATCHES};

/// A scene file that cannot be used: where, and why.
#[derive(Clone, Debug, Error, PartialEq)]
#[error("{file}:{line}:{column}: {message}")]
pub struct SceneError {
    /// The file (or a label such as `<default scene>`).
    pub file: String,
    /// 1-based line of the offending text.
    pub line: usize,
    /// 1-based column.
    pub column: usize,
    /// What is wrong, naming the key and the valid choices.
    pub message: String,
}

/// A parsed scene and the remarks made while building it (dropped degenerate triangles).
#[derive(Clone, Debug)]
pub struct LoadedScene {
    /// The scene.
    pub scene: Scene,
    /// Things the user should know, one line each.
    pub warnings: Vec<String>,
}

/// The most triangles a scene may have by default, over all its objects: 8,388,608 (about
/// 0.9 GB of transformed geometry while rendering). Procedural shapes are charged before they
/// are tessellated. `--max-triangles` changes it ([`set_max_triangles`]).
pub const MAX_TRIANGLES: u64 = 1 << 23;

static TRIANGLE_LIMIT: std::sync::atomic::AtomicU64 =
    std::sync::atomic::AtomicU64::new(MAX_TRIANGLES);

/// Sets the most triangles a scene this process loads may have.
pub fn set_max_triangles(triangles: u64) {
    TRIANGLE_LIMIT.store(triangles, std::sync::atomic::Ordering::Relaxed);
}
/// The most objects a scene may have.
pub const MAX_OBJECTS: usize = 10_000;

/// Three numbers, exactly. serde's arrays stop after their length, so a `[f32; 3]` would take
/// `[0, 0, 5, 7]` as `[0, 0, 5]`; this refuses the extra element.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
struct Triple([f32; 3]);

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
struct SceneDescription {
    #[serde(default)]
    ambient: Option<Spanned<Triple>>,
    camera: Spanned<CameraDescription>,
    #[serde(default)]
    render: RenderDescription,
    #[serde(default)]
    lights: Vec<Spanned<LightDescription>>,
    #[serde(default)]
    objects: Vec<Spanned<ObjectDescription>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct CameraDescription {
    eye: Triple,
    target: Triple,
    #[serde(default = "z_up")]
    up: Triple,
    fov: Option<f32>,
    orthographic: Option<f32>,
    #[serde(default = "default_near")]
    near: f32,
    #[serde(default = "default_far")]
    far: f32,
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
struct RenderDescription {
    width: u32,
    height: u32,
    samples: u32,
    shading: Shading,
    model: IlluminationModel,
    cull_back_faces: bool,
    background: Spanned<Triple>,
    exposure: Spanned<f32>,
    tonemap: ToneMap,
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
enum LightKind {
    Directional,
    Point,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct LightDescription {
    kind: LightKind,
    towards: Option<Triple>,
    position: Option<Triple>,
    #[serde(default = "white")]
    intensity: Triple,
}

fn white() -> Triple {
    Triple([1.0; 3])
}

#[derive(Clone, Copy, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "kebab-case")]
enum ShapeKind {
    Sphere,
    Torus,
    Plane,
    Teapot,
    Mesh,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct ObjectDescription {
    shape: ShapeKind,
    radius: Option<Spanned<f32>>,
    segments: Option<Spanned<u32>>,
    rings: Option<Spanned<u32>>,
    major: Option<Spanned<f32>>,
    minor: Option<Spanned<f32>>,
    sides: Option<Spanned<u32>>,
    size: Option<Spanned<f32>>,
    level: Option<Spanned<u32>>,
    path: Option<Spanned<String>>,
    #[serde(default)]
    translate: Triple,
    #[serde(default)]
    rotate: Triple,
    #[serde(default = "one")]
    scale: Spanned<f32>,
    #[serde(default)]
    material: MaterialDescription,
}

fn one() -> Spanned<f32> {
    Spanned::new(0..0, 1.0)
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields, default)]
struct MaterialDescription {
    ka: Spanned<f32>,
    kd: Spanned<f32>,
    ks: Spanned<f32>,
    colour: Spanned<Triple>,
    specular_colour: Spanned<Triple>,
    lobe: Spanned<String>,
    n: Spanned<f64>,
    geometry: Spanned<String>,
    normalisation: Spanned<String>,
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

/// serde's "unknown field `x`, expected one of `a`, `b`" (or "unknown variant") with the
/// nearest valid choice named, when one is close: a typo gets its correction.
fn with_nearest_choice(message: &str) -> String {
    let unknown = ["unknown field `", "unknown variant `"]
        .iter()
        .find_map(|prefix| message.strip_prefix(prefix));
    let Some((typed, rest)) = unknown.and_then(|rest| rest.split_once('`')) else {
        return message.to_owned();
    };
    if typed.chars().count() > specula::QUOTED_CHARACTERS {
        // Too long to be a typo of a key: quoted in part, and no distance computed (its cost
        // grows with the length).
        let kind = if message.starts_with("unknown field") {
            "field"
        } else {
            "variant"
        };
        return format!("unknown {kind} `{}`{rest}", specula::excerpt(typed));
    }
    // The choices are the back-quoted words after "expected".
    let choices = rest.split('`').skip(1).step_by(2);
    match specula::nearest(typed, choices) {
        Some(choice) => format!("{message}; did you mean `{choice}`?"),
        None => message.to_owned(),
    }
}

/// Turns byte spans into `file:line:column` errors.
struct Locator<'a> {
    source: &'a str,
    file: &'a str,
}

impl Locator<'_> {
    fn error(&self, span: Range<usize>, message: impl Into<String>) -> SceneError {
        let before = &self.source[..span.start.min(self.source.len())];
        let line = before.matches('\n').count() + 1;
        let column = before.len() - before.rfind('\n').map_or(0, |i| i + 1) + 1;
        SceneError {
            file: self.file.to_owned(),
            line,
            column,
            message: message.into(),
        }
    }

    fn finite_non_negative(&self, key: &str, value: &Spanned<Triple>) -> Result<Vec3, SceneError> {
        let v = value.get_ref().0;
        if v.iter().all(|c| c.is_finite() && *c >= 0.0) {
            Ok(Vec3::from_array(v))
        } else {
            Err(self.error(
                value.span(),
                format!("{key}: every component must be a finite number >= 0, got {v:?}"),
            ))
        }
    }
}

impl Scene {
    /// Reads a scene file; mesh paths in it are relative to the file's directory.
    pub fn from_file(path: &Path) -> Result<LoadedScene, SceneError> {
        let fail = |message: String| SceneError {
            file: path.display().to_string(),
            line: 0,
            column: 0,
            message: format!("cannot read the scene file: {message}"),
        };
        let bytes = crate::input::read_within(path, crate::input::MAX_SCENE_BYTES).map_err(fail)?;
        let source = String::from_utf8(bytes).map_err(|e| fail(format!("not UTF-8 text ({e})")))?;
        let base = path.parent().map(Path::to_path_buf);
        Scene::from_toml(&source, &path.display().to_string(), base.as_deref())
    }

    /// Parses a scene from TOML text; `file` labels messages, `base` resolves mesh paths.
    pub fn from_toml(
        source: &str,
        file: &str,
        base: Option<&Path>,
    ) -> Result<LoadedScene, SceneError> {
        let locate = Locator { source, file };
        let description: SceneDescription = toml::from_str(source).map_err(|error| {
            locate.error(
                error.span().unwrap_or(0..0),
                with_nearest_choice(error.message().trim_end()),
            )
        })?;
        let mut warnings = Vec::new();
        let camera = build_camera(&locate, &description.camera)?;
        let render = &description.render;
        let settings = Settings {
            width: render.width,
            height: render.height,
            samples: render.samples,
            shading: render.shading,
            model: render.model,
            cull_back_faces: render.cull_back_faces,
            background: locate.finite_non_negative("background", &render.background)?,
        };
        let exposure = *render.exposure.get_ref();
        if !(exposure.is_finite() && exposure > 0.0) {
            let message = format!("render.exposure: must be a positive number, got {exposure}");
            return Err(locate.error(render.exposure.span(), message));
        }
        let lights = description
            .lights
            .iter()
            .map(|light| build_light(&locate, light))
            .collect::<Result<_, _>>()?;
        if let Some(extra) = description.objects.get(MAX_OBJECTS) {
            return Err(locate.error(
                extra.span(),
                format!(
                    "the scene has {} objects; at most {MAX_OBJECTS}",
                    description.objects.len()
                ),
            ));
        }
        prepare_lobes(&description.objects);
        let limit = TRIANGLE_LIMIT.load(std::sync::atomic::Ordering::Relaxed);
        let mut budget = limit;
        let objects = description
            .objects
            .iter()
            .map(|object| build_object(&locate, object, base, &mut warnings, &mut budget, limit))
            .collect::<Result<_, _>>()?;
        let ambient = match &description.ambient {
            Some(value) => locate.finite_non_negative("ambient", value)?,
            None => Vec3::ZERO,
        };
        Ok(LoadedScene {
            scene: Scene {
                camera,
                lights,
                ambient,
                objects,
                settings,
                display: Display {
                    exposure,
                    tonemap: render.tonemap,
                },
            },
            warnings,
        })
    }
}

fn build_camera(
    locate: &Locator,
    camera: &Spanned<CameraDescription>,
) -> Result<Camera, SceneError> {
    let c = camera.get_ref();
    let projection = match (c.fov, c.orthographic) {
        (Some(_), Some(_)) => {
            return Err(locate.error(
                camera.span(),
                "camera: give either fov (perspective) or orthographic (a view height), not both",
            ));
        }
        (fov, None) => Projection::Perspective {
            fov_y_degrees: fov.unwrap_or(40.0),
        },
        (None, Some(height)) => Projection::Orthographic { height },
    };
    let v = Vec3::from;
    Camera::try_new(v(c.eye), v(c.target), v(c.up), projection, c.near, c.far)
        .map_err(|error| locate.error(camera.span(), format!("camera: {error}")))
}

fn build_light(locate: &Locator, light: &Spanned<LightDescription>) -> Result<Light, SceneError> {
    let l = light.get_ref();
    let intensity =
        locate.finite_non_negative("intensity", &Spanned::new(light.span(), l.intensity))?;
    let fail = |message: &str| Err(locate.error(light.span(), message));
    match (l.kind, l.towards, l.position) {
        (LightKind::Directional, Some(towards), None) => match Vec3::from(towards).try_normalize() {
            Some(towards) => Ok(Light::Directional { towards, intensity }),
            None => fail("lights.towards: must be a finite, non-zero direction (towards the light)"),
        },
        (LightKind::Point, None, Some(position))
            if Vec3::from(position).is_finite()
                && Vec3::from(position).abs().max_element() <= MAX_COORDINATE =>
        {
            Ok(Light::Point { position: Vec3::from(position), intensity })
        }
        (LightKind::Directional, ..) => fail("lights: a directional light takes `towards` (the direction to the light) and no `position`"),
        (LightKind::Point, ..) => fail("lights: a point light takes a `position` (finite, each coordinate within 1e6) and no `towards`"),
    }
}

/// The keys each shape accepts besides the common ones.
fn shape_keys(shape: ShapeKind) -> &'static [&'static str] {
    match shape {
        ShapeKind::Sphere => &["radius", "segments", "rings"],
        ShapeKind::Torus => &["major", "minor", "segments", "sides"],
        ShapeKind::Plane => &["size"],
        ShapeKind::Teapot => &["level"],
        ShapeKind::Mesh => &["path"],
    }
}

fn build_object(
    locate: &Locator,
    object: &Spanned<ObjectDescription>,
    base: Option<&Path>,
    warnings: &mut Vec<String>,
    budget: &mut u64,
    limit: u64,
) -> Result<Object, SceneError> {
    let o = object.get_ref();
    let given: [(&str, Option<Range<usize>>); 9] = [
        ("radius", o.radius.as_ref().map(Spanned::span)),
        ("segments", o.segments.as_ref().map(Spanned::span)),
        ("rings", o.rings.as_ref().map(Spanned::span)),
        ("major", o.major.as_ref().map(Spanned::span)),
        ("minor", o.minor.as_ref().map(Spanned::span)),
        ("sides", o.sides.as_ref().map(Spanned::span)),
        ("size", o.size.as_ref().map(Spanned::span)),
        ("level", o.level.as_ref().map(Spanned::span)),
        ("path", o.path.as_ref().map(Spanned::span)),
    ];
    let allowed = shape_keys(o.shape);
    for (key, span) in given {
        if let Some(span) = span.filter(|_| !allowed.contains(&key)) {
            return Err(locate.error(
                span,
                format!(
                    "{key}: does not apply to this shape; its keys are {}",
                    allowed.join(", ")
                ),
            ));
        }
    }
    let length = |key: &str, value: &Option<Spanned<f32>>, default: f32| match value {
        None => Ok(default),
        Some(v) if v.get_ref().is_finite() && *v.get_ref() > 0.0 => Ok(*v.get_ref()),
        Some(v) => Err(locate.error(
            v.span(),
            format!("{key}: must be a positive length, got {}", v.get_ref()),
        )),
    };
    let count =
        |key: &str, value: &Option<Spanned<u32>>, default: u32, range: Range<u32>| match value {
            None => Ok(default),
            Some(v) if range.contains(v.get_ref()) => Ok(*v.get_ref()),
            Some(v) => Err(locate.error(
                v.span(),
                format!(
                    "{key}: must be in [{}, {}], got {}",
                    range.start,
                    range.end - 1,
                    v.get_ref()
                ),
            )),
        };
    // Each shape's triangles are charged to the scene's budget before it is tessellated.
    let mut charge = |triangles: u64| {
        if triangles > *budget {
            Err(locate.error(
                object.span(),
                format!(
                    "this object's {triangles} triangles take the scene past its limit of {limit} triangles (raise it with --max-triangles)"
                ),
            ))
        } else {
            *budget -= triangles;
            Ok(())
        }
    };
    let mesh = match o.shape {
        ShapeKind::Sphere => {
            let radius = length("radius", &o.radius, 1.0)?;
            let segments = count("segments", &o.segments, 96, 3..4097)?;
            let rings = count("rings", &o.rings, 48, 2..4097)?;
            charge(2 * u64::from(segments) * u64::from(rings))?;
            sphere(radius, segments, rings)
        }
        ShapeKind::Torus => {
            let (major, minor) = (
                length("major", &o.major, 1.0)?,
                length("minor", &o.minor, 0.3)?,
            );
            let segments = count("segments", &o.segments, 96, 3..4097)?;
            let sides = count("sides", &o.sides, 48, 3..4097)?;
            charge(2 * u64::from(segments) * u64::from(sides))?;
            torus(major, minor, segments, sides)
        }
        ShapeKind::Plane => {
            charge(2)?;
            plane(length("size", &o.size, 10.0)?)
        }
        ShapeKind::Teapot => {
            let level = count("level", &o.level, 12, 1..65)?;
            charge(2 * TEAPOT_PATCHES as u64 * u64::from(level) * u64::from(level))?;
            teapot(level)
        }
        ShapeKind::Mesh => {
            let Some(path) = &o.path else {
                return Err(locate.error(object.span(), "path: a mesh object needs `path`, a .obj, .stl or .ply file relative to the scene"));
            };
            let full: PathBuf =
                base.map_or_else(|| PathBuf::from(path.get_ref()), |b| b.join(path.get_ref()));
            let loaded = load_mesh(&full)
                .map_err(|error| locate.error(path.span(), format!("path: {error}")))?;
            charge(loaded.mesh.triangles().len() as u64)?;
            if loaded.degenerate_triangles > 0 {
                warnings.push(format!(
                    "{}: skipped {} degenerate triangle(s)",
                    full.display(),
                    loaded.degenerate_triangles
                ));
            }
            loaded.mesh
        }
    };
    let scale = *o.scale.get_ref();
    if !(scale.is_finite() && scale > 0.0) {
        return Err(locate.error(
            o.scale.span(),
            format!("scale: must be a positive number, got {scale}"),
        ));
    }
    let translate = Vec3::from(o.translate);
    let r = o.rotate.0.map(f32::to_radians);
    if !(translate.is_finite() && r.iter().all(|a| a.is_finite())) {
        return Err(locate.error(object.span(), "translate and rotate must be finite"));
    }
    if translate.abs().max_element() > MAX_COORDINATE {
        return Err(locate.error(
            object.span(),
            format!("translate: each coordinate must be within {MAX_COORDINATE:e} scene units"),
        ));
    }
    let rotation = Mat3::from_euler(EulerRot::ZYX, r[2], r[1], r[0]);
    let mesh = transform(&mesh, rotation, scale, translate);
    Ok(Object {
        mesh,
        material: build_material(locate, &o.material)?,
    })
}

fn transform(mesh: &Mesh, rotation: Mat3, scale: f32, translate: Vec3) -> Mesh {
    let positions = mesh
        .positions()
        .iter()
        .map(|&p| rotation * (scale * p) + translate)
        .collect();
    let normals = mesh.normals().iter().map(|&n| rotation * n).collect();
    // A rotation, uniform scale and translation of a valid mesh is valid.
    Mesh::try_new(positions, normals, mesh.triangles().to_vec()).unwrap_or_default()
}

/// Prepares every distinct valid (lobe, n) of the scene's materials in parallel, so that the
/// fits some lobes need (a Remez fit for `minimax2`, about 0.7 ms) are computed across the
/// cores and then served from the library's cache as each object is built. Invalid values are
/// skipped here; building the object reports them.
fn prepare_lobes(objects: &[Spanned<ObjectDescription>]) {
    use rayon::prelude::*;
    let mut distinct: Vec<(LobeKind, Exponent)> = objects
        .iter()
        .filter_map(|object| {
            let m = &object.get_ref().material;
            let kind = LobeKind::parse(m.lobe.get_ref()).ok()?;
            Some((kind, Exponent::try_new(*m.n.get_ref()).ok()?))
        })
        .collect();
    distinct.sort_by(|a, b| {
        (a.0.id(), a.1.get())
            .partial_cmp(&(b.0.id(), b.1.get()))
            .unwrap_or(core::cmp::Ordering::Equal)
    });
    distinct.dedup();
    distinct.par_iter().for_each(|&(kind, n)| {
        let _ = Lobe::new(kind, n);
    });
}

fn build_material(locate: &Locator, m: &MaterialDescription) -> Result<Material, SceneError> {
    let coefficient = |key: &str, v: &Spanned<f32>| {
        let value = *v.get_ref();
        if value.is_finite() && value >= 0.0 {
            Ok(value)
        } else {
            Err(locate.error(
                v.span(),
                format!("material.{key}: must be a finite number >= 0, got {value}"),
            ))
        }
    };
    let invalid = |key: &'static str, span: Range<usize>| {
        move |error: specula::Error| locate.error(span, format!("material.{key}: {error}"))
    };
    let kind = LobeKind::parse(m.lobe.get_ref()).map_err(invalid("lobe", m.lobe.span()))?;
    let n = Exponent::try_new(*m.n.get_ref()).map_err(invalid("n", m.n.span()))?;
    let geometry =
        Geometry::parse(m.geometry.get_ref()).map_err(invalid("geometry", m.geometry.span()))?;
    let normalisation = Normalisation::parse(m.normalisation.get_ref())
        .map_err(invalid("normalisation", m.normalisation.span()))?;
    Ok(Material {
        ka: coefficient("ka", &m.ka)?,
        kd: coefficient("kd", &m.kd)?,
        ks: coefficient("ks", &m.ks)?,
        colour: locate.finite_non_negative("material.colour", &m.colour)?,
        specular_colour: locate
            .finite_non_negative("material.specular_colour", &m.specular_colour)?,
        lobe: Lobe::new(kind, n),
        geometry,
        normalisation,
    })
}
