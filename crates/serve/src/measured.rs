//! The explorer's measured-materials view: the five materials specula carries (embedded in the
//! binary) and the `.bsdf` files of the `--data` folder, every lobe and GGX fitted to each (the
//! library's fit, `specula fit --material`'s), and the polar plots of the material against its
//! fits.
//!
//! **Names, never paths.** The folder is listed once, at start-up ([`Materials::with_folder`]):
//! the `*.bsdf` entries directly in it whose final target is a regular file (as every file the
//! renderer reads), at most [`MAX_MATERIALS`]; a file named like a bundled material takes its
//! place (the user's measurement wins). A request names a material by its stem from that list
//! (`paper_white_rgb`); anything else, a path included, is refused with the valid names, so no
//! request reaches a file that was not listed.
//!
//! **Computed once.** A material's fits take seconds (27 shared-`n` fits: 13 lobes in both
//! geometries and GGX), so each material's result is computed at its first request, through
//! the bounded computation queue like every other computation, and kept (with its JSON); a
//! request for a material already fitted is answered at once, without taking a place in the
//! queue. The view shows the shared-`n` fits (one `n` per material, what a renderer's material
//! has).

use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex, OnceLock};
use std::time::Instant;

use axum::body::Bytes;
use glam::DVec3;
use serde::Serialize;
use specula::brdf::luminance;
use specula::measured::fit::{
    families, fit_all, plane_of_incidence, Fit, Observations, Sharing, Specular, GRID,
    MAX_ELEVATION_DEGREES, POLAR_ANGLES_DEGREES,
};
use specula::{Exponent, Lobe, LobeKind};
use specula_render::ibl::{render_ibl_with, IblSettings, Reflectance, Strategy};
use specula_render::measured::{
    load_measured, material_scene, FittedReflectance, MeasuredBrdf, MeasuredReflectance,
    BUNDLED_MATERIALS,
};

use super::query::{ApiError, Params};
use crate::costs::{costs_versus_pow, CostModel, TargetCost};

/// The most materials a `--data` folder may hold.
pub const MAX_MATERIALS: usize = 64;

/// Directions along each polar plot's plane of incidence.
pub const POLAR_POINTS: usize = 120;

/// The widest material render, in pixels (the height is 9/16 of it).
pub const MAX_MATERIAL_RENDER_SIZE: u32 = 384;

/// The most samples per pixel of a material render.
pub const MAX_MATERIAL_RENDER_SPP: u32 = 64;

/// What a material render shows besides its fits: the measurement itself.
pub const MEASURED: &str = "measured";

/// The measured materials the server offers: the bundled ones and the files of its `--data`
/// folder, each with its fits once computed.
#[derive(Debug, Default)]
pub struct Materials {
    entries: Vec<Entry>,
    /// The last material read for a render (one at a time: a file holds megabytes of tables).
    loaded: Mutex<Option<(usize, Arc<MeasuredBrdf>)>>,
}

#[derive(Debug)]
struct Entry {
    name: String,
    source: Source,
    assessment: OnceLock<Result<Arc<Assessment>, String>>,
}

/// Where a material's bytes come from.
#[derive(Debug)]
enum Source {
    /// Embedded in the binary ([`BUNDLED_MATERIALS`]).
    Bundled(&'static [u8]),
    /// A file of the `--data` folder.
    File(PathBuf),
}

impl Entry {
    fn new(name: String, source: Source) -> Self {
        Self {
            name,
            source,
            assessment: OnceLock::new(),
        }
    }
}

/// A material's shared-`n` fits (in `fit_all`'s order) and the view's JSON of them.
#[derive(Debug)]
pub struct Assessment {
    fits: Vec<Fit>,
    body: Bytes,
}

impl Assessment {
    /// The JSON the fits endpoint answers.
    #[must_use]
    pub fn body(&self) -> Bytes {
        self.body.clone()
    }
}

impl Materials {
    /// No material: the view says how to give one.
    #[must_use]
    pub fn none() -> Self {
        Self::default()
    }

    /// The five materials specula carries ([`BUNDLED_MATERIALS`]), read from the binary.
    #[must_use]
    pub fn bundled() -> Self {
        Self::from_entries(
            BUNDLED_MATERIALS
                .iter()
                .map(|&(name, bytes)| Entry::new(name.to_owned(), Source::Bundled(bytes)))
                .collect(),
        )
    }

    /// The `*.bsdf` files directly in `folder` whose final target is a regular file, by name,
    /// alone.
    pub fn from_folder(folder: &Path) -> Result<(Self, Vec<String>), String> {
        Self::none().with_folder(folder)
    }

