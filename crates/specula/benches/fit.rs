//! criterion benches of `specula fit`'s work: each bundled material (`data/rgl`) fitted with
//! every built-in lobe and GGX in the classic model, and with every lobe, Beckmann and GGX in
//! the microfacet model. After criterion's timings, one run of each prints its observation
//! evaluations per second against the solver's own peak on this machine
//! ([`evaluation_peak`]: its two vector passes and nothing else, on one thread) times the
//! threads the fit had: how much of what the vector units allow the fit makes.

// criterion's macros generate the undocumented `benches` and `main`.
#![allow(missing_docs)]

use std::path::PathBuf;
use std::time::Instant;

use criterion::{criterion_group, criterion_main, Criterion};
use specula::measured::fit::{
    evaluation_peak, families, fit_families_counted, microfacet_families, Observations, Specular,
};
use specula::measured::MeasuredBrdf;
use specula::LobeKind;

/// The bundled materials, read from the repository's `data/rgl`.
fn materials() -> Vec<(String, Observations)> {
    let folder = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../data/rgl");
    let mut files: Vec<PathBuf> = std::fs::read_dir(&folder)
        .expect("data/rgl")
        .map(|entry| entry.expect("data/rgl").path())
        .filter(|path| path.extension().is_some_and(|e| e == "bsdf"))
        .collect();
    files.sort();
    files
        .into_iter()
        .map(|path| {
            let bytes = std::fs::read(&path).expect("a material");
            let measured = MeasuredBrdf::from_bytes(&bytes).expect("an RGL .bsdf");
            let name = path.file_stem().unwrap().to_string_lossy().into_owned();
            (name, Observations::of(|wo, wi| measured.f_cos(wo, wi)))
        })
        .collect()
}

fn models() -> [(&'static str, Vec<Specular>); 2] {
    [
        ("classic", families(&LobeKind::ALL)),
        ("microfacet", microfacet_families(&LobeKind::ALL)),
    ]
}

fn fits(c: &mut Criterion) {
    let materials = materials();
    let mut group = c.benchmark_group("fit");
    group.sample_size(10);
    for (name, observations) in &materials {
        for (model, families) in models() {
            group.bench_function(format!("{name}/{model}"), |b| {
                b.iter(|| fit_families_counted(observations, &families));
            });
        }
    }
    group.finish();
    let threads = rayon::current_num_threads();
    println!(
        "\nobservation evaluations per second: each fit's, against the solver's peak on one \
         thread ({}) times {threads} threads",
        describe_peak()
    );
    for (name, observations) in &materials {
        let peak = evaluation_peak(observations, 0.5) * threads as f64;
        for (model, families) in models() {
            let start = Instant::now();
            let (_, evaluations) = fit_families_counted(observations, &families);
            let seconds = start.elapsed().as_secs_f64();
            let rate = evaluations as f64 / seconds;
            println!(
                "{name:>24} {model:>10}: {seconds:6.2} s, {:7.1} M evaluations, {:7.0} M/s = \
                 {:3.0} % of {:5.0} M/s",
                evaluations as f64 / 1e6,
                rate / 1e6,
                100.0 * rate / peak,
                peak / 1e6
            );
        }
    }
}

/// Which vector units the solver's passes run on.
fn describe_peak() -> &'static str {
    // pulp's dispatch, which the passes go through.
    #[cfg(target_arch = "x86_64")]
    {
        if pulp::x86::V4::try_new().is_some() {
            return "AVX-512";
        }
        if pulp::x86::V3::try_new().is_some() {
            return "AVX2";
        }
    }
    "the baseline's vectors"
}

criterion_group!(benches, fits);
criterion_main!(benches);
