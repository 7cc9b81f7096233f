//! Which lobe to ship on a target at an accuracy.
//!
//! Every lobe is measured against `t^n` at each exponent asked for; a lobe's error is its
//! worst over them. Those within the allowed error are ranked by cost on the target: on the
//! CPU, the measured throughput of its SIMD kernel on this machine (one thread, L1, the
//! slowest over the exponents); on a GPU generation, the evaluations per clock per
//! multiprocessor of the machine code its vendor's compiler writes for the lobe (the naga-IR
//! model where the compiler is missing, said so); on the FPGA, its cheapest datapath at the
//! width the error needs, synthesized or estimated ([`crate::costing`]). The Pareto front is
//! taken over every lobe, met or not.

use indicatif::ProgressBar;
use specula::analysis::energy_ratio;
use specula::gpus::Gpu;
use specula::{Exponent, Lobe, LobeKind};

use crate::costing::{compile_ahead, Costing, Point};
use crate::ranking::rank;
pub use crate::recommendation::{Candidate, Recommendation};
use crate::{check_lobes, Target, Zone};
use specula_synth::OnMiss;

/// What to decide: the cheapest of `lobes` on `target` within `max_error` at every exponent.
#[derive(Clone, Debug, PartialEq)]
pub struct Request {
    /// Where the lobe will run.
    pub target: Target,
    /// A GPU target's generation (its vendor's current one where `None`).
    pub gpu: Option<Gpu>,
    /// The exponents the answer must hold at (at least one; see [`crate::sample_exponents`]
    /// for a range).
    pub exponents: Vec<Exponent>,
    /// The largest error allowed, as a fraction in `(0, 1]`.
    pub max_error: f64,
    /// Where the error is measured.
    pub zone: Zone,
    /// Only lobes whose energy stays within 0.1 % of `t^n`'s meet the request.
    pub energy_conserving: bool,
    /// The candidates (at least one), ranked in this order where their costs tie.
    pub lobes: Vec<LobeKind>,
}

impl Request {
    /// Every built-in lobe on `target` at `exponents` within `max_error`, in the epicentre,
    /// energy not asked for.
    #[must_use]
    pub fn new(target: Target, exponents: Vec<Exponent>, max_error: f64) -> Self {
        Self {
            target,
            gpu: None,
            exponents,
            max_error,
            zone: Zone::Epicentre,
            energy_conserving: false,
            lobes: LobeKind::ALL.to_vec(),
        }
    }
}

/// Refuses a request no answer can come from, in one line.
fn check(request: &Request) -> Result<(), String> {
    let max_error = request.max_error;
    if !(max_error.is_finite() && max_error > 0.0 && max_error <= 1.0) {
        return Err(format!(
            "the largest error allowed must be a fraction in (0, 1], not {max_error}"
        ));
    }
    if request.exponents.is_empty() {
        return Err("no exponent to decide at: give at least one n in [1, 1000]".to_owned());
    }
    if request.lobes.is_empty() {
        return Err("no lobe to choose from: give at least one candidate".to_owned());
    }
    check_lobes(&request.lobes, &request.exponents)
}

/// Measures every candidate of `request` on its target and ranks them: those that meet the
/// request first, cheapest first, each with why it stands there. `progress` counts the
/// lobes, names the one being measured, and is cleared at the end (pass
/// [`ProgressBar::hidden`] for none).
pub fn recommend(request: &Request, progress: &ProgressBar) -> Result<Recommendation, String> {
    let mut answers = recommend_each(request, &[request.max_error], progress)?;
    Ok(answers.remove(0))
}

/// [`recommend`] at each of `bounds` in place of `request.max_error`, one answer per bound:
/// each lobe's error, cost and energy are measured once where they do not depend on the
/// bound (the CPU's and the GPUs'), and the FPGA's datapath, whose word length does, is
/// chosen per bound.
pub fn recommend_each(
    request: &Request,
    bounds: &[f64],
    progress: &ProgressBar,
) -> Result<Vec<Recommendation>, String> {
    recommend_each_or(request, bounds, progress, OnMiss::Synthesize).map(|(answers, _)| answers)
}

