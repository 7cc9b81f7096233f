//! The report's hardware section: each datapath's error against word length beside its float
//! model, the smallest width that matches it, the resources there, and the block diagrams.

use std::sync::Arc;

use specula_hw::analysis::MEETS_TOLERANCE;
use specula_hw::{diagram, HwLobe, Resources, BITS};

use super::html::{linked_figure, paragraph, table};
use super::plot::{Chart, Series};
use super::prose;
use super::sections::colour;
use super::Context;
use specula_hw::analysis::WidthSweep;
use specula_synth::cache::Cache;
use specula_synth::claim::{self, CLAIM_N};
use specula_synth::OnMiss;

use specula_decide::fpga_estimate::logic_cells;

use crate::format::{percent, resource_cells, sig};

/// The word length the diagrams show.
const DIAGRAM_BITS: u32 = 16;

/// The arithmetic at one width, in one cell.
fn arithmetic(r: &Resources) -> String {
    let [multipliers, squarers, adders, dividers, ..] = resource_cells(r);
    format!("mul {multipliers}; sq {squarers}; add {adders}; div {dividers}")
}

/// Claim 8 by synthesis: every datapath at equal error, through Yosys and nextpnr (cached),
/// or, without the tools or a cached result, the formula estimate, labelled as such.
fn synthesized(
    context: &mut Context,
    all: &[(u32, Arc<Vec<WidthSweep>>)],
) -> Result<String, String> {
    let sweeps = all
        .iter()
        .find(|(n, _)| *n == CLAIM_N)
        .map(|(_, sweeps)| sweeps.as_slice())
        .ok_or_else(|| format!("the hardware sweeps lack n = {CLAIM_N}"))?;
    // A full report synthesizes the claim's designs, after its page is first written.
    let full = context.sizes.synthesis == OnMiss::Synthesize;
    let on_miss = if context.synthesize {
        context.sizes.synthesis
    } else {
        OnMiss::Skip
    };
    let claim = claim::evaluate(sweeps, Cache::default_location().as_ref(), on_miss, &|| {});
    let estimate = |lobe: HwLobe, bits: Option<u32>| -> String {
        let resources = bits.and_then(|bits| {
            sweeps
                .iter()
                .find(|sweep| sweep.lobe == lobe)?
                .rows
                .iter()
                .find(|row| row.bits == bits)
                .map(|row| row.resources.clone())
        });
        resources.map_or("-".to_owned(), |r| logic_cells(&r).to_string())
    };
    let mut html = format!("<h3>Claim {}</h3>\n", super::html::escape(claim::STATEMENT));
    let complete = claim.as_ref().ok().filter(|claim| {
        claim
            .designs
            .iter()
            .all(|design| design.bits.is_none() || design.synthesis.is_some())
    });
    let Some(claim) = complete else {
        let why = match &claim {
            Err(problem) => {
                context.machine_note(format!(
                    "The hardware claim's designs were not synthesized: {problem}."
                ));
                "the designs could not be synthesized here (see the notes on this machine)"
                    .to_owned()
            }
            Ok(claim)
                if full
                    && !context.synthesize
                    && specula_synth::ToolVersions::find(claim::CLAIM_TARGET).is_ok() =>
            {
                // A full report's first pass: synthesized after the page is written.
                let missing = claim
                    .designs
                    .iter()
                    .filter(|design| design.bits.is_some() && design.synthesis.is_none())
                    .count();
                context.pending_synthesis += missing;
                format!(
                    "still coming: {missing} designs are not in the synthesis cache yet, and \
                     specula report synthesizes them after writing this page, then writes it \
                     again"
                )
            }
            Ok(_) => "not every design is in the synthesis cache (a quick report does not \
                synthesize the claim; run the full report or `specula claims`)"
                .to_owned(),
        };
        let (target, designs) = claim::designs(sweeps);
        html += &paragraph(&format!(
            "Not measured: {why}. In its place, a fallback that is not a synthesis: the formula \
             estimate of LUT4 logic cells (crates/decide/src/fpga_estimate.rs) for each datapath \
             at the \
             smallest width reaching {} epicentre error at n = {CLAIM_N}.",
            percent(target)
        ));
        let rows: Vec<Vec<String>> = designs
            .iter()
            .map(|design| {
                vec![
                    design.lobe.id().to_owned(),
                    design
                        .bits
                        .map_or("not by 24".to_owned(), |b| b.to_string()),
                    estimate(design.lobe, design.bits),
                ]
            })
            .collect();
        html += &table(&["datapath", "W", "estimated logic cells (formula)"], &rows);
        return Ok(html);
    };
    html += &paragraph(&format!(
        "Verdict: {}. {}. Reading: {}.",
        claim.verdict.name(),
        claim.measured,
        claim.reading
    ));
    // The cost direction of the rest of the report: throughput per LUT as a multiple of pow's.
    let pow_cost = claim
        .designs
        .iter()
        .find(|design| design.lobe == HwLobe::Pow)
        .and_then(|design| design.synthesis.as_ref()?.logic_ns_per_result());
    let rows: Vec<Vec<String>> = claim
        .designs
        .iter()
        .map(|design| {
            let synthesis = design.synthesis.as_ref();
            let cell = |f: &dyn Fn(&specula_synth::Synthesis) -> String| {
                synthesis.map_or("-".to_owned(), f)
            };
            vec![
                design.lobe.id().to_owned(),
                design
                    .bits
                    .map_or("not by 24".to_owned(), |b| b.to_string()),
                design.epicentre_max_rel.map_or("-".to_owned(), percent),
                cell(&|s| s.cells.logic.to_string()),
                cell(&|s| s.cells.carry.to_string()),
                cell(&|s| s.cells.flip_flops.to_string()),
                cell(&|s| s.fmax_mhz.map_or("-".to_owned(), |f| format!("{f:.1}"))),
                cell(&|s| s.latency.to_string()),
                cell(&|s| {
                    s.logic_ns_per_result()
                        .map_or("-".to_owned(), |v| format!("{v:.0}"))
                }),
                cell(&|s| match (pow_cost, s.logic_ns_per_result()) {
                    (Some(pow), Some(own)) => format!("{:.2}x", pow / own),
                    _ => "-".to_owned(),
                }),
                estimate(design.lobe, design.bits),
            ]
        })
        .collect();
    html += &table(
        &[
            "datapath",
            "W",
            "epicentre max rel",
            "SB_LUT4",
            "SB_CARRY",
            "FF",
            "Fmax MHz",
            "latency",
            "LUT x ns/result",
            "x pow's throughput per LUT (higher is better)",
            "formula estimate (cells)",
        ],
        &rows,
    );
    Ok(html)
}

