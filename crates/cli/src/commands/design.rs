//! `specula design`: the cheapest lobe for a target, a range of `n` and an accuracy, searched
//! for in the formula language. The search is `specula_decide::design::design`; this module
//! parses, prints and writes the lobe file.

use std::path::PathBuf;

use indicatif::ProgressBar;
use specula_decide::design::grammar::{self, Fate};
use specula_decide::design::{default_whole_error, design, Bounds, Design, DesignRequest};
use specula_decide::hardware::circuit_for_range;
use specula_decide::Target;

use super::recommend::spread_versus_pow;
use super::CommandResult;
use crate::args::described;
use crate::output::Table;

/// Arguments of `specula design`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// Where the lobe will run (on the FPGA, the transcendental-free families, each compiled
    /// to a fixed-point datapath and synthesized).
    #[arg(long, value_parser = described(&Target::ALL, Target::id, Target::summary))]
    target: Target,
    /// A GPU target's generation, by its vendor's name (sm_75 .. sm_120, gfx900 .. gfx1100,
    /// tgllp, dg2) [default: sm_89, gfx1100, dg2].
    #[arg(long, value_parser = crate::args::choice(&specula::gpus::Gpu::ALL, |gpu| gpu.id))]
    gpu: Option<specula::gpus::Gpu>,
    /// The exponent, or a range `LOW..HIGH` the lobe must hold over.
    #[arg(long, allow_hyphen_values = true, default_value = "64", value_parser = parse_range)]
    n: Range,
    /// The epicentre's largest relative error, as a percentage (`0.1%` or `0.1`): the error
    /// `recommend` counts.
    #[arg(
        long,
        allow_hyphen_values = true,
        value_parser = crate::args::parse_percent,
        required_unless_present = "against_thesis"
    )]
    max_error: Option<f64>,
    /// The whole lobe's largest absolute error, as a percentage of the peak [default: 1%, or
    /// --max-error where that is larger].
    #[arg(long, allow_hyphen_values = true, value_parser = crate::args::parse_percent)]
    max_whole_error: Option<f64>,
    /// Also match t^n's energy within this percentage at every n.
    #[arg(long, allow_hyphen_values = true, value_parser = crate::args::parse_percent)]
    energy_tolerance: Option<f64>,
    /// Only lobes without a transcendental operation per evaluation (polynomial-only
    /// targets).
    #[arg(long)]
    no_transcendentals: bool,
    /// Also rank these lobes beside the built-ins and the designs: your own (`@FILE.toml`,
    /// `=FORMULA`) or a built-in with other parameters (`cosquad:v=5`); comma separated.
    #[arg(long, value_parser = crate::args::LobeListParser)]
    lobe: Vec<crate::args::LobeList>,
    /// Write the cheapest designed lobe meeting the request as a lobe file (TOML), for
    /// `--lobe @FILE` everywhere; with --target fpga, its Verilog (.v) and structural diagram
    /// (.svg) beside it.
    #[arg(short, long)]
    output: Option<PathBuf>,
    /// The cost bound: the most operations per evaluation a searched structure may have (the
    /// formula's own count, once n's constants are prepared) [default: 16, the whole grammar;
    /// 10 on the FPGA, where every verified structure is synthesized].
    #[arg(long, value_parser = parse_operations)]
    max_operations: Option<usize>,
    /// Also print every structure the grammar enumerated, with its operations and what became
    /// of it: pruned before its fit (and why), pruned by its fit, or kept (verified).
    #[arg(short, long)]
    verbose: bool,
    /// Output format.
    #[arg(long, value_enum, default_value_t = crate::args::OutputFormat::Table)]
    format: crate::args::OutputFormat,
    /// Also print the limit: each verified design's epicentre error at five exponents of the
    /// range beside its family's optimum there (Sollya's minimax, certified by its supnorm;
    /// `sollya` must be installed).
    #[arg(long)]
    limit: bool,
    /// Instead of one accuracy, the thesis's lobes (schlick-mod, cheb2-thesis, logexp,
    /// cosquad) at their own: each one's largest epicentre and whole-lobe errors over the range
    /// are the bounds, and the cheapest lobe meeting them (designed or built in, the thesis
    /// lobe ranked too) is shown beside it.
    #[arg(long, conflicts_with_all = ["max_error", "max_whole_error", "output", "limit"])]
    against_thesis: bool,
}

/// The range of exponents, its ends.
#[derive(Clone, Copy, Debug)]
pub struct Range(specula::Exponent, specula::Exponent);

fn parse_operations(text: &str) -> Result<usize, String> {
    text.parse()
        .ok()
        .filter(|&bound| (1..=1000).contains(&bound))
        .ok_or_else(|| {
            format!(
                "the cost bound must be a whole number of operations in [1, 1000], not '{text}'"
            )
        })
}

fn parse_range(text: &str) -> Result<Range, String> {
    let ends = specula_decide::parse_exponent_range(text, 1)?;
    Ok(Range(ends[0], ends[ends.len() - 1]))
}

