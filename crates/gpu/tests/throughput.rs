//! The GPU throughput benchmark times real work: invocation 0's sum over its chain of
//! cosines, read back from the timed dispatch, is the sum the CPU's `f32` path computes.

mod common;

use specula::{Exponent, Lobe, LobeKind};
use specula_gpu::throughput::{first_invocation_sum, measure, CHAIN};

#[test]
fn every_lobe_is_timed_on_the_work_it_claims() {
    let Some(gpu) = common::gpu() else { return };
    for kind in LobeKind::ALL {
        let lobe = Lobe::new(kind, Exponent::new(64.0));
        let (rate, gpu_sum) = measure(&gpu, &lobe).unwrap();
        let cpu_sum = first_invocation_sum(&lobe);
        // Each value within the compute-parity bounds (at most 4e-4 for the acos lobes).
        assert!(
            (gpu_sum - cpu_sum).abs() <= 4e-4 * CHAIN as f32 + 1e-3 * cpu_sum,
            "{kind}: GPU sum {gpu_sum}, CPU {cpu_sum}"
        );
        assert!(
            cpu_sum > 1.0,
            "{kind}: the chain stays on the lobe ({cpu_sum})"
        );
        assert!(rate.evals_per_second.is_finite() && rate.evals_per_second > 0.0);
        assert_eq!(rate.evaluations % u64::from(CHAIN), 0);
    }
}
