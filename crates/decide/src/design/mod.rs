//! `specula design`: the cheapest lobe for a target, a range of `n` and an accuracy, searched
//! for in the formula language and proven by the analysis.
//!
//! Each family of [`families`] has its coefficients fitted across the range ([`fit`]), is
//! written as a formula, and is then verified by the same `f64` analysis as `specula analyze`
//! at [`VERIFY_STEPS`]` + 1` log-spaced exponents and `recommend`'s sampled ones: the
//! epicentre's largest relative error and the whole lobe's largest absolute error within
//! their bounds (zone edges solved exactly, [`SWEEP_SAMPLES`] angles per zone), a lobe by the
//! rules ([`specula::Lobe::checked`]: finite, in `[0, 1]`), 1 at `t = 1`, non-decreasing in
//! `t`, and, where asked, its energy within a tolerance of `t^n`'s. The verified ones are
//! costed with the built-ins by [`crate::recommend`] itself (the recorded expression's shader
//! on the GPU models, the compiled batch kernel measured on the CPU), so a designed lobe and a
//! built-in are ranked by one measure.

mod cache;
pub mod families;
mod fit;
pub mod grammar;
pub mod limit;
mod rank;
pub mod thesis;
mod verdict;
mod verify;

pub use verdict::removed;

use indicatif::ProgressBar;
use rayon::prelude::*;
use serde::Serialize;
use specula::formula::Definition;
use specula::{Exponent, LobeKind};

pub use families::Family;
pub use fit::Bounds;
pub use specula_synth::cache::Cache;

pub use crate::percent::percent;
use crate::recommend::Candidate;
use crate::{log_spaced, sample_exponents, Target};
use rank::rank;
use verify::{register, short, unmeasured, verified};

/// The whole lobe's largest absolute error allowed by default, at least: 1 % of the peak,
/// under three 8-bit steps, so that no bloom or tail a display shows is invented.
pub const DEFAULT_WHOLE_ERROR: f64 = 0.01;

/// The whole lobe's bound when none is given: [`DEFAULT_WHOLE_ERROR`], or the epicentre's
/// bound where that is looser (a lobe allowed 2 % at its peak may be 2 % off in its bloom).
#[must_use]
pub fn default_whole_error(epicentre: f64) -> f64 {
    epicentre.max(DEFAULT_WHOLE_ERROR)
}

/// Log-spaced steps of the verification's exponents (beside `recommend`'s).
pub const VERIFY_STEPS: u32 = 48;

/// The fit's score (its epicentre error over the bound, penalties added) above which a family
/// is reported from the fit's own grids instead of verified: a fit this far outside its
/// bounds on the coarse grids cannot meet them on the dense ones, and the verification is
/// most of a design's time.
const FIT_SCORE_WORTH_VERIFYING: f64 = 1.05;

/// Log-spaced steps of the fit's exponents.
const FIT_STEPS: u32 = 16;

/// What to design.
#[derive(Clone, Debug, PartialEq)]
pub struct DesignRequest {
    /// Where the lobe will run.
    pub target: Target,
    /// A GPU target's generation (its vendor's current one where `None`).
    pub gpu: Option<specula::gpus::Gpu>,
    /// The exponents the lobe must hold over, from the first to the second.
    pub range: (Exponent, Exponent),
    /// The bounds: the epicentre's (the error `recommend` counts), the whole lobe's, and the
    /// energy's where asked.
    pub bounds: Bounds,
    /// Only families without a transcendental operation per evaluation (FPGA- and
    /// polynomial-only targets).
    pub no_transcendentals: bool,
    /// Lobes ranked beside the built-ins and the designs (a user's own).
    pub also: Vec<LobeKind>,
    /// The cost bound: the most operations per evaluation a searched structure may have
    /// ([`grammar::DEFAULT_MAX_OPERATIONS`] by default).
    pub max_operations: usize,
}

