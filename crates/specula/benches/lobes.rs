//! criterion benches of lobe evaluation: the scalar `f32` path and the batch (SIMD) path of
//! every lobe, against `powf` and a plain copy, on an L1-resident buffer (2048 cosines).
//! `specula bench lobes` prints the same comparison, with streaming sizes, threads and limits,
//! from one run.

// criterion's macros generate the undocumented `benches` and `main`.
#![allow(missing_docs)]

use std::hint::black_box;

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use specula::{Exponent, Lobe, LobeKind};

const SIZE: usize = 2048;

fn cosines() -> Vec<f32> {
    (0..SIZE)
        .map(|i| 1.0 - 0.2 * (i as f32 / SIZE as f32).powi(2))
        .collect()
}

fn lobes(c: &mut Criterion) {
    let ts = cosines();
    let mut out = vec![0.0_f32; SIZE];
    let n = Exponent::new(64.0);
    let mut group = c.benchmark_group("lobes-n64-l1");
    group.throughput(Throughput::Elements(SIZE as u64));
    group.bench_function("copy", |b| b.iter(|| out.copy_from_slice(black_box(&ts))));
    group.bench_function("powf", |b| {
        b.iter(|| {
            for (o, &t) in out.iter_mut().zip(black_box(&ts)) {
                *o = t.powf(64.0);
            }
        });
    });
    for kind in LobeKind::ALL {
        let lobe = Lobe::new(kind, n);
        group.bench_function(format!("{kind}/scalar"), |b| {
            b.iter(|| {
                for (o, &t) in out.iter_mut().zip(black_box(&ts)) {
                    *o = lobe.eval(t);
                }
            });
        });
        group.bench_function(format!("{kind}/batch"), |b| {
            b.iter(|| lobe.eval_batch(black_box(&ts), &mut out));
        });
    }
    group.finish();
}

criterion_group!(benches, lobes);
criterion_main!(benches);
