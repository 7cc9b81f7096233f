//! `specula claims`: the thesis's claims with measured figures and verdicts.

use indicatif::ProgressBar;
use specula::claims::{ClaimId, ClaimOptions, ClaimResult};

use specula_hw::{HwLobe, BITS};
use specula_synth::cache::Cache;
use specula_synth::claim::{self, HardwareClaim, CLAIM_N};
use specula_synth::OnMiss;

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

/// The hardware claim: the datapaths' sweeps at its exponent, then synthesis (cached; the
/// first run takes minutes), or why it could not be measured.
pub fn hardware_claim(
    samples_per_zone: usize,
    on_miss: OnMiss,
    on_each: &(dyn Fn() + Sync),
) -> Result<HardwareClaim, String> {
    let sweeps = specula_decide::sweeps(
        &HwLobe::ALL,
        CLAIM_N,
        (*BITS.start(), *BITS.end()),
        samples_per_zone,
        &ProgressBar::hidden(),
    )?;
    claim::evaluate(
        &sweeps,
        Cache::default_location().as_ref(),
        on_miss,
        on_each,
    )
    .map_err(|e| e.to_string())
}

/// Tests every claim (in parallel) and prints the results in the thesis's order, the
/// hardware claim last (it needs Yosys and nextpnr; without them it is reported as not
/// measured, and the others stand).
pub fn run(args: &Args) -> CommandResult {
    let options = ClaimOptions::default();
    let progress = crate::progress::bar("claims", 0, "{spinner} testing {msg} {elapsed}");
    progress.set_message(format!("{} claims", ClaimId::ALL.len()));
    progress.enable_steady_tick(std::time::Duration::from_millis(100));
    let results: Vec<ClaimResult> = specula_decide::analyses::claims(&options);
    progress.set_message("the hardware claim: synthesizing, 8");
    let hardware = hardware_claim(
        options.samples_per_zone.min(20_001),
        OnMiss::Synthesize,
        &|| {
            progress.tick();
        },
    );
    progress.finish_and_clear();
    match args.format {
        ClaimsFormat::Json => {
            let hardware = match &hardware {
                Ok(claim) => serde_json::to_value(claim),
                Err(problem) => Ok(serde_json::json!({
                    "claim": claim::STATEMENT,
                    "verdict": null,
                    "measured": format!("not measured: {problem}"),
                    "reading": "needs Yosys and nextpnr-ice40",
                    "figures": [],
                })),
            }
            .map_err(|e| e.to_string())?;
            let mut all = serde_json::to_value(&results).map_err(|e| e.to_string())?;
            if let Some(array) = all.as_array_mut() {
                array.push(hardware);
            }
            print_json(&all)
        }
        ClaimsFormat::Table => {
            let mut blocks: Vec<[String; 4]> = results
                .iter()
                .map(|result| {
                    [
                        result.claim.to_owned(),
                        result.verdict.name().to_owned(),
                        result.measured.clone(),
                        result.reading.clone(),
                    ]
                })
                .collect();
            blocks.push(match &hardware {
                Ok(claim) => [
                    claim.claim.to_owned(),
                    claim.verdict.name().to_owned(),
                    claim.measured.clone(),
                    claim.reading.clone(),
                ],
                Err(problem) => [
                    claim::STATEMENT.to_owned(),
                    "not measured".to_owned(),
                    problem.clone(),
                    "needs Yosys and nextpnr-ice40".to_owned(),
                ],
            });
            let mut summary = Table::new(&["claim", "verdict"]);
            for [claim, verdict, ..] in &blocks {
                summary.push(vec![claim.clone(), verdict.clone()]);
            }
            print!("{}", summary.render());
            for [claim, verdict, measured, reading] in &blocks {
                println!(
                    "\n{claim}\n  verdict:  {verdict}\n  measured: {measured}\n  reading:  \
                        {reading}"
                );
            }
            Ok(())
        }
    }
}
