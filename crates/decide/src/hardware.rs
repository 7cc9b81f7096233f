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

/// Of `kind`'s datapaths among `sweeps`, each at the smallest word length whose `zone` error
/// is at most `max_error` (or at its widest, where none is), the one with the fewest estimated
/// logic cells, those within the bound first; `None` where `kind` has no datapath.
#[must_use]
pub(crate) fn cheapest_datapath(
    sweeps: &[WidthSweep],
    kind: LobeKind,
    zone: Zone,
    max_error: f64,
) -> Option<Chosen> {
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
