//! `specula hw`: the hardware datapaths: error against word length and resources, Verilog with
//! a self-checking testbench, and the block diagram, all from one description per lobe.

use std::path::PathBuf;

use indicatif::{ProgressBar, ProgressStyle};
use specula_decide::sweeps;
use specula_hw::analysis::MEETS_TOLERANCE;
use specula_hw::{diagram, integer_exponent, verilog, HwLobe, BITS};
use specula_report::format::{resource_cells, resource_numbers, RESOURCE_NUMBER_COLUMNS};

use super::{print_json, synth, CommandResult};
use crate::args::OutputFormat;
use crate::output::{number, percent, sig, Table};

/// Arguments of `specula hw`.
#[derive(Debug, clap::Args)]
pub struct Args {
    #[command(subcommand)]
    action: Action,
}

#[derive(Debug, clap::Subcommand)]
enum Action {
    /// Error against t^n per word length, and the resources, for each datapath.
    Table(TableArgs),
    /// A pipelined Verilog module, and optionally a self-checking testbench.
    Verilog(VerilogArgs),
    /// The structural scheme as an SVG block diagram.
    Diagram(DiagramArgs),
    /// Synthesized resources (Yosys) and placed-and-routed Fmax (nextpnr-ice40) per datapath.
    Synth(SynthArgs),
}

/// A datapath id, parsed with the valid ids in the message; a lobe file (`@FILE.toml`, a
/// designed lobe) is read and its formula compiled.
fn parse_lobe(text: &str) -> Result<HwLobe, String> {
    if text.trim().starts_with('@') {
        let kind = specula_render::lobe_file::parse_lobe(text, None)?;
        return HwLobe::of_kind(kind).map_err(|e| e.to_string());
    }
    HwLobe::parse(text).map_err(|e| e.to_string())
}

/// A word length in [8, 24].
fn parse_bits(text: &str) -> Result<u32, String> {
    let bits: u32 = text
        .trim()
        .parse()
        .map_err(|_| format!("`{text}` is not a word length; valid: an integer from 8 to 24"))?;
    if BITS.contains(&bits) {
        Ok(bits)
    } else {
        Err(format!(
            "word length {bits} is out of range; valid: 8 to 24"
        ))
    }
}

/// `A..B`, `A-B` or `A`, each within [8, 24].
fn parse_bits_range(text: &str) -> Result<(u32, u32), String> {
    let (low, high) = text
        .split_once("..")
        .or_else(|| {
            text.split_once('-')
                .filter(|(low, _)| !low.trim().is_empty())
        })
        .unwrap_or((text, text));
    let (low, high) = (parse_bits(low)?, parse_bits(high)?);
    if low <= high {
        Ok((low, high))
    } else {
        Err(format!(
            "`{text}` is an empty range; write LOW..HIGH with LOW <= HIGH"
        ))
    }
}

/// An integer exponent in [1, 1000].
fn parse_integer_exponent(text: &str) -> Result<u32, String> {
    let n: f64 = text
        .trim()
        .parse()
        .map_err(|_| format!("`{text}` is not a number; n must be an integer in [1, 1000]"))?;
    integer_exponent(n).map_err(|e| e.to_string())
}

#[derive(Debug, clap::Args)]
struct TableArgs {
    /// Datapaths, comma separated (default: all built-ins); a lobe file of yours
    /// (`@FILE.toml`, a designed lobe) is compiled from its formula.
    #[arg(long, value_parser = parse_lobe, value_delimiter = ',')]
    lobe: Vec<HwLobe>,
    /// Word lengths: LOW..HIGH or one width.
    #[arg(
        long,
        allow_hyphen_values = true,
        value_parser = parse_bits_range,
        default_value = "8..24",
    )]
    bits: (u32, u32),
    /// The integer exponent.
    #[arg(
        long,
        allow_hyphen_values = true,
        value_parser = parse_integer_exponent,
        default_value = "64",
    )]
    n: u32,
    /// Angles sampled per zone.
    #[arg(
        long,
        default_value_t = 20_000,
        value_parser = clap::value_parser!(u32).range(100..=1_000_000),
    )]
    samples: u32,
    /// Output format.
    #[arg(long, value_enum, default_value_t)]
    format: OutputFormat,
}

#[derive(Debug, clap::Args)]
struct VerilogArgs {
    /// The datapath: a built-in's id, or a lobe file of yours (`@FILE.toml`).
    #[arg(long, value_parser = parse_lobe)]
    lobe: HwLobe,
    /// The word length.
    #[arg(long, allow_hyphen_values = true, value_parser = parse_bits)]
    bits: u32,
    /// The module's file (.v; `-` for standard output).
    #[arg(short, long)]
    output: PathBuf,
    /// Also write a self-checking testbench here, with vectors from the Rust model.
    #[arg(long)]
    testbench: Option<PathBuf>,
    /// Test vectors in the testbench (default: every input word, at n = 64, up to 16 bits;
    /// 10,000 spread over the lobe above).
    #[arg(long, value_parser = clap::value_parser!(u32).range(2..=100_000))]
    vectors: Option<u32>,
    /// The combinational form (module `<name>_comb`, no clock, no register) instead of the
    /// pipeline.
    #[arg(long)]
    combinational: bool,
}

