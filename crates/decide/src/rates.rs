//! This machine's lobe rates: every lobe's explicit SIMD kernel against its bound (the
//! machine's measured peaks and the instructions the kernel executes), its plain loop, `powf`
//! and the fast pow, with its error, all from one run ([`measure`]: `specula bench lobes`
//! prints it, the report's cost section shows it); the rates of lobes timed together
//! ([`kernel_rates`]), the CPU's costs in `recommend.rs`; and one kernel's rate
//! ([`kernel_rate`]), a material's verdict's.

use std::hint::black_box;
use std::time::Instant;

use indicatif::ProgressBar;
use rayon::prelude::*;
use serde::Serialize;
use specula::analysis::{error_figures, Precision};
use specula::simd::cost::{Bound, Peaks};
use specula::simd::tally::Instructions;
use specula::simd::{peak, BatchLoop, Level};
use specula::{Exponent, Lobe, LobeKind};

use crate::pinned::Pinned;

/// Elements of the L1-resident buffers (8 KiB in, 8 KiB out).
pub const L1_SIZE: usize = 2048;
/// Elements of the streaming buffers (128 MiB in, 128 MiB out).
pub const STREAM_SIZE: usize = 32 << 20;
/// Each L1 measurement runs at least this long.
pub(crate) const MIN_SECONDS: f64 = 0.05;
/// Rounds between two readings of the clock: a reading costs tens of nanoseconds on a
/// virtual machine, 15 % of a round of the fastest kernels if taken every round.
pub(crate) const ROUNDS_PER_CLOCK: u64 = 16;

/// One lobe's figures.
#[derive(Clone, Debug, Serialize)]
pub struct LobeRate {
    /// The lobe's id.
    pub lobe: String,
    /// What its kernel executes per vector.
    pub instructions: Instructions,
    /// Evaluations per second of the explicit kernel, L1, one thread.
    pub explicit: f64,
    /// The same for the plain loop of the same formula.
    pub plain: f64,
    /// The kernel's bound.
    pub bound: Bound,
    /// Streaming evaluations per second, one thread and all threads (when measured).
    pub stream: Option<[f64; 2]>,
    /// Epicentre max relative error of the batch path.
    pub epicentre_max_rel: f64,
}

impl LobeRate {
    /// The measured rate as a fraction of the bound.
    #[must_use]
    pub fn of_bound(&self) -> f64 {
        self.explicit / self.bound.evals_per_second
    }
}

/// A whole run.
#[derive(Clone, Debug, Serialize)]
pub struct Measured {
    /// The exponent.
    pub n: f64,
    /// Where the kernels ran.
    pub level: Level,
    /// Threads of the all-thread figures.
    pub threads: usize,
    /// The measured peaks.
    pub peaks: Peaks,
    /// `f32::powf` per element (libm), L1, one thread.
    pub powf: f64,
    /// Copy rate streaming, one thread and all (floats per second, when measured).
    pub copy_stream: Option<[f64; 2]>,
    /// Every lobe.
    pub lobes: Vec<LobeRate>,
}

impl Measured {
    /// The fast pow's explicit rate (the `pow` lobe's kernel).
    #[must_use]
    pub fn fast_pow(&self) -> f64 {
        self.lobes
            .iter()
            .find(|r| r.lobe == LobeKind::Pow.id())
            .map_or(f64::NAN, |r| r.explicit)
    }
}

/// The thesis's `K_4` written by hand as a formula (`docs/lobes/k4.toml`): the user lobe the
/// benchmark holds against the built-in `cosquad` it spells.
#[must_use]
pub fn cosquad_formula() -> Option<LobeKind> {
    let definition = specula_render::lobe_file::parse_definition(
        include_str!("../../../docs/lobes/k4.toml"),
        "docs/lobes/k4.toml",
    )
    .expect("docs/lobes/k4.toml is a lobe file");
    // Numbered if a lobe of the user's took its name; absent only if the registry is full.
    specula::formula::define(definition, specula::formula::Naming::Unique)
        .and_then(|formula| specula::formula::instance(formula, &[]))
        .ok()
}

