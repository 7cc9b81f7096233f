//! `specula fit --material FILE...`: every lobe fitted to measured materials, and the
//! verdict on which to ship (see `specula::measured::fit` for the model, the error and the
//! optimiser). One material is one job: with `--format json` each prints one line, so a list
//! of files, or an array job's one file, appends to a JSON Lines file.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use indicatif::{ProgressBar, ProgressStyle};
use serde::Serialize;
use specula::measured::fit::verdict::{verdict, Verdict};
use specula::measured::fit::{
    fit_all, Fit, Observations, Sharing, Specular, MAX_ELEVATION_DEGREES,
};
use specula::{Exponent, Lobe, LobeKind, Normalisation};
use specula_render::measured::{load_measured, material_name, MeasuredBrdf};

use super::recommend::{lobe_rate, parse_margin, Target};
use super::CommandResult;
use crate::output::Table;

/// The fit error allowed over pow's by default: 5 %.
pub const DEFAULT_MARGIN: f64 = 0.05;

/// How `fit` prints.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, clap::ValueEnum)]
pub enum FitFormat {
    /// A summary and a table per material.
    #[default]
    Table,
    /// One JSON object per material, one per line (JSON Lines).
    Json,
}

/// Arguments of `specula fit`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// Measured materials: RGL isotropic RGB `.bsdf` files (one job each).
    #[arg(long, num_args = 1.., required = true)]
    material: Vec<PathBuf>,
    /// Where the chosen lobe will run (its cost model; `cpu` is timed on this machine).
    #[arg(long, value_enum, default_value_t = Target::GpuNvidia)]
    target: Target,
    /// The fit error allowed over pow's, as a percentage (`5%`).
    #[arg(long, allow_hyphen_values = true, default_value = "5%", value_parser = parse_margin)]
    margin: f64,
    /// Also fit these lobes: your own (`@FILE.toml`, `=FORMULA`) or a built-in with other
    /// parameters (`cosquad:v=5`); comma separated.
    #[arg(long, value_parser = crate::args::LobeListParser)]
    lobe: Vec<crate::args::LobeList>,
    /// Output format.
    #[arg(long, value_enum, default_value_t = FitFormat::Table)]
    format: FitFormat,
}

/// A fit as printed: the library's figures and what they mean for a renderer.
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
    /// The margin over pow's error, as a fraction.
    pub margin: f64,
    /// Every fit.
    pub fits: Vec<FitRow>,
    /// The index in `fits` of the lobe to ship.
    pub chosen: usize,
    /// Pow's best shared-`n` fit error, the reference.
    pub reference_error: f64,
}

/// Luminance of a linear RGB triple (Rec. 709).
pub fn luminance(rgb: [f64; 3]) -> f64 {
    specula::brdf::luminance(glam::DVec3::from_array(rgb))
}

/// Every built-in lobe and `extra`, with user lobes checked over the whole range of `n`.
pub fn lobes_to_fit(extra: &[LobeKind]) -> Result<Vec<LobeKind>, String> {
    crate::args::check_lobes(extra, &crate::args::parse_exponent_range("1..1000", 8)?)?;
    let mut kinds = LobeKind::ALL.to_vec();
    kinds.extend(extra.iter().filter(|k| !LobeKind::ALL.contains(k)));
    Ok(kinds)
}

