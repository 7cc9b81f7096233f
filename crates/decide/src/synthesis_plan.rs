//! Synthesis only where it decides: on the FPGA every candidate is first costed by its
//! estimate (the datapath's logic cells, no tool run); Yosys and nextpnr then run in the
//! order of the estimates, as many lobes side by side as there are cores. A lobe's rate is
//! its lowest over the exponents, so each lobe is synthesized first at the exponent its
//! estimate finds weakest: where that alone is below the best whole lobe so far, the lobe
//! cannot win and nothing more of it is synthesized (exact). The lobes whose estimates are
//! below the best even at [`MARGIN`] times the largest synthesized-to-estimated ratio seen are
//! not synthesized at all (the estimate ranks datapaths well but not exactly: that ratio
//! spans about 2x over the built-ins, which the margin covers half again). The answer's note
//! says which lobes each rule left out.

use rayon::prelude::*;
use specula::{Exponent, LobeKind};
use specula_hw::analysis::WidthSweep;
use specula_hw::HwLobe;
use specula_synth::OnMiss;

use crate::costing::{synthesized_rate, FPGA_TARGET};
use crate::hardware::cheapest_datapath;
use crate::Zone;

/// How far beyond the largest synthesized-to-estimated ratio seen a lobe's synthesis could
/// still land before it is ruled out. 1: the largest ratio seen is a single design's, and a
/// lobe's rate is its lowest over the exponents, whose ratio has stayed below it (measured
/// over the README's `design --target fpga --n 8..512 --max-error 2%`: every candidate
/// synthesized at its weakest exponent, lobe ratios from 1.4 to 10.1 against 11.8 for the
/// first designs; docs/hardware.md).
pub(crate) const MARGIN: f64 = 1.0;

/// How a lobe was ruled out.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) enum Why {
    /// Its estimate, even at [`MARGIN`] times the largest synthesized-to-estimated ratio
    /// seen, is below the best synthesized rate (nothing of it synthesized).
    Estimate,
    /// Its datapath at its weakest exponent (by the estimate), synthesized, is already below
    /// the best: a lobe's rate is its lowest over the exponents, so it cannot win (exact).
    Synthesis,
    /// Its datapath misses the bound at some exponent: it cannot meet the request, and no
    /// tool runs for it.
    Short,
}

impl Why {
    /// What a ruled-out datapath's name gains: why it was not synthesized whole.
    pub(crate) fn says(self, at_most: f64) -> String {
        match self {
            Why::Estimate => format!("not synthesized: at most {at_most:.3e} by its estimate"),
            Why::Synthesis => {
                format!("not synthesized whole: at most {at_most:.3e} at its weakest n")
            }
            Why::Short => "not synthesized: short of the error at some n".to_owned(),
        }
    }
}

/// A lobe left unsynthesized (or synthesized at one exponent) at one bound: its rate is at
/// most `at_most`, below the best synthesized one.
#[derive(Clone, Debug)]
pub(crate) struct RuledOut {
    pub max_error: f64,
    pub kind: LobeKind,
    pub at_most: f64,
    pub why: Why,
}

/// What the plan did: the lobes ruled out at each bound and the designs synthesized.
#[derive(Clone, Debug, Default)]
pub(crate) struct Plan {
    pub ruled_out: Vec<RuledOut>,
    pub synthesized: usize,
    /// Designs the plan needed that the cache lacked, where it was not to synthesize
    /// ([`OnMiss::Skip`]): the plan stopped at the first wave that missed one.
    pub missing: usize,
}

impl Plan {
    /// The lobe's upper bound at `max_error` and why, where it was ruled out there.
    pub(crate) fn ruled_out(&self, kind: LobeKind, max_error: f64) -> Option<(f64, Why)> {
        self.ruled_out
            .iter()
            .find(|r| r.kind == kind && r.max_error == max_error)
            .map(|r| (r.at_most, r.why))
    }

