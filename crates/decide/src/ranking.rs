//! Ranking costed candidates, shared by `recommend` and `design`: the Pareto front of error
//! against cost, the order (those that meet first, cheapest first), a measured tie given to
//! the most accurate lobe, and each candidate's why.

use specula::LobeKind;

use crate::recommendation::{Candidate, Recommendation};
use crate::Target;

/// Which of `points` (error, rate) no other point dominates (at least as accurate and at
/// least as cheap, and better in one).
#[must_use]
pub fn pareto_front(points: &[(f64, f64)]) -> Vec<bool> {
    points
        .iter()
        .map(|&(error, rate)| {
            !points
                .iter()
                .any(|&(e, r)| e <= error && r >= rate && (e < error || r > rate))
        })
        .collect()
}

/// The answer from measured candidates: the Pareto front marked, those that meet first and
/// cheapest first, each with why.
pub(crate) fn rank(
    mut candidates: Vec<Candidate>,
    unit: &'static str,
    note: Option<String>,
    target: Target,
    max_error: f64,
) -> Recommendation {
    // A bound is no point of the front: it neither stands on it nor pushes others off.
    let front = pareto_front(
        &candidates
            .iter()
            .map(|c| {
                if c.at_most {
                    (f64::INFINITY, 0.0)
                } else {
                    (c.error, c.rate)
                }
            })
            .collect::<Vec<_>>(),
    );
    for (candidate, on_front) in candidates.iter_mut().zip(front) {
        candidate.pareto = on_front && !candidate.at_most;
    }
    candidates.sort_by(|a, b| b.meets.cmp(&a.meets).then(b.rate.total_cmp(&a.rate)));
    let tie = break_tie(&mut candidates, |c| Standing {
        meets: c.meets,
        rate: c.rate,
        spread: c.spread,
        error: c.error,
    });
    let tied = candidates[..tie].iter().map(|c| c.lobe.clone()).collect();
    let mut recommendation = Recommendation {
        unit,
        note,
        basis: None,
        candidates,
        tied,
    };
    let pow_rate = recommendation.pow_rate();
    let best = recommendation.best_candidate().map(|c| c.lobe.clone());
    for candidate in &mut recommendation.candidates {
        candidate.why = why(candidate, best.as_deref(), pow_rate, target, max_error);
        if candidate.at_most && candidate.meets {
            candidate.why = format!(
                "meets it, at most {} pow's throughput: not synthesized whole, as it cannot win",
                versus_pow(candidate.rate, pow_rate)
            );
        }
        if recommendation.tied.contains(&candidate.lobe) {
            candidate.why += if Some(&candidate.lobe) == best.as_ref() {
                "; tied with the fastest (rates overlap), the most accurate of the tie"
            } else {
                "; tied with the answer (rates overlap), less accurate"
            };
        }
    }
    recommendation
}

/// Whether two (rate, spread) pairs cannot be told apart: their measured spreads overlap.
/// Unmeasured rates (modelled, synthesized) are exact, and tie only where equal.
#[must_use]
pub(crate) fn rates_overlap(a: (f64, Option<[f64; 2]>), b: (f64, Option<[f64; 2]>)) -> bool {
    match (a.1, b.1) {
        (Some([a_low, a_high]), Some([b_low, b_high])) => a_low <= b_high && b_low <= a_high,
        _ => a.0 == b.0,
    }
}

/// What [`break_tie`] reads of a ranked lobe: whether it meets the request, its rate and
/// spread, its error.
pub(crate) struct Standing {
    pub(crate) meets: bool,
    pub(crate) rate: f64,
    pub(crate) spread: Option<[f64; 2]>,
    pub(crate) error: f64,
}

/// Among `sorted` (those that meet first, fastest first), the measured lobes that meet and
/// whose spreads overlap the fastest's, a tie this run cannot break: the most accurate of
/// them (the faster where equally accurate) is moved to the front, the answer. Returns how
/// many lead `sorted` in the tie, the answer first (the overlapping ones are a prefix: a
/// faster lobe's fastest pass is at least a slower one's); 0 where the fastest stands alone
/// or nothing is measured. `recommend` and `design` rank alike through it.
pub(crate) fn break_tie<T>(sorted: &mut [T], standing: impl Fn(&T) -> Standing) -> usize {
    let Some(fastest) = sorted
        .first()
        .map(&standing)
        .filter(|s| s.meets && s.spread.is_some())
    else {
        return 0;
    };
    let fastest = (fastest.rate, fastest.spread);
    let tie = sorted
        .iter()
        .map(&standing)
        .take_while(|s| s.meets && rates_overlap((s.rate, s.spread), fastest))
        .count();
    if tie < 2 {
        return 0;
    }
    let answer = (0..tie)
        .min_by(|&a, &b| {
            let (a, b) = (standing(&sorted[a]), standing(&sorted[b]));
            a.error.total_cmp(&b.error).then(b.rate.total_cmp(&a.rate))
        })
        .unwrap_or(0);
    sorted[..=answer].rotate_right(1);
    tie
}

/// `rate` as a multiple of pow's (`1.52x`), or `-` where pow has no cost on the target (no
/// datapath).
#[must_use]
pub fn versus_pow(rate: f64, pow_rate: f64) -> String {
    if pow_rate > 0.0 && pow_rate.is_finite() {
        format!("{:.2}x", rate / pow_rate)
    } else {
        "-".to_owned()
    }
}

fn why(c: &Candidate, best: Option<&str>, pow_rate: f64, target: Target, max_error: f64) -> String {
    let speed = versus_pow(c.rate, pow_rate);
    let relative = if speed == "-" {
        String::new()
    } else {
        format!(" at {speed} pow's throughput")
    };
    if !c.meets {
        if target == Target::Fpga && c.datapath.is_none() {
            return "no fixed-point datapath for this lobe".to_owned();
        }
        if let Some(datapath) = c.datapath.as_deref().filter(|_| c.rate <= 0.0) {
            if c.error <= max_error {
                return format!("{datapath}: it cannot be built on the part");
            }
        }
        if c.error > max_error {
            return format!(
                "error {:.3} % exceeds {:.3} %",
                100.0 * c.error,
                100.0 * max_error
            );
        }
        return format!("energy {:.2} % above t^n's", 100.0 * (c.energy_ratio - 1.0));
    }
    if Some(c.lobe.as_str()) == best {
        return format!("cheapest that meets it{relative}");
    }
    if c.lobe == LobeKind::Pow.id() {
        return "exact, the reference".to_owned();
    }
    format!("meets it{relative}")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_front_keeps_exactly_the_undominated() {
        // (error, rate): b dominates c; a and b trade off; d is dominated by a.
        let points = [(0.0, 1.0), (0.01, 3.0), (0.02, 2.0), (0.001, 0.5)];
        assert_eq!(pareto_front(&points), [true, true, false, false]);
    }
}
