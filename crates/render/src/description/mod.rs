//! The TOML scene format, and its translation into a [`Scene`].
//!
//! Every key is optional except the camera's `eye` and `target`; unknown keys are refused. A
//! problem is reported as `file:line:column: key: what is wrong (and the valid choices)`: syntax
//! and type errors with the position `toml` gives, value errors (an unknown lobe id, `n` out of
//! range, a key that does not apply to the shape) with the position of the offending value.

//!
//! `format.rs` is the file's shape (serde), `build.rs` the checks and the building; this file
//! reads the text and reports errors at their position.

mod build;
mod format;

use std::ops::Range;
use std::path::Path;

use glam::Vec3;
use thiserror::Error;
use toml::Spanned;

use self::build::{build_camera, build_light, build_object, prepare_lobes, TriangleBudget};
use self::format::{SceneDescription, Triple};
use crate::image::Display;
use crate::scene::{Scene, Settings, DEFAULT_SCENE, IBL_SCENE};

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
    /// The scene's directory: relative mesh and lobe-file paths start there.
    base: Option<&'a Path>,
}

impl Locator<'_> {
    fn error(&self, span: Range<usize>, message: impl Into<String>) -> SceneError {
        let (line, column) = specula::line_column(self.source, span.start);
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
    /// The scene a render starts from: the file at `path`, else the embedded default scene
    /// (lit by lights), or the environment scene when the render is `lit_by_environment`.
    pub fn from_file_or_default(
        path: Option<&Path>,
        lit_by_environment: bool,
    ) -> Result<LoadedScene, SceneError> {
        match path {
            Some(path) => Scene::from_file(path),
            None if lit_by_environment => Scene::from_toml(IBL_SCENE, "<environment scene>", None),
            None => Scene::from_toml(DEFAULT_SCENE, "<default scene>", None),
        }
    }

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
        let locate = Locator { source, file, base };
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
        let mut budget =
            TriangleBudget::new(TRIANGLE_LIMIT.load(std::sync::atomic::Ordering::Relaxed));
        let objects = description
            .objects
            .iter()
            .map(|object| build_object(&locate, object, base, &mut warnings, &mut budget))
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
