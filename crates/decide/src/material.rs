//! A measured material's verdict: every lobe (and GGX) fitted to it (`specula::measured::fit`),
//! each shared-`n` lobe's rate on a target at its fitted `n` ([`crate::lobe_rate`]), and the
//! cheapest lobe whose fit is within a margin of pow's (the core's verdict), with the figures a
//! renderer needs. What `specula fit`, `recommend --material`, the report's real materials and
//! the JSON lines share.

use std::collections::BTreeMap;
use std::path::Path;

use serde::Serialize;
pub use specula::measured::fit::verdict::Model;
use specula::measured::fit::verdict::{verdict_of, Verdict};
use specula::measured::fit::{
    families, fit_families, microfacet_families, Fit, Normals, Observations, Sharing, Specular,
    MAX_ELEVATION_DEGREES,
};
use specula::{Exponent, Lobe, LobeKind, Normalisation};
use specula_render::measured::{material_name, MeasuredBrdf};

use crate::microfacet_cost::{ggx_microfacet_rate, microfacet_rate};
use crate::{lobe_rates, log_spaced, rate_unit, Target};

/// The fit error allowed over pow's by default: 5 %.
pub const DEFAULT_MARGIN: f64 = 0.05;

/// A fit as shown: the library's figures and what they mean for a renderer.
#[derive(Clone, Debug, Serialize)]
pub struct FitRow {
    /// The fit.
    #[serde(flatten)]
    pub fit: Fit,
    /// `ks` per channel under each normalisation (lobes only).
    #[serde(skip_serializing_if = "BTreeMap::is_empty")]
    pub ks: BTreeMap<&'static str, [f64; 3]>,
    /// The fitted model's albedo at normal incidence, per channel.
    pub albedo_at_normal: [f64; 3],
    /// A channel's `n` (or `alpha`) at an end of the range searched.
    pub at_range_end: bool,
    /// `E / E_pow` in the same geometry and sharing.
    pub relative_to_pow: f64,
    /// `E / E_ggx` with the same sharing.
    pub relative_to_ggx: f64,
    /// The rate on the target at the fitted `n` (shared-`n` lobes only; higher is cheaper).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub rate: Option<f64>,
    /// In the microfacet model, the rate of the whole specular term on the target
    /// ([`crate::microfacet_cost`]; shared-`n` distributions and GGX only).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub brdf_rate: Option<f64>,
    /// Within the margin of pow's best fit (shared-`n` lobes only).
    pub meets: bool,
}

/// One material's assessment: its fits and the verdict on a target.
#[derive(Clone, Debug, Serialize)]
pub struct Assessment {
    /// The file's stem.
    pub material: String,
    /// The file.
    pub file: String,
    /// The file's own description.
    pub description: String,
    /// How the fits were compared (the error's definition, in words).
    pub error_measure: String,
    /// Direction pairs compared.
    pub pairs: usize,
    /// The measured material's albedo at normal incidence, per channel.
    pub measured_albedo_at_normal: [f64; 3],
    /// The target costed.
    pub target: Target,
    /// Its rate's unit.
    pub rate_unit: &'static str,
    /// The margin over the reference's error, as a fraction.
    pub margin: f64,
    /// The model the verdict ranks: the classic lobes against pow, or the lobes as
    /// microfacet distributions against GGX (the classic fits beside them).
    pub model: Model,
    /// Whether the answer is within the margin of the reference: always in the classic model
    /// (pow meets itself); in the microfacet model, where no distribution comes within the
    /// margin of GGX, the answer is the closest distribution and this is false.
    pub within_margin: bool,
    /// Every fit.
    pub fits: Vec<FitRow>,
    /// The index in `fits` of the lobe to ship.
    pub chosen: usize,
    /// The reference's shared-`n` fit error (pow's best, or GGX's in the microfacet model).
    pub reference_error: f64,
}

/// Luminance of a linear RGB triple (Rec. 709).
#[must_use]
pub fn luminance(rgb: [f64; 3]) -> f64 {
    specula::brdf::luminance(glam::DVec3::from_array(rgb))
}

