//! `specula recommend`: which lobe to ship on a target at an accuracy. The decision is
//! `specula_decide::recommend` (a range of `n` sampled by `specula_decide::sample_exponents`);
//! with `--material`, `specula_decide::material`. This module parses and prints.

use indicatif::{ProgressBar, ProgressStyle};
use specula::Exponent;
use specula_decide::material::{assess, lobes_to_fit, ranking, DEFAULT_MARGIN};
use specula_decide::{recommend, versus_pow, Request, Target, Zone};

use super::CommandResult;
use crate::args::{described, parse_margin};
use crate::output::{number, Table};

/// Arguments of `specula recommend`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// Where the lobe will run.
    #[arg(long, value_parser = described(&Target::ALL, Target::id, Target::summary))]
    target: Target,
    /// A GPU target's generation, by its vendor's name: NVIDIA sm_75, sm_86, sm_89, sm_90,
    /// sm_120; AMD gfx900, gfx1010, gfx1030, gfx1100; Intel tgllp, dg2 [default: sm_89,
    /// gfx1100, dg2].
    #[arg(
        long,
        value_parser = crate::args::choice(&specula::gpus::Gpu::ALL, |gpu| gpu.id),
        conflicts_with = "material"
    )]
    gpu: Option<specula::gpus::Gpu>,
    /// The exponent, or a range `LOW..HIGH` over which the answer must hold.
    #[arg(long, allow_hyphen_values = true, default_value = "64", value_parser = parse_exponents)]
    n: Exponents,
    /// The largest error allowed, as a percentage (`1%` or `1`).
    #[arg(
        long,
        allow_hyphen_values = true,
        value_parser = crate::args::parse_percent,
        required_unless_present = "material",
    )]
    max_error: Option<f64>,
    /// Rank by the fit to a measured material instead (an RGL isotropic RGB `.bsdf`): the
    /// cheapest lobe whose fit error is within `--margin` of pow's (see `specula fit`).
    #[arg(long, conflicts_with_all = ["max_error", "n", "zone", "energy_conserving"])]
    material: Option<std::path::PathBuf>,
    /// With `--material`: the fit error allowed over pow's, as a percentage [default: 5%].
    #[arg(
        long,
        allow_hyphen_values = true,
        value_parser = parse_margin,
        requires = "material",
        conflicts_with = "max_error",
    )]
    margin: Option<f64>,
    /// Which error.
    #[arg(
        long,
        value_parser = described(&Zone::ALL, Zone::id, Zone::summary),
        default_value_t = Zone::Epicentre,
    )]
    zone: Zone,
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
    #[arg(long, value_enum, default_value_t = crate::args::OutputFormat::Table)]
    format: crate::args::OutputFormat,
}

/// One exponent or a sampled range.
#[derive(Clone, Debug)]
pub struct Exponents(Vec<Exponent>);

fn parse_exponents(text: &str) -> Result<Exponents, String> {
    specula_decide::parse_exponents(text).map(Exponents)
}