    /// A sentence for the answer's note, or `None` where nothing was ruled out.
    pub(crate) fn note(&self, max_error: f64) -> Option<String> {
        let named = |why: Why| {
            self.ruled_out
                .iter()
                .filter(|r| r.max_error == max_error && r.why == why)
                .map(|r| r.kind.to_string())
                .collect::<Vec<_>>()
                .join(", ")
        };
        let (by_estimate, by_synthesis) = (named(Why::Estimate), named(Why::Synthesis));
        if by_estimate.is_empty() && by_synthesis.is_empty() {
            return None;
        }
        let mut note = format!(
            "{} datapaths synthesized, only where they could decide",
            self.synthesized
        );
        if !by_synthesis.is_empty() {
            note += &format!(
                "; below the best at their weakest exponent, the rest not synthesized: \
                 {by_synthesis}"
            );
        }
        if !by_estimate.is_empty() {
            note += &format!(
                "; ruled out by their estimates (below the best even at {MARGIN}x the largest \
                 synthesized-to-estimated ratio seen): {by_estimate}"
            );
        }
        Some(note)
    }
}

/// One candidate's datapaths over the exponents at one bound, each with its estimated rate,
/// and the lobe's estimated rate (the lowest over the exponents, as a lobe's rate is).
#[derive(Clone)]
struct Candidate {
    kind: LobeKind,
    designs: Vec<((HwLobe, u32), f64)>,
    estimate: f64,
}

impl Candidate {
    /// `kind` with its designs and their estimates (`None` for none).
    fn new(kind: LobeKind, designs: Vec<((HwLobe, u32), f64)>) -> Option<Self> {
        let estimate = designs
            .iter()
            .map(|&(_, e)| e)
            .fold(f64::INFINITY, f64::min);
        (!designs.is_empty()).then_some(Self {
            kind,
            designs,
            estimate,
        })
    }

    /// The design at the exponent the estimate finds weakest.
    fn weakest(&self) -> (HwLobe, u32) {
        self.designs
            .iter()
            .min_by(|a, b| a.1.total_cmp(&b.1))
            .map(|&(design, _)| design)
            .unwrap_or_else(|| unreachable!("a candidate has a design per exponent"))
    }
}

/// The candidates' lobes, named for a progress message.
fn names<'c>(candidates: impl IntoIterator<Item = &'c Candidate>) -> String {
    candidates
        .into_iter()
        .map(|c| c.kind.to_string())
        .collect::<Vec<_>>()
        .join(", ")
}

/// What the plan asks of the tools: synthesize designs side by side, then their rates.
trait Synthesizer {
    /// Synthesizes those of `designs` not yet done.
    fn run(&mut self, designs: &[(HwLobe, u32)]);
    /// A design's rate once done (0 where the tools failed on it).
    fn rate(&self, design: (HwLobe, u32)) -> Option<f64>;
    /// Designs the cache lacked where the plan was not to synthesize.
    fn missing(&self) -> usize;
    /// Designs done.
    fn done(&self) -> usize;
}

/// Yosys and nextpnr through the synthesis cache: the designs done so far, each with its
/// rate.
struct Synthesized {
    cache: Option<specula_synth::cache::Cache>,
    on_miss: OnMiss,
    rates: Vec<((HwLobe, u32), f64)>,
    /// Designs the cache lacked under [`OnMiss::Skip`].
    missing: usize,
}

impl Synthesizer for Synthesized {
    fn run(&mut self, designs: &[(HwLobe, u32)]) {
        let mut todo: Vec<(HwLobe, u32)> = Vec::new();
        for &design in designs {
            if !todo.contains(&design) && self.rate(design).is_none() {
                todo.push(design);
            }
        }
        let (cache, on_miss) = (self.cache.as_ref(), self.on_miss);
        let rates: Vec<((HwLobe, u32), Option<f64>)> = todo
            .par_iter()
            .map(|&(lobe, bits)| {
                // A failure costs 0 here; the lobe's own costing reports it by name.
                let rate =
                    match specula_synth::synthesize_or(lobe, bits, FPGA_TARGET, cache, on_miss) {
                        Ok(Some(synthesis)) => Some(synthesized_rate(&synthesis).0),
                        Ok(None) => None,
                        Err(_) => Some(0.0),
                    };
                ((lobe, bits), rate)
            })
            .collect();
        for (design, rate) in rates {
            match rate {
                Some(rate) => self.rates.push((design, rate)),
                None => self.missing += 1,
            }
        }
    }

