//! The thesis's claims (SPEC section 9, claims 1-6), tested with measured figures.
//!
//! Each claim is evaluated under stated readings; the verdict follows from the measured
//! figures and fixed thresholds that come from the claim's own wording (0.5 %, 0.29 %,
//! "equals", "conserves"), never from the figures themselves. Claim 7 (speed) belongs to the
//! benchmarks. Every figure is computed when [`evaluate`] or [`evaluate_all`] runs.

use rayon::prelude::*;
use serde::Serialize;

use crate::analysis::{error_figures, error_figures_on, ErrorFigures, Precision, ZoneSamples};
use crate::{Exponent, Lobe, LobeKind};

mod accuracy;
mod energy;

use accuracy::{chebyshev_epicentre, logexp_delta, schlick_mod_bloom};
use energy::{cosquad_coefficient, cosquad_energy, energy_correct_model, thesis_phong_coefficient};

/// Which claim.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize)]
pub enum ClaimId {
    /// 1: modified Schlick renders the bloom more realistically than Schlick.
    SchlickModBloom,
    /// 2: the Chebyshev quadratic's relative error is at most 0.5 % in the epicentre.
    ChebyshevEpicentre,
    /// 3: the log/exp model's error is 0.29 %.
    LogExpDelta,
    /// 4: the cosine-quadratic model integrates to `1/(n+1)`.
    CosQuadEnergy,
    /// 5a: Phong's energy coefficient is `1.063 n / (2 pi)`.
    ThesisPhongCoefficient,
    /// 5b: `K_4`'s energy coefficient is `(n+1)/(2 pi)`.
    CosQuadCoefficient,
    /// 6: the energy-correct model conserves energy and is reciprocal.
    EnergyCorrectModel,
}

impl ClaimId {
    /// Every claim, in the thesis's order.
    pub const ALL: [ClaimId; 7] = [
        ClaimId::SchlickModBloom,
        ClaimId::ChebyshevEpicentre,
        ClaimId::LogExpDelta,
        ClaimId::CosQuadEnergy,
        ClaimId::ThesisPhongCoefficient,
        ClaimId::CosQuadCoefficient,
        ClaimId::EnergyCorrectModel,
    ];

    /// The claim's number and statement.
    #[must_use]
    pub fn statement(self) -> &'static str {
        match self {
            ClaimId::SchlickModBloom => {
                "1: modified Schlick renders the blooming zone more realistically than Schlick"
            }
            ClaimId::ChebyshevEpicentre => {
                "2: the quadratic Chebyshev model's relative error is <= 0.5 % in the epicentre"
            }
            ClaimId::LogExpDelta => "3: the log/exp model's error is delta = 0.29 %",
            ClaimId::CosQuadEnergy => {
                "4: the cosine-quadratic model integrates to 1/(n+1), like cos^n"
            }
            ClaimId::ThesisPhongCoefficient => {
                "5a: Phong's energy coefficient is coef1(n) = 1.063 n / (2 pi)"
            }
            ClaimId::CosQuadCoefficient => {
                "5b: K_4's energy coefficient is coef2(n) = (n+1)/(2 pi)"
            }
            ClaimId::EnergyCorrectModel => {
                "6: the energy-correct model conserves energy and is Helmholtz-reciprocal"
            }
        }
    }

    /// The lobes whose error figures against `cos^n` the claim compares, at every exponent.
    #[must_use]
    pub fn compared_lobes(self) -> &'static [LobeKind] {
        match self {
            ClaimId::SchlickModBloom => &[LobeKind::Schlick, LobeKind::SchlickMod],
            ClaimId::ChebyshevEpicentre => {
                &[LobeKind::Cheb2Thesis, LobeKind::Cheb2, LobeKind::Minimax2]
            }
            ClaimId::LogExpDelta => &[LobeKind::LogExp],
            ClaimId::CosQuadEnergy
            | ClaimId::ThesisPhongCoefficient
            | ClaimId::CosQuadCoefficient
            | ClaimId::EnergyCorrectModel => &[],
        }
    }
}

