//! "Designed lobes", beside "Which lobe when": for each GPU vendor's current generation, the
//! lobe `specula design` searches out over `n` from 8 to 512 at a few epicentre bounds, next
//! to the cheapest built-in that meets the same bound, with its formula and figures, and the
//! Pareto plot of both kinds at the tightest bound. Every figure is
//! [`specula_decide::design::design`]'s answer (the command's library call), so the page and
//! `specula design` cannot disagree. The CPU's costs are timed, so its designs are left to
//! `specula design --target cpu` on a quiet machine.

use indicatif::ProgressBar;
use specula::{Exponent, LobeKind};
use specula_decide::design::{
    default_whole_error, design_each, percent, removed, Bounds, Design, DesignRequest,
    DEFAULT_WHOLE_ERROR,
};
use specula_decide::{versus_pow, Target};

use super::html::{escape, paragraph, table};
use super::plot::Series;
use super::prose;
use super::verdict::{pareto_chart, EXACT_FLOOR};
use super::Context;

const RANGE: (f64, f64) = (8.0, 512.0);

fn request(target: Target, bound: f64, also: &[LobeKind]) -> DesignRequest {
    DesignRequest {
        target,
        gpu: None,
        range: (Exponent::new(RANGE.0), Exponent::new(RANGE.1)),
        bounds: Bounds {
            epicentre: bound,
            whole: default_whole_error(bound),
            energy: None,
        },
        no_transcendentals: false,
        also: also.to_vec(),
        max_operations: specula_decide::design::grammar::DEFAULT_MAX_OPERATIONS,
    }
}

/// The section, stored by a first run of the build and copied back by a later one: its
/// costs are the compilers' machine code (or the model's), no timing; the compilers found are
/// part of the key.
pub fn designed(context: &mut Context) -> Result<String, String> {
    super::stored::section(context, super::DESIGNED, &tools_found()?, designed_now)
}

/// The tools the section's answers depend on, as this machine has them (each GPU's compiler
/// and version, or the model; Sollya or not): part of the stored section's key, so that a
/// tool installed after a first report changes the next one.
fn tools_found() -> Result<String, String> {
    let mut found = Target::GPUS
        .into_iter()
        .map(|target| specula_decide::gpu_basis(target, None).map(Option::unwrap_or_default))
        .collect::<Result<Vec<String>, String>>()?;
    found.push(format!(
        "sollya {}",
        if specula_decide::design::limit::sollya_found() {
            "found"
        } else {
            "missing"
        }
    ));
    Ok(found.join("; "))
}

fn designed_now(context: &mut Context) -> Result<String, String> {
    let bounds = context.sizes.design_bounds;
    // The user's lobes are ranked beside the built-ins and the designs.
    let yours = context.yours();
    let families = super::verdict::families();
    let named: Vec<(Target, &str)> = families
        .iter()
        .map(|(target, name)| (*target, name.as_str()))
        .collect();
    let jobs: Vec<(Target, &str, f64)> = named
        .iter()
        .flat_map(|&(target, name)| bounds.iter().map(move |&b| (target, name, b)))
        .collect();
    let requests: Vec<DesignRequest> = jobs
        .iter()
        .map(|&(target, _, bound)| request(target, bound, &yours))
        .collect();
    let answers: Vec<Design> = design_each(&requests, &ProgressBar::hidden())?;
    let verified = answers.first().map_or(0, |a| a.exponents_verified);
    let mut html = paragraph(&prose::fill(
        prose::DESIGNED,
        &[
            ("low", &RANGE.0),
            ("high", &RANGE.1),
            ("verified", &verified),
            ("whole", &percent(DEFAULT_WHOLE_ERROR)),
        ],
    )?);
    // Bounds whose answer is one design (the fit does not scale with the epicentre's bound,
    // so a family that meets several is one lobe) share a row, a verdict and a formula.
    let mut rows = Vec::new();
    let mut verdicts = String::new();
    let mut formulas = String::new();
    for group in groups(&jobs, &answers) {
        let (_, name, first_bound) = jobs[group[0]];
        let answer = &answers[group[0]];
        let named = group
            .iter()
            .map(|&k| percent(jobs[k].2))
            .collect::<Vec<_>>()
            .join(", ");
        let builtin = answer.best_compared().map_or("-".to_owned(), |c| {
            format!(
                "{} ({} pow's throughput)",
                c.lobe,
                versus_pow(c.rate, answer.pow_rate)
            )
        });
        let mut row = vec![name.to_owned(), named.clone()];
        match answer.best() {
            Some(best) => {
                formulas += &format!(
                    "<p>{name}, within {}: <code>{}</code></p>\n<pre>{}</pre>\n",
                    escape(&named),
                    escape(&best.name),
                    escape(&best.formula)
                );
                row.extend([
                    best.name.clone(),
                    percent(best.epicentre_error),
                    percent(best.whole_error),
                    versus_pow(best.rate, answer.pow_rate),
                ]);
            }
            None => row.extend(["-", "-", "-", "-"].map(str::to_owned)),
        }
        row.push(builtin);
        rows.push(row);
        verdicts += &paragraph(&format!(
            "{name}, within {}: {}",
            percent(first_bound),
            answer.verdict
        ));
        // A looser bound of the group says only what its whole-lobe bound removed.
        for &k in &group[1..] {
            let (target, _, bound) = jobs[k];
            if let Some(removed) = removed(&answers[k], &request(target, bound, &yours)) {
                verdicts += &paragraph(&format!("{name}, within {}: {removed}", percent(bound)));
            }
        }
    }
    html += &table(
        &[
            "target",
            "epicentre bound",
            "designed lobe",
            "its epicentre error",
            "its whole-lobe error",
            "designed vs pow",
            "cheapest other lobe (vs pow)",
        ],
        &rows,
    );
    html += &verdicts;
    html += &formulas;
    // The search does not depend on the target: one answer's designs are every target's.
    if let Some(answer) = answers.first() {
        html += &super::designer_checks::enumeration(
            answer,
            specula_decide::design::grammar::DEFAULT_MAX_OPERATIONS,
        );
        html += &super::designer_checks::limit(context, answer, RANGE)?;
    }
    html += &super::designer_checks::thesis_table(&named, RANGE)?;
    for (k, (target, name)) in named.iter().enumerate() {
        // The tightest bound's answer for this family.
        let answer = &answers[k * bounds.len()];
        html += &pareto_plot(context, *target, name, bounds[0], answer)?;
    }
    Ok(html)
}