/// One family's designed lobe and its figures.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct DesignedLobe {
    /// The family's id.
    pub family: String,
    /// The lobe's name (a formula lobe's id).
    pub name: String,
    /// One line on what it is.
    pub description: String,
    /// The formula, coefficients written out.
    pub formula: String,
    /// `int_t^1 lobe`, where the family has a closed form.
    pub tail: Option<String>,
    /// The fitted global coefficients.
    pub coefficients: Vec<f64>,
    /// The worst epicentre relative error over the verification's exponents.
    pub epicentre_error: f64,
    /// The worst whole-lobe absolute error (fraction of the peak).
    pub whole_error: f64,
    /// The worst `|energy ratio - 1|`.
    pub energy_deviation: f64,
    /// Whether the verification ran: the fit came within its bounds on the coarse grids.
    pub checked: bool,
    /// Whether it passed every check at every exponent.
    pub verified: bool,
    /// It passed every check but the whole lobe's bound: what a looser
    /// `--max-whole-error` would admit (costed, never meeting).
    pub short_of_whole_only: bool,
    /// Its cost on the target in [`Design::unit`] (0 where not costed).
    pub rate: f64,
    /// On the FPGA, the datapath compiled from its formula and the word length costed (at
    /// the first exponent), as `recommend` names the built-ins'.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub datapath: Option<String>,
    /// Where the rate was measured (the CPU): the median and fastest passes' rates
    /// ([`Candidate::spread`]).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub spread: Option<[f64; 2]>,
    /// Where rates are measured: the designed lobes whose rates overlap the fastest design's
    /// (a tie this run cannot break), the most accurate of them first, as [`Design::best`].
    /// Empty unless such a tie holds more than one.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub tied: Vec<String>,
    /// Meets every bound and was costed.
    pub meets: bool,
    /// No lobe, designed or built in, is at least as accurate and as cheap, better in one.
    pub pareto: bool,
    /// Why it stands where it does.
    pub why: String,
    #[serde(skip)]
    kind: Option<LobeKind>,
}

impl DesignedLobe {
    /// The lobe as the formula registry holds it (`None` where the text was refused).
    #[must_use]
    pub fn kind(&self) -> Option<LobeKind> {
        self.kind
    }

    /// The lobe file's fields.
    #[must_use]
    pub fn definition(&self) -> Definition {
        Definition {
            name: self.name.clone(),
            description: Some(self.description.clone()),
            formula: self.formula.clone(),
            tail: self.tail.clone(),
            parameters: Default::default(),
        }
    }
}

/// The answer: every designed lobe (those that meet first, cheapest first), the built-ins
/// ranked beside them, and the verdict.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Design {
    /// The unit of every rate.
    pub unit: &'static str,
    /// How many exponents each lobe was verified at.
    pub exponents_verified: usize,
    /// Every structure the grammar wrote, with what became of it (the search's record:
    /// enumerated, pruned, kept).
    pub enumerated: Vec<grammar::Enumerated>,
    /// The designed lobes.
    pub designed: Vec<DesignedLobe>,
    /// The built-ins (and the request's other lobes) as `recommend` ranks them on the same
    /// target and bound.
    pub compared: Vec<Candidate>,
    /// `pow`'s rate, what "vs pow" compares with.
    pub pow_rate: f64,
    /// The designed lobes that met every bound but the whole lobe's, cheapest first: what the
    /// whole-lobe bound removed.
    pub removed_by_whole: Vec<String>,
    /// The whole-lobe bound that admits the cheapest of [`Design::removed_by_whole`], as the
    /// command line takes it (`1.1%`), where one is removed.
    pub admit_whole: Option<String>,
    /// One line: what the search found against the built-ins.
    pub verdict: String,
    /// What the face should tell its user about the costs, if anything.
    pub note: Option<String>,
}

