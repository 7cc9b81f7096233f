//! `specula recommend`: which lobe to ship on a target at an accuracy.
//!
//! Every lobe is measured against `t^n` at each exponent asked for (a range is sampled at
//! log-spaced points, its ends and the powers of two inside, where `schlick-mod` and
//! `cosquad` change shape); a lobe's error is its worst over them. Those within the allowed
//! error are ranked by cost on the target: on `cpu`, the measured throughput of its SIMD
//! kernel on this machine (one thread, L1, the slowest over the exponents); on a GPU family,
//! the modelled evaluations per clock per multiprocessor of its exported shader
//! (`specula::gpu_cost`). The Pareto front is taken over every lobe, met or not.

use indicatif::{ProgressBar, ProgressStyle};
use serde::Serialize;
use specula::analysis::{energy_ratio, error_figures, ErrorFigures, Precision};
use specula::gpu_cost::GpuFamily;
use specula::{Exponent, Lobe, LobeKind};
use specula_hw::analysis::WidthSweep;
use specula_hw::{HwLobe, BITS};

use super::fpga_estimate::logic_cells;
use super::CommandResult;
use crate::output::Table;

/// Where the lobe will run.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum Target {
    /// This machine's CPU: measured SIMD throughput.
    Cpu,
    /// NVIDIA GPUs (compute capability 8.6-9.0): modelled from the shader's instructions.
    GpuNvidia,
    /// AMD RDNA GPUs: modelled from the shader's instructions.
    GpuAmd,
    /// FPGA: estimated from the fixed-point datapaths' operators (see docs/analysis.md).
    Fpga,
}

/// Where the error is measured.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum ZoneChoice {
    /// The epicentre's largest relative error (where `t^n >= 1/2`).
    Epicentre,
    /// The bloom's largest absolute error, as a fraction of the peak.
    Bloom,
    /// The largest absolute error anywhere, as a fraction of the peak.
    Whole,
}

/// Arguments of `specula recommend`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// Where the lobe will run.
    #[arg(long, value_enum)]
    target: Target,
    /// The exponent, or a range `LOW..HIGH` over which the answer must hold.
    #[arg(long, allow_hyphen_values = true, default_value = "64", value_parser = parse_exponents)]
    n: Exponents,
    /// The largest error allowed, as a percentage (`1%` or `1`).
    #[arg(long, allow_hyphen_values = true, value_parser = parse_percent, required_unless_present = "material")]
    max_error: Option<f64>,
    /// Rank by the fit to a measured material instead (an RGL isotropic RGB `.bsdf`): the
    /// cheapest lobe whose fit error is within `--margin` of pow's (see `specula fit`).
    #[arg(long, conflicts_with_all = ["max_error", "n", "zone", "energy_conserving"])]
    material: Option<std::path::PathBuf>,
    /// With `--material`: the fit error allowed over pow's, as a percentage [default: 5%].
    #[arg(long, allow_hyphen_values = true, value_parser = parse_margin, requires = "material", conflicts_with = "max_error")]
    margin: Option<f64>,
    /// Which error.
    #[arg(long, value_enum, default_value_t = ZoneChoice::Epicentre)]
    zone: ZoneChoice,
    /// Only lobes whose energy stays within 0.1 % of t^n's (so the n + 1 normalisation keeps
    /// the BRDF energy-conserving).
    #[arg(long)]
    energy_conserving: bool,
    /// Also consider these lobes: your own (`@FILE.toml`, `=FORMULA`), or a built-in with
    /// other parameters (`cosquad:v=5`); comma separated. On `fpga` a lobe without a
    /// fixed-point datapath is listed as unavailable.
    #[arg(long, value_parser = crate::args::LobeListParser)]
    lobe: Vec<crate::args::LobeList>,
    /// Output format.
    #[arg(long, value_enum, default_value_t = crate::args::Format::Table)]
    format: crate::args::Format,
}

/// One exponent or a sampled range.
#[derive(Clone, Debug)]
pub struct Exponents(Vec<Exponent>);

fn parse_exponents(text: &str) -> Result<Exponents, String> {
    let sampled = crate::args::parse_exponent_range(text, 8)?;
    let (low, high) = (sampled[0].get(), sampled[sampled.len() - 1].get());
    // The powers of two inside the range too: schlick-mod and cosquad change shape there.
    let mut values: Vec<f64> = sampled
        .iter()
        .map(|n| n.get())
        .chain(
            (0..10)
                .map(|p| f64::from(1u32 << p))
                .filter(|&v| v > low && v < high),
        )
        .collect();
    values.sort_by(f64::total_cmp);
    values.dedup_by(|a, b| (*a - *b).abs() < 1e-9);
    Ok(Exponents(values.into_iter().map(Exponent::new).collect()))
}

