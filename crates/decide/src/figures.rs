//! A lobe's `f64` error figures at [`SWEEP_SAMPLES`] angles per zone, computed once per
//! process for each lobe and exponent: `recommend` and `design` measure the same built-ins at
//! the same exponents again and again (the report asks for six designs and dozens of
//! answers), and a designed lobe's verification already measured it at every exponent its
//! ranking asks for. The reference samples (`cos^n` at every angle) are shared by every lobe
//! at an exponent. A lobe kind names one immutable lobe for the whole process (a user's
//! formula is registered for good), so a figure never goes stale.

use std::collections::HashMap;
use std::sync::{Arc, Mutex, OnceLock, PoisonError};

use specula::analysis::{error_figures_on, ErrorFigures, Precision, ZoneSamples};
use specula::{Exponent, Lobe, LobeKind};

use crate::hardware::SWEEP_SAMPLES;

/// The figures of `lobe` in `f64`, as `error_figures(lobe, F64, SWEEP_SAMPLES)` gives them.
#[must_use]
pub(crate) fn f64_figures(lobe: &Lobe) -> ErrorFigures {
    static FIGURES: OnceLock<Mutex<HashMap<(LobeKind, u64), ErrorFigures>>> = OnceLock::new();
    let key = (lobe.kind(), lobe.exponent().get().to_bits());
    let figures = FIGURES.get_or_init(Mutex::default);
    if let Some(&known) = figures
        .lock()
        .unwrap_or_else(PoisonError::into_inner)
        .get(&key)
    {
        return known;
    }
    // Measured outside the lock: two threads may both measure one lobe, never wait on it.
    let measured = error_figures_on(lobe, &mut Precision::F64, &samples(lobe.exponent()));
    figures
        .lock()
        .unwrap_or_else(PoisonError::into_inner)
        .insert(key, measured);
    measured
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