impl Design {
    /// The cheapest designed lobe that meets the request, if any does.
    #[must_use]
    pub fn best(&self) -> Option<&DesignedLobe> {
        self.designed.first().filter(|d| d.meets)
    }

    /// The cheapest lobe not designed here (built in, or given) that meets the request, if
    /// any does.
    #[must_use]
    pub fn best_compared(&self) -> Option<&Candidate> {
        self.compared.first().filter(|c| c.meets)
    }
}

fn check(request: &DesignRequest) -> Result<(), String> {
    let fraction = |what: &str, value: f64| {
        if value.is_finite() && value > 0.0 && value <= 1.0 {
            Ok(())
        } else {
            Err(format!("{what} must be a fraction in (0, 1], not {value}"))
        }
    };
    fraction("the epicentre's largest error", request.bounds.epicentre)?;
    fraction("the whole lobe's largest error", request.bounds.whole)?;
    if let Some(energy) = request.bounds.energy {
        fraction("the energy tolerance", energy)?;
    }
    if request.range.0.get() > request.range.1.get() {
        return Err(format!(
            "the range of n is empty ({}..{}): give LOW..HIGH with LOW <= HIGH in [1, 1000]",
            request.range.0, request.range.1
        ));
    }
    Ok(())
}

/// The exponents a designed lobe is verified at: [`VERIFY_STEPS`]` + 1` log-spaced ones and
/// `recommend`'s, increasing, once each.
#[must_use]
pub fn verification_exponents(low: Exponent, high: Exponent) -> Vec<Exponent> {
    let mut all: Vec<f64> = if low == high {
        vec![low.get()]
    } else {
        log_spaced(low, high, VERIFY_STEPS)
            .into_iter()
            .map(Exponent::get)
            .collect()
    };
    all.extend(sample_exponents(low, high).into_iter().map(Exponent::get));
    all.sort_by(f64::total_cmp);
    all.dedup_by(|a, b| (*a - *b).abs() < 1e-9);
    all.into_iter().map(Exponent::new).collect()
}

/// Searches every family for the cheapest lobe on the target within the bounds over the
/// range; `progress` counts the families fitted, then the lobes costed (pass
/// [`ProgressBar::hidden`] for none). The search is read from the design cache
/// ([`Cache::default_for`]`("design")`) where this build made it before.
pub fn design(request: &DesignRequest, progress: &ProgressBar) -> Result<Design, String> {
    check(request)?;
    let request = &searched_as(request);
    let searched = search(request, Cache::default_for("design").as_ref(), progress);
    answer(request, searched, progress)
}

/// [`design`] for several requests at once, the answers in the requests' order: requests
/// alike but for the target (the search does not see it) share one search, made once, so a
/// page that asks every GPU for the same bound pays for one search, not one per vendor.
/// `progress` counts the searches, then the answers.
pub fn design_each(
    requests: &[DesignRequest],
    progress: &ProgressBar,
) -> Result<Vec<Design>, String> {
    for request in requests {
        check(request)?;
    }
    let requests: Vec<DesignRequest> = requests.iter().map(searched_as).collect();
    let keys: Vec<String> = requests.iter().map(cache::key).collect();
    let mut distinct: Vec<usize> = Vec::new();
    for (k, key) in keys.iter().enumerate() {
        if !distinct.iter().any(|&d| keys[d] == *key) {
            distinct.push(k);
        }
    }
    let cache = Cache::default_for("design");
    let hidden = ProgressBar::hidden();
    progress.set_length((distinct.len() + requests.len()) as u64);
    progress.set_message(format!(
        "fitting and verifying the families for {} distinct request{}",
        distinct.len(),
        if distinct.len() == 1 { "" } else { "s" }
    ));
    let searches: Vec<Vec<DesignedLobe>> = distinct
        .par_iter()
        .map(|&k| {
            let searched = search(&requests[k], cache.as_ref(), &hidden);
            progress.inc(1);
            searched
        })
        .collect();
    progress.set_message("costing the lobes on each target");
    requests
        .par_iter()
        .zip(&keys)
        .map(|(request, key)| {
            let shared = distinct
                .iter()
                .position(|&d| keys[d] == *key)
                .map(|position| searches[position].clone())
                .unwrap_or_default();
            let answered = answer(request, shared, &hidden);
            progress.inc(1);
            answered
        })
        .collect()
}

