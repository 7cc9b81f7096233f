//! The report's analysis sections: models, lobe shapes, errors, claims and cost (energy
//! and reciprocity are `energy.rs`). Every figure is computed here, during the run.

use rayon::prelude::*;
use specula::analysis::{error_figures, error_figures_on, ErrorFigures, Precision, ZoneSamples};
use specula::claims::{ClaimOptions, Verdict};
use specula::zones::{bloom_angle, epicentre_angle};
use specula::{Exponent, Lobe, LobeKind};
use specula_synth::OnMiss;

use super::html::{escape, multiples, paragraph, table};
use super::plot::{Chart, Series, LEGEND_WIDTH, SEQUENCE};
use super::{prose, Context, RealScanSizes, Sizes};
use crate::format::sig;

/// The plotting area of a small multiple, displayed pixels: with its legend, two to a row at
/// their own size in the page's column at 1400 pixels (1112 wide).
const SMALL: (u32, u32) = (390, 300);

/// Chooses one figure.
type Pick = fn(&ErrorFigures) -> f64;

/// Exponents from 1 to 1000, log-spaced, `steps + 1` of them.
pub(crate) fn exponents(steps: usize) -> Vec<Exponent> {
    (0..=steps)
        .map(|k| Exponent::new(1000f64.powf(k as f64 / steps as f64).clamp(1.0, 1000.0)))
        .collect()
}

/// The lobe's colour, the same in every plot and in the explorer (`LobeKind::line_style`).
pub(crate) fn colour(kind: LobeKind) -> plotters::style::RGBColor {
    let [r, g, b] = kind.line_style().rgb;
    plotters::style::RGBColor(r, g, b)
}

pub(crate) fn series(kind: LobeKind, points: Vec<(f64, f64)>) -> Series {
    Series {
        name: kind.to_string(),
        points,
        colour: colour(kind),
        width: if kind == LobeKind::Pow { 3 } else { 2 },
        markers: false,
        dashed: kind.line_style().dashed,
    }
}

pub fn models(context: &mut Context) -> Result<String, String> {
    let n = Exponent::new(100.0);
    let rows: Vec<Vec<String>> = context
        .lobes
        .iter()
        .map(|&kind| {
            let info = kind.info();
            let params = info
                .params
                .iter()
                .map(|p| {
                    format!(
                        "{} (default {}, {}..{}): {}",
                        p.name, p.default, p.min, p.max, p.description
                    )
                })
                .collect::<Vec<_>>()
                .join("; ");
            let ops = Lobe::new(kind, n).ops();
            vec![
                info.id.to_owned(),
                info.origin.name().to_owned(),
                info.formula.to_owned(),
                if params.is_empty() {
                    "n".to_owned()
                } else {
                    format!("n; {params}")
                },
                ops.to_string(),
                ops.total().to_string(),
            ]
        })
        .collect();
    Ok(paragraph(
        "Every lobe approximates t^n, t the cosine of the angle g to the lobe's axis (R.V \
        for Phong, N.H for Blinn). Operation counts are measured by running each formula on a \
        counting number type at n = 100.",
    ) + &table(
        &[
            "id",
            "origin",
            "formula",
            "parameters",
            "operations",
            "total",
        ],
        &rows,
    ))
}