/// Every built-in lobe and `extra` to fit for a verdict on `target`, with user lobes checked
/// over the whole range of `n` (the fits search it) and the target refused if a material's
/// verdict cannot take it: what a face calls before it loads any material.
pub fn lobes_to_fit(extra: &[LobeKind], target: Target) -> Result<Vec<LobeKind>, String> {
    crate::costing::material_target(target)?;
    crate::check_lobes(
        extra,
        &log_spaced(Exponent::new(1.0), Exponent::new(1000.0), 8),
    )?;
    Ok(crate::candidates(extra))
}

/// Fits every lobe in `kinds` to `material` (read from `path`, which names it) and ranks them
/// on `target` (not the FPGA: [`crate::FPGA_MATERIAL_REFUSAL`]) with `margin`, a fraction in
/// `[0, 1]`, allowed over pow's fit error.
pub fn assess(
    material: &MeasuredBrdf,
    path: &Path,
    kinds: &[LobeKind],
    target: Target,
    margin: f64,
) -> Result<Assessment, String> {
    assess_model(material, path, kinds, target, margin, Model::Classic)
}

/// [`assess`] for `model`: in the microfacet model every lobe is fitted twice, classic and as
/// a distribution, beside GGX and Beckmann, and the verdict names the cheapest distribution
/// within the margin of GGX's fit.
pub fn assess_model(
    material: &MeasuredBrdf,
    path: &Path,
    kinds: &[LobeKind],
    target: Target,
    margin: f64,
    model: Model,
) -> Result<Assessment, String> {
    crate::costing::material_target(target)?;
    if !(0.0..=1.0).contains(&margin) {
        return Err(format!(
            "the margin over pow's fit error must be a fraction in [0, 1], not {margin}"
        ));
    }
    let observations = Observations::of(|wo, wi| material.f_cos(wo, wi));
    // The classic fits, and in the microfacet model the distributions' beside them, each set
    // cached on its own: a classic assessment of the material reuses the first.
    let classic = families(kinds);
    let mut fits = crate::fit_cache::fits(&observations, &classic, || {
        fit_families(&observations, &classic)
    });
    if model == Model::Microfacet {
        let distributions = microfacet_families(kinds);
        fits.extend(crate::fit_cache::fits(
            &observations,
            &distributions,
            || fit_families(&observations, &distributions),
        ));
    }
    // The shared-n lobes at their fitted n, costed together (one compile on a GPU).
    let costed: Vec<Option<Lobe>> = fits
        .iter()
        .map(|fit| match (fit.specular.kind(), fit.sharing) {
            (Some(kind), Sharing::Shared) => {
                Some(Lobe::new(kind, Exponent::clamped(fit.parameter[0])))
            }
            _ => None,
        })
        .collect();
    let lobes: Vec<Lobe> = costed.iter().flatten().copied().collect();
    let mut lobe_rates = lobe_rates(target, &lobes)?.into_iter();
    let rates: Vec<Option<f64>> = costed
        .iter()
        .map(|lobe| lobe.and_then(|_| lobe_rates.next()))
        .collect();
    // In the microfacet model no distribution may come within the margin of GGX: the verdict
    // is then the closest distribution, not within it (`within_margin`).
    let Some(Verdict {
        standings,
        chosen,
        reference_error,
        within_margin,
        ..
    }) = verdict_of(model, &fits, margin, &rates)
    else {
        return Err(format!(
            "{}: no verdict: the reference's fit ({}) or every rate on the target is missing",
            path.display(),
            match model {
                Model::Classic => "pow",
                Model::Microfacet => "GGX",
            }
        ));
    };
    let normal = glam::DVec3::Z;
    let measured = material.albedo(normal, 256);
    let mut brdf_rates = Vec::with_capacity(fits.len());
    for fit in &fits {
        brdf_rates.push(brdf_rate(model, target, fit)?);
    }
    let rows = fits
        .into_iter()
        .zip(standings)
        .zip(brdf_rates)
        .map(|((fit, standing), brdf_rate)| FitRow {
            ks: Normalisation::ALL
                .iter()
                .filter_map(|&norm| Some((norm.id(), fit.ks(norm)?)))
                .collect(),
            albedo_at_normal: fit.albedo_at_normal(),
            at_range_end: fit.at_range_end(),
            relative_to_pow: standing.relative_to_pow,
            relative_to_ggx: standing.relative_to_ggx,
            rate: standing.rate,
            brdf_rate,
            meets: standing.meets,
            fit,
        })
        .collect();
    Ok(Assessment {
        material: material_name(path),
        file: path.display().to_string(),
        description: material.description().to_owned(),
        error_measure: format!(
            "RMS over solid-angle-weighted direction pairs (theta <= {MAX_ELEVATION_DEGREES} deg) \
                and channels of cbrt(f cos theta_i)"
        ),
        pairs: observations.len(),
        measured_albedo_at_normal: measured.to_array(),
        target,
        rate_unit: rate_unit(target),
        margin,
        model,
        within_margin,
        fits: rows,
        chosen,
        reference_error,
    })
}