    /// These materials and the `*.bsdf` files directly in `folder` whose final target is a
    /// regular file, by name; a file named like one of these takes its place. Refused, in a
    /// line: a folder that cannot be listed, one with no such file, or one with more than
    /// [`MAX_MATERIALS`]. Entries whose names are not UTF-8 are left out, and files that take a
    /// bundled material's place said, in the second value, one line each.
    pub fn with_folder(self, folder: &Path) -> Result<(Self, Vec<String>), String> {
        let shown = folder.display();
        let listing = std::fs::read_dir(folder)
            .map_err(|e| format!("--data {shown}: cannot list the folder: {e}"))?;
        let mut found = Vec::new();
        let mut notes = Vec::new();
        for item in listing {
            let item = item.map_err(|e| format!("--data {shown}: cannot list the folder: {e}"))?;
            let path = item.path();
            if path.extension().is_none_or(|e| e != "bsdf") {
                continue;
            }
            if !std::fs::metadata(&path).is_ok_and(|meta| meta.is_file()) {
                continue;
            }
            let Some(name) = path.file_stem().and_then(|s| s.to_str()) else {
                notes.push(format!(
                    "{}: left out, its name is not UTF-8",
                    path.display()
                ));
                continue;
            };
            if found.len() == MAX_MATERIALS {
                return Err(format!(
                    "--data {shown} holds more than {MAX_MATERIALS} .bsdf files; the explorer \
                        offers at most {MAX_MATERIALS}: pass a folder with fewer (links to the \
                        files will do)"
                ));
            }
            found.push((name.to_owned(), path.clone()));
        }
        if found.is_empty() {
            return Err(format!(
                "--data {shown} holds no .bsdf file (measured materials are read from the folder \
                    itself, not its subfolders)"
            ));
        }
        let mut entries = self.entries;
        for (name, path) in found {
            let at = entries.iter().position(|e| e.name == name);
            if at.is_some() {
                notes.push(format!(
                    "{}: offered as `{name}` instead of the material of that name already offered",
                    path.display()
                ));
            }
            let entry = Entry::new(name, Source::File(path));
            match at {
                Some(at) => entries[at] = entry,
                None => entries.push(entry),
            }
        }
        Ok((Self::from_entries(entries), notes))
    }

    fn from_entries(mut entries: Vec<Entry>) -> Self {
        entries.sort_by(|a, b| a.name.cmp(&b.name));
        Self {
            entries,
            loaded: Mutex::new(None),
        }
    }

    /// The names offered, sorted.
    pub fn names(&self) -> impl Iterator<Item = &str> {
        self.entries.iter().map(|e| e.name.as_str())
    }

    /// The index of the material named `name`, if it is offered.
    #[must_use]
    pub fn find(&self, name: &str) -> Option<usize> {
        self.entries.iter().position(|e| e.name == name)
    }

    /// Whether the material at `index` has been fitted.
    #[must_use]
    pub fn is_fitted(&self, index: usize) -> bool {
        self.entries[index].assessment.get().is_some()
    }

    /// The fits of the material at `index` if already computed.
    #[must_use]
    pub fn fitted(&self, index: usize) -> Option<Result<Arc<Assessment>, String>> {
        self.entries[index].assessment.get().cloned()
    }

    /// The fits of the material at `index`, computed now if they were not (seconds: run it on
    /// the blocking pool). A file that cannot be read is an error kept like a result: the
    /// folder was listed once, at start-up.
    pub fn assess(&self, index: usize, costs: &CostModel) -> Result<Arc<Assessment>, String> {
        self.entries[index]
            .assessment
            .get_or_init(|| {
                let material = self.load(index)?;
                assess(&self.entries[index].name, &material, costs).map(Arc::new)
            })
            .clone()
    }

    /// The material at `index`, read from its bytes unless it was the last one read.
    fn load(&self, index: usize) -> Result<Arc<MeasuredBrdf>, String> {
        let mut loaded = self.loaded.lock().unwrap_or_else(|e| e.into_inner());
        if let Some((at, material)) = loaded.as_ref() {
            if *at == index {
                return Ok(Arc::clone(material));
            }
        }
        let entry = &self.entries[index];
        let read = match &entry.source {
            Source::Bundled(bytes) => MeasuredBrdf::from_bytes(bytes).map_err(|e| e.to_string()),
            Source::File(path) => load_measured(path).map_err(|message| {
                // The file's folder is the server's business; its name is the material's.
                let prefix = format!("{}: ", path.display());
                message.strip_prefix(&prefix).unwrap_or(&message).to_owned()
            }),
        };
        let material =
            Arc::new(read.map_err(|reason| {
                format!("the material `{}` cannot be read: {reason}", entry.name)
            })?);
        *loaded = Some((index, Arc::clone(&material)));
        Ok(material)
    }