pub fn shapes(context: &mut Context) -> Result<String, String> {
    let html = paragraph(
        "Each lobe against cos^n over the angle; the epicentre (t^n >= 1/2) and \
        bloom (t^n >= 1/256) zones are shaded. The log-scale variant beside each shows the tail.",
    );
    let mut figures = String::new();
    for n in [2.0, 8.0, 32.0, 128.0, 512.0] {
        let exponent = Exponent::new(n);
        let (epicentre, bloom) = (
            epicentre_angle(exponent).to_degrees(),
            bloom_angle(exponent).to_degrees(),
        );
        let right = (2.0 * bloom).min(90.0);
        let curves: Vec<Series> = context
            .lobes
            .iter()
            .map(|&kind| {
                let lobe = Lobe::new(kind, exponent);
                let points = (0..=400)
                    .map(|i| {
                        let g = right * f64::from(i) / 400.0;
                        (g, lobe.eval(g.to_radians().cos()))
                    })
                    .collect();
                series(kind, points)
            })
            .collect();
        for log_y in [false, true] {
            let chart = Chart {
                title: format!(
                    "lobes at n = {n}{}",
                    if log_y { " (log scale)" } else { "" }
                ),
                x_label: "angle from the lobe's axis (degrees)".into(),
                y_label: "lobe value".into(),
                x: (0.0, right),
                y: if log_y { (1e-4, 1.0) } else { (0.0, 1.05) },
                log_y,
                series: curves.clone(),
                bands: vec![
                    (
                        0.0,
                        epicentre,
                        plotters::style::RGBColor(255, 80, 0),
                        "epicentre",
                    ),
                    (
                        epicentre,
                        bloom,
                        plotters::style::RGBColor(0, 90, 255),
                        "bloom",
                    ),
                ],
                ..Chart::default()
            };
            let name = format!("shape-n{n}{}.svg", if log_y { "-log" } else { "" });
            figures += &context.svg_sized(
                &name,
                &chart,
                &if log_y {
                    format!(
                        "lobes at n = {n}, log scale: look at the tail, where a lobe that \
                        falls too slowly (schlick, sg) or stops short (the quadratics) shows"
                    )
                } else {
                    format!(
                        "lobes at n = {n}: look at the epicentre (shaded first), where a lobe \
                        that departs from pow changes the highlight's core"
                    )
                },
                SMALL,
            )?;
        }
    }
    Ok(html + &multiples(&figures, SMALL.0 + LEGEND_WIDTH))
}

/// The section, or a run's of this build on the same lobes: its curves are functions of
/// those alone ([`stored`](super::stored)).
pub fn errors(context: &mut Context) -> Result<String, String> {
    super::stored::section(context, super::ERRORS, "", error_curves)
}