/// `request` as the search sees it: on the FPGA a lobe is a datapath compiled from its
/// formula, which takes no transcendental (those are the built-in table units' work).
fn searched_as(request: &DesignRequest) -> DesignRequest {
    DesignRequest {
        no_transcendentals: request.no_transcendentals || request.target == Target::Fpga,
        ..request.clone()
    }
}

/// The answer to `request` from its search: the families ranked on its target.
fn answer(
    request: &DesignRequest,
    searched: Vec<DesignedLobe>,
    progress: &ProgressBar,
) -> Result<Design, String> {
    let enumerated = enumeration(request, &searched);
    let mut answer = rank(request, searched, progress)?;
    answer.enumerated = enumerated;
    Ok(answer)
}

/// The grammar's structures for `request`, each with its fate in `searched`.
fn enumeration(request: &DesignRequest, searched: &[DesignedLobe]) -> Vec<grammar::Enumerated> {
    grammar::enumerate(request.max_operations, request.no_transcendentals)
        .into_iter()
        .map(|(family, mut enumerated)| {
            let fitted = searched.iter().find(|d| d.family == family.id());
            if let (grammar::Fate::Kept, Some(lobe)) = (&enumerated.fate, fitted) {
                if !lobe.checked {
                    enumerated.fate = grammar::Fate::FitMissed;
                }
            }
            enumerated
        })
        .collect()
}

/// Every family fitted and verified for `request`'s range and bounds (the target plays no
/// part): read from `cache` where this build searched alike before, else searched and stored.
/// `progress` counts the families. Two processes searching alike at once both search (no
/// lock: a search runs inside rayon's pool, where a thread waiting on a lock its own
/// process holds would wait for ever); the entry is written atomically either way.
#[must_use]
pub(crate) fn search(
    request: &DesignRequest,
    cache: Option<&Cache>,
    progress: &ProgressBar,
) -> Vec<DesignedLobe> {
    let key = cache::key(request);
    if let Some(found) = cache.and_then(|c| cache::load(c, &key, request)) {
        return found;
    }
    let searched = search_now(request, progress);
    if let Some(cache) = cache {
        // A cache that cannot be written costs the next run the search, nothing else.
        let _ = cache::store(cache, &key, &searched);
    }
    searched
}

fn search_now(request: &DesignRequest, progress: &ProgressBar) -> Vec<DesignedLobe> {
    let (low, high) = request.range;
    let families: Vec<Family> =
        grammar::enumerate(request.max_operations, request.no_transcendentals)
            .into_iter()
            .filter(|(_, enumerated)| enumerated.fate == grammar::Fate::Kept)
            .map(|(family, _)| family)
            .collect();
    let grids: Vec<fit::Grid> = if low == high {
        vec![low]
    } else {
        log_spaced(low, high, FIT_STEPS)
    }
    .into_iter()
    .map(|n| fit::Grid::new(n.get()))
    .collect();
    let verify = verification_exponents(low, high);
    progress.set_length(families.len() as u64);
    progress.set_message("fitting and verifying the families");
    let searched = families
        .par_iter()
        .map(|&family| {
            let (beta, score) = fit::fit(family, &grids, request.bounds);
            let lobe = if score <= FIT_SCORE_WORTH_VERIFYING {
                verified(family, &beta, request, &verify)
            } else {
                short(family, &beta, request, &grids)
            };
            progress.inc(1);
            lobe
        })
        .collect();
    progress.reset();
    searched
}

#[cfg(test)]
mod tests;