#[derive(Debug, clap::Args)]
struct SynthArgs {
    /// Datapaths, comma separated (default: all built-ins); a lobe file of yours
    /// (`@FILE.toml`) is compiled from its formula.
    #[arg(long, value_parser = parse_lobe, value_delimiter = ',')]
    lobe: Vec<HwLobe>,
    /// The word length.
    #[arg(long, allow_hyphen_values = true, value_parser = parse_bits, default_value = "16")]
    bits: u32,
    /// The synthesis flow.
    #[arg(long, value_enum, default_value_t)]
    target: synth::TargetArg,
    /// The iCE40 part (with --target ice40).
    #[arg(long, value_enum, default_value_t)]
    device: synth::DeviceArg,
    /// Output format.
    #[arg(long, value_enum, default_value_t)]
    format: synth::SynthFormat,
}

#[derive(Debug, clap::Args)]
struct DiagramArgs {
    /// The datapath: a built-in's id, or a lobe file of yours (`@FILE.toml`).
    #[arg(long, value_parser = parse_lobe)]
    lobe: HwLobe,
    /// The word length the formats are shown for.
    #[arg(long, allow_hyphen_values = true, value_parser = parse_bits, default_value = "16")]
    bits: u32,
    /// The SVG file.
    #[arg(short, long)]
    output: PathBuf,
}

/// Runs the action.
pub fn run(args: &Args) -> CommandResult {
    match &args.action {
        Action::Table(args) => table(args),
        Action::Verilog(args) => write_verilog(args),
        Action::Diagram(args) => {
            let datapath = args.lobe.build(args.bits).map_err(|e| e.to_string())?;
            let title = format!("{}: structural scheme at W = {}", args.lobe.id(), args.bits);
            write_text(&args.output, &diagram::svg(&datapath, &title))
        }
        Action::Synth(args) => synth::run(
            &args.lobe,
            args.bits,
            synth::target(args.target, args.device),
            args.format,
        ),
    }
}

fn write_text(path: &std::path::Path, text: &str) -> CommandResult {
    specula_render::write_atomically(path, |writer| {
        writer.write_all(text.as_bytes()).map_err(|e| e.to_string())
    })
    .map_err(|e| e.to_string())
}

fn write_verilog(args: &VerilogArgs) -> CommandResult {
    if let Some(bench) = &args.testbench {
        let absolute = |path: &std::path::Path| std::path::absolute(path).ok();
        if absolute(bench) == absolute(&args.output) && args.output != std::path::Path::new("-") {
            return Err(format!(
                "--testbench and -o both name {}; give the testbench its own file",
                args.output.display()
            ));
        }
    }
    let datapath = args.lobe.build(args.bits).map_err(|e| e.to_string())?;
    let form = if args.combinational {
        verilog::Form::Combinational
    } else {
        verilog::Form::Pipelined
    };
    if let Some(path) = &args.testbench {
        let vectors = match args.vectors {
            Some(count) => verilog::test_vectors(args.lobe, &datapath, args.bits, count as usize),
            None => verilog::default_vectors(args.lobe, &datapath, args.bits, 64),
        };
        write_text(path, &verilog::testbench_in(&datapath, &vectors, form))?;
    }
    write_text(
        &args.output,
        &verilog::module_in(&datapath, args.lobe, args.bits, form),
    )
}

fn table(args: &TableArgs) -> CommandResult {
    let lobes = if args.lobe.is_empty() {
        HwLobe::ALL.to_vec()
    } else {
        args.lobe.clone()
    };
    let progress = ProgressBar::new(0).with_style(
        ProgressStyle::with_template("datapaths {bar:30} {pos}/{len} widths {elapsed}")
            .unwrap_or_else(|_| ProgressStyle::default_bar()),
    );
    let results = sweeps(&lobes, args.n, args.bits, args.samples as usize, &progress)?;
    if args.format == OutputFormat::Json {
        return print_json(&results);
    }
    // CSV is data: the error in % as a number, with all its digits, and each kind of
    // operator's count and summed size where the table lists widths.
    let csv = args.format == OutputFormat::Csv;
    let mut header = vec![
        "datapath",
        "bits",
        if csv {
            "epicentre max rel (%)"
        } else {
            "epicentre max rel"
        },
        "bloom max abs",
    ];
    if csv {
        header.extend(RESOURCE_NUMBER_COLUMNS);
    } else {
        header.extend([
            "multipliers",
            "squarers",
            "adders",
            "dividers",
            "shifters",
            "ROM bits",
            "register bits",
            "latency",
        ]);
    }
    let mut table = Table::new(&header);
    for result in &results {
        for row in &result.rows {
            let mut cells = vec![
                result.lobe.id().to_owned(),
                row.bits.to_string(),
                if csv {
                    number(100.0 * row.errors.epicentre_max_rel)
                } else {
                    percent(row.errors.epicentre_max_rel)
                },
                if csv {
                    number(row.errors.bloom_max_abs)
                } else {
                    sig(row.errors.bloom_max_abs)
                },
            ];
            if csv {
                cells.extend(resource_numbers(&row.resources));
            } else {
                cells.extend(resource_cells(&row.resources));
            }
            table.push(cells);
        }
    }
    table.print(args.format);
    if args.format == OutputFormat::Table {
        println!(
            "\nn = {}; widths are in bits; \"meets\" = epicentre max rel within \
            {MEETS_TOLERANCE}x the f64 model's.",
            args.n
        );
        for result in &results {
            let meets = result.minimum_width().map_or_else(
                || {
                    format!(
                        "does not meet it within {}..{} bits",
                        args.bits.0, args.bits.1
                    )
                },
                |w| format!("meets it from {w} bits"),
            );
            println!(
                "{:16} f64 model: epicentre {}, bloom {}; {meets}",
                result.lobe.id(),
                percent(result.float.epicentre_max_rel),
                sig(result.float.bloom_max_abs)
            );
        }
    }
    Ok(())
}