fn error_curves(context: &mut Context) -> Result<String, String> {
    let mut html = paragraph(
        "Signed error lobe - t^n against the angle, scaled by the bloom's \
        edge so that every n fits one axis, for n = 8, 64 and 512: one small chart per lobe, each \
        on its own vertical scale. An error that keeps its shape across n is the model's; one that \
        grows with n is its approximation breaking down.",
    );
    let mut figures = String::new();
    for kind in context
        .lobes
        .clone()
        .into_iter()
        .filter(|&k| k != LobeKind::Pow)
    {
        let mut low: f64 = -1e-3;
        let mut high: f64 = 1e-3;
        let curves: Vec<Series> = [8.0, 64.0, 512.0]
            .iter()
            .enumerate()
            .map(|(k, &n)| {
                let exponent = Exponent::new(n);
                let (lobe, edge) = (Lobe::new(kind, exponent), bloom_angle(exponent));
                let points: Vec<(f64, f64)> = (0..=400)
                    .map(|i| {
                        let x = 1.5 * f64::from(i) / 400.0;
                        let t = (x * edge).min(core::f64::consts::FRAC_PI_2).cos();
                        (x, lobe.eval(t) - t.powf(n))
                    })
                    .collect();
                for &(_, e) in &points {
                    low = low.min(e);
                    high = high.max(e);
                }
                Series {
                    name: format!("n = {n}"),
                    points,
                    colour: SEQUENCE[k % SEQUENCE.len()],
                    width: 1,
                    markers: false,
                    dashed: false,
                }
            })
            .collect();
        let pad = 0.05 * (high - low);
        let chart = Chart {
            title: format!("{kind}: error against the angle"),
            x_label: "angle / bloom edge".into(),
            y_label: "lobe - t^n".into(),
            x: (0.0, 1.5),
            y: (low - pad, high + pad),
            series: curves,
            ..Chart::default()
        };
        figures += &context.svg_sized(
            &format!("error-angle-{}.svg", kind.id()),
            &chart,
            &format!("{kind}: one curve per n"),
            (SMALL.0, 280),
        )?;
    }
    html += &multiples(&figures, SMALL.0 + LEGEND_WIDTH);
    let sizes = context.sizes.clone();
    let grid = exponents(sizes.n_steps);
    let kinds: Vec<LobeKind> = context
        .lobes
        .iter()
        .copied()
        .filter(|&k| k != LobeKind::Pow)
        .collect();
    // Each exponent's zone samples (the cosines and pow there) taken once, for every lobe.
    let by_exponent: Vec<Vec<ErrorFigures>> = grid
        .par_iter()
        .map(|&n| {
            let samples = ZoneSamples::new(n, sizes.samples_per_zone);
            kinds
                .iter()
                .map(|&kind| error_figures_on(&Lobe::new(kind, n), &mut Precision::F64, &samples))
                .collect()
        })
        .collect();
    let figures: Vec<Vec<(f64, ErrorFigures)>> = (0..kinds.len())
        .map(|k| {
            grid.iter()
                .zip(&by_exponent)
                .map(|(n, at_n)| (n.get(), at_n[k]))
                .collect()
        })
        .collect();
    html += &paragraph(&format!(
        "The figures of SPEC section 4 against n (log axis, {} exponents \
        from 1 to 1000, {} samples per zone).",
        grid.len(),
        sizes.samples_per_zone
    ));
    let zone_charts: [(&str, &str, Pick); 4] = [
        (
            "epicentre max relative error",
            "error-n-epicentre.svg",
            |f| f.epicentre_max_rel,
        ),
        ("bloom max absolute error", "error-n-bloom.svg", |f| {
            f.bloom_max_abs
        }),
        ("tail max absolute error", "error-n-tail.svg", |f| {
            f.tail_max_abs
        }),
        ("RMS error over the visible lobe", "error-n-rms.svg", |f| {
            f.rms
        }),
    ];
    for (title, file, pick) in zone_charts {
        let curves = kinds
            .iter()
            .zip(&figures)
            .map(|(&kind, rows)| {
                series(
                    kind,
                    rows.iter().map(|(n, f)| (*n, pick(f).max(1e-9))).collect(),
                )
            })
            .collect();
        let chart = Chart {
            title: title.to_owned(),
            x_label: "n".into(),
            y_label: title.to_owned(),
            x: (1.0, 1000.0),
            y: (1e-9, 2.0),
            log_x: true,
            log_y: true,
            series: curves,
            legend_below: true,
            ..Chart::default()
        };
        let caption = format!(
            "{title} against n for every lobe: flat lines are errors that hold \
            at every n; rising ones grow with the exponent"
        );
        html += &context.svg(file, &chart, &caption)?;
    }
    let rows: Vec<Vec<String>> = kinds
        .iter()
        .zip(&figures)
        .map(|(kind, rows)| {
            let max = |pick: fn(&ErrorFigures) -> f64| {
                rows.iter().map(|(_, f)| pick(f)).fold(0.0, f64::max)
            };
            vec![
                kind.to_string(),
                format!("{:.3}%", 100.0 * max(|f| f.epicentre_max_rel)),
                sig(max(|f| f.bloom_max_abs)),
                sig(max(|f| f.tail_max_abs)),
                sig(max(|f| f.rms)),
            ]
        })
        .collect();
    html += &paragraph("The worst over every exponent:");
    html += &table(
        &[
            "lobe",
            "epicentre max rel",
            "bloom max abs",
            "tail max abs",
            "RMS",
        ],
        &rows,
    );
    Ok(html)
}

