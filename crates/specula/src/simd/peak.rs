//! Measuring [`Peaks`]: each instruction class alone, in [`CHAINS`] independent
//! register-resident chains (enough to cover the longest latency times the pipes that run it,
//! and few enough to stay in the 16 registers AVX2 has), through the same [`Lanes`] methods
//! the kernels call, so a peak is the throughput of exactly the instruction a kernel executes.
//!
//! Timing only, no I/O; the benchmark (`specula bench lobes`) calls it.

use core::hint::black_box;
use std::time::Instant;

use super::cost::Peaks;
use super::tally::Class;
use super::{dispatch, BatchLoop, Drive, Job, Kernel, Lanes, Level};

/// Independent chains per measurement.
pub const CHAINS: usize = 12;

/// Steps per timed run (each step is one instruction on every chain).
const STEPS: usize = 200_000;

/// Instructions of one class per second, best of 3, on one thread at `level`.
#[must_use]
pub fn class_peak(level: Level, class: Class) -> Option<f64> {
    let run = ClassLoop { class };
    run.measurable().then(|| {
        (0..3)
            .map(|_| (CHAINS * STEPS) as f64 / dispatch(level, run))
            .fold(0.0, f64::max)
    })
}

/// Every peak at `level`, with the dispatch rate and the L1 copy rate.
#[must_use]
pub fn measure(level: Level) -> Peaks {
    let per_class = Class::ALL.map(|class| class_peak(level, class));
    let dispatch = (0..3)
        .map(|_| (CHAINS * STEPS) as f64 / dispatch(level, Mix))
        .fold(0.0, f64::max);
    Peaks {
        level,
        per_class,
        dispatch,
        copy: copy_rate(level) / level.lanes() as f64,
    }
}

/// Floats per second the driver moves through L1 with an identity kernel, best of 3.
#[must_use]
pub fn copy_rate(level: Level) -> f64 {
    const LEN: usize = 2048;
    const ROUNDS: usize = 20_000;
    let ts = vec![0.5_f32; LEN];
    let mut out = vec![0.0_f32; LEN];
    (0..3)
        .map(|_| {
            let started = Instant::now();
            for _ in 0..ROUNDS {
                copy(level, black_box(&ts), black_box(&mut out));
            }
            (LEN * ROUNDS) as f64 / started.elapsed().as_secs_f64()
        })
        .fold(0.0, f64::max)
}

/// Copies `ts` to `out` through the kernels' driver (an identity kernel: the same loads and
/// stores a lobe kernel makes, and nothing else), the peer of a streaming kernel.
pub fn copy(level: Level, ts: &[f32], out: &mut [f32]) {
    #[derive(Clone, Copy)]
    struct Identity;
    impl Kernel for Identity {
        fn eval_lanes<V: Lanes>(self, t: V) -> V {
            t
        }
    }
    dispatch(
        level,
        Drive {
            kernel: Identity,
            ts,
            out,
            batch_loop: BatchLoop::Explicit,
        },
    );
}

/// `CHAINS` chains of one instruction.
#[derive(Clone, Copy)]
struct ClassLoop {
    class: Class,
}

impl ClassLoop {
    /// Whether the class can be chained on its own: a compare yields a mask, not a vector, so
    /// compares count only towards dispatch.
    fn measurable(self) -> bool {
        self.class != Class::Compare
    }
}

/// Runs `CHAINS` chains of `op` for `STEPS` steps and returns the seconds taken. The
/// operand `b` and the mask are opaque to the compiler per step, so no chain can be folded
/// (`x & m & m` would be).
#[inline(always)]
fn chains<V: Lanes>(lanes: V, op: impl Fn(V, V, V::Mask) -> V) -> f64 {
    let mask = lanes.splat(1.0).gt(lanes.splat(0.0));
    let mut acc = [lanes.splat(1.5); CHAINS];
    for (i, x) in acc.iter_mut().enumerate() {
        *x = lanes.splat(1.5 + i as f32 / 64.0);
    }
    let b = lanes.splat(0.999_9);
    let started = Instant::now();
    for _ in 0..STEPS {
        let (b, mask) = (black_box(b), black_box(mask));
        for x in &mut acc {
            *x = op(*x, b, mask);
        }
    }
    black_box(acc);
    started.elapsed().as_secs_f64()
}

impl Job for ClassLoop {
    type Output = f64;

    #[inline(always)]
    fn run<V: Lanes>(self, lanes: V) -> f64 {
        match self.class {
            Class::Fma => chains(lanes, |x, b, _| x.mul_add(b, b)),
            // 0.9999^200000 is e^-20: no subnormals, which would slow the chain.
            Class::Mul => chains(lanes, |x, b, _| x * b),
            Class::Add => chains(lanes, |x, b, _| x - b),
            Class::Div => chains(lanes, |x, b, _| x / b),
            Class::Sqrt => chains(lanes, |x, _, _| x.sqrt()),
            Class::MinMax => chains(lanes, |x, b, _| x.max(b)),
            Class::Blend => chains(lanes, |x, b, mask| x.select(mask, b)),
            Class::Logic => chains(lanes, |x, _, mask| x.keep(mask)),
            Class::IntAdd => chains(lanes, |x, _, _| x.bits_add(1)),
            Class::Shift => chains(lanes, |x, _, _| x.bits_shr_signed::<1>()),
            Class::Convert => chains(lanes, |x, _, _| x.float_to_int()),
            Class::Compare => unreachable!("compares are not measured alone (see `measurable`)"),
        }
    }
}

/// The dispatch rate: 4 chains of `fma`, 3 of `sub` and 5 of integer `add`, 12 instructions a
/// step. Latency allows at least 1 `fma`, 1 `sub` and 5 `add`s a cycle, so the step is bound
/// by how many instructions the core dispatches, not by any chain or any single pipe.
#[derive(Clone, Copy)]
struct Mix;

impl Job for Mix {
    type Output = f64;

    #[inline(always)]
    fn run<V: Lanes>(self, lanes: V) -> f64 {
        let mut acc = [lanes.splat(1.5); CHAINS];
        for (i, x) in acc.iter_mut().enumerate() {
            *x = lanes.splat(1.5 + i as f32 / 64.0);
        }
        let b = lanes.splat(0.999_9);
        let started = Instant::now();
        for _ in 0..STEPS {
            let b = black_box(b);
            let (fma, rest) = acc.split_at_mut(4);
            let (sub, add) = rest.split_at_mut(3);
            for x in fma {
                *x = x.mul_add(b, b);
            }
            for x in sub {
                *x = *x - b;
            }
            for x in add {
                *x = x.bits_add(1);
            }
        }
        black_box(acc);
        started.elapsed().as_secs_f64()
    }
}
