//! The report's first section, "Which lobe when": for each GPU vendor's current generation
//! (costed from the machine code its compiler writes) and the FPGA, the cheapest lobe within a
//! few epicentre accuracies at a few exponents, and for the GPUs the Pareto plot of error
//! against cost. Every cell is `specula recommend`'s
//! answer for its target, exponent and bound ([`specula_decide::recommend_each`]: `recommend`
//! at a row's three bounds, each lobe measured once, over the report's lobes), so the page and the
//! command cannot disagree. The CPU's answer needs timing
//! on a quiet machine, so it is `specula recommend --target cpu` (and the cost section with
//! `--bench`).

use indicatif::ProgressBar;
use rayon::prelude::*;
use specula::{Exponent, LobeKind};
use specula_decide::{
    recommend_each, recommend_each_cached, versus_pow, Recommendation, Request, Target,
};

use super::html::{paragraph, table};
use super::plot::{Chart, Series};
use super::prose;
use super::sections::series;
use super::Context;
use crate::format::sig;
use specula_decide::percent::percent;

/// Each GPU target, named by its vendor and the generation it is costed on (the vendor's
/// current one).
pub(crate) fn families() -> Vec<(Target, String)> {
    Target::GPUS
        .into_iter()
        .filter_map(|target| {
            let gpu = target.gpu(None).ok().flatten()?;
            Some((target, format!("{} {}", gpu.vendor.name(), gpu.id)))
        })
        .collect()
}
const EXPONENTS: [f64; 3] = [8.0, 64.0, 512.0];
const ACCURACIES: [f64; 3] = [0.005, 0.02, 0.10];
/// The exponent of the Pareto plots.
const PLOTTED: f64 = 64.0;
/// Where exact `pow` is drawn on the log axis.
pub(crate) const EXACT_FLOOR: f64 = 1e-6;

/// `specula recommend --target TARGET --n N --max-error BOUND` over the report's lobes, and
/// the designs still to synthesize where `synthesize` is off (the FPGA's answers are then the
/// formula estimate's until the cache holds what decides them).
fn answers(
    lobes: &[LobeKind],
    target: Target,
    n: f64,
    synthesize: bool,
) -> Result<(Vec<Recommendation>, usize), String> {
    let request = Request {
        lobes: lobes.to_vec(),
        ..Request::new(target, vec![Exponent::new(n)], ACCURACIES[0])
    };
    if synthesize {
        Ok((
            recommend_each(&request, &ACCURACIES, &ProgressBar::hidden())?,
            0,
        ))
    } else {
        recommend_each_cached(&request, &ACCURACIES, &ProgressBar::hidden())
    }
}

/// A GPU cell: the best lobe and its modelled rate over pow's, or `-`.
fn gpu_cell(answer: &Recommendation) -> String {
    answer.best_candidate().map_or("-".to_owned(), |best| {
        format!(
            "{} ({} pow's throughput)",
            best.lobe,
            versus_pow(best.rate, answer.pow_rate())
        )
    })
}

/// An FPGA cell: the best lobe's datapath at its word length, its rate and the rate's unit,
/// or `-`.
fn fpga_cell(answer: &Recommendation) -> String {
    answer.best_candidate().map_or("-".to_owned(), |best| {
        let named = match &best.datapath {
            // The datapath's id is the lobe's, or one of its variants (logexp-mitchell).
            Some(datapath) if datapath.starts_with(&format!("{} at ", best.lobe)) => {
                datapath.clone()
            }
            Some(datapath) => format!("{} as {datapath}", best.lobe),
            None => best.lobe.clone(),
        };
        format!("{named}: {} {}", sig(best.rate), answer.unit)
    })
}

