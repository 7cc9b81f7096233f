//! A lobe's `f64` error figures at [`SWEEP_SAMPLES`] angles per zone, computed once per
//! process for each lobe and exponent: `recommend` and `design` measure the same built-ins at
//! the same exponents again and again (the report asks for six designs and dozens of
//! answers), and a designed lobe's verification already measured it at every exponent its
//! ranking asks for. The reference samples (`cos^n` at every angle) are shared by every lobe
//! at an exponent. A lobe kind names one immutable lobe for the whole process (a user's
//! formula is registered for good), so a figure never goes stale.

use std::collections::HashMap;
use std::sync::{Arc, Mutex, MutexGuard, OnceLock, PoisonError};

use specula::analysis::{error_figures_on, ErrorFigures, Precision, ZoneSamples};
use specula::{Exponent, Lobe, LobeKind};

use crate::hardware::SWEEP_SAMPLES;

type Figures = HashMap<(LobeKind, u64), ErrorFigures>;

/// Every figure measured in this process, by lobe and exponent's bits.
fn memo() -> MutexGuard<'static, Figures> {
    static FIGURES: OnceLock<Mutex<Figures>> = OnceLock::new();
    FIGURES
        .get_or_init(Mutex::default)
        .lock()
        .unwrap_or_else(PoisonError::into_inner)
}

/// The figures of `lobe` in `f64`, as `error_figures(lobe, F64, SWEEP_SAMPLES)` gives them.
#[must_use]
pub(crate) fn f64_figures(lobe: &Lobe) -> ErrorFigures {
    let key = (lobe.kind(), lobe.exponent().get().to_bits());
    if let Some(&known) = memo().get(&key) {
        return known;
    }
    // Measured outside the lock: two threads may both measure one lobe, never wait on it.
    let measured = error_figures_on(lobe, &mut Precision::F64, &samples(lobe.exponent()));
    memo().insert(key, measured);
    measured
}

/// The figures of `kind` measured so far, by exponent's bits, in increasing order: what a
/// designed lobe's verification measured, which the design cache keeps beside the lobe.
#[must_use]
pub(crate) fn measured(kind: LobeKind) -> Vec<(u64, ErrorFigures)> {
    let mut found: Vec<(u64, ErrorFigures)> = memo()
        .iter()
        .filter(|((measured, _), _)| *measured == kind)
        .map(|(&(_, n), &figures)| (n, figures))
        .collect();
    found.sort_by_key(|&(n, _)| n);
    found
}

/// Takes `figures` as `kind`'s at the exponent of bits `n`, as measured by an earlier process
/// of this build (the design cache's): a lobe kind names one lobe for the whole process, so
/// they are what measuring it again would give.
pub(crate) fn remember(kind: LobeKind, n: u64, figures: ErrorFigures) {
    memo().insert((kind, n), figures);
}

/// The reference samples at `n`, made once per exponent.
fn samples(n: Exponent) -> Arc<ZoneSamples> {
    static SAMPLES: OnceLock<Mutex<HashMap<u64, Arc<ZoneSamples>>>> = OnceLock::new();
    let all = SAMPLES.get_or_init(Mutex::default);
    if let Some(known) = all
        .lock()
        .unwrap_or_else(PoisonError::into_inner)
        .get(&n.get().to_bits())
    {
        return Arc::clone(known);
    }
    let made = Arc::new(ZoneSamples::new(n, SWEEP_SAMPLES));
    Arc::clone(
        all.lock()
            .unwrap_or_else(PoisonError::into_inner)
            .entry(n.get().to_bits())
            .or_insert(made),
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use specula::analysis::error_figures;

    /// The remembered figures are the analysis's own, asked again or not.
    #[test]
    fn remembered_figures_are_the_analysis_figures() {
        for kind in [LobeKind::Schlick, LobeKind::Minimax2, LobeKind::Pow] {
            for n in [8.0, 100.0] {
                let lobe = Lobe::new(kind, Exponent::new(n));
                let direct = error_figures(&lobe, &mut Precision::F64, SWEEP_SAMPLES);
                assert_eq!(f64_figures(&lobe), direct);
                assert_eq!(f64_figures(&lobe), direct, "asked a second time");
            }
        }
    }
}
