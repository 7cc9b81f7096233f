//! `specula analyze`: every figure of SPEC section 4 for lobes x exponents.

use indicatif::{ProgressBar, ProgressStyle};
use rayon::prelude::*;
use specula::analysis::{analyze, analyze_all, LobeReport, DEFAULT_EXPONENTS};
use specula::ops::OpCounts;
use specula::{Exponent, LobeKind};
use specula_gpu::{Gpu, GpuEvaluator, LobeEvaluator};

use super::{print_json, CommandResult};
use crate::args::{parse_exponent, BackendArg, OutputFormat};
use crate::output::{number, percent, sig, Table};

/// Arguments of `specula analyze`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// Lobes to analyse, comma separated (default: all).
    #[arg(long, value_parser = crate::args::LobeListParser)]
    lobe: Vec<crate::args::LobeList>,
    /// Exponents, comma separated (default: 1,2,4,8,16,32,64,128,256,512,1000).
    #[arg(long, value_parser = parse_exponent, value_delimiter = ',', allow_hyphen_values = true)]
    n: Vec<Exponent>,
    /// Output format.
    #[arg(long, value_enum, default_value_t)]
    format: OutputFormat,
    /// Arithmetic for the error figures: the f64 reference, the f32 fast path, or f32 in a GPU
    /// compute shader.
    #[arg(long, value_enum, default_value_t)]
    backend: BackendArg,
}

/// Analyses and prints.
pub fn run(args: &Args) -> CommandResult {
    let lobes = if args.lobe.is_empty() {
        LobeKind::ALL.to_vec()
    } else {
        crate::args::flatten(&args.lobe)
    };
    let exponents: Vec<Exponent> = if args.n.is_empty() {
        DEFAULT_EXPONENTS
            .iter()
            .map(|&n| Exponent::new(n))
            .collect()
    } else {
        args.n.clone()
    };
    crate::args::check_lobes(&lobes, &exponents)?;
    let progress = ProgressBar::new((lobes.len() * exponents.len()) as u64).with_style(
        ProgressStyle::with_template("analyzing {bar:30} {pos}/{len} {elapsed}")
            .unwrap_or_else(|_| ProgressStyle::default_bar()),
    );
    let reports: Vec<LobeReport> = match args.backend.cpu_precision() {
        Some(precision) => analyze_all(&lobes, &exponents, precision, &|| progress.inc(1)),
        None => {
            let jobs: Vec<(LobeKind, Exponent)> = lobes
                .iter()
                .flat_map(|&lobe| exponents.iter().map(move |&n| (lobe, n)))
                .collect();
            let gpu = Gpu::new().map_err(|e| e.to_string())?;
            let evaluator = LobeEvaluator::new(&gpu).map_err(|e| e.to_string())?;
            jobs.par_iter()
                .map(|&(lobe, n)| {
                    let mut on_gpu = GpuEvaluator::new(&evaluator);
                    let report = analyze(lobe, n, &mut on_gpu);
                    progress.inc(1);
                    on_gpu.error().map_or(Ok(report), |e| Err(e.to_string()))
                })
                .collect::<Result<_, _>>()?
        }
    };
    progress.finish_and_clear();
    for r in reports.iter().filter(|r| !r.energy_converged) {
        eprintln!(
            "note: {} at n = {}: the energy's integral did not converge within {} panels (the \
                lobe's f64 values are noisy there); its figure is the estimate",
            r.lobe,
            r.n,
            specula::quadrature::MAX_PANELS
        );
    }
    if args.format == OutputFormat::Json {
        return print_json(&reports);
    }
    if args.format == OutputFormat::Csv {
        print_csv(&reports);
        return Ok(());
    }
    let mut table = Table::new(&[
        "lobe",
        "n",
        "epicentre max rel",
        "epicentre max abs",
        "bloom max abs",
        "tail max abs",
        "rms",
        "energy ratio",
        "max albedo",
        "ops",
    ]);
    for r in &reports {
        table.push(vec![
            r.lobe.to_string(),
            r.n.to_string(),
            percent(r.errors.epicentre_max_rel),
            sig(r.errors.epicentre_max_abs),
            sig(r.errors.bloom_max_abs),
            sig(r.errors.tail_max_abs),
            sig(r.errors.rms),
            if r.energy_converged {
                sig(r.energy_ratio)
            } else {
                format!("~{}", sig(r.energy_ratio))
            },
            sig(r.max_albedo),
            r.ops.to_string(),
        ]);
    }
    table.print(args.format);
    Ok(())
}

/// The reports as data alone: the table's figures as numbers (the epicentre's relative error
/// in %, as the table gives it), whether the energy's integral converged, and one column of
/// operations per kind.
fn print_csv(reports: &[LobeReport]) {
    let ops = OpCounts::default()
        .entries()
        .map(|(name, _)| format!("ops {name}"));
    let mut header = vec![
        "lobe",
        "n",
        "epicentre max rel (%)",
        "epicentre max abs",
        "bloom max abs",
        "tail max abs",
        "rms",
        "energy ratio",
        "energy converged",
        "max albedo",
        "max albedo theta (degrees)",
    ];
    header.extend(ops.iter().map(String::as_str));
    let mut table = Table::new(&header);
    for r in reports {
        let mut row = vec![
            r.lobe.to_string(),
            r.n.to_string(),
            number(100.0 * r.errors.epicentre_max_rel),
            number(r.errors.epicentre_max_abs),
            number(r.errors.bloom_max_abs),
            number(r.errors.tail_max_abs),
            number(r.errors.rms),
            number(r.energy_ratio),
            r.energy_converged.to_string(),
            number(r.max_albedo),
            number(r.max_albedo_theta_deg),
        ];
        row.extend(r.ops.entries().map(|(_, count)| count.to_string()));
        table.push(row);
    }
    table.print(OutputFormat::Csv);
}