/// Error against cost (in `unit`): a marker per lobe in its colour, the grey line through the
/// points flagged as the Pareto front, then `extra` series; log axes from the exact floor.
/// Errors come as fractions and are drawn in %, the tables' unit (`extra`'s too); the axis
/// ends a step past the largest error shown.
pub(crate) fn pareto_chart(
    title: String,
    points: &[(LobeKind, (f64, f64), bool)],
    extra: Vec<Series>,
    unit: &str,
) -> Chart {
    let percent = |(error, rate): (f64, f64)| (100.0 * error, rate);
    let mut front: Vec<(f64, f64)> = points
        .iter()
        .filter(|(_, _, on)| *on)
        .map(|&(_, p, _)| percent(p))
        .collect();
    front.sort_by(|a, b| a.0.total_cmp(&b.0));
    let mut series_list: Vec<Series> = points
        .iter()
        .map(|&(kind, point, _)| Series {
            markers: true,
            ..series(kind, vec![percent(point)])
        })
        .collect();
    series_list.push(Series {
        name: "Pareto front".into(),
        points: front,
        colour: plotters::style::RGBColor(150, 150, 150),
        width: 1,
        markers: false,
        dashed: false,
    });
    series_list.extend(extra.into_iter().map(|line| Series {
        points: line.points.into_iter().map(percent).collect(),
        ..line
    }));
    let most = points.iter().map(|p| p.1 .1).fold(0.0, f64::max);
    let widest = points.iter().map(|p| p.1 .0).fold(EXACT_FLOOR, f64::max);
    Chart {
        title,
        x_label: format!(
            "epicentre max relative error, % (pow, exact, at {:.0e} %)",
            100.0 * EXACT_FLOOR
        ),
        y_label: unit.to_owned(),
        // The legend stands beside the plot, so the axis ends just past the largest error.
        x: (50.0 * EXACT_FLOOR, 200.0 * widest),
        y: (0.1, most * 2.0),
        log_x: true,
        log_y: true,
        series: series_list,
        legend_below: true,
        ..Chart::default()
    }
}

pub fn verdict(context: &mut Context) -> Result<String, String> {
    let mut html = paragraph(&prose::fill(prose::VERDICT, &[])?);
    let yours: Vec<String> = context
        .lobes
        .iter()
        .filter(|kind| matches!(kind, LobeKind::Formula(_)))
        .map(LobeKind::to_string)
        .collect();
    if !yours.is_empty() {
        html += &paragraph(&format!(
            "Your lobes are candidates too: {}.",
            yours.join(", ")
        ));
    }
    let lobes = context.lobes.clone();
    // One row per GPU family and n, each lobe measured once for the row's bounds; the rows
    // in parallel. The FPGA's one after another, so that a design two rows share is
    // synthesized once and then read from the cache.
    let families = families();
    let gpu_rows: Vec<(Target, f64)> = families
        .iter()
        .flat_map(|&(target, _)| EXPONENTS.iter().map(move |&n| (target, n)))
        .collect();
    let hardware: Vec<u32> = context.sizes.hardware_exponents.to_vec();
    let synthesize = context.synthesize;
    let (gpu, fpga) = rayon::join(
        || {
            gpu_rows
                .par_iter()
                .map(|&(target, n)| Ok(answers(&lobes, target, n, false)?.0))
                .collect::<Result<Vec<_>, String>>()
        },
        || {
            hardware
                .iter()
                .map(|&n| answers(&lobes, Target::Fpga, f64::from(n), synthesize))
                .collect::<Result<Vec<_>, String>>()
        },
    );
    let gpu = gpu?;
    let (fpga, pending): (Vec<Vec<Recommendation>>, Vec<usize>) = fpga?.into_iter().unzip();
    let pending: usize = pending.iter().sum();
    context.pending_synthesis += pending;
    let gpu_answers = |target: Target, n: f64| {
        gpu_rows
            .iter()
            .position(|&row| row == (target, n))
            .map(|k| &gpu[k])
            .ok_or("every GPU row was answered")
    };
    let answer = answer(&families, &gpu_rows, &gpu, &hardware, &fpga)?;
    let mut rows = Vec::new();
    for (target, name) in &families {
        let target = *target;
        for n in EXPONENTS {
            let mut row = vec![name.clone(), n.to_string()];
            row.extend(gpu_answers(target, n)?.iter().map(gpu_cell));
            rows.push(row);
        }
    }
    for (n, answers) in hardware.iter().zip(&fpga) {
        let mut row = vec!["FPGA".to_owned(), n.to_string()];
        row.extend(answers.iter().map(fpga_cell));
        rows.push(row);
    }
    html += &table(
        &["target", "n", "within 0.5 %", "within 2 %", "within 10 %"],
        &rows,
    );
    // What each GPU row is read off: the compiler and generation, or the model and why.
    let bases: Vec<String> = families
        .iter()
        .filter_map(|&(target, _)| gpu_answers(target, EXPONENTS[0]).ok())
        .filter_map(|answers| answers[0].basis.clone())
        .collect();
    html += &paragraph(&format!(
        "The GPU rows are costed on {}.",
        bases.join("; on ")
    ));
    for note in gpu.iter().flatten().filter_map(|a| a.note.as_deref()) {
        context.machine_note(format!("GPU costs: {note}."));
    }
    html += &paragraph(&prose::fill(prose::FPGA_ROWS, &[])?);
    if pending > 0 {
        html += &paragraph(&format!(
            "Still coming: the FPGA rows above are the formula estimate, because the synthesis \
             that decides them was not in the cache when this page was written ({pending} or \
             more datapaths). specula report synthesizes them after writing the page, then \
             writes it again with the synthesized rows; an interrupted run keeps this page."
        ));
    }
    for note in fpga
        .iter()
        .flatten()
        .filter_map(|a| a.note.as_deref())
        .take(1)
    {
        context.machine_note(format!("FPGA costs: {note}."));
    }
    for (target, name) in &families {
        let target = *target;
        let plotted_answer = &gpu_answers(target, PLOTTED)?[0];
        let candidates: Vec<(LobeKind, &specula_decide::Candidate)> = context
            .lobes
            .iter()
            .filter_map(|&kind| {
                let id = kind.to_string();
                let candidate = plotted_answer.candidates.iter().find(|c| c.lobe == id)?;
                Some((kind, candidate))
            })
            .collect();
        let points: Vec<(LobeKind, (f64, f64), bool)> = candidates
            .iter()
            .map(|(kind, c)| (*kind, (c.error.max(EXACT_FLOOR), c.rate), c.pareto))
            .collect();
        let chart = pareto_chart(
            format!("{name}: epicentre error against cost, n = {PLOTTED}"),
            &points,
            Vec::new(),
            plotted_answer.unit,
        );
        html += &context.svg(
            &format!("verdict-{}.svg", target.id()),
            &chart,
            &format!(
                "{name}: error against cost, higher left is better; the grey line joins the \
                Pareto front"
            ),
        )?;
    }
    Ok(answer + &html)
}