/// The jobs in runs of one target whose answers name the same design (or none), each run the
/// jobs' indices, tightest bound first.
fn groups(jobs: &[(Target, &str, f64)], answers: &[Design]) -> Vec<Vec<usize>> {
    let design = |k: usize| answers[k].best().map(|best| best.formula.clone());
    let mut groups: Vec<Vec<usize>> = Vec::new();
    for k in 0..jobs.len() {
        match groups.last_mut() {
            Some(group) if jobs[group[0]].0 == jobs[k].0 && design(group[0]) == design(k) => {
                group.push(k);
            }
            _ => groups.push(vec![k]),
        }
    }
    groups
}

/// Error against modelled cost, the designed lobes on the joint Pareto front and the
/// built-ins, with that front: a design another lobe dominates is in the table above, not on
/// the chart, where a cluster of near-equal designs (the rational families' errors agree to
/// two digits) made one label too long to place.
fn pareto_plot(
    context: &mut Context,
    target: Target,
    name: &str,
    bound: f64,
    answer: &Design,
) -> Result<String, String> {
    let mut points: Vec<(LobeKind, (f64, f64), bool)> = answer
        .designed
        .iter()
        .filter(|d| d.verified && d.rate > 0.0 && d.pareto)
        .filter_map(|d| {
            Some((
                d.kind()?,
                (d.epicentre_error.max(EXACT_FLOOR), d.rate),
                false,
            ))
        })
        .collect();
    points.extend(answer.compared.iter().filter_map(|c| {
        let kind = context
            .lobes
            .iter()
            .copied()
            .find(|k| k.to_string() == c.lobe)?;
        Some((kind, (c.error.max(EXACT_FLOOR), c.rate), false))
    }));
    // The front over both kinds together.
    let plain: Vec<(f64, f64)> = points.iter().map(|&(_, p, _)| p).collect();
    for (point, on) in points.iter_mut().zip(specula_decide::pareto_front(&plain)) {
        point.2 = on;
    }
    let bound_line = Series {
        name: format!("the bound, {}", percent(bound)),
        points: vec![(bound, 0.1), (bound, 1e3)],
        colour: plotters::style::RGBColor(200, 60, 60),
        width: 1,
        markers: false,
        dashed: true,
    };
    let chart = pareto_chart(
        format!(
            "{name}: worst epicentre error over n = {}..{} against cost",
            RANGE.0, RANGE.1
        ),
        &points,
        vec![bound_line],
        answer.unit,
    );
    context.svg(
        &format!("designed-{}.svg", target.id()),
        &chart,
        &format!(
            "{name}: the designed lobes on the Pareto front (within {}; the others are in the \
                table) and the built-ins, error against cost; higher left is better, the grey \
                line joins the front over both, the red line is the bound",
            percent(bound)
        ),
    )
}
