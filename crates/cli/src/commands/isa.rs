//! `specula isa`: a lobe's machine code beside `pow`'s, as a GPU vendor's compiler writes it.

use core::fmt::Write as _;

use specula::{Exponent, Geometry, Lobe, LobeKind, Normalisation};
use specula_isa::{Comparison, Gpu, KernelView, Work};

use super::CommandResult;
use crate::args::{choice, parse_exponent, LobeParser};

/// What the compiled kernel computes.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, clap::ValueEnum)]
pub enum Context {
    /// The lobe alone, one evaluation per thread.
    #[default]
    Lobe,
    /// The whole specular term the engines' drop-ins replace: the geometry from a normal and
    /// two directions, the normalisation, the lobe.
    Shading,
}

/// Output format of `specula isa`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, clap::ValueEnum)]
pub enum Format {
    /// Counts by class, then both kernels' machine code.
    #[default]
    Text,
    /// One JSON object.
    Json,
}

/// Arguments of `specula isa`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// The lobe: a built-in id, @FILE.toml or =FORMULA.
    #[arg(long, value_parser = LobeParser, required_unless_present = "versus_model")]
    lobe: Option<LobeKind>,
    /// The exponent, in [1, 1000]; the lobe's constants are prepared for it.
    #[arg(long, value_parser = parse_exponent, allow_hyphen_values = true, default_value = "64")]
    n: Exponent,
    /// Every built-in lobe on every GPU instead: the compilers' throughput over pow's beside
    /// the naga-IR model's, and the transcendental instructions each counts (docs/gpu.md's
    /// table).
    #[arg(long, conflicts_with_all = ["lobe", "gpu", "context"])]
    versus_model: bool,
    /// The GPU, by its vendor's name: NVIDIA sm_75, sm_86, sm_89, sm_90, sm_120 (nvcc); AMD
    /// gfx900, gfx1010, gfx1030, gfx1100 (ACO in Mesa's RADV); Intel tgllp, dg2 (IGC through
    /// ocloc).
    #[arg(long, value_parser = choice(&Gpu::ALL, |gpu| gpu.id), default_value = "sm_89")]
    gpu: Gpu,
    /// What the kernel computes: the lobe alone, or the whole specular term (--geometry,
    /// --normalisation), so that the lobe's share of the shading shows.
    #[arg(long, value_enum, default_value_t = Context::Lobe)]
    context: Context,
    /// How the shading context forms the lobe's cosine.
    #[arg(long, value_parser = choice(&Geometry::ALL, Geometry::id), default_value = "blinn")]
    geometry: Geometry,
    /// The shading context's normalisation N(n).
    #[arg(
        long,
        value_parser = choice(&Normalisation::ALL, Normalisation::id),
        default_value = "lobe",
    )]
    normalisation: Normalisation,
    /// Output format.
    #[arg(long, value_enum, default_value_t = Format::Text)]
    format: Format,
}

/// Compiles and prints.
pub fn run(args: &Args) -> CommandResult {
    if args.versus_model {
        return versus_model(args);
    }
    let kind = args.lobe.ok_or("--lobe names the lobe to compile")?;
    let lobe = Lobe::checked(kind, args.n).map_err(|e| e.to_string())?;
    let work = match args.context {
        Context::Lobe => Work::Lobe,
        Context::Shading => Work::Shading(args.geometry, args.normalisation),
    };
    let comparison = specula_isa::compare(&lobe, args.gpu, work).map_err(|e| e.to_string())?;
    match args.format {
        Format::Json => {
            println!(
                "{}",
                serde_json::to_string_pretty(&comparison).map_err(|e| e.to_string())?
            );
        }
        Format::Text => print!("{}", text(&comparison)),
    }
    Ok(())
}