/// The rate of `fit`'s whole microfacet specular term on `target`, for the shared-`n` fits of
/// the microfacet model with a cost: a lobe's distribution, and GGX's.
fn brdf_rate(model: Model, target: Target, fit: &Fit) -> Result<Option<f64>, String> {
    if model != Model::Microfacet || fit.sharing != Sharing::Shared {
        return Ok(None);
    }
    Ok(match fit.specular {
        Specular::Microfacet {
            normals: Normals::Lobe(kind),
        } => {
            let lobe = Lobe::new(kind, Exponent::clamped(fit.parameter[0]));
            Some(microfacet_rate(target, &lobe)?)
        }
        Specular::Microfacet {
            normals: Normals::Ggx,
        } => Some(ggx_microfacet_rate(target)?),
        _ => None,
    })
}

/// `n` (or `alpha`) as shown: one value, or three when the channels differ; marked `*` at an
/// end of the range searched.
#[must_use]
pub fn parameter_text(fit: &Fit) -> String {
    let end = if fit.at_range_end() { "*" } else { "" };
    format!("{}{end}", parameter_values(fit))
}

fn parameter_values(fit: &Fit) -> String {
    let p = fit.parameter;
    let one = |v: f64| {
        if fit.specular.takes_alpha() {
            format!("{v:.4}")
        } else {
            format!("{v:.1}")
        }
    };
    if p[0] == p[1] && p[1] == p[2] {
        one(p[0])
    } else {
        format!("{}/{}/{}", one(p[0]), one(p[1]), one(p[2]))
    }
}

/// Pow's rate on the target at its fitted `n` (its better geometry's; in the microfacet
/// model, pow's distribution's).
fn pow_rate(a: &Assessment) -> f64 {
    a.fits
        .iter()
        .filter(|r| match (a.model, r.fit.specular) {
            (Model::Classic, Specular::Lobe { kind, .. }) => kind == LobeKind::Pow,
            (Model::Microfacet, Specular::Microfacet { normals }) => {
                normals == Normals::Lobe(LobeKind::Pow)
            }
            _ => false,
        })
        .filter_map(|r| r.rate)
        .fold(f64::NAN, f64::max)
}

/// In the microfacet model, what the chosen distribution saves of the whole specular term:
/// against the `pow` distribution's and GGX's.
fn brdf_saving(a: &Assessment) -> String {
    let rate_of = |pick: &dyn Fn(&Specular) -> bool| {
        a.fits
            .iter()
            .filter(|r| pick(&r.fit.specular))
            .find_map(|r| r.brdf_rate)
    };
    let chosen = a.fits[a.chosen].brdf_rate;
    let pow = rate_of(&|s| {
        *s == Specular::Microfacet {
            normals: Normals::Lobe(LobeKind::Pow),
        }
    });
    let ggx = rate_of(&|s| {
        *s == Specular::Microfacet {
            normals: Normals::Ggx,
        }
    });
    match (chosen, pow, ggx) {
        (Some(chosen), Some(pow), Some(ggx)) => format!(
            "; of the whole microfacet specular term (D, G2, Fresnel), {:.0} % of the pow \
                distribution's cost saved, {:.2}x GGX's throughput",
            100.0 * (1.0 - pow / chosen),
            chosen / ggx
        ),
        _ => String::new(),
    }
}