/// The bound the answer box states.
const HEADLINE_BOUND: f64 = 0.02;

/// The section's lead: for each target and each exponent of the table, the cheapest lobe
/// within 2 % and the figure that decides it; the CPU's measured answer named, not guessed,
/// as the command that gives it over the table's exponents.
fn answer(
    families: &[(Target, String)],
    gpu_rows: &[(Target, f64)],
    gpu: &[Vec<Recommendation>],
    hardware: &[u32],
    fpga: &[Vec<Recommendation>],
) -> Result<String, String> {
    let bound = HEADLINE_BOUND;
    let column = ACCURACIES
        .iter()
        .position(|&a| a == bound)
        .ok_or("the headline bound is one of the table's")?;
    let within = format!("epicentre error within {}", percent(bound));
    let mut lines = Vec::new();
    for (target, name) in families {
        let target = *target;
        let mut unit = "";
        let cells = EXPONENTS
            .iter()
            .map(|&n| {
                let answer = gpu_rows
                    .iter()
                    .position(|&row| row == (target, n))
                    .map(|k| &gpu[k][column])
                    .ok_or("every exponent of the table has its row")?;
                unit = answer.unit;
                Ok(match answer.best_candidate() {
                    Some(best) => format!(
                        "n = {n}: {} ({} pow's throughput)",
                        best.lobe,
                        versus_pow(best.rate, answer.pow_rate())
                    ),
                    None => format!("n = {n}: no lobe meets it"),
                })
            })
            .collect::<Result<Vec<_>, String>>()?;
        lines.push(format!(
            "{name} ({within}; {unit}, higher is better): {}.",
            cells.join("; ")
        ));
    }
    let fpga_cells: Vec<String> = hardware
        .iter()
        .zip(fpga)
        .map(|(n, answers)| format!("n = {n}: {}", fpga_cell(&answers[column])))
        .collect();
    if !fpga_cells.is_empty() {
        lines.push(format!("FPGA ({within}): {}.", fpga_cells.join("; ")));
    }
    let (low, high) = (EXPONENTS[0], EXPONENTS[EXPONENTS.len() - 1]);
    lines.push(format!(
        "CPU: measured, not modelled, on the machine that will run it: specula recommend --target \
            cpu --n {low}..{high} --max-error {}",
        flag_percent(bound)
    ));
    Ok(super::html::answer(&lines))
}

/// A bound as the command line takes it (`2%`).
fn flag_percent(fraction: f64) -> String {
    format!("{}%", fraction * 100.0)
}
