//! The pure analyses a report repeats, on disk beside the design searches: the thesis's
//! claims (about 1.5 s of CPU at their default sizes) and the datapaths' word-length sweeps
//! (about 0.3 s an exponent). Both are functions of their options and the code alone, so a
//! later run of the same build reads them back. Keyed by the options and `build.rs`'s
//! fingerprint of the sources they run (the core's claims and analysis, the datapaths);
//! numbers are stored as their `f64` bits, so a loaded figure is the measured one bit for bit.
//! A cache that cannot be read is recomputed; one that cannot be written costs the next run.

use serde::de::DeserializeOwned;
use serde::{Deserialize, Serialize};
use specula::analysis::ErrorFigures;
use specula::claims::{evaluate_all, ClaimId, ClaimOptions, ClaimResult, Figure, Verdict};
use specula_hw::analysis::{WidthRow, WidthSweep};
use specula_hw::HwLobe;
use specula_hw::Resources;
use specula_synth::cache::{key, Cache};

/// Bumped when a stored shape changes.
const FORMAT: &str = "specula analyses 1";

/// `compute()`, read from `cache` under the key of `parts` where this build computed it
/// before (and `decode` accepts it), else computed and, when it succeeds, stored.
fn stored<S, T, E>(
    cache: Option<&Cache>,
    parts: &[&str],
    encode: impl Fn(&T) -> S,
    decode: impl Fn(S) -> Option<T>,
    compute: impl FnOnce() -> Result<T, E>,
) -> Result<T, E>
where
    S: Serialize + DeserializeOwned,
{
    let Some(cache) = cache else {
        return compute();
    };
    let mut all = vec![FORMAT, env!("SPECULA_SOURCES")];
    all.extend_from_slice(parts);
    let key = key(&all);
    if let Some(found) = cache.load(&key).and_then(&decode) {
        return Ok(found);
    }
    let made = compute()?;
    let _ = cache.store(&key, &encode(&made));
    Ok(made)
}

/// The thesis's claims as [`evaluate_all`] finds them with `options`.
#[must_use]
pub fn claims(options: &ClaimOptions) -> Vec<ClaimResult> {
    claims_in(Cache::default_for("claims").as_ref(), options)
}

fn claims_in(cache: Option<&Cache>, options: &ClaimOptions) -> Vec<ClaimResult> {
    let exponents: Vec<String> = options
        .exponents
        .iter()
        .map(|n| format!("{:016x}", n.get().to_bits()))
        .collect();
    let evaluated: Result<Vec<ClaimResult>, std::convert::Infallible> = stored(
        cache,
        &[
            &exponents.join(","),
            &options.samples_per_zone.to_string(),
            &options.reciprocity_pairs.to_string(),
            &format!("{:016x}", options.seed),
        ],
        |results: &Vec<ClaimResult>| results.iter().map(StoredClaim::from).collect::<Vec<_>>(),
        |stored: Vec<StoredClaim>| stored.into_iter().map(StoredClaim::result).collect(),
        || Ok(evaluate_all(options)),
    );
    let Ok(results) = evaluated;
    results
}

/// Every datapath of `lobes` swept at `n` over `low..=high` with `samples` angles a zone, as
/// `sweep` (which the caller passes, with its progress) measures them.
pub(crate) fn sweeps(
    cache: Option<&Cache>,
    lobes: &[HwLobe],
    n: u32,
    (low, high): (u32, u32),
    samples: usize,
    sweep: impl FnOnce() -> Result<Vec<WidthSweep>, String>,
) -> Result<Vec<WidthSweep>, String> {
    let ids: Vec<&str> = lobes.iter().map(|lobe| lobe.id()).collect();
    stored(
        cache,
        &[&ids.join(","), &format!("{n} {low} {high} {samples}")],
        |swept: &Vec<WidthSweep>| swept.iter().map(StoredSweep::from).collect::<Vec<_>>(),
        |stored: Vec<StoredSweep>| stored.into_iter().map(StoredSweep::sweep).collect(),
        sweep,
    )
}

/// A claim's result as stored: its place in [`ClaimId::ALL`], its verdict's name.
#[derive(Serialize, Deserialize)]
struct StoredClaim {
    id: usize,
    reading: String,
    measured: String,
    verdict: String,
    figures: Vec<(String, u64)>,
}

impl From<&ClaimResult> for StoredClaim {
    fn from(result: &ClaimResult) -> Self {
        Self {
            id: ClaimId::ALL
                .iter()
                .position(|&id| id == result.id)
                .unwrap_or(usize::MAX),
            reading: result.reading.clone(),
            measured: result.measured.clone(),
            verdict: result.verdict.name().to_owned(),
            figures: result
                .figures
                .iter()
                .map(|figure| (figure.name.clone(), figure.value.to_bits()))
                .collect(),
        }
    }
}

