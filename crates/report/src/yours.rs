//! The user's lobes (`report --lobe`) where a section is about the built-in ones: the
//! thesis's claims name their lobes, so a user lobe is measured beside them with the claims'
//! own figures rather than given a verdict it was never claimed for.

use rayon::prelude::*;
use specula::analysis::{energy_ratio, error_figures, Precision};
use specula::{Exponent, Lobe, LobeKind};

use super::html::{paragraph, table};
use super::Context;
use crate::format::{percent, sig};

/// The exponents the rows are measured at.
const EXPONENTS: [f64; 3] = [8.0, 64.0, 512.0];

/// A table of the user's lobes' accuracy and energy figures (the accuracy claims' epicentre
/// relative error and bloom absolute error, the energy claims' ratio), or nothing.
pub fn claims_figures(context: &Context) -> String {
    let yours: Vec<LobeKind> = context
        .lobes
        .iter()
        .copied()
        .filter(|kind| matches!(kind, LobeKind::Formula(_)))
        .collect();
    if yours.is_empty() {
        return String::new();
    }
    let samples = context.sizes.samples_per_zone;
    let rows: Vec<Vec<String>> = yours
        .par_iter()
        .flat_map_iter(|&kind| {
            EXPONENTS.map(|n| {
                let lobe = Lobe::new(kind, Exponent::new(n));
                let figures = error_figures(&lobe, &mut Precision::F64, samples);
                vec![
                    kind.to_string(),
                    n.to_string(),
                    percent(figures.epicentre_max_rel),
                    sig(figures.bloom_max_abs),
                    sig(energy_ratio(&lobe)),
                ]
            })
        })
        .collect();
    paragraph(
        "Your lobes, measured with the claims' figures (the claims themselves are about the \
         thesis's lobes):",
    ) + &table(
        &[
            "lobe",
            "n",
            "epicentre max rel",
            "bloom max abs",
            "energy ratio",
        ],
        &rows,
    )
}