/// Measures, ranks and prints.
pub fn run(args: &Args) -> CommandResult {
    if let Some(material) = &args.material {
        let kinds = lobes_to_fit(&crate::args::flatten(&args.lobe), args.target)?;
        let margin = args.margin.unwrap_or(DEFAULT_MARGIN);
        let loaded = specula_render::measured::load_measured(material)?;
        let assessment = assess(&loaded, material, &kinds, args.target, margin)?;
        return super::fit::print_ranking(&assessment, &ranking(&assessment), args.format);
    }
    let exponents = &args.n.0;
    let request = Request {
        target: args.target,
        gpu: args.gpu,
        exponents: exponents.clone(),
        max_error: args
            .max_error
            .ok_or("recommend needs --max-error or --material")?,
        zone: args.zone,
        energy_conserving: args.energy_conserving,
        lobes: specula_decide::candidates(&crate::args::flatten(&args.lobe)),
    };
    let progress = ProgressBar::new(0).with_style(
        ProgressStyle::with_template("measuring {bar:30} {pos}/{len} lobes {msg}")
            .unwrap_or_else(|_| ProgressStyle::default_bar()),
    );
    let answer = recommend(&request, &progress)?;
    if let Some(note) = &answer.note {
        eprintln!("note: {note}");
    }
    if args.format == crate::args::OutputFormat::Json {
        return super::print_json(&answer.candidates);
    }
    let max_error = request.max_error;
    let span = match exponents.as_slice() {
        [only] => format!("n = {only}"),
        all => format!(
            "n from {} to {} ({} exponents sampled)",
            all[0],
            all[all.len() - 1],
            all.len()
        ),
    };
    let (zone, target) = (args.zone, args.target);
    // Off the FPGA, pow is exact, keeps t^n's energy and so always meets the request; the
    // FPGA has no datapath for it, so there nothing may meet it.
    let verdict = match answer.best_candidate().map(|c| &c.lobe) {
        Some(lobe) if answer.tied.len() > 1 => format!(
            "{lobe}: the most accurate of the lobes tied for the cheapest within {} % ({zone} \
             error) at {span} on {target} (their measured rates overlap: {})",
            100.0 * max_error,
            answer.tied.join(", ")
        ),
        Some(lobe) => format!(
            "{lobe}: the cheapest lobe within {} % ({zone} error) at {span} on {target}",
            100.0 * max_error
        ),
        None => format!(
            "no lobe is within {} % ({zone} error) at {span} on {target}; every lobe is listed, \
             with the Pareto front marked",
            100.0 * max_error
        ),
    };
    let pow_rate = answer.pow_rate();
    if args.format == crate::args::OutputFormat::Csv {
        // Data alone on stdout: numbers, ids and booleans under a header that names the
        // units; the verdict goes to stderr.
        eprintln!("{verdict}");
        let rate = format!("rate ({})", answer.unit);
        let slowest = format!("median pass ({})", answer.unit);
        let fastest = format!("fastest pass ({})", answer.unit);
        let mut table = Table::new(&[
            "lobe",
            "meets",
            "error (%)",
            &rate,
            &slowest,
            &fastest,
            "x pow's throughput (higher is better)",
            "energy ratio",
            "pareto",
        ]);
        for c in &answer.candidates {
            table.push(vec![
                c.lobe.clone(),
                c.meets.to_string(),
                if c.error.is_finite() {
                    number(100.0 * c.error)
                } else {
                    String::new()
                },
                number(c.rate),
                c.spread.map_or(String::new(), |[low, _]| number(low)),
                c.spread.map_or(String::new(), |[_, high]| number(high)),
                number(c.rate / pow_rate),
                number(c.energy_ratio),
                c.pareto.to_string(),
            ]);
        }
        table.print(args.format);
        return Ok(());
    }
    println!("{verdict}");
    if let Some(basis) = &answer.basis {
        println!("costed on {basis}");
    }
    let aco = answer
        .candidates
        .iter()
        .any(|c| c.aco_inverse_throughput.is_some());
    let mut header = vec!["lobe", "meets", "error", "rate", "x pow's throughput"];
    if aco {
        header.push("ACO's inverse throughput beyond the baseline (cycles/wave)");
    }
    header.extend(["energy ratio", "pareto", "why"]);
    let mut table = Table::new(&header);
    for c in &answer.candidates {
        let mut row = vec![
            c.lobe.clone(),
            if c.meets { "yes" } else { "no" }.to_owned(),
            if c.error.is_finite() {
                format!("{:.4} %", 100.0 * c.error)
            } else {
                "-".to_owned()
            },
            format!("{:.3e} {}", c.rate, c.unit),
            spread_versus_pow(c.rate, c.spread, pow_rate),
        ];
        if aco {
            row.push(
                c.aco_inverse_throughput
                    .map_or("-".to_owned(), |v| format!("{v}")),
            );
        }
        row.extend([
            format!("{:.4}", c.energy_ratio),
            if c.pareto { "front" } else { "" }.to_owned(),
            c.why.clone(),
        ]);
        table.push(row);
    }
    table.print(args.format);
    if answer.candidates.iter().any(|c| c.spread.is_some()) {
        eprintln!(
            "measured rates: the fastest of {} passes over every lobe (noise only slows a \
             kernel), the median pass to the fastest in brackets, at the slowest exponent; \
             lobes whose brackets overlap are a tie, which goes to the more accurate",
            specula_decide::rates::PASSES
        );
    }
    Ok(())
}

/// The rate over pow's, and where it was measured the median and fastest passes' over pow's
/// rate (`2.48x (2.40-2.48)`).
pub(super) fn spread_versus_pow(rate: f64, spread: Option<[f64; 2]>, pow_rate: f64) -> String {
    match spread {
        Some([low, high]) if pow_rate > 0.0 && pow_rate.is_finite() => format!(
            "{} ({:.2}-{:.2})",
            versus_pow(rate, pow_rate),
            low / pow_rate,
            high / pow_rate
        ),
        _ => versus_pow(rate, pow_rate),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::args::parse_percent;

    #[test]
    fn reversed_ranges_are_refused_and_errors_are_percentages() {
        // How a range is sampled is the library's, tested there.
        assert!(parse_exponents("512..8").is_err());
        assert!(parse_percent("0").is_err() && parse_percent("-1%").is_err());
        assert!(parse_percent("NaN").is_err());
        assert_eq!(parse_percent("1%"), Ok(0.01));
    }
}
