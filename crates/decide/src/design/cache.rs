//! Searched families on disk, keyed by everything that determines them: the range, the
//! bounds, whether transcendentals are allowed, and this build's fingerprint of the sources
//! the search runs (`build.rs`: the fit, the verification, the formula language, the analysis
//! and the locked crates). The costing is never stored: on the CPU it is timed on every run,
//! on a GPU it is the cost model's, which takes milliseconds.
//!
//! Numbers are stored as their `f64` bits, so a loaded lobe is the searched one bit for bit
//! (figures of lobes never verified are infinite, which JSON cannot write). Beside each lobe
//! are the figures its verification measured at every exponent, which ranking it reads again:
//! a loaded lobe is not measured twice.

use serde::{Deserialize, Serialize};
use specula_synth::cache::Cache;

use super::{register, unmeasured, DesignRequest, DesignedLobe, Family};
use crate::analyses::{figure_bits, figures_of};
use crate::figures;

/// Bumped when [`Stored`] changes shape.
const FORMAT: &str = "specula design search 3";

/// One family as searched.
#[derive(Serialize, Deserialize)]
pub(super) struct Stored {
    family: String,
    coefficients: Vec<u64>,
    epicentre_error: u64,
    whole_error: u64,
    energy_deviation: u64,
    checked: bool,
    verified: bool,
    short_of_whole_only: bool,
    why: String,
    /// The verification's figures, by exponent's bits: what ranking the lobe reads again.
    figures: Vec<(u64, [u64; 5])>,
}

/// The key of `request`'s search.
pub(super) fn key(request: &DesignRequest) -> String {
    let bits = |x: f64| format!("{:016x}", x.to_bits());
    let (low, high) = request.range;
    specula_synth::cache::key(&[
        FORMAT,
        env!("SPECULA_SOURCES"),
        &bits(low.get()),
        &bits(high.get()),
        &bits(request.bounds.epicentre),
        &bits(request.bounds.whole),
        &request.bounds.energy.map_or("none".to_owned(), bits),
        &request.max_operations.to_string(),
        if request.no_transcendentals {
            "no transcendentals"
        } else {
            "any operation"
        },
    ])
}

/// The search stored under `key`, its lobes registered again, if a whole and readable one
/// is there.
pub(super) fn load(cache: &Cache, key: &str, request: &DesignRequest) -> Option<Vec<DesignedLobe>> {
    let stored: Vec<Stored> = cache.load(key)?;
    let families = Family::all();
    stored
        .into_iter()
        .map(|entry| {
            let family = *families.iter().find(|f| f.id() == entry.family)?;
            let beta: Vec<f64> = entry
                .coefficients
                .iter()
                .map(|&b| f64::from_bits(b))
                .collect();
            let mut lobe = DesignedLobe {
                epicentre_error: f64::from_bits(entry.epicentre_error),
                whole_error: f64::from_bits(entry.whole_error),
                energy_deviation: f64::from_bits(entry.energy_deviation),
                checked: entry.checked,
                verified: entry.verified,
                short_of_whole_only: entry.short_of_whole_only,
                why: entry.why,
                ..unmeasured(family, &beta, request)
            };
            if lobe.verified || lobe.short_of_whole_only {
                // Registered when searched, so registering again can only fail where the
                // registry is full: then the entry is of no use, and the search runs again.
                register(&mut lobe).ok()?;
                let kind = lobe.kind?;
                for (n, bits) in entry.figures {
                    figures::remember(kind, n, figures_of(bits));
                }
            }
            Some(lobe)
        })
        .collect()
}

/// Stores `searched` under `key`, atomically.
pub(super) fn store(cache: &Cache, key: &str, searched: &[DesignedLobe]) -> std::io::Result<()> {
    let stored: Vec<Stored> = searched
        .iter()
        .map(|lobe| Stored {
            family: lobe.family.clone(),
            coefficients: lobe.coefficients.iter().map(|b| b.to_bits()).collect(),
            epicentre_error: lobe.epicentre_error.to_bits(),
            whole_error: lobe.whole_error.to_bits(),
            energy_deviation: lobe.energy_deviation.to_bits(),
            checked: lobe.checked,
            verified: lobe.verified,
            short_of_whole_only: lobe.short_of_whole_only,
            why: lobe.why.clone(),
            figures: lobe.kind.map_or_else(Vec::new, |kind| {
                figures::measured(kind)
                    .into_iter()
                    .map(|(n, measured)| (n, figure_bits(&measured)))
                    .collect()
            }),
        })
        .collect();
    cache.store(key, &stored)
}
