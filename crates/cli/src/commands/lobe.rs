//! `specula lobe`: start a lobe file of your own, and check one before using it.

use std::collections::BTreeSet;
use std::path::PathBuf;

use specula::analysis::{self, Shape};
use specula::{Lobe, LobeKind};

use super::CommandResult;
use crate::args::OutputFormat;
use crate::output::{sig, Table};

/// Arguments of `specula lobe`.
#[derive(Debug, clap::Args)]
pub struct Args {
    #[command(subcommand)]
    command: LobeCommand,
}

#[derive(Debug, clap::Subcommand)]
enum LobeCommand {
    /// Write a lobe file to start from: the thesis's K_4 written as a formula, commented.
    New(NewArgs),
    /// Check a lobe (a file or a formula) at every exponent of a range: its peak and where it
    /// lies, its value at t = 1, its epicentre error against t^n and its energy at five of
    /// them, and what it compiles to (constants, operations, sampling).
    Check(CheckArgs),
}

#[derive(Debug, clap::Args)]
struct NewArgs {
    /// The file to write (`.toml`); the lobe is named after it. An existing file is kept.
    path: PathBuf,
}

#[derive(Debug, clap::Args)]
struct CheckArgs {
    /// The lobe: `@FILE.toml` (with `:k=1.5` for parameter values) or `=FORMULA`.
    #[arg(value_parser = crate::args::LobeParser)]
    lobe: LobeKind,
    /// The exponents to check at: one, or `LOW..HIGH` (31 steps, logarithmic).
    #[arg(long, default_value = "1..1000", allow_hyphen_values = true)]
    n: String,
    /// Output format: `csv` and `json` give the shape at five exponents, numbers only.
    #[arg(long, value_enum, default_value_t)]
    format: OutputFormat,
}

/// The worked example a new lobe file starts as.
const TEMPLATE: &str = include_str!("../../../../docs/lobes/k4.toml");

/// Runs the subcommand.
pub fn run(args: &Args) -> CommandResult {
    match &args.command {
        LobeCommand::New(args) => new(args),
        LobeCommand::Check(args) => check(args),
    }
}

fn new(args: &NewArgs) -> CommandResult {
    let shown = args.path.display();
    if args.path.exists() {
        return Err(format!(
            "{shown} exists; give a new path (the file is kept as it is)"
        ));
    }
    let name: String = args
        .path
        .file_stem()
        .map(|stem| stem.to_string_lossy().to_ascii_lowercase())
        .unwrap_or_default()
        .chars()
        .map(|c| if c.is_ascii_alphanumeric() { c } else { '-' })
        .collect();
    // An id: a lowercase letter first, at most 32 characters, not a built-in lobe's id.
    let builtin = LobeKind::ALL.iter().any(|kind| kind.id() == name);
    let name = if name.starts_with(|c: char| c.is_ascii_lowercase()) && !builtin {
        name
    } else {
        format!("my-{name}")
    };
    let name: String = name.chars().take(32).collect();
    let text = TEMPLATE
        .replace("name = \"k4-by-hand\"", &format!("name = \"{name}\""))
        .replace(
            "description = \"the thesis's K_4 written as a formula\"",
            "description = \"started from the thesis's K_4; edit the formula\"",
        );
    specula_render::write_atomically(&args.path, |writer| {
        std::io::Write::write_all(writer, text.as_bytes()).map_err(|e| e.to_string())
    })
    .map_err(|e| e.to_string())?;
    eprintln!("wrote {shown}: the lobe '{name}'; try specula lobe check @{shown}");
    Ok(())
}

