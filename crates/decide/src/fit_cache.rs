//! A measured material's fits on disk, beside the design searches: fitting every lobe to a
//! material takes seconds of CPU each (the report fits five), and the fits depend only on the
//! observations (the material's values at the comparison pairs), the lobes and the code, so
//! a later run reads them back. Keyed by every observed value's bits, the lobes' ids and
//! `build.rs`'s fingerprint of the sources the fits run. Fits of a user's formula lobe are never
//! stored: its id names it in this process only. Numbers are stored as their `f64` bits, so
//! a loaded fit is the fitted one bit for bit.

use serde::{Deserialize, Serialize};
use specula::measured::fit::{Fit, Observations, Sharing, Specular};
use specula::LobeKind;
use specula_synth::cache::{key_of_bytes, Cache};

/// Bumped when [`Stored`] changes shape.
const FORMAT: &str = "specula material fits 3";

/// One fit as stored.
#[derive(Serialize, Deserialize)]
struct Stored {
    /// The family's label (`pow/blinn`, `ggx`, `cosquad/microfacet`, `beckmann/microfacet`).
    family: String,
    per_channel: bool,
    parameter: [u64; 3],
    kd: [u64; 3],
    k: [u64; 3],
    f0: Option<[u64; 3]>,
    error: u64,
    channel_error: [u64; 3],
}

/// The fits of `kinds` to `observations`: read from the cache where this build fitted them
/// before, else made by `fit` and stored.
pub(crate) fn fits(
    observations: &Observations,
    families: &[Specular],
    fit: impl FnOnce() -> Vec<Fit>,
) -> Vec<Fit> {
    let built_in = |specular: &Specular| specular.kind().is_none_or(|k| LobeKind::ALL.contains(&k));
    let cache = Cache::default_for("fits").filter(|_| families.iter().all(built_in));
    let Some(cache) = cache else {
        return fit();
    };
    let key = key_of(observations, families);
    if let Some(found) = load(&cache, &key, families) {
        return found;
    }
    let made = fit();
    // A cache that cannot be written costs the next run the fits, nothing else.
    let _ = cache.store(&key, &made.iter().map(stored).collect::<Vec<_>>());
    made
}

fn key_of(observations: &Observations, families: &[Specular]) -> String {
    let values: Vec<u8> = observations
        .value
        .iter()
        .flat_map(|value| value.to_array())
        .flat_map(|channel| channel.to_bits().to_le_bytes())
        .collect();
    let labels: Vec<String> = families.iter().map(|f| f.label()).collect();
    key_of_bytes(&[
        FORMAT.as_bytes(),
        env!("SPECULA_SOURCES").as_bytes(),
        &values,
        labels.join(",").as_bytes(),
    ])
}

/// The fits stored under `key`, each family found again among `families` by its label.
fn load(cache: &Cache, key: &str, families: &[Specular]) -> Option<Vec<Fit>> {
    let stored: Vec<Stored> = cache.load(key)?;
    let bits = |values: [u64; 3]| values.map(f64::from_bits);
    stored
        .into_iter()
        .map(|entry| {
            let specular = *families.iter().find(|f| f.label() == entry.family)?;
            Some(Fit {
                specular,
                sharing: if entry.per_channel {
                    Sharing::PerChannel
                } else {
                    Sharing::Shared
                },
                parameter: bits(entry.parameter),
                kd: bits(entry.kd),
                k: bits(entry.k),
                f0: entry.f0.map(bits),
                error: f64::from_bits(entry.error),
                channel_error: bits(entry.channel_error),
            })
        })
        .collect()
}

fn stored(fit: &Fit) -> Stored {
    let bits = |values: [f64; 3]| values.map(f64::to_bits);
    Stored {
        family: fit.specular.label(),
        per_channel: fit.sharing == Sharing::PerChannel,
        parameter: bits(fit.parameter),
        kd: bits(fit.kd),
        k: bits(fit.k),
        f0: fit.f0.map(bits),
        error: fit.error.to_bits(),
        channel_error: bits(fit.channel_error),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use specula::measured::fit::Normals;
    use specula::Geometry;

    /// A stored fit reads back as the same fit, bit for bit, every family alike.
    #[test]
    fn a_stored_fit_reads_back_bit_for_bit() {
        let directory = tempfile::tempdir().unwrap();
        let cache = Cache::new(directory.path());
        let fit = |specular, sharing, x: f64| Fit {
            specular,
            sharing,
            parameter: [x, x * 2.0, x / 3.0],
            kd: [0.1, 0.2, 0.3],
            k: [x.sqrt(), 1.0 / 7.0, f64::MIN_POSITIVE],
            f0: specular
                .has_fresnel()
                .then_some([0.04, x.fract(), 1.0 / 3.0]),
            error: x.ln(),
            channel_error: [1e-300, 0.5, 2.0 / 3.0],
        };
        let fits = vec![
            fit(
                Specular::Lobe {
                    kind: LobeKind::SgKaris,
                    geometry: Geometry::Blinn,
                },
                Sharing::Shared,
                37.25,
            ),
            fit(
                Specular::Lobe {
                    kind: LobeKind::Pow,
                    geometry: Geometry::Phong,
                },
                Sharing::PerChannel,
                0.1,
            ),
            fit(Specular::Ggx, Sharing::Shared, 0.3),
            fit(
                Specular::Microfacet {
                    normals: Normals::Lobe(LobeKind::Schlick),
                },
                Sharing::Shared,
                64.0,
            ),
            fit(
                Specular::Microfacet {
                    normals: Normals::Beckmann,
                },
                Sharing::PerChannel,
                0.2,
            ),
        ];
        cache
            .store("k", &fits.iter().map(stored).collect::<Vec<_>>())
            .unwrap();
        let families: Vec<Specular> = fits.iter().map(|f| f.specular).collect();
        assert_eq!(load(&cache, "k", &families), Some(fits));
    }
}
