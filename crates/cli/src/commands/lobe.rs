//! `specula lobe`: start a lobe file of your own, and check one before using it.

use std::path::PathBuf;

use specula::{Lobe, LobeKind};

use super::CommandResult;
use crate::output::Table;

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
    /// Check a lobe (a file or a formula) at every exponent of a range, and show what it
    /// compiles to: its constants, operations and sampling.
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
    println!(
        "{}: a lobe in [0, 1] at every n checked ({} from {first} to {last}); sampled by {}",
        args.lobe,
        exponents.len(),
        lobe.warp().id()
    );
    println!("operations per evaluation: {}", lobe.ops());
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
    table.print(crate::args::Format::Table);
    Ok(())
}
