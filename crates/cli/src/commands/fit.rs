//! `specula fit --material FILE...`: every lobe fitted to measured materials, and the
//! verdict on which to ship (see `specula::measured::fit` for the model, the error and the
//! optimiser). One material is one job: with `--format json` each prints one line, so a list
//! of files, or an array job's one file, appends to a JSON Lines file.

use std::path::PathBuf;

use specula::measured::fit::Sharing;
use specula_decide::material::{
    assess_model, lobes_to_fit, luminance, parameter_text, verdict_line, Assessment, Model, Ranked,
};
use specula_decide::Target;
use specula_render::measured::{load_measured, material_name};

use super::CommandResult;
use crate::args::described;
use crate::args::parse_margin;
use crate::output::Table;

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
    #[arg(
        long,
        value_parser = described(&Target::ALL, Target::id, Target::summary),
        default_value_t = Target::GpuNvidia,
    )]
    target: Target,
    /// The fit error allowed over pow's, as a percentage (`5%`).
    #[arg(long, allow_hyphen_values = true, default_value = "5%", value_parser = parse_margin)]
    margin: f64,
    /// Also fit these lobes: your own (`@FILE.toml`, `=FORMULA`) or a built-in with other
    /// parameters (`cosquad:v=5`); comma separated.
    #[arg(long, value_parser = crate::args::LobeListParser)]
    lobe: Vec<crate::args::LobeList>,
    /// The model whose fits the verdict ranks: `classic`, `kd / pi + K lobe(t)` against pow's
    /// fit; `microfacet`, each lobe also as the normal distribution of `D G2 / (4 cos cos)`,
    /// beside Beckmann's and GGX's, against GGX's fit.
    #[arg(long, value_enum, default_value_t = FitModel::Classic)]
    model: FitModel,
    /// Output format.
    #[arg(long, value_enum, default_value_t = FitFormat::Table)]
    format: FitFormat,
}

/// `--model`'s choices.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, clap::ValueEnum)]
pub enum FitModel {
    /// The lobe as the specular term, in the Phong and Blinn geometries; the verdict against
    /// pow's fit.
    #[default]
    Classic,
    /// The lobe as a microfacet normal distribution with Smith masking and Schlick's Fresnel
    /// (F0 fitted); the verdict against GGX's fit in the same model.
    Microfacet,
}

fn triple(v: [f64; 3]) -> String {
    format!("{:.3}/{:.3}/{:.3}", v[0], v[1], v[2])
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
        "F0",
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
            row.fit.f0.map_or_else(|| "-".to_owned(), triple),
            format!("{:.5}", row.fit.error),
            format!("{:.3}", row.relative_to_pow),
            format!("{:.3}", row.relative_to_ggx),
            format!("{:.3}", luminance(row.albedo_at_normal)),
            row.rate
                .map_or_else(|| "-".to_owned(), |r| format!("{r:.3e}")),
            if row.meets { "yes" } else { "" }.to_owned(),
        ]);
    }
    table.print(crate::args::OutputFormat::Table);
    println!(
        "E: {}; F0: Schlick's, fitted in the microfacet model (K is then ks, Fresnel's scale); \
            albedo: the fit's at normal incidence (luminance); rate: {}; *: at an end of the \
            range searched.\n",
        a.error_measure, a.rate_unit
    );
}

/// `recommend --material`: the shared-`n` lobes ranked on the target
/// ([`specula_decide::material::ranking`]), the verdict first.
pub fn print_ranking(
    a: &Assessment,
    ranked: &[Ranked],
    format: crate::args::OutputFormat,
) -> CommandResult {
    if format == crate::args::OutputFormat::Json {
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
    for r in ranked {
        table.push(vec![
            r.lobe.clone(),
            parameter_text(&a.fits[r.row].fit),
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
    let kinds = lobes_to_fit(&crate::args::flatten(&args.lobe), args.target)?;
    // Refuse a bad file before any output, so a list either runs or prints nothing.
    for path in &args.material {
        load_measured(path)?;
    }
    let progress = crate::progress::bar(
        "fit",
        args.material.len() as u64,
        "fitting {bar:30} {pos}/{len} materials {msg}",
    );
    for path in &args.material {
        progress.set_message(material_name(path));
        let model = match args.model {
            FitModel::Classic => Model::Classic,
            FitModel::Microfacet => Model::Microfacet,
        };
        let assessment = assess_model(
            &load_measured(path)?,
            path,
            &kinds,
            args.target,
            args.margin,
            model,
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
