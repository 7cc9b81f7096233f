//! specula's decisions, the same from every face (the command line, the report, Python):
//! which lobe to ship on a target at an accuracy ([`recommend`]), which for a measured
//! material ([`material`]), and the costs they rank by, pulled from the GPU cost model
//! (`specula-gpu`'s instruction counts), the fixed-point datapaths (`specula-hw`) and their
//! synthesis (`specula-synth`), and this machine's measured kernels ([`rates`]).
//!
//! No face lives here: nothing parses arguments or prints. Refusals are one-line messages;
//! progress goes to a [`indicatif::ProgressBar`] the caller passes (hidden for none); what a
//! face should tell its user comes back as data ([`Recommendation::note`]).

pub mod analyses;
pub mod c_twins;
mod choice;
mod costing;
pub mod design;
mod figures;
mod fit_cache;
pub mod fpga_estimate;
pub mod hardware;
pub mod material;
pub mod microfacet_cost;
pub mod percent;
mod pinned;
mod ranking;
pub mod rates;
mod recommend;
mod recommendation;
mod synthesis_plan;

pub use choice::{Target, Zone};
pub use costing::{
    gpu_basis, lobe_rate, lobe_rates, modelled_rate, rate_unit, FPGA_MATERIAL_REFUSAL,
};
pub use hardware::{hardware_sweeps, sweeps};
pub use ranking::{pareto_front, versus_pow};
pub use recommend::{
    recommend, recommend_each, recommend_each_cached, Candidate, Recommendation, Request,
};

use specula::{Exponent, LobeKind};

/// Every built-in lobe, then those of `extra` that are not among them, in order and once
/// each: the candidates a face passes in a [`Request`] when its user adds lobes.
#[must_use]
pub fn candidates(extra: &[LobeKind]) -> Vec<LobeKind> {
    let mut kinds = LobeKind::ALL.to_vec();
    for &kind in extra {
        if !kinds.contains(&kind) {
            kinds.push(kind);
        }
    }
    kinds
}

/// Parses a specular exponent in `[1, 1000]`.
pub fn parse_exponent(text: &str) -> Result<Exponent, String> {
    let value: f64 = text
        .trim()
        .parse()
        .map_err(|_| format!("'{text}' is not a number; n must be a number in [1, 1000]"))?;
    Exponent::try_new(value).map_err(|error| error.to_string())
}

/// One exponent, or `LOW..HIGH` as `steps + 1` log-spaced ones ([`log_spaced`]).
pub fn parse_exponent_range(text: &str, steps: u32) -> Result<Vec<Exponent>, String> {
    let Some((low, high)) = text.split_once("..") else {
        return Ok(vec![parse_exponent(text)?]);
    };
    let (low, high) = (parse_exponent(low)?, parse_exponent(high)?);
    if low.get() >= high.get() {
        return Err(format!(
            "'{text}': a range needs LOW < HIGH, both in [1, 1000]"
        ));
    }
    Ok(log_spaced(low, high, steps))
}

/// The exponents an answer must hold at, as every face writes them: `N`, or `LOW..HIGH`
/// sampled by [`sample_exponents`]; refused in one line otherwise.
pub fn parse_exponents(text: &str) -> Result<Vec<Exponent>, String> {
    let ends = parse_exponent_range(text, 1)?;
    Ok(sample_exponents(ends[0], ends[ends.len() - 1]))
}

/// `steps + 1` exponents from `low` to `high`, log-spaced, both ends included (`low` alone
/// for no steps).
#[must_use]
pub(crate) fn log_spaced(low: Exponent, high: Exponent, steps: u32) -> Vec<Exponent> {
    if steps == 0 {
        return vec![low];
    }
    let (low, high) = (low.get(), high.get());
    (0..=steps)
        .map(|k| Exponent::new(low * (high / low).powf(f64::from(k) / f64::from(steps))))
        .collect()
}

/// The exponents an answer over `low..=high` is measured at: 9 log-spaced ones, the ends
/// included, and the powers of two inside (where `schlick-mod` and `cosquad` change shape),
/// in increasing order; `low` alone where the two are equal. The ends are swapped if
/// `low > high`.
#[must_use]
pub fn sample_exponents(low: Exponent, high: Exponent) -> Vec<Exponent> {
    let (low, high) = if low.get() <= high.get() {
        (low, high)
    } else {
        (high, low)
    };
    let sampled = log_spaced(low, high, 8);
    let (low, high) = (low.get(), high.get());
    let mut values: Vec<f64> = sampled
        .iter()
        .map(|n| n.get())
        .chain(
            (0..10)
                .map(|p| f64::from(1u32 << p))
                .filter(|&v| v > low && v < high),
        )
        .collect();
    values.sort_by(f64::total_cmp);
    values.dedup_by(|a, b| (*a - *b).abs() < 1e-9);
    values.into_iter().map(Exponent::new).collect()
}

/// Refuses, before any work, a user's lobe whose formula is not a lobe at one of `exponents`
/// (see [`specula::Lobe::checked`]); built-in lobes pass.
pub fn check_lobes(kinds: &[LobeKind], exponents: &[Exponent]) -> Result<(), String> {
    for &kind in kinds {
        if matches!(kind, LobeKind::Formula(_)) {
            for &n in exponents {
                specula::Lobe::checked(kind, n).map_err(|e| e.to_string())?;
            }
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ranges_are_sampled_between_their_ends_with_powers_of_two() {
        let values: Vec<f64> = sample_exponents(Exponent::new(8.0), Exponent::new(512.0))
            .iter()
            .map(|n| n.get())
            .collect();
        assert_eq!((values[0], values[values.len() - 1]), (8.0, 512.0));
        for p in [16.0, 32.0, 64.0, 128.0, 256.0] {
            assert!(values.contains(&p), "{p} missing from {values:?}");
        }
        assert!(values.windows(2).all(|w| w[0] < w[1]), "{values:?}");
        let one = sample_exponents(Exponent::new(64.0), Exponent::new(64.0));
        assert_eq!(one, [Exponent::new(64.0)]);
        assert_eq!(parse_exponents("64"), Ok(one));
        assert_eq!(
            parse_exponents("8..512"),
            Ok(sample_exponents(Exponent::new(8.0), Exponent::new(512.0)))
        );
        for bad in ["512..8", "0..5", "nan", "64..64"] {
            let refusal = parse_exponents(bad).unwrap_err();
            assert_eq!(refusal.lines().count(), 1, "{refusal}");
        }
        assert_eq!(
            log_spaced(Exponent::new(1.0), Exponent::new(1000.0), 3).len(),
            4
        );
    }
}
