//! `specula bench lobes`: batch (SIMD) lobe throughput against `powf`, a plain copy and the
//! machine's measured FMA limit, with each lobe's error, all from one run.

use std::hint::black_box;
use std::time::Instant;

use rayon::prelude::*;
use specula::analysis::{error_figures, Precision};
use specula::ops::OpCounts;
use specula::{Exponent, Lobe, LobeKind};

use crate::output::{sig, Table};

/// Elements of the L1-resident buffers (8 KiB in, 8 KiB out).
const L1_SIZE: usize = 2048;
/// Elements of the streaming buffers (128 MiB in, 128 MiB out).
const STREAM_SIZE: usize = 32 << 20;
/// Each L1 measurement runs at least this long.
const MIN_SECONDS: f64 = 0.05;

fn cosines(len: usize) -> Vec<f32> {
    (0..len)
        .map(|i| 1.0 - 0.2 * ((i % 4093) as f32 / 4093.0).powi(2))
        .collect()
}

/// Evaluations per second of `work` over an L1-sized buffer, on one thread.
fn l1_rate(work: &(dyn Fn(&[f32], &mut [f32]) + Sync)) -> f64 {
    let ts = cosines(L1_SIZE);
    let mut out = vec![0.0; L1_SIZE];
    let mut best = 0.0_f64;
    for _ in 0..3 {
        let started = Instant::now();
        let mut rounds = 0_u64;
        while started.elapsed().as_secs_f64() < MIN_SECONDS {
            work(black_box(&ts), black_box(&mut out));
            rounds += 1;
        }
        best = best.max(rounds as f64 * L1_SIZE as f64 / started.elapsed().as_secs_f64());
    }
    best
}

/// The same on every thread at once, each with its own buffers.
fn l1_rate_all(work: &(dyn Fn(&[f32], &mut [f32]) + Sync)) -> f64 {
    let threads = rayon::current_num_threads();
    let started = Instant::now();
    let rounds: u64 = (0..threads)
        .into_par_iter()
        .map(|_| {
            let ts = cosines(L1_SIZE);
            let mut out = vec![0.0; L1_SIZE];
            let begun = Instant::now();
            let mut rounds = 0_u64;
            while begun.elapsed().as_secs_f64() < 2.0 * MIN_SECONDS {
                work(black_box(&ts), black_box(&mut out));
                rounds += 1;
            }
            rounds
        })
        .sum();
    rounds as f64 * L1_SIZE as f64 / started.elapsed().as_secs_f64()
}

/// Evaluations per second streaming `ts` into `out` (best of two), on one or all threads.
fn stream_rate(
    ts: &[f32],
    out: &mut [f32],
    all: bool,
    work: &(dyn Fn(&[f32], &mut [f32]) + Sync),
) -> f64 {
    let chunk = if all {
        ts.len().div_ceil(rayon::current_num_threads())
    } else {
        ts.len()
    };
    (0..2)
        .map(|_| {
            let started = Instant::now();
            ts.par_chunks(chunk)
                .zip(out.par_chunks_mut(chunk))
                .for_each(|(t, o)| work(t, o));
            ts.len() as f64 / started.elapsed().as_secs_f64()
        })
        .fold(0.0, f64::max)
}

/// The machine's measured peak of independent `f32` fused multiply-adds per second on one
/// thread (8 chains per SIMD register file's worth of lanes: enough to cover FMA latency).
fn fma_peak() -> f64 {
    const LANES: usize = 256;
    const STEPS: usize = 200_000;
    let run = || {
        let mut acc = [1.0_f32; LANES];
        let (a, b) = (black_box(0.999_999_f32), black_box(1e-7_f32));
        for _ in 0..STEPS {
            for x in &mut acc {
                *x = x.mul_add(a, b);
            }
        }
        black_box(acc);
    };
    (0..3)
        .map(|_| {
            let started = Instant::now();
            pulp::Arch::new().dispatch(run);
            (LANES * STEPS) as f64 / started.elapsed().as_secs_f64()
        })
        .fold(0.0, f64::max)
}

