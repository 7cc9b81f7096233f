//! The compute shader against the core's `f64` reference, lobe by lobe, within the bound each
//! model states for a GPU (`Lobe::gpu_ulp_bound`, in ULPs of 1.0, `2^-23`), derived in the
//! model's file from how its formula amplifies rounding: 32 ULP for exact IEEE operations
//! (`schlick`, `schlick-mod`), `32 + 2n` through `log2` (`pow`, `logexp`, `logexp-rr`),
//! `(32 + n / 2) 2^(v-4)` for `cosquad`'s `v` squarings, 64 for one `exp2` (`sg`,
//! `sg-karis`), `128 + 4n` for the bit tricks against their exact `f64` models, 8192 through a
//! driver's `acos` (the quadratics in the angle).
//!
//! Set on llvmpipe (LLVM 15.0.6, 256 bits), Mesa 22.3.6, where the measured maxima are about
//! half these bounds; docs/gpu.md lists them.

mod common;

use specula::{Exponent, Lobe, LobeKind};
use specula_gpu::LobeEvaluator;

const ULP: f64 = 1.0 / (1u32 << 23) as f64;

/// Cosines crowded towards the peak, where the lobes live, plus the edge cases.
fn cosines() -> Vec<f32> {
    let mut ts: Vec<f32> = (0..=20_000)
        .map(|i| 1.0 - (i as f32 / 20_000.0).powi(3))
        .collect();
    ts.extend([
        0.0,
        -0.0,
        -0.5,
        -1.0,
        1.0 + f32::EPSILON,
        2.0,
        f32::NAN,
        f32::MIN_POSITIVE,
    ]);
    ts
}

#[test]
fn every_lobe_on_the_gpu_matches_f64_within_its_bound() {
    let Some(gpu) = common::gpu() else { return };
    let evaluator = LobeEvaluator::new(&gpu).unwrap();
    let ts = cosines();
    // Every variant (cosquad's every v) and every shape of schlick-mod's (a generated
    // function each).
    for kind in LobeKind::ALL.into_iter().flat_map(LobeKind::variants) {
        let mut worst = (0.0_f64, 0.0_f64);
        for n in [
            1.0, 7.3, 8.0, 16.0, 33.0, 64.0, 128.0, 255.0, 333.0, 512.0, 1000.0,
        ] {
            let lobe = Lobe::new(kind, Exponent::new(n));
            let values = evaluator.eval(&lobe, &ts).unwrap();
            let bound = lobe.gpu_ulp_bound() * ULP;
            for (&t, &value) in ts.iter().zip(&values) {
                let reference = lobe.eval(f64::from(t));
                let error = (f64::from(value) - reference).abs();
                if error > worst.0 {
                    worst = (error, n);
                }
                assert!(
                    error <= bound,
                    "{kind} n = {n} t = {t:e}: gpu {value:e}, f64 {reference:e}, error {:.0} ULP > \
                        {:.0}",
                    error / ULP,
                    bound / ULP
                );
            }
        }
        eprintln!(
            "{kind:>12}: worst {:.1e} ({:.0} ULP) at n = {}",
            worst.0,
            worst.0 / ULP,
            worst.1
        );
    }
}

/// A user's lobe, defined before the evaluator is built, runs on the GPU as its generated
/// WGSL (constants computed from `n` in the shader) and matches its own `f64` reference
/// within the bound of the built-in lobe of the same shape.
#[test]
fn user_lobes_on_the_gpu_match_f64() {
    let kinds = [
        LobeKind::parse("=let a = (n + 1) / 17; max(0, a * (t - 1) + 1) ^ 16").unwrap(),
        LobeKind::parse("=exp2(n * (t - 1) * 1.4427)").unwrap(),
        LobeKind::parse("=let w = 1.875 / (n + 1); (1 - min(1, (1 - t) / w) ^ 2) ^ 2").unwrap(),
    ];
    let Some(gpu) = common::gpu() else { return };
    let evaluator = LobeEvaluator::new(&gpu).unwrap();
    let ts = cosines();
    for kind in kinds {
        for n in [1.0, 7.3, 64.0, 1000.0] {
            let lobe = Lobe::new(kind, Exponent::new(n));
            let values = evaluator.eval(&lobe, &ts).unwrap();
            let bound = lobe.gpu_ulp_bound() * ULP;
            for (&t, &value) in ts.iter().zip(&values) {
                let reference = lobe.eval(f64::from(t));
                assert!(
                    (f64::from(value) - reference).abs() <= bound,
                    "{kind} n = {n} t = {t:e}: gpu {value:e}, f64 {reference:e}"
                );
            }
        }
    }
}

/// The rules every lobe shares hold on the GPU exactly: 0 at and below the horizon and for
/// NaN, never above 1, the peak value at `t > 1`.
#[test]
fn edge_cases_follow_the_shared_rules() {
    let Some(gpu) = common::gpu() else { return };
    let evaluator = LobeEvaluator::new(&gpu).unwrap();
    let ts = [0.0, -0.0, -0.5, f32::NAN, 1.0, 1.5];
    for kind in LobeKind::ALL {
        let lobe = Lobe::new(kind, Exponent::new(50.0));
        let values = evaluator.eval(&lobe, &ts).unwrap();
        assert_eq!(&values[..4], &[0.0; 4], "{kind}");
        assert_eq!(values[4], values[5], "{kind}: t > 1 counts as 1");
        assert!(
            values.iter().all(|v| (0.0..=1.0).contains(v)),
            "{kind}: {values:?}"
        );
    }
}

/// A batch larger than one dispatch row (65,535 workgroups of 64) reaches every element.
#[test]
fn large_batches_are_evaluated_whole() {
    let Some(gpu) = common::gpu() else { return };
    let evaluator = LobeEvaluator::new(&gpu).unwrap();
    let lobe = Lobe::new(LobeKind::Schlick, Exponent::new(10.0));
    let ts: Vec<f32> = (0..5_000_000).map(|i| (i % 1000) as f32 / 1000.0).collect();
    let values = evaluator.eval(&lobe, &ts).unwrap();
    let last = *ts.last().unwrap();
    assert!((f64::from(values[values.len() - 1]) - lobe.eval(f64::from(last))).abs() < 1e-6);
    assert!(values
        .iter()
        .zip(&ts)
        .all(|(&v, &t)| (v - lobe.eval(t)).abs() < 1e-6));
}
