//! Claims 1-3: how close the thesis's approximations come to `cos^n`.

use super::{figure, range, where_true, ClaimOptions, Errors, Outcome, Verdict};
use crate::analysis::ErrorFigures;
use crate::{Exponent, LobeKind};

pub(super) fn schlick_mod_bloom(options: &ClaimOptions, errors: &Errors) -> Outcome {
    let tested: Vec<Exponent> = options
        .exponents
        .iter()
        .copied()
        .filter(|n| n.get() >= 8.0)
        .collect();
    let rows: Vec<(ErrorFigures, ErrorFigures)> = tested
        .iter()
        .map(|&n| {
            (
                errors(LobeKind::Schlick, n),
                errors(LobeKind::SchlickMod, n),
            )
        })
        .collect();
    let ratio = |zone: fn(&ErrorFigures) -> f64| {
        range(
            rows.iter()
                .map(|(plain, modified)| zone(modified) / zone(plain)),
        )
    };
    let bloom = ratio(|e| e.bloom_max_abs);
    let epicentre = ratio(|e| e.epicentre_max_abs);
    let tail = ratio(|e| e.tail_max_abs);
    let better_everywhere = bloom.1 < 1.0 && epicentre.1 < 1.0 && tail.1 < 1.0;
    let verdict = if bloom.1 < 1.0 {
        Verdict::Holds
    } else {
        Verdict::DoesNotHold
    };
    (
        format!(
            "'more realistically' = closer to cos^n: max abs error per zone against t^n, \
             schlick-mod vs schlick, for the {} tested n >= 8 (below 8, a = 1 and the two \
             lobes are identical)",
            tested.len()
        ),
        format!(
            "schlick-mod's bloom error is {:.0}-{:.0} % of schlick's (epicentre {:.0}-{:.0} %, \
             tail {:.0}-{:.0} %){}",
            100.0 * bloom.0,
            100.0 * bloom.1,
            100.0 * epicentre.0,
            100.0 * epicentre.1,
            100.0 * tail.0,
            100.0 * tail.1,
            if better_everywhere {
                "; better in every zone at every n"
            } else {
                ""
            }
        ),
        verdict,
        vec![
            figure("bloom error ratio, min", bloom.0),
            figure("bloom error ratio, max", bloom.1),
            figure("epicentre error ratio, max", epicentre.1),
            figure("tail error ratio, max", tail.1),
        ],
    )
}

pub(super) fn chebyshev_epicentre(options: &ClaimOptions, errors: &Errors) -> Outcome {
    const BOUND: f64 = 0.005;
    let worst = |kind: LobeKind| {
        let rels: Vec<(f64, f64)> = options
            .exponents
            .iter()
            .map(|&n| (n.get(), errors(kind, n).epicentre_max_rel))
            .collect();
        let max = rels.iter().map(|r| r.1).fold(0.0, f64::max);
        let (first, last, count) = where_true(&rels, |rel| rel <= BOUND);
        (max, first, last, count)
    };
    let thesis = worst(LobeKind::Cheb2Thesis);
    let fitted = worst(LobeKind::Cheb2);
    let best = worst(LobeKind::Minimax2);
    let total = options.exponents.len();
    let describe = |(max, first, last, count): (f64, f64, f64, usize)| {
        if count == 0 {
            format!("max {:.2} %, <= 0.5 % at no tested n", 100.0 * max)
        } else if count == 1 {
            format!("max {:.2} %, <= 0.5 % only at n = {first}", 100.0 * max)
        } else {
            format!(
                "max {:.2} %, <= 0.5 % at {count} of {total} n (between n = {first:.3} and \
                    {last:.3})",
                100.0 * max
            )
        }
    };
    let verdict = if thesis.0 <= BOUND || fitted.0 <= BOUND {
        Verdict::Holds
    } else if thesis.3 > 0 || fitted.3 > 0 {
        Verdict::HoldsWithQualification
    } else {
        Verdict::DoesNotHold
    };
    (
        "max relative error against cos^n over the whole epicentre (t^n >= 1/2), for n in \
         [1, 1000]: (a) cheb2-thesis, the slide's coefficient formulas; (b) cheb2, the thesis's \
         3-node Chebyshev fit made per n over the epicentre; (c) minimax2, the best possible \
         quadratic in the angle, as a bound"
            .to_owned(),
        format!(
            "(a) {}; (b) {}; (c) {}",
            describe(thesis),
            describe(fitted),
            describe(best)
        ),
        verdict,
        vec![
            figure("cheb2-thesis epicentre max rel", thesis.0),
            figure("cheb2 epicentre max rel", fitted.0),
            figure("minimax2 epicentre max rel", best.0),
        ],
    )
}

pub(super) fn logexp_delta(options: &ClaimOptions, errors: &Errors) -> Outcome {
    let rows: Vec<ErrorFigures> = options
        .exponents
        .iter()
        .map(|&n| errors(LobeKind::LogExp, n))
        .collect();
    let (rel_min, rel_max) = range(rows.iter().map(|e| e.epicentre_max_rel));
    let bloom = rows.iter().map(|e| e.bloom_max_abs).fold(0.0, f64::max);
    // "delta = 0.29 %" read as the epicentre's maximum relative error, rounded as the slide
    // rounds it (two significant digits).
    let matches = (100.0 * rel_max * 100.0).round() / 100.0 == 0.29;
    (
        "delta = the maximum relative error against cos^n in the epicentre (t^n >= 1/2, i.e. \
         y = n log2 t in [-1, 0]), over n in [1, 1000], compared at the slide's two significant \
         digits"
            .to_owned(),
        format!(
            "epicentre max relative error {:.4} % (same at every n: {:.4}-{:.4} %); outside the \
             epicentre the lobe is cut to 0 at t^n = 1/8, so the bloom's max abs error is {:.4}",
            100.0 * rel_max,
            100.0 * rel_min,
            100.0 * rel_max,
            bloom
        ),
        if matches {
            Verdict::Holds
        } else {
            Verdict::DoesNotHold
        },
        vec![
            figure("logexp epicentre max rel", rel_max),
            figure("logexp bloom max abs", bloom),
        ],
    )
}