fn check(args: &CheckArgs) -> CommandResult {
    let exponents = crate::args::parse_exponent_range(&args.n, 30)?;
    let LobeKind::Formula(_) = args.lobe else {
        return Err(format!(
            "'{}' is a built-in lobe; check takes a lobe of yours (@FILE.toml or =FORMULA)",
            args.lobe
        ));
    };
    for &n in &exponents {
        Lobe::checked(args.lobe, n).map_err(|e| e.to_string())?;
    }
    let (first, last) = (exponents[0], exponents[exponents.len() - 1]);
    let lobe = Lobe::new(args.lobe, first);
    // Its shape at five exponents spread over the range (the ends, the quarters, the middle).
    let picks: BTreeSet<usize> = [0, 1, 2, 3, 4]
        .map(|quarter| quarter * (exponents.len() - 1) / 4)
        .into_iter()
        .collect();
    let shapes: Vec<Shape> = picks
        .iter()
        .map(|&i| analysis::shape(&Lobe::new(args.lobe, exponents[i])))
        .collect();
    warn_of(&shapes);
    let rows: Vec<ShapeRow> = shapes.iter().map(ShapeRow::from).collect();
    if args.format == OutputFormat::Json {
        return super::print_json(&rows);
    }
    let mut table = Table::new(&[
        "n",
        "peak",
        "peak at t",
        "peak angle from the mirror direction (degrees)",
        "at t = 1",
        "epicentre error against t^n (%)",
        "energy ratio (1 = t^n's)",
    ]);
    for row in &rows {
        table.push(vec![
            sig(row.n),
            format!("{:.6}", row.peak),
            format!("{:.6}", row.peak_t),
            format!("{:.3}", row.peak_degrees),
            format!("{:.6}", row.at_t_1),
            format!("{:.4}", row.epicentre_error_percent),
            format!("{:.4}", row.energy_ratio),
        ]);
    }
    if args.format == OutputFormat::Csv {
        table.print(OutputFormat::Csv);
        return Ok(());
    }
    println!(
        "{}: a lobe in [0, 1] at every n checked ({} from {first} to {last}); sampled by {}",
        args.lobe,
        exponents.len(),
        lobe.warp().id()
    );
    println!("operations per evaluation: {}", lobe.ops());
    table.print(OutputFormat::Table);
    let mut table = Table::new(&["constant", &format!("n = {first}"), &format!("n = {last}")]);
    let at_last = Lobe::new(args.lobe, last);
    for parameter in lobe.parameters() {
        let value_at = |l: &Lobe| {
            l.parameters()
                .iter()
                .find(|p| p.name == parameter.name)
                .map_or_else(|| "-".to_owned(), |p| format!("{:.6}", p.value))
        };
        table.push(vec![
            parameter.name.to_owned(),
            value_at(&lobe),
            value_at(&at_last),
        ]);
    }
    table.print(OutputFormat::Table);
    Ok(())
}

/// One exponent's shape as `lobe check` prints it, with the units its names say.
#[derive(Debug, serde::Serialize)]
struct ShapeRow {
    n: f64,
    peak: f64,
    /// The cosine where the peak lies.
    peak_t: f64,
    peak_degrees: f64,
    at_t_1: f64,
    epicentre_error_percent: f64,
    energy_ratio: f64,
}

impl From<&Shape> for ShapeRow {
    fn from(shape: &Shape) -> Self {
        Self {
            n: shape.n,
            peak: shape.peak,
            peak_t: shape.peak_cos,
            peak_degrees: shape.peak_angle_degrees(),
            at_t_1: shape.at_one,
            epicentre_error_percent: 100.0 * shape.epicentre_max_rel,
            energy_ratio: shape.energy_ratio,
        }
    }
}

/// Warns, on stderr, of a lobe that is not 1 at `t = 1` or that peaks elsewhere, at the
/// first exponent where it happens.
fn warn_of(shapes: &[Shape]) {
    if let Some(shape) = shapes.iter().find(|shape| !shape.reaches_one()) {
        let change = if shape.at_one < 1.0 {
            "dims"
        } else {
            "brightens"
        };
        let remedy = if shape.at_one > 0.0 {
            "; divide the formula by its value at t = 1"
        } else {
            ""
        };
        eprintln!(
            "warning: the lobe is {:.6} at t = 1 (n = {}), not 1: it {change} every \
                highlight{remedy}",
            shape.at_one,
            sig(shape.n)
        );
    }
    if let Some(shape) = shapes
        .iter()
        .find(|shape| shape.peak > shape.at_one + Shape::REACHES_ONE)
    {
        eprintln!(
            "warning: the lobe peaks at {:.6} where t = {:.6} ({:.2} degrees from the mirror \
                direction, n = {}), above its value at t = 1: its highlights move off the mirror \
                direction",
            shape.peak,
            shape.peak_cos,
            shape.peak_angle_degrees(),
            sig(shape.n)
        );
    }
}