    fn rate(&self, design: (HwLobe, u32)) -> Option<f64> {
        self.rates
            .iter()
            .find(|(done, _)| *done == design)
            .map(|&(_, rate)| rate)
    }

    fn missing(&self) -> usize {
        self.missing
    }

    fn done(&self) -> usize {
        self.rates.len()
    }
}

/// Synthesizes, for each of `bounds`, what decides the cheapest of `lobes` whose datapaths
/// meet the bound at every exponent: best estimate first, a wave of as many lobes as cores,
/// each wave's lobes first at their weakest exponent (a bound on their rate), then whole
/// where that bound can still win; `progress` is told each wave.
pub(crate) fn synthesize_what_can_win(
    hardware: &[(Exponent, std::sync::Arc<Vec<WidthSweep>>)],
    lobes: &[LobeKind],
    zone: Zone,
    bounds: &[f64],
    on_miss: OnMiss,
    progress: &indicatif::ProgressBar,
) -> Plan {
    let wave = std::thread::available_parallelism().map_or(2, std::num::NonZeroUsize::get);
    let mut plan = Plan::default();
    let mut tools = Synthesized {
        cache: specula_synth::cache::Cache::default_location(),
        on_miss,
        rates: Vec::new(),
        missing: 0,
    };
    for &max_error in bounds {
        if tools.missing() > 0 {
            break;
        }
        let candidates = candidates(hardware, lobes, zone, max_error, &mut plan);
        decide(candidates, max_error, wave, &mut tools, &mut plan, progress);
    }
    plan.synthesized = tools.done();
    plan.missing = tools.missing();
    plan
}

/// The lobes whose datapaths meet `max_error` at every exponent, with their designs and
/// estimates; those short of it at some exponent are ruled out in `plan`.
fn candidates(
    hardware: &[(Exponent, std::sync::Arc<Vec<WidthSweep>>)],
    lobes: &[LobeKind],
    zone: Zone,
    max_error: f64,
    plan: &mut Plan,
) -> Vec<Candidate> {
    lobes
        .iter()
        .filter_map(|&kind| {
            let mut designs = Vec::new();
            for (_, sweeps) in hardware {
                // No datapath: the costing says so; one short of the bound: ruled out.
                let chosen = cheapest_datapath(sweeps, kind, zone, max_error)?;
                if chosen.error > max_error {
                    plan.ruled_out.push(RuledOut {
                        max_error,
                        kind,
                        at_most: 0.0,
                        why: Why::Short,
                    });
                    return None;
                }
                let design = (chosen.lobe, chosen.bits);
                if !designs.iter().any(|&(d, _)| d == design) {
                    designs.push((design, 1e3 / chosen.cells as f64));
                }
            }
            Candidate::new(kind, designs)
        })
        .collect()
}

