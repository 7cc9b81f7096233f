//! `specula design`'s answer in one line: the cheapest designed lobe within the bounds and the
//! cheapest other lobe beside it, or what came closest; and, apart, what the whole lobe's
//! bound removed and the flag that admits it.

use super::{percent, Design, DesignRequest};
use crate::ranking::{rates_overlap, versus_pow};

/// The answer in one line.
pub(super) fn verdict(design: &Design, request: &DesignRequest) -> String {
    let (low, high) = request.range;
    let within = format!(
        "within {} in the epicentre (whole lobe {}{}) at n from {low} to {high} on {}",
        percent(request.bounds.epicentre),
        percent(request.bounds.whole),
        request
            .bounds
            .energy
            .map_or(String::new(), |e| format!(", energy {}", percent(e))),
        request.target.id()
    );
    let others = if request.also.is_empty() {
        "built-in"
    } else {
        "built-in or given lobe"
    };
    let builtin = design.best_compared().map_or_else(
        || format!("no {others} meets it"),
        |c| {
            format!(
                "the cheapest {others} is {} at {} pow's throughput",
                c.lobe,
                versus_pow(c.rate, design.pow_rate)
            )
        },
    );
    let found = match design.best() {
        Some(best) => {
            let versus = match design.best_compared() {
                Some(c) if rates_overlap((c.rate, c.spread), (best.rate, best.spread)) => {
                    format!(
                        "; {builtin}, tied with it (their measured rates overlap): ship the more \
                            accurate, {}",
                        if c.error <= best.epicentre_error {
                            &c.lobe
                        } else {
                            &best.name
                        }
                    )
                }
                Some(c) if c.rate > best.rate => {
                    format!("; {builtin}, cheaper than every design: ship the built-in")
                }
                _ => format!("; {builtin}"),
            };
            let tie = if best.tied.len() > 1 {
                format!(
                    " (the most accurate of the designs tied for the cheapest, whose measured \
                        rates overlap: {})",
                    best.tied.join(", ")
                )
            } else {
                String::new()
            };
            format!(
                "{}: the cheapest designed lobe {within}, at {} pow's throughput{tie}{versus}",
                best.name,
                versus_pow(best.rate, design.pow_rate)
            )
        }
        None => {
            let closest = design
                .designed
                .iter()
                .min_by(|a, b| a.epicentre_error.total_cmp(&b.epicentre_error));
            format!(
                "no designed lobe {within}: searched {} families; the closest, {}, reached {} \
                    in the epicentre and {} over the whole lobe; {builtin}",
                design.designed.len(),
                closest.map_or("none", |d| d.family.as_str()),
                closest.map_or("-".to_owned(), |d| percent(d.epicentre_error)),
                closest.map_or("-".to_owned(), |d| percent(d.whole_error)),
            )
        }
    };
    match removed(design, request) {
        Some(removed) => format!("{found}. {removed}"),
        None => found,
    }
}

/// What the whole lobe's bound removed that would be cheaper than the answer, and the flag
/// that admits it; `None` where it removed nothing cheaper.
pub fn removed(design: &Design, request: &DesignRequest) -> Option<String> {
    let floor = design.best().map_or(0.0, |best| best.rate);
    let cheapest = design
        .designed
        .iter()
        .find(|d| d.short_of_whole_only && d.rate > floor)?;
    let flag = design.admit_whole.as_deref()?;
    let others = design
        .designed
        .iter()
        .filter(|d| d.short_of_whole_only && d.rate > floor)
        .count()
        - 1;
    let also = match others {
        0 => String::new(),
        1 => " (and 1 other design)".to_owned(),
        k => format!(" (and {k} other designs)"),
    };
    Some(format!(
        "The whole lobe's bound ({}{}) removed {}{also}, within {} in the epicentre but {} over \
            the whole lobe, at {} pow's throughput: admit it with --max-whole-error {flag}",
        percent(request.bounds.whole),
        if request.bounds.whole == super::default_whole_error(request.bounds.epicentre) {
            ", the default"
        } else {
            ""
        },
        cheapest.name,
        percent(cheapest.epicentre_error),
        percent(cheapest.whole_error),
        versus_pow(cheapest.rate, design.pow_rate)
    ))
}
