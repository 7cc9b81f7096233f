//! What `recommend` answers: each lobe's figures on the target ([`Candidate`]) and the
//! ranked whole ([`Recommendation`]). Apart from the ranking that builds them
//! (`ranking.rs`) and the measuring that feeds it (`recommend.rs`), so that neither imports
//! the other's.

use serde::Serialize;
use specula::LobeKind;

/// One lobe's figures.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Candidate {
    /// The lobe's id (a user's lobe as its name).
    pub lobe: String,
    /// On the FPGA, the datapath and word length costed (at the first exponent); `None` where
    /// the lobe has no datapath, and off the FPGA.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub datapath: Option<String>,
    /// The worst error over the exponents, as a fraction (infinite where the target cannot
    /// run the lobe).
    pub error: f64,
    /// The cost figure in [`Candidate::unit`], the smallest over the exponents. Higher is
    /// cheaper.
    pub rate: f64,
    /// Where the rate was measured (the CPU), its spread: the median and the fastest of the
    /// timing's passes at the exponent that sets the rate, the slowest (the rate is the
    /// fastest pass's: noise only ever slows a kernel). Two candidates whose spreads overlap
    /// cannot be told apart by this run.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub spread: Option<[f64; 2]>,
    /// On AMD, ACO's own estimate beside the rate: the lobe kernel's inverse throughput beyond
    /// a kernel that only loads and stores, in cycles a wave (the worst over the exponents).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub aco_inverse_throughput: Option<f64>,
    /// Its unit.
    pub unit: &'static str,
    /// The worst energy ratio against `t^n` over the exponents.
    pub energy_ratio: f64,
    /// Whether it meets the error (and the energy condition, if asked).
    pub meets: bool,
    /// No other lobe is at least as accurate and at least as cheap, and better in one.
    pub pareto: bool,
    /// On the FPGA, `rate` is an upper bound, not a synthesis: the lobe was left out of the
    /// synthesis as it could not win, and is on no Pareto front.
    #[serde(skip_serializing_if = "std::ops::Not::not")]
    pub at_most: bool,
    /// Why it stands where it does.
    pub why: String,
}

/// The answer: every candidate, those that meet the request first, cheapest first.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Recommendation {
    /// The unit of every candidate's rate.
    pub unit: &'static str,
    /// What a face should tell its user about how the costs were obtained (the FPGA's tools
    /// missing, so its costs are the formula estimate), if anything.
    pub note: Option<String>,
    /// On a GPU: what the costs are read off, the generation and compiler named.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub basis: Option<String>,
    /// Every candidate: those that meet the request first, the answer first among them, then
    /// by rate, highest first.
    pub candidates: Vec<Candidate>,
    /// Where rates are measured: the lobes that meet the request and whose spreads overlap
    /// the fastest one's, a tie the run cannot break; the answer is the most accurate of
    /// them. Empty where the fastest stands alone, and off the CPU.
    pub tied: Vec<String>,
}

impl Recommendation {
    /// The exact lobe's rate, what "vs pow" compares with (NaN where pow was no candidate).
    #[must_use]
    pub fn pow_rate(&self) -> f64 {
        self.candidates
            .iter()
            .find(|c| c.lobe == LobeKind::Pow.id())
            .map_or(f64::NAN, |c| c.rate)
    }

    /// The cheapest candidate that meets the request, if any does: the first, as those that
    /// meet come first, cheapest first.
    #[must_use]
    pub fn best_candidate(&self) -> Option<&Candidate> {
        self.candidates.first().filter(|c| c.meets)
    }
}