/// Runs the plan over `candidates` at one bound with `tools`, recording in `plan` what it
/// ruled out and why.
fn decide(
    mut candidates: Vec<Candidate>,
    max_error: f64,
    wave: usize,
    tools: &mut impl Synthesizer,
    plan: &mut Plan,
    progress: &indicatif::ProgressBar,
) {
    candidates.sort_by(|a, b| b.estimate.total_cmp(&a.estimate));
    // The best whole lobe's synthesized rate so far, and the largest ratio of a design's
    // synthesized rate to its estimate.
    let (mut best, mut ratio) = (0.0_f64, 0.0_f64);
    let mut next = 0;
    while next < candidates.len() {
        let first = &candidates[next];
        if best > 0.0 && first.estimate * ratio * MARGIN < best {
            // In falling order of estimate: none after it can win either.
            plan.ruled_out
                .extend(candidates[next..].iter().map(|c| RuledOut {
                    max_error,
                    kind: c.kind,
                    at_most: c.estimate * ratio * MARGIN,
                    why: Why::Estimate,
                }));
            break;
        }
        let this_wave = &candidates[next..(next + wave).min(candidates.len())];
        next += this_wave.len();
        // The first wave is synthesized whole at once: nothing yet to fall short of.
        if best > 0.0 {
            progress.set_message(format!(
                "synthesizing {} at their weakest n",
                names(this_wave)
            ));
            let weakest: Vec<(HwLobe, u32)> = this_wave.iter().map(Candidate::weakest).collect();
            tools.run(&weakest);
            if tools.missing() > 0 {
                break;
            }
        }
        let mut whole = Vec::new();
        for candidate in this_wave {
            let at_most = tools.rate(candidate.weakest()).unwrap_or(0.0);
            if best > 0.0 && at_most < best {
                plan.ruled_out.push(RuledOut {
                    max_error,
                    kind: candidate.kind,
                    at_most,
                    why: Why::Synthesis,
                });
            } else {
                whole.push(candidate);
            }
        }
        progress.set_message(format!(
            "synthesizing {} at every n",
            names(whole.iter().copied())
        ));
        let designs: Vec<(HwLobe, u32)> = whole
            .iter()
            .flat_map(|c| c.designs.iter().map(|&(design, _)| design))
            .collect();
        tools.run(&designs);
        if tools.missing() > 0 {
            break;
        }
        for candidate in whole {
            let mut lowest = f64::INFINITY;
            for &(design, estimate) in &candidate.designs {
                let rate = tools.rate(design).unwrap_or(0.0);
                lowest = lowest.min(rate);
                if rate > 0.0 {
                    ratio = ratio.max(rate / estimate);
                }
            }
            best = best.max(lowest);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::{decide, Candidate, Plan, Synthesizer, Why};
    use specula::LobeKind;
    use specula_hw::HwLobe;

    /// Tools whose every design's rate is known in advance, counting what they synthesize.
    struct Known {
        rates: Vec<((HwLobe, u32), f64)>,
        done: Vec<(HwLobe, u32)>,
    }

    impl Synthesizer for Known {
        fn run(&mut self, designs: &[(HwLobe, u32)]) {
            for design in designs {
                if !self.done.contains(design) {
                    self.done.push(*design);
                }
            }
        }
        fn rate(&self, design: (HwLobe, u32)) -> Option<f64> {
            self.done.contains(&design).then(|| {
                self.rates
                    .iter()
                    .find(|(d, _)| *d == design)
                    .map_or(0.0, |&(_, rate)| rate)
            })
        }
        fn missing(&self) -> usize {
            0
        }
        fn done(&self) -> usize {
            self.done.len()
        }
    }

    /// A pseudo-random number in [0, 1).
    fn uniform(state: &mut u64) -> f64 {
        *state ^= *state << 13;
        *state ^= *state >> 7;
        *state ^= *state << 17;
        (*state >> 11) as f64 / (1u64 << 53) as f64
    }

    /// `lobes` candidates of three designs each, estimates in [0.5, 1.5] and each design's
    /// synthesized rate its estimate times a ratio from `ratio`; the two best estimates (the
    /// first wave) hold a design at the largest ratio.
    fn case(state: &mut u64, lobes: usize, ratio: (f64, f64)) -> (Vec<Candidate>, Known) {
        let mut rates = Vec::new();
        let mut candidates: Vec<Candidate> = (0..lobes)
            .map(|l| {
                let designs: Vec<((HwLobe, u32), f64)> = (0..3)
                    .map(|d| {
                        let design = (HwLobe::Schlick, (3 * l + d) as u32);
                        let estimate = 0.5 + uniform(state);
                        let r = ratio.0 + (ratio.1 - ratio.0) * uniform(state);
                        rates.push((design, estimate * r));
                        (design, estimate)
                    })
                    .collect();
                Candidate::new(LobeKind::ALL[l], designs).expect("three designs")
            })
            .collect();
        candidates.sort_by(|a, b| b.estimate.total_cmp(&a.estimate));
        for candidate in &candidates[..2] {
            let (design, estimate) = candidate.designs[0];
            if let Some(rate) = rates.iter_mut().find(|(d, _)| *d == design) {
                rate.1 = estimate * ratio.1;
            }
        }
        let tools = Known {
            rates,
            done: Vec::new(),
        };
        (candidates, tools)
    }

    /// The lobe's rate: its lowest design's.
    fn rate_of(candidate: &Candidate, rates: &[((HwLobe, u32), f64)]) -> f64 {
        candidate
            .designs
            .iter()
            .map(|(design, _)| rates.iter().find(|(d, _)| d == design).map_or(0.0, |r| r.1))
            .fold(f64::INFINITY, f64::min)
    }

    /// Where the first wave holds the largest synthesized-to-estimated ratio, the plan finds
    /// the lobe that synthesizing everything finds, synthesizes every design of each lobe it
    /// keeps, and synthesizes fewer designs than everything.
    #[test]
    fn the_plan_finds_what_synthesizing_everything_finds() {
        let mut state = 0x2545_F491_4F6C_DD1D_u64;
        let mut saved = 0;
        for _ in 0..200 {
            let (candidates, mut tools) = case(&mut state, 10, (5.0, 12.0));
            let everything = candidates
                .iter()
                .map(|c| rate_of(c, &tools.rates))
                .fold(0.0, f64::max);
            let mut plan = Plan::default();
            decide(
                candidates.clone(),
                0.02,
                2,
                &mut tools,
                &mut plan,
                &indicatif::ProgressBar::hidden(),
            );
            let kept: Vec<&Candidate> = candidates
                .iter()
                .filter(|c| plan.ruled_out(c.kind, 0.02).is_none())
                .collect();
            for candidate in &kept {
                assert!(candidate
                    .designs
                    .iter()
                    .all(|(design, _)| tools.rate(*design).is_some()));
            }
            let found = kept
                .iter()
                .map(|c| rate_of(c, &tools.rates))
                .fold(0.0, f64::max);
            assert_eq!(found, everything);
            for ruled in &plan.ruled_out {
                let candidate = candidates.iter().find(|c| c.kind == ruled.kind).unwrap();
                assert!(
                    rate_of(candidate, &tools.rates) <= ruled.at_most,
                    "{ruled:?}"
                );
            }
            saved += 30 - tools.done.len();
        }
        assert!(saved > 0, "the plan synthesized everything every time");
    }

    /// A lobe whose estimate is high but whose weakest exponent synthesizes below the best is
    /// ruled out by that one synthesis, its other designs left alone.
    #[test]
    fn a_weak_exponent_rules_a_lobe_out_after_one_synthesis() {
        let design = |k: u32| (HwLobe::Schlick, k);
        // pow: rate 11 (its weaker design), and a design 20 times its estimate.
        let strong =
            Candidate::new(LobeKind::Pow, vec![(design(0), 1.1), (design(1), 1.5)]).unwrap();
        let weak_somewhere =
            Candidate::new(LobeKind::Sg, vec![(design(2), 1.05), (design(3), 1.3)]).unwrap();
        let third = Candidate::new(LobeKind::ALL[3], vec![(design(4), 0.5)]).unwrap();
        let mut tools = Known {
            rates: vec![
                (design(0), 11.0),
                (design(1), 30.0),
                (design(2), 2.0),
                (design(3), 12.0),
                (design(4), 1.0),
            ],
            done: Vec::new(),
        };
        let mut plan = Plan::default();
        // One lobe a wave, so that each decision follows the last.
        decide(
            vec![strong, weak_somewhere, third],
            0.02,
            1,
            &mut tools,
            &mut plan,
            &indicatif::ProgressBar::hidden(),
        );
        assert_eq!(
            plan.ruled_out(LobeKind::Sg, 0.02),
            Some((2.0, Why::Synthesis))
        );
        assert!(
            tools.rate(design(3)).is_none(),
            "sg's other design was synthesized"
        );
        // The third's estimate, 0.5, at the largest ratio seen (20) is below pow's 11.
        assert_eq!(
            plan.ruled_out(LobeKind::ALL[3], 0.02).map(|(_, why)| why),
            Some(Why::Estimate)
        );
    }
}