    /// The material at `index` (or its fit labelled `shown`) under the sky, as a PNG.
    pub fn render_png(
        &self,
        index: usize,
        shown: &str,
        costs: &CostModel,
        size: u32,
        spp: u32,
    ) -> Result<Vec<u8>, String> {
        if shown == MEASURED {
            let material = self.load(index)?;
            return render(&MeasuredReflectance(&material), size, spp);
        }
        let fitted = self.assess(index, costs)?;
        let fit = fitted
            .fits
            .iter()
            .find(|f| f.specular.label() == shown)
            .ok_or_else(|| format!("no fit labelled `{shown}`"))?;
        render(&FittedReflectance::new(fit), size, spp)
    }
}

/// `reflectance` on the environment scene under the sky, `size` wide, as an sRGB PNG; seed 0,
/// so the measured image and a fit's share their random numbers.
fn render(reflectance: &dyn Reflectance, size: u32, spp: u32) -> Result<Vec<u8>, String> {
    let scene = material_scene(size);
    let settings = IblSettings {
        spp,
        seed: 0,
        strategy: Strategy::Mis,
    };
    let image = render_ibl_with(
        &scene,
        super::environment::sky(),
        &settings,
        reflectance,
        &|_, _| {},
    )
    .map_err(|e| e.to_string())?;
    specula_render::encode_png_srgb8(
        image.width(),
        image.height(),
        &image.to_srgb8(scene.display),
    )
    .map_err(|e| e.to_string())
}

/// The labels a render may show: [`MEASURED`] and every shared fit's.
#[must_use]
pub fn render_labels() -> Vec<String> {
    std::iter::once(MEASURED.to_owned())
        .chain(families(&LobeKind::ALL).into_iter().map(Specular::label))
        .collect()
}

/// One fit as the view shows it.
#[derive(Serialize)]
struct FitSummary {
    label: String,
    /// The lobe's id, or `ggx`.
    family: String,
    #[serde(skip_serializing_if = "Option::is_none")]
    geometry: Option<&'static str>,
    /// The fitted exponent (lobes).
    #[serde(skip_serializing_if = "Option::is_none")]
    n: Option<f64>,
    /// GGX's fitted roughness.
    #[serde(skip_serializing_if = "Option::is_none")]
    alpha: Option<f64>,
    kd: [f64; 3],
    k: [f64; 3],
    error: f64,
    relative_to_pow_best: f64,
    relative_to_ggx: f64,
    albedo_at_normal: [f64; 3],
    #[serde(skip_serializing_if = "Vec::is_empty")]
    costs: Vec<TargetCost>,
    #[serde(skip_serializing_if = "Option::is_none")]
    cost_error: Option<String>,
}

/// One viewing elevation's polar data: the measured luminance of `f cos(theta_i)` and each
/// fit's, in the fits' order.
#[derive(Serialize)]
struct PolarView {
    theta_o_deg: f64,
    measured: Vec<f32>,
    fits: Vec<Vec<f32>>,
}

#[derive(Serialize)]
struct AssessmentBody<'a> {
    material: &'a str,
    description: &'a str,
    error_measure: String,
    pairs: usize,
    /// Pow's best shared-`n` error (either geometry), the reference.
    reference_error: f64,
    ggx_error: f64,
    fits: Vec<FitSummary>,
    /// The light's signed elevation along the plane of incidence, degrees (the viewer at
    /// `+theta_o`, its mirror at `-theta_o`).
    polar_elevations_deg: Vec<f32>,
    polar: Vec<PolarView>,
    seconds: f64,
}