/// The comparison as a reader wants it: the counts side by side, the rates, then the code.
fn text(comparison: &Comparison) -> String {
    let Comparison { gpu, lobe, pow, .. } = comparison;
    let mut out = String::new();
    let _ = writeln!(
        out,
        "{} beside pow at n = {} on {} ({}), {}",
        lobe.lobe, comparison.n, gpu.id, gpu.name, comparison.context
    );
    let _ = writeln!(out, "compiled by {}", lobe.compiler);
    let _ = writeln!(
        out,
        "counted: what each kernel executes beyond one that only loads and stores ({} \
         instructions here)\n",
        lobe.baseline_total
    );
    let width = lobe.lobe.len().max(6);
    let _ = writeln!(out, "{:<16}{:>width$}{:>8}", "class", lobe.lobe, "pow");
    for ((class, mine), (_, theirs)) in lobe.counts.iter().zip(&pow.counts) {
        let _ = writeln!(out, "{class:<16}{mine:>width$}{theirs:>8}");
    }
    let _ = writeln!(out, "{:<16}{:>width$}{:>8}", "total", lobe.total, pow.total);
    if let (Some(mine), Some(theirs)) = (lobe.registers, pow.registers) {
        let _ = writeln!(out, "{:<16}{mine:>width$}{theirs:>8}", "registers");
    }
    for ((name, mine), (_, theirs)) in lobe.estimates.iter().zip(&pow.estimates) {
        let _ = writeln!(out, "{name}: {mine} against {theirs} (whole kernels)");
    }
    let _ = writeln!(
        out,
        "\nevaluations per clock per {}: {} (bound by {}) against pow's {} (bound by {}): \
         {:.2}x pow's throughput\n  rates: {}",
        gpu.unit,
        rate(lobe.evals_per_clock),
        lobe.bound,
        rate(pow.evals_per_clock),
        pow.bound,
        comparison.throughput_vs_pow,
        gpu.source
    );
    if let Some([mine, theirs]) = comparison.aco_inverse_throughput {
        let _ = writeln!(
            out,
            "ACO's estimated inverse throughput beyond the baseline: {mine} cycles a wave \
             against pow's {theirs}"
        );
    }
    if let Some(share) = comparison.lobe_share {
        let _ = writeln!(
            out,
            "the lobe alone is {:.0} % of the specular term's instructions",
            share * 100.0
        );
    }
    for view in [lobe, pow] {
        listing(&mut out, view);
    }
    out
}

fn rate(evals: f64) -> String {
    if evals.is_finite() {
        format!("{evals:.3}")
    } else {
        "unbounded (no counted instruction)".to_owned()
    }
}

/// A kernel's machine code, each line tagged with its class, transcendentals marked.
fn listing(out: &mut String, view: &KernelView) {
    let _ = writeln!(
        out,
        "\n{}'s kernel ({} instructions; * marks the special-function unit):",
        view.lobe,
        view.listing.len()
    );
    for (class, text) in &view.listing {
        let mark = if *class == "transcendental" { '*' } else { ' ' };
        let _ = writeln!(out, "  {mark} {class:<15} {text}");
    }
}

/// Every built-in lobe on every GPU, the compilers beside the model.
fn versus_model(args: &Args) -> CommandResult {
    let lobes: Vec<Lobe> = LobeKind::ALL
        .into_iter()
        .map(|kind| Lobe::new(kind, args.n))
        .collect();
    let rows =
        specula_isa::model_against_compilers(&lobes, &Gpu::ALL).map_err(|e| e.to_string())?;
    if args.format == Format::Json {
        let value: Vec<serde_json::Value> = rows
            .iter()
            .map(|(lobe, cells)| serde_json::json!({ "lobe": lobe, "gpus": cells }))
            .collect();
        println!(
            "{}",
            serde_json::to_string_pretty(&value).map_err(|e| e.to_string())?
        );
        return Ok(());
    }
    let mut out = format!(
        "x pow's throughput at n = {}, compiled (modelled); transcendental instructions per \
         evaluation, compiled/modelled\n\n| lobe |",
        args.n
    );
    for gpu in Gpu::ALL {
        let _ = write!(out, " {} |", gpu.id);
    }
    out.push_str("\n|---|");
    out.push_str(&"---|".repeat(Gpu::ALL.len()));
    out.push('\n');
    for (lobe, cells) in &rows {
        let _ = write!(out, "| {lobe} |");
        for cell in cells {
            let _ = write!(
                out,
                " {:.2} ({:.2}); {}/{} |",
                cell.compiled_vs_pow,
                cell.modelled_vs_pow,
                cell.compiled_transcendentals,
                cell.modelled_transcendentals
            );
        }
        out.push('\n');
    }
    print!("{out}");
    Ok(())
}