/// [`recommend_each`] without running Yosys or nextpnr: on the FPGA, where the synthesis that
/// decides the answers is not all in the cache, the answers are the formula estimate's (their
/// note says so) and the count of designs still to synthesize comes with them (0 where nothing
/// is missing, and off the FPGA). A report answers at once this way, and synthesizes after.
pub fn recommend_each_cached(
    request: &Request,
    bounds: &[f64],
    progress: &ProgressBar,
) -> Result<(Vec<Recommendation>, usize), String> {
    recommend_each_or(request, bounds, progress, OnMiss::Skip)
}

fn recommend_each_or(
    request: &Request,
    bounds: &[f64],
    progress: &ProgressBar,
    on_miss: OnMiss,
) -> Result<(Vec<Recommendation>, usize), String> {
    for &max_error in bounds {
        check(&Request {
            max_error,
            lobes: request.lobes.clone(),
            exponents: request.exponents.clone(),
            ..*request
        })?;
    }
    let (mut costing, mut note) = Costing::new(request.target, request.gpu, &request.exponents)?;
    let basis = crate::costing::gpu_basis(request.target, request.gpu)?;
    costing.time_kernels(&request.lobes, &request.exponents, progress);
    if matches!(costing, Costing::Gpu(..)) {
        progress.set_message("compiling the lobes");
        compile_ahead(&costing, &request.lobes, &request.exponents);
    }
    let per_bound = matches!(costing, Costing::Estimated(_) | Costing::Synthesized(_));
    // On the FPGA, synthesis only where it can decide; the rest costed by their estimates.
    let mut plan = match &costing {
        Costing::Synthesized(hardware) => crate::synthesis_plan::synthesize_what_can_win(
            hardware,
            &request.lobes,
            request.zone,
            bounds,
            on_miss,
            progress,
        ),
        _ => crate::synthesis_plan::Plan::default(),
    };
    let pending = plan.missing;
    if let (Costing::Synthesized(hardware), true) = (&costing, pending > 0) {
        costing = Costing::Estimated(hardware.clone());
        plan = crate::synthesis_plan::Plan::default();
        note = Some(format!(
            "the synthesis that decides these answers has not run yet ({pending} or more \
             datapaths not in the cache): FPGA costs are the formula estimate until it has"
        ));
    }
    progress.set_length(request.lobes.len() as u64);
    let mut tallies: Vec<Vec<Tally>> = vec![Vec::new(); bounds.len()];
    for &kind in &request.lobes {
        progress.set_message(kind.to_string());
        let mut lobe_tallies = vec![Tally::default(); bounds.len()];
        let mut energy = 0.0_f64;
        for &n in &request.exponents {
            let lobe = Lobe::new(kind, n);
            energy = energy.max(energy_ratio(&lobe));
            let shared = if per_bound {
                None
            } else {
                Some(costing.point(&lobe, request.zone, bounds[0])?)
            };
            for (tally, &max_error) in lobe_tallies.iter_mut().zip(bounds) {
                let point = match (&shared, plan.ruled_out(kind, max_error)) {
                    (Some(point), _) => point.clone(),
                    (None, Some((at_most, why))) => costing
                        .estimated_point(&lobe, request.zone, max_error)
                        .map(|point| Point {
                            rate: at_most,
                            at_most: true,
                            datapath: point
                                .datapath
                                .map(|datapath| format!("{datapath} ({})", why.says(at_most))),
                            ..point
                        }),
                    (None, None) => costing.point(&lobe, request.zone, max_error)?,
                };
                tally.add(point);
            }
        }
        for (all, mut tally) in tallies.iter_mut().zip(lobe_tallies) {
            tally.energy = energy;
            tally.kind = Some(kind);
            all.push(tally);
        }
        progress.inc(1);
    }
    progress.finish_and_clear();
    let unit = costing.unit();
    let answers = tallies
        .into_iter()
        .zip(bounds)
        .map(|(tallies, &max_error)| {
            let candidates = tallies
                .into_iter()
                .map(|tally| tally.candidate(unit, max_error, request.energy_conserving))
                .collect();
            let note = match (note.clone(), plan.note(max_error)) {
                (Some(note), Some(plan)) => Some(format!("{note}; {plan}")),
                (note, plan) => note.or(plan),
            };
            let mut answer = rank(candidates, unit, note, request.target, max_error);
            answer.basis.clone_from(&basis);
            answer
        })
        .collect();
    Ok((answers, pending))
}