/// A margin over pow's fit error: a percentage in `[0, 100]`.
pub(crate) fn parse_margin(text: &str) -> Result<f64, String> {
    let number = text.trim().trim_end_matches('%');
    match number.parse::<f64>() {
        Ok(value) if (0.0..=100.0).contains(&value) => Ok(value / 100.0),
        _ => Err(format!(
            "'{text}' is not a margin in [0, 100] %; write it as 5% or 2.5"
        )),
    }
}

fn parse_percent(text: &str) -> Result<f64, String> {
    let number = text.trim().trim_end_matches('%');
    match number.parse::<f64>() {
        Ok(value) if value > 0.0 && value <= 100.0 => Ok(value / 100.0),
        _ => Err(format!(
            "'{text}' is not an error in (0, 100] %; write it as 1% or 0.5"
        )),
    }
}

/// One lobe's figures.
#[derive(Clone, Debug, Serialize)]
struct Candidate {
    lobe: String,
    /// On `fpga`, the datapath and word length costed (at the first exponent); `None` where
    /// the lobe has no datapath.
    #[serde(skip_serializing_if = "Option::is_none")]
    datapath: Option<String>,
    /// The worst error over the exponents, as a fraction.
    error: f64,
    /// The cost figure: evaluations per second (cpu) or per clock per multiprocessor (gpu),
    /// the smallest over the exponents. Higher is cheaper.
    rate: f64,
    /// Its unit.
    unit: &'static str,
    /// The worst energy ratio against `t^n` over the exponents.
    energy_ratio: f64,
    /// Whether it meets the error (and the energy condition, if asked).
    meets: bool,
    /// No other lobe is at least as accurate and at least as cheap, and better in one.
    pareto: bool,
    /// Why it stands where it does.
    why: String,
}

fn zone_error(figures: &ErrorFigures, zone: ZoneChoice) -> f64 {
    match zone {
        ZoneChoice::Epicentre => figures.epicentre_max_rel,
        ZoneChoice::Bloom => figures.bloom_max_abs,
        ZoneChoice::Whole => figures
            .epicentre_max_abs
            .max(figures.bloom_max_abs)
            .max(figures.tail_max_abs),
    }
}

/// How a target's costs are obtained.
enum Costing {
    /// Timed on this machine's CPU.
    Measured,
    /// The GPU cost model of one family.
    Modelled(GpuFamily),
    /// Estimated from the fixed-point datapaths' sweeps, per exponent (without Yosys).
    Estimated(Vec<(Exponent, Vec<WidthSweep>)>),
    /// Synthesized and placed (Yosys, nextpnr-ice40 on an iCE40 HX8K; cached), at the word
    /// lengths the sweeps choose.
    Synthesized(Vec<(Exponent, Vec<WidthSweep>)>),
}

/// Where recommend's FPGA costs are synthesized: every operator in LUTs, one area figure.
const FPGA_TARGET: specula_synth::Target =
    specula_synth::Target::Ice40(specula_synth::Ice40Device::Hx8k);

/// One lobe at one exponent: its error, its cost figure (higher is cheaper), and on the FPGA
/// the datapath costed.
struct Point {
    error: f64,
    rate: f64,
    datapath: Option<String>,
}

impl Costing {
    fn new(target: Target, exponents: &[Exponent]) -> Result<Self, String> {
        let family = |id: &str| {
            GpuFamily::find(id).ok_or_else(|| format!("no GPU family '{id}' in the model"))
        };
        Ok(match target {
            Target::Cpu => Costing::Measured,
            Target::GpuNvidia => Costing::Modelled(family("gpu-nvidia")?),
            Target::GpuAmd => Costing::Modelled(family("gpu-amd")?),
            Target::Fpga => {
                let sweeps = hardware_sweeps(exponents)?;
                match specula_synth::ToolVersions::find(FPGA_TARGET) {
                    Ok(_) => Costing::Synthesized(sweeps),
                    Err(missing) => {
                        eprintln!("note: {missing}; FPGA costs are the formula estimate instead");
                        Costing::Estimated(sweeps)
                    }
                }
            }
        })
    }