/// Fits `material` and writes the view's JSON.
fn assess(name: &str, material: &MeasuredBrdf, costs: &CostModel) -> Result<Assessment, String> {
    let started = Instant::now();
    let observations = Observations::of(|wo, wi| material.f_cos(wo, wi));
    let fits: Vec<Fit> = fit_all(&observations, &LobeKind::ALL)
        .into_iter()
        .filter(|f| f.sharing == Sharing::Shared)
        .collect();
    let best = |pick: &dyn Fn(&Fit) -> bool| {
        fits.iter()
            .filter(|f| pick(f))
            .map(|f| f.error)
            .min_by(f64::total_cmp)
            .unwrap_or(f64::NAN)
    };
    let reference_error = best(&|f| {
        matches!(
            f.specular,
            Specular::Lobe {
                kind: LobeKind::Pow,
                ..
            }
        )
    });
    let ggx_error = best(&|f| f.specular == Specular::Ggx);
    let summaries = fits
        .iter()
        .map(|fit| summary(fit, reference_error, ggx_error, costs))
        .collect();
    let elevations = plane_of_incidence(0.0, POLAR_POINTS)
        .iter()
        .map(|(elevation, _, _)| elevation.to_degrees() as f32)
        .collect();
    let polar = POLAR_ANGLES_DEGREES
        .iter()
        .map(|&theta_o| {
            let plane = plane_of_incidence(theta_o.to_radians(), POLAR_POINTS);
            let along = |f_cos: &dyn Fn(DVec3, DVec3) -> DVec3| {
                plane
                    .iter()
                    .map(|&(_, wo, wi)| luminance(f_cos(wo, wi)) as f32)
                    .collect()
            };
            PolarView {
                theta_o_deg: theta_o,
                measured: along(&|wo, wi| material.f_cos(wo, wi)),
                fits: fits
                    .iter()
                    .map(|fit| {
                        let model = fit.prepare();
                        along(&|wo, wi| model.f_cos(wo, wi))
                    })
                    .collect(),
            }
        })
        .collect();
    let [nh, nd, nphi] = GRID;
    let body = AssessmentBody {
        material: name,
        description: material.description(),
        error_measure: format!(
            "root mean square over {} direction pairs (a {nh} x {nd} x {nphi} grid in half and \
                difference angles, both directions within {MAX_ELEVATION_DEGREES} degrees of the \
                normal, weighted by solid angle) of the difference of the cube roots of f \
                cos(theta_i), the three channels averaged",
            observations.len()
        ),
        pairs: observations.len(),
        reference_error,
        ggx_error,
        fits: summaries,
        polar_elevations_deg: elevations,
        polar,
        seconds: started.elapsed().as_secs_f64(),
    };
    let body = serde_json::to_vec(&body).map_err(|e| e.to_string())?;
    Ok(Assessment {
        fits,
        body: Bytes::from(body),
    })
}

fn summary(fit: &Fit, reference_error: f64, ggx_error: f64, costs: &CostModel) -> FitSummary {
    let parameter = fit.parameter[0];
    let (family, geometry, n, alpha, priced) = match fit.specular.kind() {
        Some(kind) => {
            let lobe = Lobe::new(kind, Exponent::clamped(parameter));
            let geometry = match fit.specular {
                Specular::Lobe { geometry, .. } => geometry.id(),
                _ => "microfacet",
            };
            (
                kind.to_string(),
                Some(geometry),
                Some(parameter),
                None,
                Some(costs_versus_pow(costs, &lobe)),
            )
        }
        None => (fit.specular.label(), None, None, Some(parameter), None),
    };
    let (costs, cost_error) = match priced {
        Some(Ok(costs)) => (costs, None),
        Some(Err(error)) => (Vec::new(), Some(error)),
        None => (Vec::new(), None),
    };
    FitSummary {
        label: fit.specular.label(),
        family,
        geometry,
        n,
        alpha,
        kd: fit.kd,
        k: fit.k,
        error: fit.error,
        relative_to_pow_best: fit.error / reference_error,
        relative_to_ggx: fit.error / ggx_error,
        albedo_at_normal: fit.albedo_at_normal(),
        costs,
        cost_error,
    }
}

/// The request's `material`: a name from the list, never a path. Refused with the valid
/// names, or with how to start the server with some when it has none.
pub(crate) fn material(params: &Params, materials: &Materials) -> Result<usize, ApiError> {
    let names: Vec<&str> = materials.names().collect();
    if names.is_empty() {
        return Err(ApiError::bad(
            "material",
            NO_DATA.into(),
            "none: this server was started without --data".into(),
        ));
    }
    let valid = || names.join(", ");
    let Some(text) = params.text("material") else {
        return Err(ApiError::bad(
            "material",
            "`material` is required".into(),
            valid(),
        ));
    };
    materials.find(text).ok_or_else(|| {
        ApiError::bad(
            "material",
            format!("unknown material `{}`", specula::excerpt(text)),
            valid(),
        )
    })
}

/// What the view says when the server has no materials.
pub(crate) const NO_DATA: &str = "the server offers no measured materials: start it with `specula \
    serve` (the five bundled ones) or `specula serve --data DIR`, DIR a folder of RGL .bsdf files";