/// One lobe's measurements over the request's exponents, at one bound.
#[derive(Clone, Debug, Default)]
struct Tally {
    kind: Option<LobeKind>,
    /// The largest error over the exponents.
    error: f64,
    /// The lowest rate over the exponents (`None` before the first).
    cheapest: Option<f64>,
    /// The datapath named at the first exponent, or the one that cannot be built.
    datapath: Option<String>,
    /// Measured: the median and fastest passes' rates at the slowest exponent so far.
    spread: Option<[f64; 2]>,
    /// Some exponent has no datapath.
    unavailable: bool,
    /// ACO's estimate, the worst over the exponents.
    aco_inverse_throughput: Option<f64>,
    /// Some exponent's rate is a bound, not a synthesis.
    at_most: bool,
    energy: f64,
}

impl Tally {
    fn add(&mut self, point: Option<Point>) {
        let Some(point) = point else {
            self.unavailable = true;
            return;
        };
        self.error = self.error.max(point.error);
        self.at_most |= point.at_most;
        if let Some(cycles) = point.aco_inverse_throughput {
            self.aco_inverse_throughput = Some(
                self.aco_inverse_throughput
                    .map_or(cycles, |c| c.max(cycles)),
            );
        }
        // The spread is the slowest exponent's, the one that sets the rate.
        if self.cheapest.is_none_or(|c| point.rate < c) {
            self.spread = point.spread;
        }
        self.cheapest = Some(self.cheapest.map_or(point.rate, |c| c.min(point.rate)));
        // The first exponent's datapath names the lobe's, unless one cannot be built: that
        // one says why the lobe does not meet the request.
        self.datapath = if point.rate <= 0.0 && point.datapath.is_some() {
            point.datapath
        } else {
            self.datapath.take().or(point.datapath)
        };
    }