    fn unit(&self) -> &'static str {
        match self {
            Costing::Measured => "evals/s, 1 thread",
            Costing::Modelled(_) => "evals/clock/multiprocessor (modelled)",
            Costing::Estimated(_) => "evals/clock per 1000 logic cells (estimated)",
            Costing::Synthesized(_) => "results/us per 1000 LUTs (synthesized, iCE40 HX8K)",
        }
    }

    /// `lobe` at its exponent, or `None` where the target cannot run it (no datapath).
    fn point(
        &self,
        lobe: &Lobe,
        zone: ZoneChoice,
        max_error: f64,
    ) -> Result<Option<Point>, String> {
        let float_error = || zone_error(&error_figures(lobe, &mut Precision::F64, 20_001), zone);
        Ok(match self {
            Costing::Measured => Some(Point {
                error: float_error(),
                rate: super::bench::lobes::kernel_rate(lobe),
                datapath: None,
            }),
            Costing::Modelled(family) => {
                let ops = specula_gpu::shader_ops::lobe_shader_ops(lobe)?;
                Some(Point {
                    error: float_error(),
                    rate: family.cost(&ops).evals_per_clock,
                    datapath: None,
                })
            }
            Costing::Estimated(hardware) | Costing::Synthesized(hardware) => {
                let Some(chosen) = hardware
                    .iter()
                    .find(|(at, _)| *at == lobe.exponent())
                    .and_then(|(_, sweeps)| {
                        cheapest_datapath(sweeps, lobe.kind(), zone, max_error)
                    })
                else {
                    return Ok(None);
                };
                let mut datapath = format!("{} at {} bits", chosen.lobe.id(), chosen.bits);
                let rate = match self {
                    // A datapath that cannot reach the error is not worth the tools' minutes:
                    // it is listed, with its error, as not meeting.
                    Costing::Synthesized(_) if chosen.error > max_error => {
                        datapath += " (not synthesized: short of the error)";
                        0.0
                    }
                    Costing::Synthesized(_) => {
                        let cache = specula_synth::cache::Cache::default_location();
                        let synthesis = specula_synth::synthesize(
                            chosen.lobe,
                            chosen.bits,
                            FPGA_TARGET,
                            cache.as_ref(),
                        )
                        .map_err(|e| e.to_string())?;
                        synthesis
                            .logic_ns_per_result()
                            .map_or(0.0, |lut_ns| 1e6 / lut_ns)
                    }
                    _ => 1e3 / chosen.cells as f64,
                };
                Some(Point {
                    error: chosen.error,
                    rate,
                    datapath: Some(datapath),
                })
            }
        })
    }
}

/// Every datapath's sweep over word lengths at each exponent, rounded to an integer (the
/// datapaths take integer `n`).
fn hardware_sweeps(exponents: &[Exponent]) -> Result<Vec<(Exponent, Vec<WidthSweep>)>, String> {
    exponents
        .iter()
        .map(|&n| {
            let whole = n.get().round().clamp(1.0, 1000.0) as u32;
            let sweeps = super::hw::sweeps(
                &HwLobe::ALL,
                whole,
                (*BITS.start(), *BITS.end()),
                20_001,
                false,
            )?;
            Ok((n, sweeps))
        })
        .collect()
}

/// A datapath at a word length, with its error there and its formula estimate.
pub(crate) struct Chosen {
    pub lobe: HwLobe,
    pub bits: u32,
    pub error: f64,
    pub cells: u64,
}

/// Of `kind`'s datapaths at `n`, each at the smallest word length whose `zone` error is at
/// most `max_error` (or at its widest, where none is), the one with the fewest estimated
/// logic cells among those within the bound, else the most accurate.
pub(crate) fn cheapest_datapath(
    sweeps: &[WidthSweep],
    kind: LobeKind,
    zone: ZoneChoice,
    max_error: f64,
) -> Option<Chosen> {
    sweeps
        .iter()
        .filter(|sweep| sweep.lobe.float_kind() == kind)
        .filter_map(|sweep| {
            let row = sweep
                .rows
                .iter()
                .find(|row| zone_error(&row.errors, zone) <= max_error)
                .or_else(|| sweep.rows.last())?;
            Some(Chosen {
                lobe: sweep.lobe,
                bits: row.bits,
                error: zone_error(&row.errors, zone),
                cells: logic_cells(&row.resources),
            })
        })
        .min_by_key(|chosen| (chosen.error > max_error, chosen.cells))
}

/// Which of `points` (error, rate) no other point dominates.
pub(crate) fn pareto_front(points: &[(f64, f64)]) -> Vec<bool> {
    points
        .iter()
        .map(|&(error, rate)| {
            !points
                .iter()
                .any(|&(e, r)| e <= error && r >= rate && (e < error || r > rate))
        })
        .collect()
}