pub fn claims(context: &mut Context) -> Result<String, String> {
    let options = context.sizes.claims.clone();
    let results = specula_decide::analyses::claims(&options);
    let mut html = format!(
        "<p>Each claim of SPEC section 9, tested over {} exponents from 1 to 1000; thresholds come \
            from the claims' own \
            words.</p>\n<table><thead><tr><th>claim</th><th>verdict</th><th>measured</th><th>readin\
            g</th></tr></thead><tbody>",
        options.exponents.len()
    );
    for result in &results {
        let class = match result.verdict {
            Verdict::Holds => "holds",
            Verdict::HoldsWithQualification => "qualified",
            Verdict::DoesNotHold => "fails",
        };
        html += &format!(
            "<tr><td>{}</td><td class=\"{class}\">{}</td><td>{}</td><td>{}</td></tr>",
            escape(result.claim),
            escape(result.verdict.name()),
            escape(&result.measured),
            escape(&result.reading)
        );
    }
    html += "</tbody></table>\n";
    let figure_rows: Vec<Vec<String>> = results
        .iter()
        .flat_map(|r| {
            r.figures.iter().map(move |f| {
                vec![
                    r.claim.split(' ').next().unwrap_or_default().to_owned(),
                    f.name.clone(),
                    sig(f.value),
                ]
            })
        })
        .collect();
    html += &paragraph("The figures behind the verdicts:");
    html += &table(&["claim", "figure", "value"], &figure_rows);
    html += &super::yours::claims_figures(context);
    Ok(html)
}

/// The cost section's heading.
pub const COST: &str = "Cost";

pub fn cost(context: &mut Context) -> Result<String, String> {
    let n = Exponent::new(64.0);
    let measured = context
        .bench
        .then(|| specula_decide::rates::measure(n, false, &indicatif::ProgressBar::hidden()));
    let mut rows = Vec::new();
    let mut points = Vec::new();
    let pow = Lobe::new(LobeKind::Pow, n);
    let pow_instructions = pow.batch_instructions().total();
    // Each vendor's current generation, costed as `recommend` costs it: from the machine code
    // its compiler writes (the model where the compiler is missing, which the unit says).
    let gpu_targets = specula_decide::Target::GPUS;
    // Each target's rates for pow and every lobe, compiled in one batch per compiler.
    let costed: Vec<Lobe> = std::iter::once(pow)
        .chain(context.lobes.iter().map(|&kind| Lobe::new(kind, n)))
        .collect();
    let gpu_rates = gpu_targets
        .iter()
        .map(|&target| specula_decide::lobe_rates(target, &costed))
        .collect::<Result<Vec<Vec<f64>>, String>>()?;
    let pow_rates: Vec<f64> = gpu_rates.iter().map(|rates| rates[0]).collect();
    for (index, kind) in context.lobes.clone().into_iter().enumerate() {
        let lobe = Lobe::new(kind, n);
        let error = error_figures(&lobe, &mut Precision::F64, context.sizes.samples_per_zone)
            .epicentre_max_rel;
        let instructions = lobe.batch_instructions();
        let mut row = vec![
            kind.to_string(),
            format!("{:.3}%", 100.0 * error),
            format!(
                "{:.2}x",
                f64::from(pow_instructions) / f64::from(instructions.total().max(1))
            ),
        ];
        for (rates, pow_rate) in gpu_rates.iter().zip(&pow_rates) {
            let rate = rates[index + 1];
            row.push(format!("{:.2}x ({rate:.2})", rate / pow_rate));
        }
        row.push(format!("{} ({instructions})", instructions.total()));
        if let Some(measured) = &measured {
            // The measured lobes are the built-in ones and K4's formula: a lobe of the
            // user's is found by its id or shown unmeasured.
            let id = kind.to_string();
            match measured.lobes.iter().find(|rate| rate.lobe == id) {
                Some(rate) => {
                    row.extend([
                        format!("{:.2}", rate.explicit / 1e9),
                        format!("{:.0}% ({})", 100.0 * rate.of_bound(), rate.bound.limit),
                        format!("{:.1}x", rate.explicit / measured.powf),
                    ]);
                    points.push((kind, 1e9 / rate.explicit, error.max(1e-7)));
                }
                None => row.extend(["not measured".to_owned(), "-".to_owned(), "-".to_owned()]),
            }
        }
        rows.push(row);
    }
    let gpu_headers: Vec<String> = gpu_targets
        .iter()
        .map(|&target| {
            let gpu = target.gpu(None).ok().flatten();
            format!(
                "{} {}: x pow's throughput ({})",
                gpu.map_or("", |g| g.vendor.name()),
                gpu.map_or("", |g| g.id),
                specula_decide::rate_unit(target)
            )
        })
        .collect();
    let mut header = vec![
        "lobe",
        "epicentre max rel error (n = 64)",
        "CPU, counted: x pow's throughput (SIMD instructions)",
    ];
    header.extend(gpu_headers.iter().map(String::as_str));
    header.push("SIMD instructions per 8 lanes (counted from the kernel)");
    let mut html = paragraph(&prose::fill(prose::COST, &[])?);
    if let Some(measured) = &measured {
        header.extend([
            "CPU, measured: G evaluations/s (one thread, L1)",
            "CPU, measured: of its bound",
            "CPU, measured: x powf's throughput",
        ]);
        html += &paragraph(&format!(
            "CPU, measured: timed on this machine, as specula recommend --target cpu times it \
             ({}; the bound is the fastest the kernel's instructions could run at the machine's \
             measured per-instruction peaks, see `specula bench lobes`); powf (libm) runs at \
             {:.2} G/s.",
            measured.level.name(),
            measured.powf / 1e9
        ));
        let right = points.iter().map(|p| p.1).fold(0.0, f64::max) * 1.1;
        let chart = Chart {
            title: "error against speed (n = 64): lower left is better".into(),
            x_label: "ns per evaluation (explicit SIMD kernel, one thread)".into(),
            y_label: "epicentre max relative error".into(),
            x: (0.0, right),
            y: (1e-7, 1.0),
            log_y: true,
            series: points
                .iter()
                .map(|&(kind, ns, error)| Series {
                    markers: true,
                    ..series(kind, vec![(ns, error)])
                })
                .collect(),
            legend_below: true,
            ..Chart::default()
        };
        html += &context.svg(
            "pareto.svg",
            &chart,
            "error against time per evaluation: lower left \
            is better; a lobe below and left of another beats it on both",
        )?;
    } else {
        html += &paragraph(
            "Run `specula report --bench` to add measured throughput, each kernel's \
            share of its bound and the error-against-speed plot.",
        );
    }
    Ok(table(&header, &rows) + &html)
}