/// Searches, prints, and writes the lobe.
pub fn run(args: &Args) -> CommandResult {
    let progress = crate::progress::bar("design", 0, "designing {bar:30} {pos}/{len} {msg}");
    let Some(max_error) = args.max_error else {
        return print_against_thesis(args, &progress);
    };
    let request = DesignRequest {
        target: args.target,
        gpu: args.gpu,
        range: (args.n.0, args.n.1),
        bounds: Bounds {
            epicentre: max_error,
            whole: args
                .max_whole_error
                .unwrap_or_else(|| default_whole_error(max_error)),
            energy: args.energy_tolerance,
        },
        no_transcendentals: args.no_transcendentals,
        also: crate::args::flatten(&args.lobe),
        max_operations: args
            .max_operations
            .unwrap_or_else(|| grammar::default_max_operations(args.target)),
    };
    let answer = design(&request, &progress)?;
    if let Some(note) = &answer.note {
        eprintln!("note: {note}");
    }
    if let Some(path) = &args.output {
        write_lobe(&answer, &request, path)?;
    }
    if args.format == crate::args::OutputFormat::Json {
        return super::print_json(&answer);
    }
    println!("{}", answer.verdict);
    print_table(&answer, args.format);
    if args.verbose {
        print_enumeration(&answer, args.format);
    }
    if args.limit {
        print_limit(&answer, &request, args.format)?;
    }
    Ok(())
}

/// The thesis's lobes at their own accuracy, against the designer's answer there.
fn print_against_thesis(args: &Args, progress: &ProgressBar) -> CommandResult {
    let rows = specula_decide::design::thesis::against_thesis(
        args.target,
        args.gpu,
        (args.n.0, args.n.1),
        progress,
    )?;
    progress.finish_and_clear();
    if args.format == crate::args::OutputFormat::Json {
        return super::print_json(&rows);
    }
    let mut table = Table::new(&[
        "thesis lobe",
        "epicentre",
        "whole lobe",
        "rate",
        "answer",
        "rate",
        "x the thesis lobe's",
        "answer's formula",
    ]);
    for row in &rows {
        table.push(vec![
            row.thesis.clone(),
            format!("{:.4} %", 100.0 * row.epicentre_error),
            format!("{:.4} %", 100.0 * row.whole_error),
            format!("{:.3e}", row.thesis_rate),
            format!(
                "{}{}",
                row.answer,
                if row.designed { " (designed)" } else { "" }
            ),
            format!("{:.3e}", row.answer_rate),
            format!("{:.2}", row.answer_rate / row.thesis_rate),
            row.answer_formula.replace('\n', " "),
        ]);
    }
    table.print(args.format);
    eprintln!(
        "each thesis lobe's largest errors over n = {}..{} are the bounds; the answer is the \
            cheapest lobe meeting both on {} (the thesis lobe itself when none is cheaper)",
        args.n.0,
        args.n.1,
        args.target.id()
    );
    Ok(())
}

/// Each verified design against its family's optimum at five exponents of the range.
fn print_limit(
    answer: &Design,
    request: &DesignRequest,
    format: crate::args::OutputFormat,
) -> CommandResult {
    let rows = specula_decide::design::limit::limit_table(&answer.designed, request.range, 4)?;
    let mut table = Table::new(&["family", "n", "designed", "optimum", "designed / optimum"]);
    for row in &rows {
        table.push(vec![
            row.family.clone(),
            format!("{:.1}", row.n),
            format!("{:.3e}", row.designed),
            format!("{:.3e}", row.optimum),
            if row.optimum > 0.0 {
                format!("{:.2}", row.designed / row.optimum)
            } else {
                "- (the family holds t^n)".to_owned()
            },
        ]);
    }
    println!();
    table.print(format);
    eprintln!(
        "optimum: the least epicentre error any member of the family reaches at that n alone \
            (Sollya's Remez, its error certified by supnorm); designed: one set of closed-form \
            constants for the whole range"
    );
    Ok(())
}

/// Every designed lobe, then the built-ins, with the Pareto front over both.
fn print_table(answer: &Design, format: crate::args::OutputFormat) {
    let mut table = Table::new(&[
        "lobe",
        "kind",
        "meets",
        "epicentre",
        "whole lobe",
        "rate",
        "x pow's throughput",
        "pareto",
        "why",
    ]);
    let error = |e: f64| {
        if e.is_finite() {
            format!("{:.4} %", 100.0 * e)
        } else {
            "-".to_owned()
        }
    };
    let cost = |rate: f64| {
        if rate > 0.0 {
            format!("{rate:.3e}")
        } else {
            "-".to_owned()
        }
    };
    for d in &answer.designed {
        table.push(vec![
            d.name.clone(),
            "designed".to_owned(),
            if d.meets { "yes" } else { "no" }.to_owned(),
            error(d.epicentre_error),
            error(d.whole_error),
            cost(d.rate),
            if d.rate > 0.0 {
                spread_versus_pow(d.rate, d.spread, answer.pow_rate)
            } else {
                "-".to_owned()
            },
            if d.pareto { "front" } else { "" }.to_owned(),
            with_datapath(&d.why, d.datapath.as_deref()),
        ]);
    }
    for c in &answer.compared {
        table.push(vec![
            c.lobe.clone(),
            if specula::LobeKind::ALL.iter().any(|k| k.id() == c.lobe) {
                "built-in"
            } else {
                "given"
            }
            .to_owned(),
            if c.meets { "yes" } else { "no" }.to_owned(),
            error(c.error),
            "".to_owned(),
            cost(c.rate),
            spread_versus_pow(c.rate, c.spread, answer.pow_rate),
            if c.pareto { "front" } else { "" }.to_owned(),
            with_datapath(&c.why, c.datapath.as_deref()),
        ]);
    }
    table.print(format);
    eprintln!(
        "costs in {}; designed lobes verified at {} exponents of the range by the f64 analysis",
        answer.unit, answer.exponents_verified
    );
}