/// Why `--material` refuses the FPGA target.
pub(crate) const FPGA_MATERIAL_REFUSAL: &str = "a material verdict cannot target fpga: the fixed-point datapaths take an integer n and a word length chosen for an error against t^n, which a material's fit does not give; valid targets: cpu, gpu-nvidia, gpu-amd";

/// A lobe's rate on `target` for a material's verdict (higher is cheaper): measured on the
/// CPU, modelled on a GPU.
pub(crate) fn lobe_rate(target: Target, lobe: &Lobe) -> Result<f64, String> {
    if target == Target::Fpga {
        return Err(FPGA_MATERIAL_REFUSAL.to_owned());
    }
    match Costing::new(target, &[lobe.exponent()])? {
        Costing::Measured => Ok(super::bench::lobes::kernel_rate(lobe)),
        Costing::Modelled(family) => {
            let ops = specula_gpu::shader_ops::lobe_shader_ops(lobe)?;
            Ok(family.cost(&ops).evals_per_clock)
        }
        Costing::Estimated(_) | Costing::Synthesized(_) => Err(FPGA_MATERIAL_REFUSAL.to_owned()),
    }
}

/// The unit of [`lobe_rate`] on `target`.
pub(crate) fn rate_unit(target: Target) -> &'static str {
    match target {
        // Costing the FPGA would run its sweeps; material verdicts refuse it anyway.
        Target::Fpga => "",
        _ => Costing::new(target, &[]).map_or("", |costing| costing.unit()),
    }
}

/// Measures, ranks and prints.
pub fn run(args: &Args) -> CommandResult {
    if let Some(material) = &args.material {
        let kinds = super::fit::lobes_to_fit(&crate::args::flatten(&args.lobe))?;
        if args.target == Target::Fpga {
            return Err(FPGA_MATERIAL_REFUSAL.to_owned());
        }
        let margin = args.margin.unwrap_or(super::fit::DEFAULT_MARGIN);
        let loaded = specula_render::measured::load_measured(material)?;
        let assessment = super::fit::assess(&loaded, material, &kinds, args.target, margin)?;
        return super::fit::print_ranking(&assessment, args.format);
    }
    let max_error = args.max_error.unwrap_or(f64::NAN);
    let exponents = &args.n.0;
    let yours = crate::args::flatten(&args.lobe);
    crate::args::check_lobes(&yours, exponents)?;
    let mut kinds = LobeKind::ALL.to_vec();
    for &kind in &yours {
        if !kinds.contains(&kind) {
            kinds.push(kind);
        }
    }
    let costing = Costing::new(args.target, exponents)?;
    let progress = ProgressBar::new(kinds.len() as u64).with_style(
        ProgressStyle::with_template("measuring {bar:30} {pos}/{len} lobes {msg}")
            .unwrap_or_else(|_| ProgressStyle::default_bar()),
    );
    let mut candidates = Vec::new();
    for kind in kinds {
        progress.set_message(kind.to_string());
        let mut error = 0.0_f64;
        let mut energy = 0.0_f64;
        let mut cheapest = f64::INFINITY;
        // The datapath named at the first exponent; none if any exponent has none.
        let mut datapath = None;
        let mut unavailable = false;
        for &n in exponents {
            let lobe = Lobe::new(kind, n);
            energy = energy.max(energy_ratio(&lobe));
            match costing.point(&lobe, args.zone, max_error)? {
                Some(point) => {
                    error = error.max(point.error);
                    cheapest = cheapest.min(point.rate);
                    datapath = datapath.or(point.datapath);
                }
                None => unavailable = true,
            }
        }
        if unavailable {
            (error, cheapest, datapath) = (f64::INFINITY, 0.0, None);
        }
        let unit = costing.unit();
        let meets = error <= max_error && (!args.energy_conserving || energy <= 1.001);
        candidates.push(Candidate {
            lobe: kind.to_string(),
            datapath,
            error,
            rate: cheapest,
            unit,
            energy_ratio: energy,
            meets,
            pareto: false,
            why: String::new(),
        });
        progress.inc(1);
    }
    progress.finish_and_clear();
    let front = pareto_front(
        &candidates
            .iter()
            .map(|c| (c.error, c.rate))
            .collect::<Vec<_>>(),
    );
    let pow_rate = candidates
        .iter()
        .find(|c| c.lobe == LobeKind::Pow.id())
        .map_or(f64::NAN, |c| c.rate);
    for (candidate, on_front) in candidates.iter_mut().zip(front) {
        candidate.pareto = on_front;
    }
    candidates.sort_by(|a, b| b.meets.cmp(&a.meets).then(b.rate.total_cmp(&a.rate)));
    let best = candidates.iter().find(|c| c.meets).map(|c| c.lobe.clone());
    for candidate in &mut candidates {
        candidate.why = why(candidate, best.as_deref(), pow_rate, args.target, max_error);
    }
    if args.format == crate::args::Format::Json {
        return super::print_json(&candidates);
    }
    let span = match exponents.as_slice() {
        [only] => format!("n = {only}"),
        all => format!(
            "n from {} to {} ({} exponents sampled)",
            all[0],
            all[all.len() - 1],
            all.len()
        ),
    };
    let name = |value: &dyn Fn() -> Option<clap::builder::PossibleValue>| {
        value().map_or_else(String::new, |v| v.get_name().to_owned())
    };
    let zone = name(&|| clap::ValueEnum::to_possible_value(&args.zone));
    let target = name(&|| clap::ValueEnum::to_possible_value(&args.target));
    // Off the FPGA, pow is exact, keeps t^n's energy and so always meets the request; the
    // FPGA has no datapath for it, so there nothing may meet it.
    match &best {
        Some(lobe) => println!(
            "{lobe}: the cheapest lobe within {} % ({zone} error) at {span} on {target}",
            100.0 * max_error
        ),
        None => println!(
            "no lobe is within {} % ({zone} error) at {span} on {target}; every lobe is listed, \
             with the Pareto front marked",
            100.0 * max_error
        ),
    }
    let mut table = Table::new(&[
        "lobe",
        "meets",
        "error",
        "cost",
        "vs pow",
        "energy ratio",
        "pareto",
        "why",
    ]);
    for c in &candidates {
        table.push(vec![
            c.lobe.clone(),
            if c.meets { "yes" } else { "no" }.to_owned(),
            if c.error.is_finite() {
                format!("{:.4} %", 100.0 * c.error)
            } else {
                "-".to_owned()
            },
            format!("{:.3e} {}", c.rate, c.unit),
            versus_pow(c.rate, pow_rate),
            format!("{:.4}", c.energy_ratio),
            if c.pareto { "front" } else { "" }.to_owned(),
            c.why.clone(),
        ]);
    }
    table.print(args.format);
    Ok(())
}

