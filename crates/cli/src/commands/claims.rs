//! `specula claims`: the thesis's claims with measured figures and verdicts.

use indicatif::{ProgressBar, ProgressStyle};
use specula::claims::{evaluate_all, ClaimId, ClaimOptions, ClaimResult};

use super::{print_json, CommandResult};
use crate::output::Table;

/// Arguments of `specula claims`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// Output format.
    #[arg(long, value_enum, default_value_t)]
    format: ClaimsFormat,
}

/// Output formats of `specula claims`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, clap::ValueEnum)]
pub enum ClaimsFormat {
    /// One block per claim, for reading.
    #[default]
    Table,
    /// JSON: an array of objects with claim, reading, measured, verdict, figures.
    Json,
}

/// Tests every claim (in parallel) and prints the results in the thesis's order.
pub fn run(args: &Args) -> CommandResult {
    let options = ClaimOptions::default();
    let progress = ProgressBar::new_spinner().with_style(
        ProgressStyle::with_template("{spinner} testing {msg} claims {elapsed}")
            .unwrap_or_else(|_| ProgressStyle::default_spinner()),
    );
    progress.set_message(ClaimId::ALL.len().to_string());
    progress.enable_steady_tick(std::time::Duration::from_millis(100));
    let results: Vec<ClaimResult> = evaluate_all(&options);
    progress.finish_and_clear();
    match args.format {
        ClaimsFormat::Json => print_json(&results),
        ClaimsFormat::Table => {
            let mut summary = Table::new(&["claim", "verdict"]);
            for result in &results {
                summary.push(vec![
                    result.claim.to_owned(),
                    result.verdict.name().to_owned(),
                ]);
            }
            print!("{}", summary.render());
            for result in &results {
                println!(
                    "\n{}\n  verdict:  {}\n  measured: {}\n  reading:  {}",
                    result.claim,
                    result.verdict.name(),
                    result.measured,
                    result.reading
                );
            }
            Ok(())
        }
    }
}