/// Every structure the grammar wrote, its operations and its fate.
fn print_enumeration(answer: &Design, format: crate::args::OutputFormat) {
    let mut table = Table::new(&["structure", "operations", "fate"]);
    for e in &answer.enumerated {
        table.push(vec![
            e.structure.clone(),
            e.operations.to_string(),
            match &e.fate {
                Fate::Pruned(why) => format!("pruned: {why}"),
                Fate::FitMissed => "pruned by its fit: the coarse grids' best misses the \
                    bounds (not verified)"
                    .to_owned(),
                Fate::Kept => "kept: fitted, verified and costed".to_owned(),
            },
        ]);
    }
    println!();
    table.print(format);
    let [enumerated, pruned, missed, kept] = grammar::counts(&answer.enumerated);
    eprintln!(
        "{enumerated} structures enumerated: {pruned} pruned before their fit, {missed} by \
            their fit, {kept} kept"
    );
}

/// Why a lobe stands where it does, and on the FPGA the datapath costed.
fn with_datapath(why: &str, datapath: Option<&str>) -> String {
    match datapath {
        Some(datapath) => format!("{why} [{datapath}]"),
        None => why.to_owned(),
    }
}

/// Writes the cheapest designed lobe that meets the request, or refuses (nothing written).
fn write_lobe(answer: &Design, request: &DesignRequest, path: &std::path::Path) -> CommandResult {
    let Some(best) = answer.best() else {
        return Err(format!(
            "nothing written to {}: {}",
            path.display(),
            answer.verdict
        ));
    };
    let (low, high) = request.range;
    let comments = vec![
        format!(
            "Designed by specula design --target {} --n {low}..{high}: {}",
            request.target.id(),
            answer.verdict
        ),
        format!(
            "Verified at {} exponents: epicentre error {:.4} %, whole lobe {:.4} % of the peak.",
            answer.exponents_verified,
            100.0 * best.epicentre_error,
            100.0 * best.whole_error
        ),
    ];
    let text = specula_render::lobe_file::lobe_file_text(&best.definition(), &comments);
    // On the FPGA the datapath is part of the answer: its Verilog and diagram go beside the
    // lobe, made before anything is written so that a failure leaves no file.
    let hardware = match (request.target, best.kind()) {
        (Target::Fpga, Some(kind)) => Some(datapath_files(kind, request, path)?),
        _ => None,
    };
    write_text(path, &text)?;
    eprintln!(
        "wrote {}: the lobe '{}'; use it as --lobe @{}",
        path.display(),
        best.name,
        path.display()
    );
    for (file, text, what) in hardware.into_iter().flatten() {
        write_text(&file, &text)?;
        eprintln!("wrote {}: {what}", file.display());
    }
    Ok(())
}

/// The designed lobe's datapath as one circuit for the request's whole range (the widest
/// word length its exponents need): the pipelined Verilog module and its structural diagram,
/// each with the path beside `lobe_file` it goes to and what it is.
fn datapath_files(
    kind: specula::LobeKind,
    request: &DesignRequest,
    lobe_file: &std::path::Path,
) -> Result<Vec<(PathBuf, String, String)>, String> {
    let (lobe, bits) = circuit_for_range(kind, request.range, request.bounds.epicentre)?
        .ok_or_else(|| {
            format!(
                "nothing written to {}: the designed lobe's datapath reaches the bound at no \
                 word length from 8 to 24 bits",
                lobe_file.display()
            )
        })?;
    let datapath = lobe.build(bits).map_err(|e| e.to_string())?;
    let (low, high) = request.range;
    Ok(vec![
        (
            lobe_file.with_extension("v"),
            specula_hw::verilog::module(&datapath, lobe, bits),
            format!(
                "its pipelined datapath at {bits} bits, for every n in {low}..{high} (specula hw \
                 takes the lobe as --lobe @{})",
                lobe_file.display()
            ),
        ),
        (
            lobe_file.with_extension("svg"),
            specula_hw::diagram::svg(
                &datapath,
                &format!("{}: structural scheme at W = {bits}", lobe.id()),
            ),
            "its structural scheme".to_owned(),
        ),
    ])
}

fn write_text(path: &std::path::Path, text: &str) -> CommandResult {
    specula_render::write_atomically(path, |writer| {
        std::io::Write::write_all(writer, text.as_bytes()).map_err(|e| e.to_string())
    })
    .map_err(|e| e.to_string())
}
