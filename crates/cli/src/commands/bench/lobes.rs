//! `specula bench lobes`: every lobe's explicit SIMD kernel against its bound (the machine's
//! measured peaks and the instructions the kernel executes), its plain loop, `powf` and the
//! fast pow, with its error, all from one run: `specula_decide::rates::measure`, printed.

use indicatif::{ProgressBar, ProgressStyle};
use serde::Serialize;
use specula::simd::tally::{Class, Instructions};
use specula::{Exponent, LobeKind};
use specula_decide::c_twins::{self, CTwins};
use specula_decide::rates::{cosquad_formula, measure, LobeRate, Measured, L1_SIZE, STREAM_SIZE};

use crate::args::OutputFormat;
use crate::output::{number, percent, sig, Table};

/// Measures and prints.
pub fn run(n: Exponent, format: OutputFormat) -> Result<(), String> {
    let progress = ProgressBar::new(1).with_style(
        ProgressStyle::with_template("measuring {bar:30} {pos}/{len} {msg}")
            .unwrap_or_else(|_| ProgressStyle::default_bar()),
    );
    let measured = measure(n, true, &progress);
    let cc = std::env::var("CC").unwrap_or_else(|_| "gcc".into());
    let twins = c_twins::measure(n, &cc)
        .inspect_err(|error| eprintln!("no C twins: {error}"))
        .ok();
    let over: Vec<&LobeRate> = measured
        .lobes
        .iter()
        .filter(|r| r.of_bound() > 1.0)
        .collect();
    for rate in &over {
        eprintln!(
            "MODEL ERROR: {} runs at {} of its bound ({}): a peak was measured too low or a \
             resource is missing from the model (crates/specula/src/simd/cost.rs)",
            rate.lobe,
            percent(rate.of_bound()),
            rate.bound.limit
        );
    }
    if let Some(copy) = measured.copy_stream {
        for rate in &measured.lobes {
            let Some(stream) = rate.stream else { continue };
            if stream[1] > copy[1] {
                eprintln!(
                    "MODEL ERROR: {} streams at {} of copy: the copy peer measured low (memory \
                     bandwidth varies on a shared host; rerun on a quiet machine)",
                    rate.lobe,
                    percent(stream[1] / copy[1])
                );
            }
        }
    }
    if format == OutputFormat::Json {
        return super::super::print_json(&WithTwins {
            measured: &measured,
            c_twins: twins.as_ref(),
        });
    }
    if format == OutputFormat::Csv {
        // Data alone on stdout: the machine's notes go to stderr, the C twins to JSON.
        eprintln!("{}", peaks_line(&measured));
        print_csv(&measured);
        return Ok(());
    }
    println!("{}", peaks_line(&measured));
    let g = |rate: f64| format!("{:.2}", rate / 1e9);
    let table = lobe_table(&measured, Figure::shown, |column| column.table);
    println!(
        "lobes at n = {}: {L1_SIZE} cosines in L1 on one thread unless stated; streaming {} Mi \
         cosines; level {}; powf (libm) {} G/s; copy streaming 1T / all {} G floats/s",
        measured.n,
        STREAM_SIZE >> 20,
        measured.level.name(),
        g(measured.powf),
        measured
            .copy_stream
            .map_or("-".into(), |c| format!("{} / {}", g(c[0]), g(c[1]))),
    );
    table.print(format);
    let rate_of = |kind: LobeKind| {
        measured
            .lobes
            .iter()
            .find(|r| r.lobe == kind.to_string())
            .map_or(f64::NAN, |r| r.explicit)
    };
    if let Some(formula) = cosquad_formula() {
        let (mine, built_in) = (rate_of(formula), rate_of(LobeKind::CosQuad { v: 4 }));
        println!(
            "cosquad written as a formula ({formula}, docs/lobes/k4.toml) runs at {} of the \
             built-in cosquad's kernel (the user-lobe floor is 50 %)",
            percent(mine / built_in)
        );
    }
    if let Some(twins) = &twins {
        print_twins(&measured, twins, format);
    }
    Ok(())
}

/// `bench lobes --format json`: the run, and the C twins measured in it.
#[derive(Serialize)]
struct WithTwins<'a> {
    #[serde(flatten)]
    measured: &'a Measured,
    c_twins: Option<&'a CTwins>,
}

fn print_twins(measured: &Measured, twins: &CTwins, format: OutputFormat) {
    println!(
        "C twins: the same formulas as plain C loops ({}, {}; libmvec for exp and log), one \
         thread, the same cosines in L1",
        twins.compiler, twins.flags
    );
    let mut table = Table::new(&[
        "lobe",
        "specula G/s",
        "C G/s",
        "specula / C",
        "max rel difference",
    ]);
    for twin in &twins.twins {
        let mine = measured
            .lobes
            .iter()
            .find(|r| r.lobe == twin.lobe)
            .map_or(f64::NAN, |r| r.explicit);
        table.push(vec![
            twin.lobe.clone(),
            format!("{:.2}", mine / 1e9),
            format!("{:.2}", twin.rate / 1e9),
            format!("{:.2}x", mine / twin.rate),
            format!("{:.2e}", twin.max_rel_difference),
        ]);
    }
    table.print(format);
}

/// `bench lobes --format csv`: one row a lobe, every figure a number with all its digits, the
/// unit in its column's name (ratios as multiples, shares in %).
fn print_csv(measured: &Measured) {
    lobe_table(measured, Figure::data, |column| column.csv).print(OutputFormat::Csv);
}

