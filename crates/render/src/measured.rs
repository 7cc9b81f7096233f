//! Measured materials from files and in pictures: an RGL `.bsdf` read through
//! [`crate::input`] (a regular file, within [`MAX_MATERIAL_BYTES`], checked before a byte is
//! read) and handed to the core's [`MeasuredBrdf`], whose refusals come back prefixed by the
//! path; the measured material and its fits as the environment renderer's BRDFs
//! ([`MeasuredReflectance`], [`FittedReflectance`]); and the comparison render, every model
//! in the same scene with the same random numbers, each scored by FLIP against the
//! measurement ([`render_comparison`]).

use core::f64::consts::FRAC_1_PI;
use std::path::Path;

use glam::DVec3;
use specula::brdf::luminance;
use specula::measured::fit::{Fit, FittedModel, Shape};
pub use specula::measured::MeasuredBrdf;
use specula::microfacet::Distribution;
use specula::sampling::SpecularSampler;
use specula::Normalisation;

use crate::ibl::{
    cosine_direction, render_ibl_with, Environment, IblSettings, Reflectance, Strategy,
};
use crate::image::Image;
use crate::metrics::compare;
use crate::scene::{Overrides, Scene};

/// The largest material file read: 64 MiB (the RGL RGB files are 0.7 to 10 MiB).
pub const MAX_MATERIAL_BYTES: u64 = 64 << 20;

/// `(name, bytes)` of the file `data/rgl/<name>.bsdf` (the name is the file's stem).
macro_rules! bundled {
    ($name:literal) => {
        (
            $name,
            include_bytes!(concat!("../../../data/rgl/", $name, ".bsdf")),
        )
    };
}

/// The measured materials specula carries (`data/rgl`: five isotropic RGB files of the RGL
/// database, CC0, their provenance in its README), embedded so that every build offers them
/// without a folder: each material's name (the file's stem) and the file's bytes.
pub const BUNDLED_MATERIALS: [(&str, &[u8]); 5] = [
    bundled!("cc_ibiza_sunset_rgb"),
    bundled!("cc_iris_purple_gem_rgb"),
    bundled!("colodur_napoli_4f_rgb"),
    bundled!("paper_white_rgb"),
    bundled!("vch_golden_yellow_rgb"),
];

/// Reads the measured material at `path`; every refusal is one line naming the file.
pub fn load_measured(path: &Path) -> Result<MeasuredBrdf, String> {
    let named = |e: &dyn std::fmt::Display| format!("{}: {e}", path.display());
    let bytes = crate::input::read_within(path, MAX_MATERIAL_BYTES).map_err(|e| named(&e))?;
    MeasuredBrdf::from_bytes(&bytes).map_err(|e| named(&e))
}

/// The material's name: the file's stem (`paper_white_rgb` for `.../paper_white_rgb.bsdf`).
#[must_use]
pub fn material_name(path: &Path) -> String {
    path.file_stem().map_or_else(
        || path.display().to_string(),
        |s| s.to_string_lossy().into_owned(),
    )
}

/// A measured material as the environment renderer's BRDF, sampled by its own data (the
/// luminance and VNDF warps, as Mitsuba's `measured` plugin samples it). Channels that dip
/// below zero (a spectrum's RGB) are taken as zero, so no pixel goes negative.
pub struct MeasuredReflectance<'a>(pub &'a MeasuredBrdf);

impl Reflectance for MeasuredReflectance<'_> {
    fn f_and_pdf(&self, wo: DVec3, wi: DVec3) -> (DVec3, f64) {
        (self.0.f(wo, wi).max(DVec3::ZERO), self.0.pdf(wo, wi))
    }

    fn sample(&self, wo: DVec3, u: [f64; 3]) -> Option<(DVec3, DVec3, f64)> {
        let drawn = self.0.sample(wo, [u[1], u[2]])?;
        Some((drawn.wi, drawn.f.max(DVec3::ZERO), drawn.pdf))
    }
}

/// How a fitted model's specular directions are drawn: at the first channel's parameter,
/// the others' values apart (the mixture's density is exact, so the estimate is unbiased).
enum SpecularDraw {
    /// The lobe's own sampler.
    Lobe(SpecularSampler),
    /// A microfacet distribution's normals (GGX's, Beckmann's, a lobe's) in proportion to
    /// `D(h) cos(theta_h)`.
    Microfacet(Distribution),
}

/// A fitted model as the environment renderer's BRDF, drawn from a mixture of the cosine and
/// the specular term in proportion to their albedos.
pub struct FittedReflectance {
    model: FittedModel,
    draw: SpecularDraw,
    specular_share: f64,
}