impl StoredClaim {
    fn result(self) -> Option<ClaimResult> {
        let id = *ClaimId::ALL.get(self.id)?;
        let verdict = [
            Verdict::Holds,
            Verdict::HoldsWithQualification,
            Verdict::DoesNotHold,
        ]
        .into_iter()
        .find(|verdict| verdict.name() == self.verdict)?;
        Some(ClaimResult {
            id,
            claim: id.statement(),
            reading: self.reading,
            measured: self.measured,
            verdict,
            figures: self
                .figures
                .into_iter()
                .map(|(name, value)| Figure {
                    name,
                    value: f64::from_bits(value),
                })
                .collect(),
        })
    }
}

/// A sweep as stored: the datapath's id, every figure's bits.
#[derive(Serialize, Deserialize)]
struct StoredSweep {
    lobe: String,
    n: u32,
    float: [u64; 5],
    rows: Vec<(u32, [u64; 5], Resources)>,
}

impl From<&WidthSweep> for StoredSweep {
    fn from(sweep: &WidthSweep) -> Self {
        Self {
            lobe: sweep.lobe.id().to_owned(),
            n: sweep.n,
            float: figure_bits(&sweep.float),
            rows: sweep
                .rows
                .iter()
                .map(|row| (row.bits, figure_bits(&row.errors), row.resources.clone()))
                .collect(),
        }
    }
}

impl StoredSweep {
    fn sweep(self) -> Option<WidthSweep> {
        Some(WidthSweep {
            lobe: HwLobe::parse(&self.lobe).ok()?,
            n: self.n,
            float: figures_of(self.float),
            rows: self
                .rows
                .into_iter()
                .map(|(bits, errors, resources)| WidthRow {
                    bits,
                    errors: figures_of(errors),
                    resources,
                })
                .collect(),
        })
    }
}

/// The figures' bits, in their declared order.
pub(crate) fn figure_bits(figures: &ErrorFigures) -> [u64; 5] {
    [
        figures.epicentre_max_rel,
        figures.epicentre_max_abs,
        figures.bloom_max_abs,
        figures.tail_max_abs,
        figures.rms,
    ]
    .map(f64::to_bits)
}

/// The figures [`figure_bits`] wrote.
pub(crate) fn figures_of(bits: [u64; 5]) -> ErrorFigures {
    let [epicentre_max_rel, epicentre_max_abs, bloom_max_abs, tail_max_abs, rms] =
        bits.map(f64::from_bits);
    ErrorFigures {
        epicentre_max_rel,
        epicentre_max_abs,
        bloom_max_abs,
        tail_max_abs,
        rms,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use specula_hw::analysis::sweep;

    /// The claims and a sweep read back from a fresh cache equal, bit for bit, what measuring
    /// them again gives (the first call stores, the second loads; `PartialEq` on `f64`
    /// compares values, so the bits are compared too).
    #[test]
    fn stored_analyses_read_back_as_measured() {
        let directory = tempfile::tempdir().unwrap();
        let cache = Cache::new(directory.path());
        let options = ClaimOptions {
            exponents: specula::claims::claim_exponents(3),
            samples_per_zone: 501,
            reciprocity_pairs: 200,
            ..ClaimOptions::default()
        };
        let measured = evaluate_all(&options);
        assert_eq!(claims_in(Some(&cache), &options), measured);
        let loaded = claims_in(Some(&cache), &options);
        let bits = |results: &[ClaimResult]| -> Vec<u64> {
            results
                .iter()
                .flat_map(|r| r.figures.iter().map(|f| f.value.to_bits()))
                .collect()
        };
        assert_eq!(loaded, measured);
        assert_eq!(bits(&loaded), bits(&measured));

        let lobes = [HwLobe::Cheb2, HwLobe::LogExp];
        let direct = || -> Result<Vec<WidthSweep>, String> {
            lobes
                .iter()
                .map(|&lobe| sweep(lobe, 64, 10..=12, 301, &mut |_| {}).map_err(|e| e.to_string()))
                .collect()
        };
        let expected = direct().expect("the sweeps");
        let first = sweeps(Some(&cache), &lobes, 64, (10, 12), 301, direct);
        assert_eq!(first, Ok(expected.clone()));
        let again = || Err("measured again, not read back".to_owned());
        assert_eq!(
            sweeps(Some(&cache), &lobes, 64, (10, 12), 301, again),
            Ok(expected)
        );
        // A failed measurement is not stored: a different request fails again.
        let failing = || Err("no datapath".to_owned());
        assert!(sweeps(Some(&cache), &lobes, 8, (10, 12), 301, failing).is_err());
        assert!(sweeps(Some(&cache), &lobes, 8, (10, 12), 301, failing).is_err());
    }
}