/// A figure of a lobe's row, in the unit it is measured in.
enum Figure {
    /// Evaluations per second.
    Rate(f64),
    /// A fraction of a whole.
    Share(f64),
    /// A multiple of another rate.
    Times(f64),
    /// The kernel's instructions per vector.
    Instructions(Instructions),
    /// Words.
    Text(String),
}

impl Figure {
    /// As the table shows it: G/s to two places, shares in %, multiples with an x, the
    /// instructions with their classes.
    fn shown(&self) -> String {
        match self {
            Figure::Rate(rate) => format!("{:.2}", rate / 1e9),
            Figure::Share(share) => percent(*share),
            Figure::Times(times) => format!("{times:.2}x"),
            Figure::Instructions(count) => format!("{} ({count})", count.total()),
            Figure::Text(text) => text.clone(),
        }
    }

    /// As CSV holds it: every digit, in the unit its header names (G evaluations/s, %, a
    /// multiple, a count).
    fn data(&self) -> String {
        match self {
            Figure::Rate(rate) => number(rate / 1e9),
            Figure::Share(share) => number(100.0 * share),
            Figure::Times(times) => number(*times),
            Figure::Instructions(count) => count.total().to_string(),
            Figure::Text(text) => text.clone(),
        }
    }
}

/// A column of the lobes' table: its header in the table and in CSV, and its figure.
struct Column {
    table: &'static str,
    csv: &'static str,
    figure: fn(&Measured, &LobeRate) -> Figure,
}

/// Each lobe's figures, written once for both outputs.
const COLUMNS: [Column; 14] = [
    Column {
        table: "lobe",
        csv: "lobe",
        figure: |_, rate| Figure::Text(rate.lobe.clone()),
    },
    Column {
        table: "G/s",
        csv: "G evaluations/s",
        figure: |_, rate| Figure::Rate(rate.explicit),
    },
    Column {
        table: "bound G/s",
        csv: "bound (G evaluations/s)",
        figure: |_, rate| Figure::Rate(rate.bound.evals_per_second),
    },
    Column {
        table: "of bound",
        csv: "of bound (%)",
        figure: |_, rate| Figure::Share(rate.of_bound()),
    },
    Column {
        table: "limited by",
        csv: "limited by",
        figure: |_, rate| Figure::Text(rate.bound.limit.to_string()),
    },
    Column {
        table: "instructions per vector",
        csv: "instructions per vector",
        figure: |_, rate| Figure::Instructions(rate.instructions),
    },
    Column {
        table: "plain loop G/s",
        csv: "plain loop (G evaluations/s)",
        figure: |_, rate| Figure::Rate(rate.plain),
    },
    Column {
        table: "vs plain",
        csv: "x the plain loop",
        figure: |_, rate| Figure::Times(rate.explicit / rate.plain),
    },
    Column {
        table: "vs powf",
        csv: "x powf",
        figure: |measured, rate| Figure::Times(rate.explicit / measured.powf),
    },
    Column {
        table: "vs fast pow",
        csv: "x the fast pow",
        figure: |measured, rate| Figure::Times(rate.explicit / measured.fast_pow()),
    },
    Column {
        table: "stream 1T G/s",
        csv: "streaming 1 thread (G evaluations/s)",
        figure: |_, rate| Figure::Rate(rate.stream.map_or(f64::NAN, |s| s[0])),
    },
    Column {
        table: "stream all G/s",
        csv: "streaming all threads (G evaluations/s)",
        figure: |_, rate| Figure::Rate(rate.stream.map_or(f64::NAN, |s| s[1])),
    },
    Column {
        table: "of copy (all)",
        csv: "of copy, all threads (%)",
        figure: |measured, rate| {
            let copy_all = measured.copy_stream.map_or(f64::NAN, |c| c[1]);
            Figure::Share(rate.stream.map_or(f64::NAN, |s| s[1]) / copy_all)
        },
    },
    Column {
        table: "epicentre max rel",
        csv: "epicentre max rel (%)",
        figure: |_, rate| Figure::Share(rate.epicentre_max_rel),
    },
];

/// The lobes' table: `header` names each column, `write` each figure.
fn lobe_table(
    measured: &Measured,
    write: fn(&Figure) -> String,
    header: fn(&Column) -> &'static str,
) -> Table {
    let mut table = Table::new(&COLUMNS.each_ref().map(header));
    for rate in &measured.lobes {
        table.push(
            COLUMNS
                .iter()
                .map(|column| write(&(column.figure)(measured, rate)))
                .collect(),
        );
    }
    table
}

fn peaks_line(measured: &Measured) -> String {
    let lanes = measured.level.lanes() as f64;
    let peaks = &measured.peaks;
    let mut parts: Vec<String> = Class::ALL
        .iter()
        .filter_map(|&class| {
            peaks
                .of(class)
                .map(|p| format!("{} {}", class.name(), sig(p / 1e9)))
        })
        .collect();
    parts.push(format!("dispatch {}", sig(peaks.dispatch / 1e9)));
    parts.push(format!("L1 copy {}", sig(peaks.copy / 1e9)));
    format!(
        "measured peaks, G vector instructions/s on one thread ({} lanes each; compares count \
            against dispatch): {}",
        lanes,
        parts.join(", ")
    )
}
