//! From the description to the scene: each camera, light, object and material checked and
//! built, with the offending value's position in every message.

use std::ops::Range;
use std::path::{Path, PathBuf};

use glam::{EulerRot, Mat3, Vec3};
use specula::{Exponent, Geometry, Lobe, LobeKind, Normalisation};
use toml::Spanned;

use super::format::{
    CameraDescription, LightDescription, LightKind, MaterialDescription, ObjectDescription,
    ShapeKind,
};
use super::{Locator, SceneError};
use crate::camera::Camera;
use crate::camera::{in_scene_range, Projection, MAX_COORDINATE};
use crate::load::load_mesh;
use crate::material::{Light, Material};
use crate::mesh::Mesh;
use crate::scene::Analytic;
use crate::scene::Object;
use crate::shapes::{plane, sphere, torus};
use crate::teapot::{teapot, TEAPOT_PATCHES};

pub(super) fn build_camera(
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

pub(super) fn build_light(
    locate: &Locator,
    light: &Spanned<LightDescription>,
) -> Result<Light, SceneError> {
    let l = light.get_ref();
    let intensity =
        locate.finite_non_negative("intensity", &Spanned::new(light.span(), l.intensity))?;
    let fail = |message: &str| Err(locate.error(light.span(), message));
    match (l.kind, l.towards, l.position) {
        (LightKind::Directional, Some(towards), None) => {
            match Vec3::from(towards).try_normalize() {
                Some(towards) => Ok(Light::Directional { towards, intensity }),
                None => fail(
                    "lights.towards: must be a finite, non-zero direction (towards the \
                light)",
                ),
            }
        }
        (LightKind::Point, None, Some(position)) if in_scene_range(position.into()) => {
            Ok(Light::Point {
                position: position.into(),
                intensity,
            })
        }
        (LightKind::Directional, ..) => fail(
            "lights: a directional light takes `towards` (the \
            direction to the light) and no `position`",
        ),
        (LightKind::Point, ..) => Err(locate.error(
            light.span(),
            format!(
                "lights: a point light \
            takes a `position` (finite, each coordinate within {MAX_COORDINATE:e}) and no \
            `towards`"
            ),
        )),
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

/// The triangles a scene may still add: the limit (`--max-triangles`) less what its objects
/// have taken so far.
pub(super) struct TriangleBudget {
    limit: u64,
    left: u64,
}

impl TriangleBudget {
    pub(super) fn new(limit: u64) -> Self {
        Self { limit, left: limit }
    }

    /// Takes `triangles` from what is left, or says the scene would pass its limit.
    fn charge(&mut self, triangles: u64) -> Result<(), String> {
        self.left = self.left.checked_sub(triangles).ok_or_else(|| {
            format!(
                "this object's {triangles} triangles take the scene past its limit of {} triangles \
                    (raise it with --max-triangles)",
                self.limit
            )
        })?;
        Ok(())
    }
}

pub(super) fn build_object(
    locate: &Locator,
    object: &Spanned<ObjectDescription>,
    base: Option<&Path>,
    warnings: &mut Vec<String>,
    budget: &mut TriangleBudget,
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
        budget
            .charge(triangles)
            .map_err(|message| locate.error(object.span(), message))
    };
    // The sphere's radius before the object's scale, for its exact shape.
    let mut sphere_radius = None;
    let mesh = match o.shape {
        ShapeKind::Sphere => {
            let radius = length("radius", &o.radius, 1.0)?;
            let segments = count("segments", &o.segments, 96, 3..4097)?;
            let rings = count("rings", &o.rings, 48, 2..4097)?;
            charge(2 * u64::from(segments) * u64::from(rings))?;
            sphere_radius = Some(radius);
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
                return Err(locate.error(
                    object.span(),
                    "path: a mesh object needs `path`, a .obj, \
                    .stl or .ply file relative to the scene",
                ));
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
    if !in_scene_range(translate) {
        return Err(locate.error(
            object.span(),
            format!("translate: each coordinate must be within {MAX_COORDINATE:e} scene units"),
        ));
    }
    let rotation = Mat3::from_euler(EulerRot::ZYX, r[2], r[1], r[0]);
    let mesh = transform(&mesh, rotation, scale, translate);
    // A rotation, uniform scale and translation keep a sphere a sphere.
    let analytic = sphere_radius.map(|radius| Analytic::Sphere {
        centre: translate,
        radius: scale * radius,
    });
    Ok(Object {
        mesh,
        analytic,
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
pub(super) fn prepare_lobes(objects: &[Spanned<ObjectDescription>]) {
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
    let kind = crate::lobe_file::parse_lobe(m.lobe.get_ref(), locate.base)
        .map_err(|error| locate.error(m.lobe.span(), format!("material.lobe: {error}")))?;
    let n = Exponent::try_new(*m.n.get_ref()).map_err(invalid("n", m.n.span()))?;
    let lobe = Lobe::checked(kind, n).map_err(invalid("lobe", m.lobe.span()))?;
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
        lobe,
        geometry,
        normalisation,
    })
}