pub(crate) fn cosines(len: usize) -> Vec<f32> {
    (0..len)
        .map(|i| 1.0 - 0.2 * ((i % 4093) as f32 / 4093.0).powi(2))
        .collect()
}

/// Evaluations per second of `lobe`'s SIMD kernel, L1-resident, one thread (best of 3).
#[must_use]
pub(crate) fn kernel_rate(lobe: &Lobe) -> f64 {
    let level = Level::detect();
    l1_rate(&|t: &[f32], o: &mut [f32]| {
        lobe.eval_batch_with(level, BatchLoop::Explicit, t, o);
    })
}

/// Passes of [`kernel_rates`] over every lobe.
pub const PASSES: usize = 9;
/// Seconds one lobe at one exponent is timed in one pass of [`kernel_rates`].
const PASS_SECONDS: f64 = 0.015;

/// The kernel rates of `lobes[i]` at each of its exponents in each pass (`[lobe][exponent]
/// [pass]`), L1-resident, one thread, timed so that lobes compare like with like on a machine
/// whose speed drifts (this project's shared virtual machine slows by up to 40 % for a second
/// or more at a time): in [`PASSES`] passes over every lobe, each pass timing each lobe at all
/// its exponents, on the CPU that was idlest when it began ([`Pinned`]). A slow spell then
/// costs a lobe one pass at the exponents it covered, every lobe is timed in every part of the
/// run, and the passes' spread says how far one rate can be told from another. `progress`
/// ticks once a pass per lobe.
#[must_use]
pub(crate) fn kernel_rates(lobes: &[Vec<Lobe>], progress: &ProgressBar) -> Vec<Vec<Vec<f64>>> {
    let level = Level::detect();
    let _pinned = Pinned::to_idlest_cpu();
    let mut passes: Vec<Vec<Vec<f64>>> = lobes
        .iter()
        .map(|at| vec![Vec::with_capacity(PASSES); at.len()])
        .collect();
    for _ in 0..PASSES {
        for (at, timed) in lobes.iter().zip(&mut passes) {
            for (lobe, timed) in at.iter().zip(timed.iter_mut()) {
                timed.push(timed_rate(PASS_SECONDS, &|t: &[f32], o: &mut [f32]| {
                    lobe.eval_batch_with(level, BatchLoop::Explicit, t, o);
                }));
            }
            progress.inc(1);
        }
    }
    passes
}

/// Evaluations per second of `work` over an L1-sized buffer, on one thread (best of 3).
pub(crate) fn l1_rate(work: &(dyn Fn(&[f32], &mut [f32]) + Sync)) -> f64 {
    (0..3)
        .map(|_| timed_rate(MIN_SECONDS, work))
        .fold(0.0, f64::max)
}

/// Evaluations per second of `work` over an L1-sized buffer, on one thread, timed for at
/// least `seconds`.
fn timed_rate(seconds: f64, work: &(dyn Fn(&[f32], &mut [f32]) + Sync)) -> f64 {
    let ts = cosines(L1_SIZE);
    let mut out = vec![0.0; L1_SIZE];
    let started = Instant::now();
    let mut rounds = 0_u64;
    while started.elapsed().as_secs_f64() < seconds {
        for _ in 0..ROUNDS_PER_CLOCK {
            work(black_box(&ts), black_box(&mut out));
        }
        rounds += ROUNDS_PER_CLOCK;
    }
    rounds as f64 * L1_SIZE as f64 / started.elapsed().as_secs_f64()
}

/// Evaluations per second streaming `ts` into `out`, one thread and all (best of 3 each).
fn stream_rates(
    ts: &[f32],
    out: &mut [f32],
    work: &(dyn Fn(&[f32], &mut [f32]) + Sync),
) -> [f64; 2] {
    [ts.len(), ts.len().div_ceil(rayon::current_num_threads())].map(|chunk| {
        (0..3)
            .map(|_| {
                let started = Instant::now();
                ts.par_chunks(chunk)
                    .zip(out.par_chunks_mut(chunk))
                    .for_each(|(t, o)| work(t, o));
                ts.len() as f64 / started.elapsed().as_secs_f64()
            })
            .fold(0.0, f64::max)
    })
}