    fn candidate(self, unit: &'static str, max_error: f64, energy_conserving: bool) -> Candidate {
        let spread = self.spread;
        let (error, rate, datapath) = if self.unavailable {
            (f64::INFINITY, 0.0, None)
        } else {
            (
                self.error,
                self.cheapest.unwrap_or(f64::INFINITY),
                self.datapath,
            )
        };
        // A rate of 0 is a lobe the target cannot run (a datapath that does not fit the part).
        let meets =
            error <= max_error && rate > 0.0 && (!energy_conserving || self.energy <= 1.001);
        Candidate {
            lobe: self.kind.map(|k| k.to_string()).unwrap_or_default(),
            datapath,
            error,
            rate,
            spread: spread.filter(|_| !self.unavailable),
            aco_inverse_throughput: self.aco_inverse_throughput,
            unit,
            energy_ratio: self.energy,
            meets,
            pareto: false,
            at_most: self.at_most,
            why: String::new(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A datapath nextpnr could not place (rate 0, named "does not fit") does not meet even
    /// within the error, and ranks below one that was placed.
    #[test]
    fn a_datapath_that_does_not_fit_the_part_does_not_meet() {
        let tally = |kind: LobeKind, rate: f64, datapath: &str| {
            let mut tally = Tally {
                kind: Some(kind),
                ..Tally::default()
            };
            tally.add(Some(Point {
                error: 0.03,
                rate,
                datapath: Some(datapath.to_owned()),
                spread: None,
                aco_inverse_throughput: None,
                at_most: false,
            }));
            tally.candidate("unit", 0.05, false)
        };
        let unfit = tally(
            LobeKind::SchlickMod,
            0.0,
            "schlick-mod at 16 bits (does not fit the iCE40 HX8K)",
        );
        let placed = tally(LobeKind::Sg, 2.5, "sg at 14 bits");
        let answer = rank(vec![unfit, placed], "unit", None, Target::Fpga, 0.05);
        let [first, second] = answer.candidates.as_slice() else {
            panic!("two candidates: {:?}", answer.candidates);
        };
        assert!(first.meets && first.lobe == LobeKind::Sg.id(), "{first:?}");
        assert!(!second.meets && second.rate == 0.0, "{second:?}");
        assert!(second.datapath.as_deref().unwrap().contains("does not fit"));
    }

    #[test]
    fn bad_requests_are_refused_in_one_line() {
        let n = vec![Exponent::new(64.0)];
        for max_error in [0.0, -0.01, 1.5, f64::NAN, f64::INFINITY] {
            let request = Request::new(Target::GpuAmd, n.clone(), max_error);
            let refusal = recommend(&request, &ProgressBar::hidden()).unwrap_err();
            assert_eq!(refusal.lines().count(), 1, "{refusal}");
        }
        let none = Request::new(Target::GpuAmd, Vec::new(), 0.01);
        assert!(recommend(&none, &ProgressBar::hidden()).is_err());
        let empty = Request {
            lobes: Vec::new(),
            ..Request::new(Target::GpuAmd, n, 0.01)
        };
        assert!(recommend(&empty, &ProgressBar::hidden()).is_err());
    }

    /// Measuring once for several bounds answers as measuring for each: the same candidates,
    /// order and reasons.
    #[test]
    fn answers_at_several_bounds_are_the_answers_at_each() {
        let bounds = [0.005, 0.02, 0.1];
        let request = Request::new(Target::GpuAmd, vec![Exponent::new(64.0)], bounds[0]);
        let together = recommend_each(&request, &bounds, &ProgressBar::hidden()).unwrap();
        for (answer, max_error) in together.iter().zip(bounds) {
            let alone = Request {
                max_error,
                ..request.clone()
            };
            assert_eq!(answer, &recommend(&alone, &ProgressBar::hidden()).unwrap());
        }
        let met = |answer: &Recommendation| answer.candidates.iter().filter(|c| c.meets).count();
        assert!(
            met(&together[0]) < met(&together[2]),
            "the bounds admit different lobes"
        );
    }

    #[test]
    fn on_a_gpu_the_exact_lobe_always_meets_and_the_met_come_first() {
        let request = Request::new(Target::GpuNvidia, vec![Exponent::new(64.0)], 0.01);
        let answer = recommend(&request, &ProgressBar::hidden()).unwrap();
        assert_eq!(answer.candidates.len(), LobeKind::ALL.len());
        assert!(answer.note.is_none());
        let pow = answer.candidates.iter().find(|c| c.lobe == "pow").unwrap();
        assert!(pow.meets && pow.error == 0.0, "{pow:?}");
        let best = answer.best_candidate().expect("pow at least meets");
        assert!(
            best.why.starts_with("cheapest that meets it"),
            "{}",
            best.why
        );
        let met: Vec<f64> = answer
            .candidates
            .iter()
            .take_while(|c| c.meets)
            .map(|c| c.rate)
            .collect();
        assert!(met.windows(2).all(|w| w[0] >= w[1]), "{met:?}");
        assert!(
            answer.candidates[met.len()..].iter().all(|c| !c.meets),
            "every lobe that meets comes before every one that does not"
        );
        assert!(answer.candidates.iter().all(|c| c.datapath.is_none()));
    }
}