/// A verdict on a claim.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
pub enum Verdict {
    /// The measured figures satisfy the claim as stated.
    #[serde(rename = "holds")]
    Holds,
    /// They satisfy it only under a restriction, stated in the reading.
    #[serde(rename = "holds with qualification")]
    HoldsWithQualification,
    /// They contradict it.
    #[serde(rename = "does not hold")]
    DoesNotHold,
}

impl Verdict {
    /// The verdict in words.
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            Verdict::Holds => "holds",
            Verdict::HoldsWithQualification => "holds with qualification",
            Verdict::DoesNotHold => "does not hold",
        }
    }
}

/// One named measured figure behind a verdict.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Figure {
    /// What was measured.
    pub name: String,
    /// Its value.
    pub value: f64,
}

/// The outcome of testing one claim.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct ClaimResult {
    /// Which claim.
    #[serde(skip)]
    pub id: ClaimId,
    /// Its number and statement.
    pub claim: &'static str,
    /// The reading under which it was tested.
    pub reading: String,
    /// The measured result, in one sentence.
    pub measured: String,
    /// The verdict.
    pub verdict: Verdict,
    /// The figures behind it.
    pub figures: Vec<Figure>,
}

/// How thoroughly to measure.
#[derive(Clone, Debug, PartialEq)]
pub struct ClaimOptions {
    /// Exponents to test (each claim over all of them).
    pub exponents: Vec<Exponent>,
    /// Samples per zone for error figures.
    pub samples_per_zone: usize,
    /// Direction pairs for the reciprocity checks.
    pub reciprocity_pairs: usize,
    /// Seed of the reciprocity checks' random directions.
    pub seed: u64,
}

impl Default for ClaimOptions {
    /// 49 log-spaced exponents from 1 to 1000 plus every power of two in range, `10^5`
    /// samples per zone, `10^5` direction pairs.
    fn default() -> Self {
        Self {
            exponents: claim_exponents(48),
            samples_per_zone: crate::analysis::DEFAULT_SAMPLES_PER_ZONE,
            reciprocity_pairs: 100_000,
            seed: 0x5eed_5bec,
        }
    }
}

/// `steps + 1` log-spaced exponents from 1 to 1000, with the powers of two (where
/// `schlick-mod` and `cosquad` change behaviour) merged in.
#[must_use]
pub fn claim_exponents(steps: usize) -> Vec<Exponent> {
    let mut values: Vec<f64> = (0..=steps)
        .map(|k| {
            1000f64
                .powf(k as f64 / steps.max(1) as f64)
                .clamp(1.0, 1000.0)
        })
        .chain((0..10).map(|p| f64::from(1u32 << p)))
        .collect();
    values.sort_by(f64::total_cmp);
    values.dedup_by(|a, b| (*a - *b).abs() < 1e-9);
    values.into_iter().map(Exponent::new).collect()
}

/// Tests one claim.
#[must_use]
pub fn evaluate(id: ClaimId, options: &ClaimOptions) -> ClaimResult {
    evaluate_with(
        id,
        options,
        &ErrorTable::measure(id.compared_lobes(), options),
    )
}

/// Tests every claim, in the thesis's order, in parallel, measuring the error figures they
/// share once.
#[must_use]
pub fn evaluate_all(options: &ClaimOptions) -> Vec<ClaimResult> {
    let mut kinds: Vec<LobeKind> = Vec::new();
    for kind in ClaimId::ALL.iter().flat_map(|id| id.compared_lobes()) {
        if !kinds.contains(kind) {
            kinds.push(*kind);
        }
    }
    let table = ErrorTable::measure(&kinds, options);
    ClaimId::ALL
        .par_iter()
        .map(|&id| evaluate_with(id, options, &table))
        .collect()
}

fn evaluate_with(id: ClaimId, options: &ClaimOptions, table: &ErrorTable) -> ClaimResult {
    let errors = |kind, n| table.get(kind, n, options);
    let (reading, measured, verdict, figures) = match id {
        ClaimId::SchlickModBloom => schlick_mod_bloom(options, &errors),
        ClaimId::ChebyshevEpicentre => chebyshev_epicentre(options, &errors),
        ClaimId::LogExpDelta => logexp_delta(options, &errors),
        ClaimId::CosQuadEnergy => cosquad_energy(options),
        ClaimId::ThesisPhongCoefficient => thesis_phong_coefficient(options),
        ClaimId::CosQuadCoefficient => cosquad_coefficient(options),
        ClaimId::EnergyCorrectModel => energy_correct_model(options),
    };
    ClaimResult {
        id,
        claim: id.statement(),
        reading,
        measured,
        verdict,
        figures,
    }
}