/// An estimate of a lobe's vector-instruction cost per evaluation, in FMA slots: simple
/// operations 1; division 4 and square root 6 (their throughput on current x86 is a quarter to
/// a sixth of an FMA's); the batch path's `log2` 16, `exp2` 12 and `acos` 16 (the operations of
/// their polynomials, both `acos` branches included); `pow` is a `log2` and an `exp2`.
fn fma_slots(ops: &OpCounts) -> f64 {
    ops.entries()
        .iter()
        .map(|&(name, count)| {
            let weight = match name {
                "div" => 4.0,
                "sqrt" => 6.0,
                "log2" | "acos" => 16.0,
                "exp2" => 12.0,
                "pow" => 29.0,
                _ => 1.0,
            };
            weight * f64::from(count)
        })
        .sum()
}

struct Row {
    name: String,
    scalar: Option<f64>,
    l1: f64,
    l1_all: f64,
    stream: f64,
    stream_all: f64,
    slots: Option<f64>,
    errors: Option<(f64, f64)>,
}

/// Measures and prints.
pub fn run(n: Exponent) -> Result<(), String> {
    let threads = rayon::current_num_threads();
    let peak = fma_peak();
    println!(
        "lobes at n = {n}: {L1_SIZE} cosines in L1, {} Mi streaming; {threads} threads; measured FMA peak {:.1} G lane-ops/s per thread",
        STREAM_SIZE >> 20,
        peak / 1e9
    );
    let ts = cosines(STREAM_SIZE);
    let mut out = vec![0.0; STREAM_SIZE];
    let mut rows = Vec::new();
    let mut measure = |name: String,
                       scalar: Option<f64>,
                       slots,
                       errors,
                       work: &(dyn Fn(&[f32], &mut [f32]) + Sync)| {
        rows.push(Row {
            name,
            scalar,
            l1: l1_rate(work),
            l1_all: l1_rate_all(work),
            stream: stream_rate(&ts, &mut out, false, work),
            stream_all: stream_rate(&ts, &mut out, true, work),
            slots,
            errors,
        });
    };
    let pow_n = n.get() as f32;
    measure("copy (memory limit)".into(), None, None, None, &|t, o| {
        o.copy_from_slice(t)
    });
    let powf_errors = error_figures(&Lobe::new(LobeKind::Pow, n), &mut Precision::F32, 20_001);
    measure(
        "powf (libm, scalar)".into(),
        None,
        None,
        Some((powf_errors.epicentre_max_rel, powf_errors.bloom_max_abs)),
        &|t, o| o.iter_mut().zip(t).for_each(|(o, &t)| *o = t.powf(pow_n)),
    );
    for kind in LobeKind::ALL {
        let lobe = Lobe::new(kind, n);
        let scalar = l1_rate(&|t, o| o.iter_mut().zip(t).for_each(|(o, &t)| *o = lobe.eval(t)));
        let errors = error_figures(&lobe, &mut Precision::F32Simd, 20_001);
        let name = if kind == LobeKind::Pow {
            "pow (fast pow: exp2(n log2 t))".to_owned()
        } else {
            kind.to_string()
        };
        measure(
            name,
            Some(scalar),
            Some(fma_slots(&lobe.ops())),
            Some((errors.epicentre_max_rel, errors.bloom_max_abs)),
            &|t, o| lobe.eval_batch(t, o),
        );
    }
    let (copy, powf) = (rows[0].stream, rows[1].l1);
    let mut table = Table::new(&[
        "lobe",
        "scalar 1T",
        "SIMD 1T L1",
        "SIMD all L1",
        "SIMD 1T stream",
        "SIMD all stream",
        "vs powf (L1)",
        "vs copy (stream)",
        "FMA limit",
        "of limit",
        "epicentre max rel",
        "bloom max abs",
    ]);
    let rate = |r: f64| format!("{:.2}", r / 1e9);
    for row in &rows {
        let limit = row.slots.map(|slots| peak / slots);
        table.push(vec![
            row.name.clone(),
            row.scalar.map_or("-".into(), rate),
            rate(row.l1),
            rate(row.l1_all),
            rate(row.stream),
            rate(row.stream_all),
            format!("{:.1}x", row.l1 / powf),
            format!("{:.0}%", 100.0 * row.stream / copy),
            limit.map_or("-".into(), rate),
            limit.map_or("-".into(), |l| format!("{:.0}%", 100.0 * row.l1 / l)),
            row.errors
                .map_or("-".into(), |e| format!("{:.4}%", 100.0 * e.0)),
            row.errors.map_or("-".into(), |e| sig(e.1)),
        ]);
    }
    println!("rates in G evaluations/s (copy: G floats/s); FMA limit = measured peak / estimated FMA slots per evaluation");
    table.print(crate::args::Format::Table);
    Ok(())
}