pub fn hardware(context: &mut Context) -> Result<String, String> {
    let all = context.hardware_sweeps()?;
    let mut html = paragraph(&prose::fill(
        prose::HARDWARE,
        &[("tolerance", &MEETS_TOLERANCE)],
    )?);
    let mut rows = Vec::new();
    for (n, results) in &all {
        let series: Vec<Series> = results
            .iter()
            .map(|result| Series {
                name: result.lobe.id().to_owned(),
                points: result
                    .rows
                    .iter()
                    .map(|row| (f64::from(row.bits), row.errors.epicentre_max_rel.max(1e-6)))
                    .collect(),
                colour: colour(result.lobe.float_kind()),
                width: 2,
                markers: false,
                // Mitchell's log2 shares logexp's float model, and so its colour.
                dashed: result.lobe == HwLobe::LogExpMitchell
                    || result.lobe.float_kind().line_style().dashed,
            })
            .collect();
        let chart = Chart {
            title: format!("epicentre max relative error against word length, n = {n}"),
            x_label: "word length W (bits)".into(),
            y_label: "epicentre max rel error".into(),
            x: (f64::from(*BITS.start()), f64::from(*BITS.end())),
            y: (1e-4, 1.0),
            log_y: true,
            series,
            ..Chart::default()
        };
        html += &context.svg(
            &format!("hardware-error-n{n}.svg"),
            &chart,
            &format!(
                "every datapath's epicentre error against its word length, n = {n}: where \
                each curve flattens, extra bits stop paying; the floor is the float model's own \
                error"
            ),
        )?;
        for result in results.iter() {
            let width = result.minimum_width();
            let at = width.and_then(|w| result.rows.iter().find(|row| row.bits == w));
            rows.push(vec![
                result.lobe.id().to_owned(),
                n.to_string(),
                percent(result.float.epicentre_max_rel),
                width.map_or("not by 24".to_owned(), |w| w.to_string()),
                at.map_or("-".to_owned(), |row| percent(row.errors.epicentre_max_rel)),
                at.map_or("-".to_owned(), |row| sig(row.errors.bloom_max_abs)),
                at.map_or("-".to_owned(), |row| arithmetic(&row.resources)),
                at.map_or("-".to_owned(), |row| row.resources.rom_bits.to_string()),
                at.map_or("-".to_owned(), |row| row.resources.latency.to_string()),
            ]);
        }
    }
    html += &table(
        &[
            "datapath",
            "n",
            "f64 epicentre max rel",
            "smallest W meeting it",
            "epicentre max rel at W",
            "bloom max abs at W",
            "arithmetic at W",
            "ROM bits",
            "latency (cycles)",
        ],
        &rows,
    );
    html += &synthesized(context, &all)?;
    html += &paragraph(&format!(
        "The structural schemes, drawn from the same descriptions as the models and the Verilog, \
            at W = {DIAGRAM_BITS}: one column per pipeline stage."
    ));
    for lobe in HwLobe::ALL {
        let datapath = lobe.build(DIAGRAM_BITS).map_err(|e| e.to_string())?;
        let name = format!("hardware-{}.svg", lobe.id());
        let title = format!("{}: structural scheme at W = {DIAGRAM_BITS}", lobe.id());
        context.write(&name, diagram::svg(&datapath, &title).as_bytes())?;
        html += &linked_figure(&name, &title);
    }
    Ok(html)
}
