//! The fixed-point datapaths' sweeps over word lengths, from which the FPGA's answers choose a
//! datapath and a width: [`sweeps`] for any selection, [`hardware_sweeps`] for every datapath
//! at every width at the samples `recommend` measures with, memoised per exponent so that the
//! report's cells, its hardware section and repeated requests share one computation.

use std::collections::BTreeMap;
use std::sync::{Arc, Mutex, PoisonError};

use indicatif::ProgressBar;
use rayon::prelude::*;
use specula::LobeKind;
use specula_hw::analysis::{sweep, WidthSweep};
use specula_hw::{HwLobe, BITS};

use specula_synth::cache::Cache;

use crate::analyses;
use crate::fpga_estimate::logic_cells;
use crate::Zone;

/// Angles sampled per zone in the sweeps the decisions read (as `recommend`'s float errors).
pub(crate) const SWEEP_SAMPLES: usize = 20_001;

/// Sweeps each of `lobes` at the integer exponent `n` over the word lengths `low..=high` with
/// `samples` angles per zone, in parallel; `progress` counts the widths (pass
/// [`ProgressBar::hidden`] for none) and is cleared at the end.
pub fn sweeps(
    lobes: &[HwLobe],
    n: u32,
    (low, high): (u32, u32),
    samples: usize,
    progress: &ProgressBar,
) -> Result<Vec<WidthSweep>, String> {
    let widths = u64::from(high.saturating_sub(low) + 1);
    progress.set_length(lobes.len() as u64 * widths);
    let result = lobes
        .par_iter()
        .map(|&lobe| sweep(lobe, n, low..=high, samples, &mut |_| progress.inc(1)))
        .collect::<Result<Vec<_>, _>>()
        .map_err(|e| e.to_string());
    progress.finish_and_clear();
    result
}

/// Every datapath's sweep over every word length ([`BITS`]) at the integer exponent `n`, with
/// [`SWEEP_SAMPLES`] angles per zone: what `recommend --target fpga` chooses from. Computed
/// once per `n` in a process (a pure function of it) and shared after, and read back from
/// disk by a later process of the same build ([`analyses`]).
pub fn hardware_sweeps(n: u32) -> Result<Arc<Vec<WidthSweep>>, String> {
    static MEMO: Mutex<BTreeMap<u32, Arc<Vec<WidthSweep>>>> = Mutex::new(BTreeMap::new());
    let memo = || MEMO.lock().unwrap_or_else(PoisonError::into_inner);
    if let Some(known) = memo().get(&n) {
        return Ok(Arc::clone(known));
    }
    // Computed without the lock held: the sweep runs on rayon, whose threads may meanwhile
    // take other work that asks for sweeps. Two callers racing compute twice; the first kept.
    let widths = (*BITS.start(), *BITS.end());
    let cache = Cache::default_for("sweeps");
    let computed = Arc::new(analyses::sweeps(
        cache.as_ref(),
        &HwLobe::ALL,
        n,
        widths,
        SWEEP_SAMPLES,
        || {
            sweeps(
                &HwLobe::ALL,
                n,
                widths,
                SWEEP_SAMPLES,
                &ProgressBar::hidden(),
            )
        },
    )?);
    Ok(Arc::clone(memo().entry(n).or_insert(computed)))
}

/// A datapath at a word length, with its error there and its formula estimate.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Chosen {
    /// The datapath.
    pub lobe: HwLobe,
    /// The word length.
    pub bits: u32,
    /// Its error in the zone asked for.
    pub error: f64,
    /// Its estimated logic cells ([`logic_cells`]).
    pub cells: u64,
}

/// A lobe of yours compiled to a datapath ([`HwLobe::Formula`]): its sweep over every word
/// length ([`BITS`]) at the integer exponent `n`, with [`SWEEP_SAMPLES`] angles per zone,
/// computed once per lobe and exponent in a process; `None` where its formula has no datapath.
fn compiled_sweep(kind: LobeKind, n: u32) -> Option<Arc<WidthSweep>> {
    type Memo = Vec<((LobeKind, u32), Option<Arc<WidthSweep>>)>;
    static MEMO: Mutex<Memo> = Mutex::new(Vec::new());
    let memo = || MEMO.lock().unwrap_or_else(PoisonError::into_inner);
    let known = |memo: &Memo| {
        memo.iter()
            .find(|(at, _)| *at == (kind, n))
            .map(|(_, sweep)| sweep.clone())
    };
    if let Some(found) = known(&memo()) {
        return found;
    }
    // Computed without the lock, as the built-ins' sweeps are.
    let computed = HwLobe::of_kind(kind)
        .ok()
        .and_then(|lobe| sweep(lobe, n, BITS, SWEEP_SAMPLES, &mut |_| {}).ok())
        .map(Arc::new);
    let mut memo = memo();
    if known(&memo).is_none() {
        memo.push(((kind, n), computed));
    }
    known(&memo).flatten()
}

/// Of `kind`'s datapaths among `sweeps` (all at one exponent), or, for a lobe of yours, of its
/// compiled datapath's sweep at that exponent, each at the smallest word length whose `zone`
/// error is at most `max_error` (or at its widest, where none is), the one with the fewest
/// estimated logic cells, those within the bound first; `None` where `kind` has no datapath.
#[must_use]
pub(crate) fn cheapest_datapath(
    sweeps: &[WidthSweep],
    kind: LobeKind,
    zone: Zone,
    max_error: f64,
) -> Option<Chosen> {
    let compiled = match (kind, sweeps.first()) {
        (LobeKind::Formula(_), Some(built_in)) => compiled_sweep(kind, built_in.n),
        _ => None,
    };
    let sweeps = compiled.as_deref().map_or(sweeps, core::slice::from_ref);
    sweeps
        .iter()
        .filter(|sweep| sweep.lobe.float_kind() == kind)
        .filter_map(|sweep| {
            let row = sweep
                .rows
                .iter()
                .find(|row| zone.error(&row.errors) <= max_error)
                .or_else(|| sweep.rows.last())?;
            Some(Chosen {
                lobe: sweep.lobe,
                bits: row.bits,
                error: zone.error(&row.errors),
                cells: logic_cells(&row.resources),
            })
        })
        .min_by_key(|chosen| (chosen.error > max_error, chosen.cells))
}

/// The datapath of `kind` (a built-in's cheapest, or a lobe of yours compiled) as one circuit
/// serving every exponent of `low..=high`: the largest of the word lengths each of
/// `recommend`'s sample exponents needs for an epicentre error of at most `max_error`; `None`
/// where it has no datapath or some exponent's error is out of reach at every width.
pub fn circuit_for_range(
    kind: LobeKind,
    (low, high): (specula::Exponent, specula::Exponent),
    max_error: f64,
) -> Result<Option<(HwLobe, u32)>, String> {
    let mut circuit: Option<(HwLobe, u32)> = None;
    for n in crate::sample_exponents(low, high) {
        let n = n.get().round().clamp(1.0, 1000.0) as u32;
        let sweeps = hardware_sweeps(n)?;
        let Some(chosen) = cheapest_datapath(&sweeps, kind, Zone::Epicentre, max_error)
            .filter(|chosen| chosen.error <= max_error)
        else {
            return Ok(None);
        };
        let bits = circuit.map_or(chosen.bits, |(_, bits)| bits.max(chosen.bits));
        circuit = Some((chosen.lobe, bits));
    }
    Ok(circuit)
}