/// Error figures against `cos^n` of some lobes at every claim exponent. Each exponent's zone
/// samples (`cos` and `powf` in `f64` at three zones of `samples_per_zone` angles, the larger
/// part of the work) are computed once and shared by every lobe compared there, whichever
/// claim compares it.
struct ErrorTable {
    figures: Vec<(Exponent, LobeKind, ErrorFigures)>,
}

impl ErrorTable {
    /// Measures `kinds` at every exponent of `options`, one exponent per task.
    fn measure(kinds: &[LobeKind], options: &ClaimOptions) -> Self {
        if kinds.is_empty() {
            return Self {
                figures: Vec::new(),
            };
        }
        let figures = options
            .exponents
            .par_iter()
            .flat_map_iter(|&n| {
                let samples = ZoneSamples::new(n, options.samples_per_zone);
                kinds
                    .iter()
                    .map(|&kind| {
                        let lobe = Lobe::new(kind, n);
                        (
                            n,
                            kind,
                            error_figures_on(&lobe, &mut Precision::F64, &samples),
                        )
                    })
                    .collect::<Vec<_>>()
            })
            .collect();
        Self { figures }
    }

    /// The figures of `kind` at `n`: from the table, or measured now if it lacks them.
    fn get(&self, kind: LobeKind, n: Exponent, options: &ClaimOptions) -> ErrorFigures {
        self.figures
            .iter()
            .find(|(at, measured, _)| *at == n && *measured == kind)
            .map_or_else(
                || {
                    error_figures(
                        &Lobe::new(kind, n),
                        &mut Precision::F64,
                        options.samples_per_zone,
                    )
                },
                |(.., figures)| *figures,
            )
    }
}

pub(crate) type Outcome = (String, String, Verdict, Vec<Figure>);

pub(crate) fn figure(name: impl Into<String>, value: f64) -> Figure {
    Figure {
        name: name.into(),
        value,
    }
}

/// The error figures of a lobe at an exponent, as a claim asks for them.
pub(crate) type Errors<'a> = dyn Fn(LobeKind, Exponent) -> ErrorFigures + 'a;

/// The smallest and largest of `values`.
pub(crate) fn range(values: impl IntoIterator<Item = f64>) -> (f64, f64) {
    values
        .into_iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| {
            (lo.min(v), hi.max(v))
        })
}

/// Of measured `(n, value)` pairs, the exponents whose value satisfies `holds`, as
/// `(first, last, count)`.
pub(crate) fn where_true(
    measured: &[(f64, f64)],
    holds: impl Fn(f64) -> bool,
) -> (f64, f64, usize) {
    let passing: Vec<f64> = measured
        .iter()
        .filter(|&&(_, value)| holds(value))
        .map(|&(n, _)| n)
        .collect();
    let (lo, hi) = range(passing.iter().copied());
    (lo, hi, passing.len())
}

#[cfg(test)]
mod tests {
    use rand::SeedableRng;

    use super::*;
    use crate::analysis::max_reciprocity_error;

    #[test]
    fn exponent_grid_spans_the_range_with_powers_of_two() {
        let grid = claim_exponents(12);
        assert_eq!(grid.first().map(|n| n.get()), Some(1.0));
        assert_eq!(grid.last().map(|n| n.get()), Some(1000.0));
        for p in 0..10 {
            assert!(grid.iter().any(|n| n.get() == f64::from(1u32 << p)));
        }
        assert!(grid.windows(2).all(|w| w[0].get() < w[1].get()));
    }

    #[test]
    fn reciprocity_measure_sees_an_asymmetric_function() {
        let mut rng = rand::rngs::StdRng::seed_from_u64(1);
        let asymmetric = max_reciprocity_error(|a, _| glam::DVec3::splat(a.z), 100, &mut rng);
        assert!(asymmetric > 0.1);
    }
}