/// Fits every lobe in `kinds` to `material` (read from `path`) and ranks them on `target`.
pub fn assess(
    material: &MeasuredBrdf,
    path: &Path,
    kinds: &[LobeKind],
    target: Target,
    margin: f64,
) -> Result<Assessment, String> {
    let observations = Observations::of(|wo, wi| material.f_cos(wo, wi));
    let fits = fit_all(&observations, kinds);
    let mut rates = Vec::with_capacity(fits.len());
    for fit in &fits {
        rates.push(match (fit.specular, fit.sharing) {
            (Specular::Lobe { kind, .. }, Sharing::Shared) => {
                let n = Exponent::clamped(fit.parameter[0]);
                Some(lobe_rate(target, &Lobe::new(kind, n))?)
            }
            _ => None,
        });
    }
    let Some(Verdict {
        standings,
        chosen,
        reference_error,
        ..
    }) = verdict(&fits, margin, &rates)
    else {
        return Err(format!(
            "{}: no verdict: pow's fit or every rate on the target is missing",
            path.display()
        ));
    };
    let normal = glam::DVec3::Z;
    let measured = material.albedo(normal, 256);
    let rows = fits
        .into_iter()
        .zip(standings)
        .map(|(fit, standing)| FitRow {
            ks: Normalisation::ALL
                .iter()
                .filter_map(|&norm| Some((norm.id(), fit.ks(norm)?)))
                .collect(),
            albedo_at_normal: fit.albedo_at_normal(),
            at_range_end: fit.at_range_end(),
            relative_to_pow: standing.relative_to_pow,
            relative_to_ggx: standing.relative_to_ggx,
            rate: standing.rate,
            meets: standing.meets,
            fit,
        })
        .collect();
    Ok(Assessment {
        material: material_name(path),
        file: path.display().to_string(),
        description: material.description().to_owned(),
        error_measure: format!(
            "RMS over solid-angle-weighted direction pairs (theta <= {MAX_ELEVATION_DEGREES} deg) and channels of cbrt(f cos theta_i)"
        ),
        pairs: observations.len(),
        measured_albedo_at_normal: measured.to_array(),
        target,
        rate_unit: super::recommend::rate_unit(target),
        margin,
        fits: rows,
        chosen,
        reference_error,
    })
}

/// `n` (or `alpha`) as printed: one value, or three when the channels differ; marked `*`
/// at an end of the range searched.
pub fn parameter_text(fit: &Fit) -> String {
    let end = if fit.at_range_end() { "*" } else { "" };
    format!("{}{end}", parameter_values(fit))
}

fn parameter_values(fit: &Fit) -> String {
    let p = fit.parameter;
    let one = |v: f64| match fit.specular {
        Specular::Ggx => format!("{v:.4}"),
        Specular::Lobe { .. } => format!("{v:.1}"),
    };
    if p[0] == p[1] && p[1] == p[2] {
        one(p[0])
    } else {
        format!("{}/{}/{}", one(p[0]), one(p[1]), one(p[2]))
    }
}

fn triple(v: [f64; 3]) -> String {
    format!("{:.3}/{:.3}/{:.3}", v[0], v[1], v[2])
}

/// Pow's rate on the target (its better geometry's, at its fitted `n`).
fn pow_rate(a: &Assessment) -> f64 {
    a.fits
        .iter()
        .filter(|r| {
            matches!(
                r.fit.specular,
                Specular::Lobe {
                    kind: LobeKind::Pow,
                    ..
                }
            )
        })
        .filter_map(|r| r.rate)
        .fold(f64::NAN, f64::max)
}

/// The sentence naming the lobe to ship.
pub fn verdict_line(a: &Assessment) -> String {
    let chosen = &a.fits[a.chosen];
    let pow_rate = pow_rate(a);
    let target = clap::ValueEnum::to_possible_value(&a.target)
        .map_or_else(String::new, |v| v.get_name().to_owned());
    format!(
        "{}, n = {}: the cheapest lobe on {target} whose fit is within {} % of pow's (E = {:.4}, {:.3}x pow's best; {:.2}x pow's rate)",
        chosen.fit.specular.label(),
        parameter_text(&chosen.fit),
        100.0 * a.margin,
        chosen.fit.error,
        chosen.fit.error / a.reference_error,
        chosen.rate.unwrap_or(f64::NAN) / pow_rate,
    )
}

