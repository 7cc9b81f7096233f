//! Against the thesis: each of the thesis's lobes at its own accuracy over a range of `n`, and
//! what the designer returns on a target asked for that accuracy there. The thesis lobe is
//! ranked beside the designs and the other built-ins (`DesignRequest::also`), so the answer is
//! at least as cheap as the thesis lobe, and is the thesis lobe itself (or another built-in)
//! when no design meeting its accuracy is cheaper.
//!
//! "Its own accuracy" is its largest epicentre error over the range's verification exponents,
//! and its largest whole-lobe error there is the whole lobe's bound (at least the epicentre's),
//! so a design must be as good as the thesis lobe everywhere the analysis looks.

use indicatif::ProgressBar;
use serde::Serialize;
use specula::{Exponent, Lobe, LobeKind};

use super::{design_each, verification_exponents, Bounds, DesignRequest};
use crate::Target;

/// The thesis's lobes: modified Schlick, its quadratic Chebyshev, log/exp and `K_4`.
#[must_use]
pub fn thesis_lobes() -> Vec<LobeKind> {
    ["schlick-mod", "cheb2-thesis", "logexp", "cosquad"]
        .iter()
        .filter_map(|id| LobeKind::ALL.iter().copied().find(|k| k.id() == *id))
        .collect()
}

/// One thesis lobe against the designer's answer at its accuracy.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct ThesisRow {
    /// The thesis lobe's id and formula.
    pub thesis: String,
    /// Its formula.
    pub thesis_formula: String,
    /// Its largest epicentre error over the range: the accuracy asked.
    pub epicentre_error: f64,
    /// Its largest whole-lobe error there: the whole lobe's bound.
    pub whole_error: f64,
    /// Its rate on the target.
    pub thesis_rate: f64,
    /// The answer: the cheapest lobe meeting that accuracy, designed or built in.
    pub answer: String,
    /// The answer's formula.
    pub answer_formula: String,
    /// Its rate.
    pub answer_rate: f64,
    /// Whether the answer is a designed lobe.
    pub designed: bool,
}

/// The largest epicentre relative and whole-lobe absolute errors of `kind` at `exponents`.
fn errors(kind: LobeKind, exponents: &[Exponent]) -> Result<(f64, f64), String> {
    let (mut epicentre, mut whole) = (0.0_f64, 0.0_f64);
    for &n in exponents {
        let lobe = Lobe::checked(kind, n).map_err(|e| e.to_string())?;
        let figures = crate::figures::f64_figures(&lobe);
        epicentre = epicentre.max(figures.epicentre_max_rel);
        whole = whole
            .max(figures.epicentre_max_abs)
            .max(figures.bloom_max_abs)
            .max(figures.tail_max_abs);
    }
    Ok((epicentre, whole))
}

/// Every thesis lobe on `target` over `range`, against the design at its accuracy;
/// `progress` counts the searches, then the answers.
pub fn against_thesis(
    target: Target,
    gpu: Option<specula::gpus::Gpu>,
    range: (Exponent, Exponent),
    progress: &ProgressBar,
) -> Result<Vec<ThesisRow>, String> {
    let mut rows = against_thesis_each(&[(target, gpu)], range, progress)?;
    Ok(rows.pop().unwrap_or_default())
}

/// [`against_thesis`] on several targets at once, in their order: each thesis lobe's
/// accuracy is one search whatever the target, made once ([`design_each`]).
pub fn against_thesis_each(
    targets: &[(Target, Option<specula::gpus::Gpu>)],
    range: (Exponent, Exponent),
    progress: &ProgressBar,
) -> Result<Vec<Vec<ThesisRow>>, String> {
    let exponents = verification_exponents(range.0, range.1);
    let accuracies = thesis_lobes()
        .into_iter()
        .map(|kind| Ok((kind, errors(kind, &exponents)?)))
        .collect::<Result<Vec<_>, String>>()?;
    let requests: Vec<DesignRequest> = targets
        .iter()
        .flat_map(|&(target, gpu)| {
            accuracies.iter().map(move |&(kind, (epicentre, whole))| {
                // Its own errors must meet the bounds they set: a hair above, against
                // rounding.
                let bound = (epicentre * (1.0 + 1e-9)).min(1.0);
                DesignRequest {
                    target,
                    gpu,
                    range,
                    bounds: Bounds {
                        epicentre: bound,
                        whole: (whole * (1.0 + 1e-9)).max(bound).min(1.0),
                        energy: None,
                    },
                    no_transcendentals: false,
                    also: vec![kind],
                    max_operations: crate::design::grammar::default_max_operations(target),
                }
            })
        })
        .collect();
    let answers = design_each(&requests, progress)?;
    answers
        .chunks(accuracies.len().max(1))
        .zip(targets)
        .map(|(answers, &(target, _))| {
            answers
                .iter()
                .zip(&accuracies)
                .map(|(answer, &(kind, (epicentre, whole)))| {
                    row(answer, kind, epicentre, whole, target)
                })
                .collect()
        })
        .collect()
}

/// One thesis lobe's row from the answer at its accuracy.
fn row(
    answer: &super::Design,
    kind: LobeKind,
    epicentre: f64,
    whole: f64,
    target: Target,
) -> Result<ThesisRow, String> {
    let thesis = answer
        .compared
        .iter()
        .find(|c| c.lobe == kind.to_string())
        .ok_or_else(|| format!("{kind} was not ranked on {}", target.id()))?;
    let designed = answer.best();
    let built_in = answer.best_compared();
    let row = match (designed, built_in) {
        (Some(d), Some(c)) if d.rate <= c.rate => {
            (c.lobe.clone(), formula_of(&c.lobe), c.rate, false)
        }
        (Some(d), _) => (d.name.clone(), d.formula.clone(), d.rate, true),
        (None, Some(c)) => (c.lobe.clone(), formula_of(&c.lobe), c.rate, false),
        (None, None) => (
            kind.to_string(),
            formula_of(&kind.to_string()),
            thesis.rate,
            false,
        ),
    };
    Ok(ThesisRow {
        thesis: kind.to_string(),
        thesis_formula: kind.info().formula.to_owned(),
        epicentre_error: epicentre,
        whole_error: whole,
        thesis_rate: thesis.rate,
        answer: row.0,
        answer_formula: row.1,
        answer_rate: row.2,
        designed: row.3,
    })
}

/// A built-in's formula from its id (the id itself for a lobe not in the registry).
fn formula_of(id: &str) -> String {
    LobeKind::parse(id).map_or_else(|_| id.to_owned(), |kind| kind.info().formula.to_owned())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// On a modelled GPU (deterministic), the answer at each thesis lobe's own accuracy is at
    /// least as cheap as the thesis lobe, and a designed answer meets that accuracy.
    #[test]
    fn the_design_is_never_costlier_than_a_thesis_lobe_at_its_accuracy() {
        let range = (Exponent::new(16.0), Exponent::new(128.0));
        let rows = against_thesis(Target::GpuAmd, None, range, &ProgressBar::hidden()).unwrap();
        assert_eq!(rows.len(), 4);
        for row in &rows {
            assert!(row.answer_rate >= row.thesis_rate, "{row:?}");
            if row.designed {
                let kind = LobeKind::parse(&format!("={}", row.answer_formula)).unwrap();
                let exponents = verification_exponents(range.0, range.1);
                let (epicentre, _) = errors(kind, &exponents).unwrap();
                assert!(epicentre <= row.epicentre_error * (1.0 + 1e-6), "{row:?}");
            }
        }
    }
}