/// `rate` as a multiple of pow's, or `-` where pow has no cost on the target (no datapath).
fn versus_pow(rate: f64, pow_rate: f64) -> String {
    if pow_rate > 0.0 && pow_rate.is_finite() {
        format!("{:.2}x", rate / pow_rate)
    } else {
        "-".to_owned()
    }
}

fn why(c: &Candidate, best: Option<&str>, pow_rate: f64, target: Target, max_error: f64) -> String {
    let speed = versus_pow(c.rate, pow_rate);
    let relative = if speed == "-" {
        String::new()
    } else {
        format!(" at {speed} pow's rate")
    };
    if !c.meets {
        if target == Target::Fpga && c.datapath.is_none() {
            return "no fixed-point datapath for this lobe".to_owned();
        }
        if c.error > max_error {
            return format!(
                "error {:.3} % exceeds {:.3} %",
                100.0 * c.error,
                100.0 * max_error
            );
        }
        return format!("energy {:.2} % above t^n's", 100.0 * (c.energy_ratio - 1.0));
    }
    if Some(c.lobe.as_str()) == best {
        return format!("cheapest that meets it{relative}");
    }
    if c.lobe == LobeKind::Pow.id() {
        return "exact, the reference".to_owned();
    }
    format!("meets it{relative}")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_front_keeps_exactly_the_undominated() {
        // (error, rate): b dominates c; a and b trade off; d is dominated by a.
        let points = [(0.0, 1.0), (0.01, 3.0), (0.02, 2.0), (0.001, 0.5)];
        assert_eq!(pareto_front(&points), [true, true, false, false]);
    }

    #[test]
    fn ranges_are_sampled_between_their_ends_with_powers_of_two() {
        let Exponents(values) = parse_exponents("8..512").unwrap();
        let values: Vec<f64> = values.iter().map(|n| n.get()).collect();
        assert_eq!((values[0], values[values.len() - 1]), (8.0, 512.0));
        for p in [16.0, 32.0, 64.0, 128.0, 256.0] {
            assert!(values.contains(&p), "{p} missing from {values:?}");
        }
        assert!(parse_exponents("512..8").is_err());
        assert!(parse_percent("0").is_err() && parse_percent("-1%").is_err());
        assert!(parse_percent("NaN").is_err());
        assert_eq!(parse_percent("1%"), Ok(0.01));
    }
}
