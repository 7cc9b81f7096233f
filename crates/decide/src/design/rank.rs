//! Ranking the searched lobes beside the built-ins on the request's target, as `recommend`
//! ranks them: the costed answer, its Pareto front and a measured tie's most accurate lobe.

use indicatif::ProgressBar;
use specula::LobeKind;

use super::{verdict, verification_exponents, Design, DesignRequest, DesignedLobe};
use crate::percent::flag_percent_above;
use crate::ranking::{pareto_front, Standing};
use crate::recommend::{recommend, Candidate, Request};
use crate::{sample_exponents, Zone};

/// Ranks the searched lobes with the built-ins (and the request's other lobes) on the
/// request's target, as `recommend` does: the costed answer.
pub(super) fn rank(
    request: &DesignRequest,
    mut designed: Vec<DesignedLobe>,
    progress: &ProgressBar,
) -> Result<Design, String> {
    let (low, high) = request.range;
    // The lobes short of the whole lobe's bound alone are costed too: what that bound removed.
    let kinds: Vec<LobeKind> = designed
        .iter()
        .filter(|d| d.verified || d.short_of_whole_only)
        .filter_map(DesignedLobe::kind)
        .collect();
    let mut lobes = crate::candidates(&request.also);
    let compared_ids: Vec<String> = lobes.iter().map(LobeKind::to_string).collect();
    lobes.extend(&kinds);
    let ranking = recommend(
        &Request {
            target: request.target,
            gpu: request.gpu,
            exponents: sample_exponents(low, high),
            max_error: request.bounds.epicentre,
            zone: Zone::Epicentre,
            energy_conserving: false,
            lobes,
        },
        progress,
    )?;
    let pow_rate = ranking.pow_rate();
    for lobe in &mut designed {
        let costed = ranking.candidates.iter().find(|c| c.lobe == lobe.name);
        if let Some(costed) = costed {
            lobe.rate = costed.rate;
            lobe.datapath.clone_from(&costed.datapath);
            lobe.spread = costed.spread;
            lobe.meets = lobe.verified && costed.meets;
            if lobe.meets && costed.at_most {
                lobe.why = format!(
                    "meets every bound, at most {:.2}x pow's throughput: not synthesized \
                     whole, as it cannot win",
                    costed.rate / pow_rate
                );
            } else if lobe.meets {
                lobe.why = format!(
                    "meets every bound at {:.2}x pow's throughput",
                    costed.rate / pow_rate
                );
            } else if !costed.meets {
                lobe.why.clone_from(&costed.why);
            }
        }
    }
    let compared: Vec<Candidate> = ranking
        .candidates
        .iter()
        .filter(|c| compared_ids.contains(&c.lobe))
        .cloned()
        .collect();
    let bounds_only: Vec<String> = ranking
        .candidates
        .iter()
        .filter(|c| c.at_most)
        .map(|c| c.lobe.clone())
        .collect();
    mark_front(&mut designed, &compared, &bounds_only);
    designed.sort_by(|a, b| b.meets.cmp(&a.meets).then(b.rate.total_cmp(&a.rate)));
    break_tie(&mut designed);
    let removed: Vec<&DesignedLobe> = designed
        .iter()
        .filter(|d| d.short_of_whole_only && d.rate > 0.0)
        .collect();
    let admit_whole = removed.first().map(|d| flag_percent_above(d.whole_error));
    let removed_by_whole = removed.iter().map(|d| d.name.clone()).collect();
    let mut answer = Design {
        unit: ranking.unit,
        enumerated: Vec::new(),
        exponents_verified: verification_exponents(low, high).len(),
        designed,
        compared,
        pow_rate,
        removed_by_whole,
        admit_whole,
        verdict: String::new(),
        note: ranking.note,
    };
    answer.verdict = verdict::verdict(&answer, request);
    Ok(answer)
}

/// Where the fastest designs' measured rates overlap, the most accurate of them first (as
/// `recommend` breaks its ties), the tie recorded in that lobe's [`DesignedLobe::tied`].
pub(super) fn break_tie(sorted: &mut [DesignedLobe]) {
    let tie = crate::ranking::break_tie(sorted, |d| Standing {
        meets: d.meets,
        rate: d.rate,
        spread: d.spread,
        error: d.epicentre_error,
    });
    let names = sorted[..tie].iter().map(|d| d.name.clone()).collect();
    if let Some(answer) = sorted.first_mut() {
        answer.tied = names;
    }
}

/// Marks the designed lobes no lobe (designed or built in) dominates in error and rate.
fn mark_front(designed: &mut [DesignedLobe], compared: &[Candidate], bounds_only: &[String]) {
    // A rate that is only a bound (FPGA, not synthesized whole) is no point of the front.
    let placed = |d: &DesignedLobe| d.rate > 0.0 && !bounds_only.contains(&d.name);
    let points: Vec<(f64, f64)> = designed
        .iter()
        .filter(|d| placed(d))
        .map(|d| (d.epicentre_error, d.rate))
        .chain(
            compared
                .iter()
                .filter(|c| !c.at_most)
                .map(|c| (c.error, c.rate)),
        )
        .collect();
    let front = pareto_front(&points);
    let mut on_front = front.into_iter();
    for lobe in designed.iter_mut() {
        lobe.pareto = placed(lobe) && on_front.next().unwrap_or(false);
    }
}
