//! The analysis target's check, also run by `crates/serve/tests/fuzz_regressions.rs` on the
//! seeds and every crash input kept in `fuzz/regressions/analysis/`: every formula the language
//! accepts and `Lobe::checked` admits at an exponent is analysed (`specula analyze`'s figures)
//! in bounded time, whatever its `f64` values do (cancellation noise made the energy's
//! quadrature bisect without end), with figures that are numbers.

use std::time::{Duration, Instant};

use specula::analysis::{analyze, Precision};
use specula::{Exponent, Lobe};

use crate::formula::lobe;

/// The longest one analysis may take: a clean lobe takes milliseconds.
const BOUND: Duration = Duration::from_secs(20);

/// Analyses `data`, a formula, at `n = 16` (where the noisy formula of issue 48 stalled) and at
/// an exponent drawn from the text.
pub fn check_analysis(data: &[u8]) {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    let Some(kind) = lobe(text) else {
        return;
    };
    let drawn = 1 + data
        .iter()
        .fold(0_u32, |h, &b| h.wrapping_mul(31).wrapping_add(u32::from(b)))
        % 1000;
    for n in [16.0, f64::from(drawn)] {
        let n = Exponent::new(n);
        if Lobe::checked(kind, n).is_err() {
            continue;
        }
        let started = Instant::now();
        let report = analyze(kind, n, &mut Precision::F64);
        let took = started.elapsed();
        assert!(took < BOUND, "{text:?} at n = {n}: analysed in {took:?}");
        assert!(
            report.energy_ratio.is_finite() && report.max_albedo.is_finite(),
            "{text:?} at n = {n}: energy {} albedo {}",
            report.energy_ratio,
            report.max_albedo
        );
    }
}
