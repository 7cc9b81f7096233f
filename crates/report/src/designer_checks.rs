//! The designer's two checks in "Designed lobes": how far each design lies from its family's
//! optimum (Sollya's minimax at each `n` alone, what `specula design --limit` prints), and each
//! of the thesis's lobes at its own accuracy over the range against what `specula design`
//! returns there on each GPU family, with both formulas
//! ([`specula_decide::design::thesis::against_thesis`], what `specula design --against-thesis`
//! prints).

use indicatif::ProgressBar;
use specula::Exponent;
use specula_decide::design::grammar::{self, Fate};
use specula_decide::design::limit::limit_table;
use specula_decide::design::thesis::{against_thesis_each, ThesisRow};
use specula_decide::design::{percent, Design};
use specula_decide::Target;

use super::html::{escape, paragraph, table};
use super::Context;

/// Each verified design of `answer` against its family's optimum at five exponents of
/// `low..high`; without Sollya, a machine note instead.
pub(crate) fn limit(
    context: &mut Context,
    answer: &Design,
    (low, high): (f64, f64),
) -> Result<String, String> {
    let range = (Exponent::new(low), Exponent::new(high));
    let rows = match limit_table(&answer.designed, range, 4) {
        Ok(rows) => rows,
        Err(why) => {
            context.machine_note(format!("Designed lobes' limit table: {why}"));
            return Ok(String::new());
        }
    };
    let mut exponents: Vec<f64> = rows.iter().map(|row| row.n).collect();
    exponents.sort_by(f64::total_cmp);
    exponents.dedup();
    let mut header = vec!["family".to_owned()];
    header.extend(exponents.iter().map(|n| format!("n = {n:.0}")));
    let header: Vec<&str> = header.iter().map(String::as_str).collect();
    let mut families: Vec<Vec<String>> = Vec::new();
    for row in &rows {
        let cell = if row.optimum > 0.0 {
            format!("{:.2}x", row.designed / row.optimum)
        } else {
            "holds t^n".to_owned()
        };
        match families.last_mut() {
            Some(last) if last[0] == row.family => last.push(cell),
            _ => families.push(vec![row.family.clone(), cell]),
        }
    }
    let mut html = paragraph(&format!(
        "How far from the best each family can do: each design's epicentre error over its \
         family's optimum at that n alone (Sollya's Remez, its error certified by supnorm), \
         what one set of closed-form constants for n = {low}..{high} costs against a fit per n; \
         specula design --target TARGET --n {low}..{high} --max-error BOUND --limit."
    ));
    html += &table(&header, &families);
    Ok(html)
}

/// The table and the designed answers' formulas, for `families` (a target and its name) over
/// `low..high`.
pub(crate) fn thesis_table(
    families: &[(Target, &str)],
    (low, high): (f64, f64),
) -> Result<String, String> {
    let range = (Exponent::new(low), Exponent::new(high));
    let targets: Vec<(Target, Option<specula::gpus::Gpu>)> =
        families.iter().map(|&(target, _)| (target, None)).collect();
    let answers: Vec<Vec<ThesisRow>> =
        against_thesis_each(&targets, range, &ProgressBar::hidden())?;
    let mut html = paragraph(&format!(
        "Against the thesis: each of its lobes asks for the accuracy it reaches itself over n = \
         {low}..{high} (its largest epicentre error, and its largest whole-lobe error as the whole \
         lobe's bound); the answer is the cheapest lobe meeting both, designed or built in, the \
         thesis lobe ranked with them, so it is never costlier than the thesis lobe. Each column \
         is specula design --target TARGET --n {low}..{high} --against-thesis."
    ));
    let mut header = vec![
        "thesis lobe".to_owned(),
        "its formula".to_owned(),
        "its errors (epicentre, whole lobe)".to_owned(),
    ];
    header.extend(
        families
            .iter()
            .map(|(_, name)| format!("{name}: the answer (x the thesis lobe's throughput)")),
    );
    let header: Vec<&str> = header.iter().map(String::as_str).collect();
    let mut rows = Vec::new();
    let mut formulas = String::new();
    for (k, thesis) in answers
        .first()
        .map_or(&[][..], Vec::as_slice)
        .iter()
        .enumerate()
    {
        let mut row = vec![
            thesis.thesis.clone(),
            thesis.thesis_formula.clone(),
            format!(
                "{}, {}",
                percent(thesis.epicentre_error),
                percent(thesis.whole_error)
            ),
        ];
        for (family, (_, name)) in answers.iter().zip(families) {
            let answer = &family[k];
            row.push(format!(
                "{}{} ({:.2}x)",
                answer.answer,
                if answer.designed { ", designed" } else { "" },
                answer.answer_rate / answer.thesis_rate
            ));
            if answer.designed {
                formulas += &format!(
                    "<p>{name}, at {}'s accuracy: <code>{}</code></p>\n<pre>{}</pre>\n",
                    escape(&thesis.thesis),
                    escape(&answer.answer),
                    escape(&answer.answer_formula)
                );
            }
        }
        rows.push(row);
    }
    html += &table(&header, &rows);
    html += &formulas;
    Ok(html)
}

/// What the search enumerated for `answer` and what became of each structure: its grammar's
/// structures grouped by fate, each with its operations (`specula design --verbose`).
pub(crate) fn enumeration(answer: &Design, max_operations: usize) -> String {
    let [enumerated, pruned, missed, kept] = grammar::counts(&answer.enumerated);
    let listed = |keep: fn(&Fate) -> bool| {
        let names: Vec<String> = answer
            .enumerated
            .iter()
            .filter(|e| keep(&e.fate))
            .map(|e| format!("{} ({})", e.structure, e.operations))
            .collect();
        if names.is_empty() {
            "-".to_owned()
        } else {
            names.join(", ")
        }
    };
    let mut html = paragraph(&format!(
        "The search's structures, enumerated from the formula language's operations (exp2 of a \
         series of n ln t; a power of two of a peak-shaped function of 1 - t) within the cost \
         bound of {max_operations} operations per evaluation: {enumerated} enumerated, {pruned} \
         pruned before their fit, {missed} by their fit, {kept} kept. Each structure is named \
         with its operations; specula design --verbose prints this list with the reasons."
    ));
    html += &table(
        &["fate", "structures (operations)"],
        &[
            vec![
                format!("kept: fitted, verified, costed ({kept})"),
                listed(|f| matches!(f, Fate::Kept)),
            ],
            vec![
                format!("pruned by its fit: the coarse grids' best misses the bounds ({missed})"),
                listed(|f| matches!(f, Fate::FitMissed)),
            ],
            vec![
                format!("pruned before its fit: over the cost bound ({pruned})"),
                listed(|f| matches!(f, Fate::Pruned(_))),
            ],
        ],
    );
    html
}
