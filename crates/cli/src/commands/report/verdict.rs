//! The report's first section, "Which lobe when": for each GPU family of the cost model and the
//! FPGA estimate, the cheapest lobe within a few epicentre accuracies at a few exponents, and
//! for the GPUs the Pareto plot of error against modelled cost. The CPU's answer needs timing on a quiet machine, so it is
//! `specula recommend --target cpu` (and the cost section with `--bench`).

use specula::analysis::{error_figures, Precision};
use specula::{Exponent, Lobe, LobeKind};

use super::html::{paragraph, table};
use super::plot::{Chart, Series};
use super::sections::series;
use super::Context;
use specula::gpu_cost::{GpuFamily, ShaderOps};
use specula_gpu::shader_ops::lobe_shader_ops;

use crate::commands::recommend::{cheapest_datapath, pareto_front, ZoneChoice};

const FAMILIES: [(&str, &str); 2] = [("gpu-nvidia", "NVIDIA"), ("gpu-amd", "AMD RDNA")];
const EXPONENTS: [f64; 3] = [8.0, 64.0, 512.0];
const ACCURACIES: [f64; 3] = [0.005, 0.02, 0.10];
/// The exponent of the Pareto plots.
const PLOTTED: f64 = 64.0;
/// Where exact `pow` is drawn on the log axis.
const EXACT_FLOOR: f64 = 1e-6;

/// Every lobe at `n`: its epicentre error and its shader's instructions.
fn measure(
    lobes: &[LobeKind],
    n: f64,
    samples: usize,
) -> Result<Vec<(LobeKind, f64, ShaderOps)>, String> {
    lobes
        .iter()
        .copied()
        .map(|kind| {
            let lobe = Lobe::new(kind, Exponent::new(n));
            let error = error_figures(&lobe, &mut Precision::F64, samples).epicentre_max_rel;
            Ok((kind, error, lobe_shader_ops(&lobe)?))
        })
        .collect()
}

/// `(lobe, error, modelled rate)` on `family`.
fn points(
    measured: &[(LobeKind, f64, ShaderOps)],
    family: &str,
) -> Result<Vec<(LobeKind, f64, f64)>, String> {
    let family =
        GpuFamily::find(family).ok_or_else(|| format!("no GPU family '{family}' in the model"))?;
    Ok(measured
        .iter()
        .map(|(kind, error, ops)| (*kind, *error, family.cost(ops).evals_per_clock))
        .collect())
}

pub fn verdict(context: &mut Context) -> Result<String, String> {
    let samples = context.sizes.samples_per_zone;
    let mut html = paragraph(
        "The cheapest lobe whose epicentre error (largest relative error where t^n >= 1/2) \
         stays within each accuracy, by the GPU cost model: each lobe's exported shader, its \
         instructions counted and weighed by the vendor's published per-clock rates \
         (crates/specula/src/gpu_cost.rs). The ratio is its modelled rate over pow's. For \
         the CPU, run specula recommend --target cpu: its costs are measured.",
    );
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
    let by_n = EXPONENTS
        .into_iter()
        .map(|n| Ok((n, measure(&context.lobes, n, samples)?)))
        .collect::<Result<Vec<_>, String>>()?;
    let mut rows = Vec::new();
    for (id, name) in FAMILIES {
        for (n, at_n) in &by_n {
            let measured = points(at_n, id)?;
            let pow = measured
                .iter()
                .find(|p| p.0 == LobeKind::Pow)
                .map_or(f64::NAN, |p| p.2);
            let mut row = vec![name.to_owned(), n.to_string()];
            for bound in ACCURACIES {
                let best = measured.iter().filter(|p| p.1 <= bound).fold(
                    None::<&(LobeKind, f64, f64)>,
                    |best, p| match best {
                        Some(b) if b.2 >= p.2 => Some(b),
                        _ => Some(p),
                    },
                );
                row.push(best.map_or("-".to_owned(), |b| {
                    format!("{} ({:.2}x pow)", b.0, b.2 / pow)
                }));
            }
            rows.push(row);
        }
    }
    for (n, sweeps) in context.hardware_sweeps()? {
        let mut row = vec!["FPGA (estimated)".to_owned(), n.to_string()];
        for bound in ACCURACIES {
            let best = context
                .lobes
                .iter()
                .copied()
                .filter_map(|kind| cheapest_datapath(sweeps, kind, ZoneChoice::Epicentre, bound))
                .filter(|chosen| chosen.error <= bound)
                .min_by_key(|chosen| chosen.cells);
            row.push(best.map_or("-".to_owned(), |chosen| {
                format!(
                    "{} at {} bits ({} cells)",
                    chosen.lobe.id(),
                    chosen.bits,
                    chosen.cells
                )
            }));
        }
        rows.push(row);
    }
    html += &table(
        &["target", "n", "within 0.5 %", "within 2 %", "within 10 %"],
        &rows,
    );
    html += &paragraph(
        "FPGA rows: the fixed-point datapath with the fewest estimated logic cells (a LUT4 \
         fabric without DSPs, from its operators), each at the smallest word length whose \
         epicentre error is within the bound. A formula estimate, which undercounts what \
         Yosys builds about fourfold (the Hardware section has synthesized figures at equal \
         error); `specula recommend --target fpga` synthesizes. '-': no datapath meets it.",
    );
    let plotted_n = &by_n
        .iter()
        .find(|(n, _)| *n == PLOTTED)
        .ok_or("the plotted exponent is one of the table's")?
        .1;
    for (id, name) in FAMILIES {
        let measured = points(plotted_n, id)?;
        let plotted: Vec<(f64, f64)> = measured
            .iter()
            .map(|p| (p.1.max(EXACT_FLOOR), p.2))
            .collect();
        let on_front = pareto_front(&plotted);
        let mut front: Vec<(f64, f64)> = plotted
            .iter()
            .zip(&on_front)
            .filter(|(_, on)| **on)
            .map(|(p, _)| *p)
            .collect();
        front.sort_by(|a, b| a.0.total_cmp(&b.0));
        let mut series_list: Vec<Series> = measured
            .iter()
            .zip(&plotted)
            .map(|(p, &point)| Series {
                markers: true,
                ..series(p.0, vec![point])
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
        let most = plotted.iter().map(|p| p.1).fold(0.0, f64::max);
        let chart = Chart {
            title: format!("{name}: epicentre error against modelled cost, n = {PLOTTED}"),
            x_label: format!("epicentre max relative error (pow, exact, at {EXACT_FLOOR:e})"),
            y_label: "modelled evaluations per clock per multiprocessor".into(),
            // Room on the right, past any error, for the legend.
            x: (EXACT_FLOOR / 2.0, 1e3),
            y: (0.1, most * 2.0),
            log_x: true,
            log_y: true,
            series: series_list,
            bands: Vec::new(),
            legend_below: true,
        };
        html += &context.svg(
            &format!("verdict-{id}.svg"),
            &chart,
            &format!("{name}: error against cost, higher left is better; the grey line joins the Pareto front"),
        )?;
    }
    Ok(html)
}
