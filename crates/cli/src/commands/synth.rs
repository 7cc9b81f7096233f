//! `specula hw synth`: the datapaths through Yosys (and nextpnr for iCE40), the tools' own
//! figures in a table, with their versions.

use indicatif::{ProgressBar, ProgressStyle};
use rayon::prelude::*;
use specula_hw::HwLobe;
use specula_synth::cache::Cache;
use specula_synth::{synthesize, Ice40Device, SynthError, Synthesis, Target};

use super::{print_json, CommandResult};
use crate::output::Table;

/// The flow, as a clap value.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, clap::ValueEnum)]
pub enum TargetArg {
    /// Yosys's `synth`: technology-independent gates.
    Generic,
    /// Yosys's `synth_ice40`, then nextpnr-ice40 for Fmax.
    #[default]
    Ice40,
    /// Yosys's `synth_xilinx` for 7-series (no Fmax: no open place-and-route).
    Xilinx,
}

/// The iCE40 part, as a clap value.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, clap::ValueEnum)]
pub enum DeviceArg {
    /// iCE40UP5K: 5,280 cells, eight SB_MAC16 multipliers (synthesis uses them).
    #[default]
    Up5k,
    /// iCE40HX8K: 7,680 cells, no multipliers (every operator in LUTs).
    Hx8k,
}

/// Output formats of `hw synth`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, clap::ValueEnum)]
pub enum SynthFormat {
    /// Aligned columns for reading.
    #[default]
    Table,
    /// JSON: an array of results, every cell type included.
    Json,
}

/// The library's target for the arguments.
#[must_use]
pub fn target(target: TargetArg, device: DeviceArg) -> Target {
    match target {
        TargetArg::Generic => Target::Generic,
        TargetArg::Xilinx => Target::Xilinx,
        TargetArg::Ice40 => Target::Ice40(match device {
            DeviceArg::Up5k => Ice40Device::Up5k,
            DeviceArg::Hx8k => Ice40Device::Hx8k,
        }),
    }
}

/// A bar over `count` syntheses.
pub fn progress_bar(count: usize, what: &str) -> ProgressBar {
    let bar = ProgressBar::new(count as u64).with_style(
        ProgressStyle::with_template(&format!("{{bar:30}} {{pos}}/{{len}} {what} {{elapsed}}"))
            .unwrap_or_else(|_| ProgressStyle::default_bar()),
    );
    bar.tick();
    bar
}

/// Synthesizes each of `lobes` at `bits` for `target`, in the given order, one per core at
/// a time (each tool run is single-threaded).
pub fn synthesize_all(
    lobes: &[HwLobe],
    bits: u32,
    target: Target,
    progress: &ProgressBar,
) -> Result<Vec<Synthesis>, SynthError> {
    let cache = Cache::default_location();
    lobes
        .par_iter()
        .map(|&lobe| {
            let result = synthesize(lobe, bits, target, cache.as_ref());
            progress.inc(1);
            result
        })
        .collect()
}

/// Prints `results` as a table with the tool versions beneath.
pub fn print_table(results: &[Synthesis], target: Target) {
    let mut table = Table::new(&[
        "datapath",
        "bits",
        target.logic_unit(),
        "carry",
        "DSP",
        "FF",
        "Fmax MHz",
        "latency",
        "LUT x ns/result",
    ]);
    for result in results {
        let or_dash = |value: Option<String>| value.unwrap_or_else(|| "-".to_owned());
        table.push(vec![
            result.lobe.clone(),
            result.bits.to_string(),
            result.cells.logic.to_string(),
            result.cells.carry.to_string(),
            result.cells.dsp.to_string(),
            result.cells.flip_flops.to_string(),
            or_dash(result.fmax_mhz.map(|mhz| format!("{mhz:.1}"))),
            result.latency.to_string(),
            or_dash(result.logic_ns_per_result().map(|v| format!("{v:.0}"))),
        ]);
    }
    print!("{}", table.render());
    println!(
        "\ntarget {}; latency in clock cycles, one result per clock.",
        target.name()
    );
    if let Some(first) = results.first() {
        println!("tools: {}", first.tools.describe());
    }
    for result in results {
        if let Some(note) = &result.fmax_note {
            println!("{}: no Fmax: {note}", result.lobe);
        }
    }
}

/// Runs `hw synth`.
pub fn run(lobes: &[HwLobe], bits: u32, target: Target, format: SynthFormat) -> CommandResult {
    let lobes = if lobes.is_empty() {
        HwLobe::ALL.to_vec()
    } else {
        lobes.to_vec()
    };
    let progress = progress_bar(lobes.len(), &format!("synthesized for {}", target.name()));
    let results = synthesize_all(&lobes, bits, target, &progress).map_err(|e| e.to_string());
    progress.finish_and_clear();
    let results = results?;
    match format {
        SynthFormat::Json => print_json(&results),
        SynthFormat::Table => {
            print_table(&results, target);
            Ok(())
        }
    }
}