/// Sizes for `--quick` and the default.
pub fn sizes(quick: bool) -> Sizes {
    if quick {
        Sizes {
            n_steps: 12,
            samples_per_zone: 2_001,
            reciprocity_pairs: 2_000,
            claims: ClaimOptions {
                exponents: specula::claims::claim_exponents(12),
                samples_per_zone: 5_001,
                reciprocity_pairs: 10_000,
                ..ClaimOptions::default()
            },
            render: (240, 135, 1),
            environment: (240, 135, 16),
            materials: (160, 16),
            volume: (32, 96, 1),
            real_scans: RealScanSizes {
                side: 64,
                frames: 1,
                every_lobe: false,
                every_scan_against_vtk: false,
            },
            hardware_exponents: &[64],
            synthesis: OnMiss::Skip,
            design_bounds: &[0.001],
        }
    } else {
        Sizes {
            n_steps: 40,
            samples_per_zone: 20_001,
            reciprocity_pairs: 20_000,
            claims: ClaimOptions::default(),
            render: (480, 270, 2),
            environment: (480, 270, 64),
            materials: (480, 64),
            volume: (64, 192, 2),
            real_scans: RealScanSizes {
                side: 128,
                frames: 3,
                every_lobe: true,
                every_scan_against_vtk: true,
            },
            hardware_exponents: &[8, 64, 512],
            synthesis: OnMiss::Synthesize,
            design_bounds: &[0.001, 0.005, 0.02],
        }
    }
}