/// The sentence naming the lobe to ship.
#[must_use]
pub fn verdict_line(a: &Assessment) -> String {
    let chosen = &a.fits[a.chosen];
    let pow_rate = pow_rate(a);
    let rate = chosen.rate.unwrap_or(f64::NAN);
    // The figures every verdict gives: the lobe and its n, the fit error and its ratio to
    // the reference's, and the throughput against pow's.
    let (label, n, error, ratio, versus_pow) = (
        chosen.fit.specular.label(),
        parameter_text(&chosen.fit),
        chosen.fit.error,
        chosen.fit.error / a.reference_error,
        rate / pow_rate,
    );
    let (target, margin) = (a.target, 100.0 * a.margin);
    match (a.model, a.within_margin) {
        (Model::Microfacet, false) => format!(
            "no distribution's microfacet fit on {target} is within {margin} % of GGX's; the \
                closest is {label}, n = {n} (E = {error:.4}, {ratio:.3}x GGX's; \
                {versus_pow:.2}x the pow distribution's throughput)"
        ),
        (Model::Microfacet, true) => format!(
            "{label}, n = {n}: the cheapest distribution on {target} whose microfacet fit is \
                within {margin} % of GGX's (E = {error:.4}, {ratio:.3}x GGX's); \
                {versus_pow:.2}x the pow distribution's throughput, so {:.0} % of its cost \
                saved{}",
            100.0 * (1.0 - pow_rate / rate),
            brdf_saving(a)
        ),
        (Model::Classic, _) => format!(
            "{label}, n = {n}: the cheapest lobe on {target} whose fit is within {margin} % of \
                pow's (E = {error:.4}, {ratio:.3}x pow's best; {versus_pow:.2}x pow's throughput)"
        ),
    }
}

/// One candidate of a material's ranking (`recommend --material`).
#[derive(Clone, Debug, Serialize)]
pub struct Ranked {
    /// The model's label (lobe and geometry).
    pub lobe: String,
    /// Its fitted `n`.
    pub n: f64,
    /// Within the margin of pow's best fit.
    pub meets: bool,
    /// Its fit error.
    pub error: f64,
    /// Its fit error over pow's best.
    pub relative_to_pow: f64,
    /// Its rate on the target at the fitted `n` (higher is cheaper).
    pub rate: f64,
    /// The rate's unit.
    pub unit: &'static str,
    /// The luminance of the fit's albedo at normal incidence.
    pub albedo_at_normal: f64,
    /// Why it stands where it does.
    pub why: String,
    /// Its row in [`Assessment::fits`].
    #[serde(skip)]
    pub row: usize,
}

/// The shared-`n` lobes of `a` ranked on its target: those within the margin first, then by
/// rate, highest first; each with why.
#[must_use]
pub fn ranking(a: &Assessment) -> Vec<Ranked> {
    let pow_rate = pow_rate(a);
    let mut ranked: Vec<Ranked> = a
        .fits
        .iter()
        .enumerate()
        .filter(|(_, r)| r.rate.is_some())
        .map(|(i, row)| {
            let rate = row.rate.unwrap_or(0.0);
            let why = if i == a.chosen {
                format!(
                    "cheapest within the margin, {:.2}x pow's throughput",
                    rate / pow_rate
                )
            } else if row.meets {
                format!(
                    "within the margin, {:.2}x pow's throughput",
                    rate / pow_rate
                )
            } else {
                format!(
                    "fit error {:.1} % above pow's best",
                    100.0 * (row.fit.error / a.reference_error - 1.0)
                )
            };
            Ranked {
                lobe: row.fit.specular.label(),
                n: row.fit.parameter[0],
                meets: row.meets,
                error: row.fit.error,
                relative_to_pow: row.fit.error / a.reference_error,
                rate,
                unit: a.rate_unit,
                albedo_at_normal: luminance(row.albedo_at_normal),
                why,
                row: i,
            }
        })
        .collect();
    ranked.sort_by(|x, y| y.meets.cmp(&x.meets).then(y.rate.total_cmp(&x.rate)));
    ranked
}