impl FittedReflectance {
    /// Prepares `fit` for rendering.
    #[must_use]
    pub fn new(fit: &Fit) -> Self {
        let model = fit.prepare();
        // The draw's shape is the model's first channel's, tables and all.
        let draw = match model.first_shape().clone() {
            Shape::Lobe { lobe, geometry } => {
                SpecularDraw::Lobe(SpecularSampler::new(lobe, geometry, Normalisation::None))
            }
            Shape::Microfacet(distribution) => SpecularDraw::Microfacet(distribution),
        };
        let (d, total) = (
            luminance(DVec3::from_array(fit.kd)),
            luminance(DVec3::from_array(fit.albedo_at_normal())),
        );
        Self {
            model,
            draw,
            specular_share: if total > 0.0 {
                ((total - d) / total).clamp(0.0, 1.0)
            } else {
                0.0
            },
        }
    }

    fn specular_pdf(&self, wo: DVec3, wi: DVec3) -> f64 {
        match &self.draw {
            SpecularDraw::Lobe(sampler) => sampler.pdf(wo, wi),
            SpecularDraw::Microfacet(distribution) => {
                let h = (wo + wi).normalize();
                distribution.pdf_normal(h) / (4.0 * wo.dot(h).abs())
            }
        }
    }

    fn specular_direction(&self, wo: DVec3, u: [f64; 2]) -> Option<DVec3> {
        match &self.draw {
            SpecularDraw::Lobe(sampler) => Some(sampler.sample(wo, u)?.wi),
            SpecularDraw::Microfacet(distribution) => {
                let h = distribution.sample_normal(u);
                Some(2.0 * wo.dot(h) * h - wo)
            }
        }
    }
}

impl Reflectance for FittedReflectance {
    fn f_and_pdf(&self, wo: DVec3, wi: DVec3) -> (DVec3, f64) {
        if wo.z <= 0.0 || wi.z <= 0.0 {
            return (DVec3::ZERO, 0.0);
        }
        let share = self.specular_share;
        let specular_pdf = if share > 0.0 {
            self.specular_pdf(wo, wi)
        } else {
            0.0
        };
        (
            self.model.f(wo, wi),
            (1.0 - share) * wi.z * FRAC_1_PI + share * specular_pdf,
        )
    }

    fn sample(&self, wo: DVec3, u: [f64; 3]) -> Option<(DVec3, DVec3, f64)> {
        let wi = if u[0] < self.specular_share {
            self.specular_direction(wo, [u[1], u[2]])?
        } else {
            cosine_direction([u[1], u[2]])
        };
        let (f, pdf) = self.f_and_pdf(wo, wi);
        (pdf > 0.0).then_some((wi, f, pdf))
    }
}

/// The environment scene (a sphere and the teapot under the sky) at `width` pixels wide,
/// every object to be shown in one material.
#[must_use]
pub fn material_scene(width: u32) -> Scene {
    let mut scene = Scene::ibl_scene();
    scene.apply(&Overrides {
        width: Some(width),
        height: Some((width * 9 / 16).max(1)),
        ..Overrides::default()
    });
    scene
}

/// One image of a material comparison and how far it is from the measured one.
pub struct ComparedRender {
    /// What is shown: `measured`, or a fit's label.
    pub label: String,
    /// The image (linear radiance).
    pub image: Image,
    /// Mean FLIP against the measured render (0 for the measured render itself).
    pub mean_flip: f64,
}

/// Renders `material` and each of `fits` in [`material_scene`] under `environment` with the
/// same random numbers (seed 0), so the differences FLIP measures are the models'.
pub fn render_comparison(
    material: &MeasuredBrdf,
    fits: &[&Fit],
    environment: &Environment,
    width: u32,
    spp: u32,
    progress: &(dyn Fn(usize, usize) + Sync),
) -> Result<Vec<ComparedRender>, String> {
    let scene = material_scene(width);
    let settings = IblSettings {
        spp,
        seed: 0,
        strategy: Strategy::Mis,
    };
    let total = fits.len() + 1;
    let render = |reflectance: &dyn Reflectance, index: usize| {
        render_ibl_with(
            &scene,
            environment,
            &settings,
            reflectance,
            &|done, rows| {
                progress(index * rows + done, total * rows);
            },
        )
        .map_err(|e| e.to_string())
    };
    let measured = render(&MeasuredReflectance(material), 0)?;
    let mut renders = Vec::with_capacity(total);
    for (index, fit) in fits.iter().enumerate() {
        let image = render(&FittedReflectance::new(fit), index + 1)?;
        let difference = compare(&measured, &image, scene.display).map_err(|e| e.to_string())?;
        renders.push(ComparedRender {
            label: fit.specular.label(),
            image,
            mean_flip: difference.mean_flip,
        });
    }
    renders.insert(
        0,
        ComparedRender {
            label: "measured".to_owned(),
            image: measured,
            mean_flip: 0.0,
        },
    );
    Ok(renders)
}