/// Measures every lobe at `n` (and [`cosquad_formula`]); with `stream`, also streaming through
/// 128 MiB buffers. `progress` counts the lobes and is cleared at the end.
#[must_use]
pub fn measure(n: Exponent, stream: bool, progress: &ProgressBar) -> Measured {
    let level = Level::detect();
    let kinds: Vec<LobeKind> = LobeKind::ALL.into_iter().chain(cosquad_formula()).collect();
    progress.set_length(kinds.len() as u64 + 3);
    progress.set_message("peaks");
    let peaks_before = peak::measure(level);
    progress.inc(1);
    let pow_n = n.get() as f32;
    let powf = l1_rate(&|t, o| o.iter_mut().zip(t).for_each(|(o, &t)| *o = t.powf(pow_n)));
    let mut buffers = stream.then(|| (cosines(STREAM_SIZE), vec![0.0_f32; STREAM_SIZE]));
    // The copy peer: the faster of memcpy and the driver's own loads and stores.
    let copy_rates = |buffers: &mut Option<(Vec<f32>, Vec<f32>)>| {
        buffers.as_mut().map(|(ts, out)| {
            let memcpy = stream_rates(ts, out, &|t, o| o.copy_from_slice(t));
            let driver = stream_rates(ts, out, &|t, o| peak::copy(level, t, o));
            [0, 1].map(|k| memcpy[k].max(driver[k]))
        })
    };
    let copy_before = copy_rates(&mut buffers);
    progress.inc(1);
    let lobes = kinds
        .iter()
        .map(|&kind| {
            progress.set_message(kind.to_string());
            let lobe = Lobe::new(kind, n);
            let run = |batch_loop| {
                move |t: &[f32], o: &mut [f32]| lobe.eval_batch_with(level, batch_loop, t, o)
            };
            let rate = LobeRate {
                lobe: kind.to_string(),
                instructions: lobe.batch_instructions(),
                explicit: l1_rate(&run(BatchLoop::Explicit)),
                plain: l1_rate(&run(BatchLoop::Plain)),
                bound: peaks_before.bound(&lobe.batch_instructions()),
                stream: buffers
                    .as_mut()
                    .map(|(ts, out)| stream_rates(ts, out, &run(BatchLoop::Explicit))),
                epicentre_max_rel: error_figures(&lobe, &mut Precision::F32Simd, 20_001)
                    .epicentre_max_rel,
            };
            progress.inc(1);
            rate
        })
        .collect::<Vec<_>>();
    // Peaks measured on both sides of the kernels, so that a clock change in between
    // cannot put a kernel above its bound.
    progress.set_message("peaks");
    let peaks = peaks_before.best_of(&peak::measure(level));
    let copy_stream = copy_before
        .zip(copy_rates(&mut buffers))
        .map(|(before, after)| [0, 1].map(|k| before[k].max(after[k])));
    let lobes = lobes
        .into_iter()
        .map(|rate| LobeRate {
            bound: peaks.bound(&rate.instructions),
            ..rate
        })
        .collect();
    progress.finish_and_clear();
    Measured {
        n: n.get(),
        level,
        threads: rayon::current_num_threads(),
        peaks,
        powf,
        copy_stream,
        lobes,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every lobe gets a rate at each of its exponents in every pass, in the order given, and
    /// the progress counts a tick per lobe per pass.
    #[test]
    fn every_lobe_is_timed_at_each_exponent() {
        let lobes: Vec<Vec<Lobe>> = [LobeKind::Pow, LobeKind::Schlick]
            .into_iter()
            .map(|kind| {
                [8.0, 64.0, 512.0]
                    .into_iter()
                    .map(|n| Lobe::new(kind, Exponent::new(n)))
                    .collect()
            })
            .collect();
        let progress = ProgressBar::hidden();
        let rates = kernel_rates(&lobes, &progress);
        assert_eq!(progress.position(), (2 * PASSES) as u64);
        assert_eq!(rates.len(), 2);
        for lobe in &rates {
            assert_eq!(lobe.len(), 3);
            for passes in lobe {
                assert_eq!(passes.len(), PASSES);
                assert!(
                    passes.iter().all(|&r| r.is_finite() && r > 0.0),
                    "{passes:?}"
                );
            }
        }
    }
}