fn print_table(a: &Assessment) {
    println!(
        "{} ({}): {} direction pairs; measured albedo at normal incidence {}",
        a.material,
        a.description,
        a.pairs,
        triple(a.measured_albedo_at_normal)
    );
    println!("verdict: {}", verdict_line(a));
    let mut table = Table::new(&[
        "lobe",
        "n",
        "kd",
        "K = ks N(n)",
        "E",
        "vs pow",
        "vs ggx",
        "albedo",
        "rate",
        "meets",
    ]);
    for row in &a.fits {
        let sharing = match row.fit.sharing {
            Sharing::Shared => "",
            Sharing::PerChannel => " (per channel)",
        };
        table.push(vec![
            format!("{}{sharing}", row.fit.specular.label()),
            parameter_text(&row.fit),
            triple(row.fit.kd),
            triple(row.fit.k),
            format!("{:.5}", row.fit.error),
            format!("{:.3}", row.relative_to_pow),
            format!("{:.3}", row.relative_to_ggx),
            format!("{:.3}", luminance(row.albedo_at_normal)),
            row.rate
                .map_or_else(|| "-".to_owned(), |r| format!("{r:.3e}")),
            if row.meets { "yes" } else { "" }.to_owned(),
        ]);
    }
    table.print(crate::args::Format::Table);
    println!(
        "E: {}; albedo: the fit's at normal incidence (luminance); rate: {}; *: at an end of the range searched.\n",
        a.error_measure, a.rate_unit
    );
}

/// One candidate of `recommend --material`.
#[derive(Serialize)]
struct Ranked<'a> {
    lobe: String,
    n: f64,
    meets: bool,
    error: f64,
    relative_to_pow: f64,
    rate: f64,
    unit: &'static str,
    albedo_at_normal: f64,
    why: String,
    #[serde(skip)]
    row: &'a FitRow,
}

/// `recommend --material`: the shared-`n` lobes ranked on the target, the verdict first.
pub fn print_ranking(a: &Assessment, format: crate::args::Format) -> CommandResult {
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
                    "cheapest within the margin, {:.2}x pow's rate",
                    rate / pow_rate
                )
            } else if row.meets {
                format!("within the margin, {:.2}x pow's rate", rate / pow_rate)
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
                row,
            }
        })
        .collect();
    ranked.sort_by(|x, y| y.meets.cmp(&x.meets).then(y.rate.total_cmp(&x.rate)));
    if format == crate::args::Format::Json {
        return super::print_json(&ranked);
    }
    println!("{} ({}): {}", a.material, a.description, verdict_line(a));
    let mut table = Table::new(&[
        "lobe",
        "n",
        "meets",
        "E",
        "vs pow's best",
        "cost",
        "albedo",
        "why",
    ]);
    for r in &ranked {
        table.push(vec![
            r.lobe.clone(),
            parameter_text(&r.row.fit),
            if r.meets { "yes" } else { "no" }.to_owned(),
            format!("{:.5}", r.error),
            format!("{:.3}", r.relative_to_pow),
            format!("{:.3e} {}", r.rate, r.unit),
            format!("{:.3}", r.albedo_at_normal),
            r.why.clone(),
        ]);
    }
    table.print(format);
    Ok(())
}

/// Checks every file, then fits and prints one material at a time.
pub fn run(args: &Args) -> CommandResult {
    let kinds = lobes_to_fit(&crate::args::flatten(&args.lobe))?;
    if args.target == Target::Fpga {
        return Err(super::recommend::FPGA_MATERIAL_REFUSAL.to_owned());
    }
    // Refuse a bad file before any output, so a list either runs or prints nothing.
    for path in &args.material {
        load_measured(path)?;
    }
    let progress = ProgressBar::new(args.material.len() as u64).with_style(
        ProgressStyle::with_template("fitting {bar:30} {pos}/{len} materials {msg}")
            .unwrap_or_else(|_| ProgressStyle::default_bar()),
    );
    for path in &args.material {
        progress.set_message(material_name(path));
        let assessment = assess(
            &load_measured(path)?,
            path,
            &kinds,
            args.target,
            args.margin,
        )?;
        progress.suspend(|| match args.format {
            FitFormat::Json => serde_json::to_string(&assessment)
                .map(|line| println!("{line}"))
                .map_err(|e| e.to_string()),
            FitFormat::Table => {
                print_table(&assessment);
                Ok(())
            }
        })?;
        progress.inc(1);
    }
    progress.finish_and_clear();
    Ok(())
}
