//! Verifying a fitted family: its formula written, registered and measured by the `f64`
//! analysis at every verification exponent (the rules of a lobe, the epicentre's, the whole
//! lobe's and the energy's bounds), or reported from the fit's own grids where the fit
//! missed.

use specula::analysis::energy_ratio;
use specula::formula::{define, instance, Naming};
use specula::{Exponent, Lobe, LobeKind};

use super::{fit, Bounds, DesignRequest, DesignedLobe, Family};
use crate::percent::{exceeds, percent};

/// The family with `beta` written out, not yet measured (its figures infinite).
pub(super) fn unmeasured(family: Family, beta: &[f64], request: &DesignRequest) -> DesignedLobe {
    let (low, high) = request.range;
    DesignedLobe {
        family: family.id(),
        name: family.id(),
        description: format!(
            "{}; designed by specula for n in [{low}, {high}]",
            family.description()
        ),
        formula: family.formula(beta),
        tail: family.tail(),
        coefficients: beta.to_vec(),
        epicentre_error: f64::INFINITY,
        whole_error: f64::INFINITY,
        energy_deviation: f64::INFINITY,
        checked: false,
        verified: false,
        short_of_whole_only: false,
        rate: 0.0,
        datapath: None,
        spread: None,
        tied: Vec::new(),
        meets: false,
        pareto: false,
        why: String::new(),
        kind: None,
    }
}

/// The family with `beta` as its fit left it, short of the bounds on the fit's grids: its
/// figures are those grids' (not verified, so never a candidate).
pub(super) fn short(
    family: Family,
    beta: &[f64],
    request: &DesignRequest,
    grids: &[fit::Grid],
) -> DesignedLobe {
    let figures = fit::figures(family, beta, grids, request.bounds.energy.is_some());
    DesignedLobe {
        epicentre_error: figures.epicentre,
        whole_error: figures.whole,
        energy_deviation: figures.energy,
        why: format!(
            "its best fit reaches {} in the epicentre and {} over the whole lobe (fit grids; not \
                verified)",
            percent(figures.epicentre),
            percent(figures.whole)
        ),
        ..unmeasured(family, beta, request)
    }
}

/// Registers `lobe`'s formula (numbered where a lobe of the user's took its name), naming
/// `lobe` as registered; `Err` says why the text was refused.
pub(super) fn register(lobe: &mut DesignedLobe) -> Result<(), String> {
    let formula = define(lobe.definition(), Naming::Unique).map_err(|e| e.to_string())?;
    lobe.name = formula.name().to_owned();
    lobe.kind = Some(instance(formula, &[]).map_err(|e| e.to_string())?);
    Ok(())
}

/// The family with `beta` written as a formula, registered, and verified at `exponents`.
pub(super) fn verified(
    family: Family,
    beta: &[f64],
    request: &DesignRequest,
    exponents: &[Exponent],
) -> DesignedLobe {
    let mut lobe = unmeasured(family, beta, request);
    if let Err(error) = register(&mut lobe) {
        lobe.why = format!("its formula was refused: {error}");
        return lobe;
    }
    let Some(kind) = lobe.kind else {
        return lobe;
    };
    lobe.checked = true;
    match check_lobe(kind, exponents, request.bounds, &mut lobe) {
        Checked::Holds => {
            lobe.verified = true;
            lobe.why = format!("verified at {} exponents", exponents.len());
        }
        Checked::WholeOnly(why) => {
            lobe.short_of_whole_only = true;
            lobe.why = why;
        }
        Checked::Broken(why) => lobe.why = why,
    }
    lobe
}

/// What the verification found.
enum Checked {
    /// Every rule and bound held at every exponent.
    Holds,
    /// Every rule and bound but the whole lobe's: why.
    WholeOnly(String),
    /// A rule or the epicentre's or energy's bound broken: the first, and where.
    Broken(String),
}

/// Measures `kind` at every exponent into `lobe`'s figures, and says which rules and bounds
/// held.
fn check_lobe(
    kind: LobeKind,
    exponents: &[Exponent],
    bounds: Bounds,
    lobe: &mut DesignedLobe,
) -> Checked {
    let (mut epicentre, mut whole, mut energy) = (0.0_f64, 0.0_f64, 0.0_f64);
    let (mut first_epicentre, mut first_whole, mut first_energy) = (None, None, None);
    for &n in exponents {
        let checked = match Lobe::checked(kind, n) {
            Ok(checked) => checked,
            Err(error) => return Checked::Broken(error.to_string()),
        };
        let peak = checked.eval(1.0_f64);
        if (peak - 1.0).abs() > 1e-12 {
            return Checked::Broken(format!("at n = {n} its peak is {peak}, not 1"));
        }
        if let Some(t) = decreasing_at(&checked) {
            return Checked::Broken(format!("at n = {n} it falls as t rises, at t = {t}"));
        }
        let figures = crate::figures::f64_figures(&checked);
        let here = figures
            .epicentre_max_abs
            .max(figures.bloom_max_abs)
            .max(figures.tail_max_abs);
        epicentre = epicentre.max(figures.epicentre_max_rel);
        whole = whole.max(here);
        if figures.epicentre_max_rel > bounds.epicentre && first_epicentre.is_none() {
            first_epicentre = Some(format!(
                "epicentre error {} at n = {n}",
                exceeds(figures.epicentre_max_rel, bounds.epicentre)
            ));
        }
        if here > bounds.whole && first_whole.is_none() {
            first_whole = Some(format!(
                "whole-lobe error {} at n = {n}",
                exceeds(here, bounds.whole)
            ));
        }
        if let Some(tolerance) = bounds.energy {
            let off = (energy_ratio(&checked) - 1.0).abs();
            energy = energy.max(off);
            if off > tolerance && first_energy.is_none() {
                first_energy = Some(format!(
                    "energy ratio off by {} at n = {n}",
                    exceeds(off, tolerance)
                ));
            }
        }
    }
    lobe.epicentre_error = epicentre;
    lobe.whole_error = whole;
    lobe.energy_deviation = energy;
    match (first_epicentre.or(first_energy), first_whole) {
        (Some(broken), _) => Checked::Broken(broken),
        (None, Some(whole)) => Checked::WholeOnly(whole),
        (None, None) => Checked::Holds,
    }
}

/// A cosine at which `lobe` falls as `t` rises (by more than rounding), if any: checked on
/// 4000 steps of `w = n (1 - t)` over the lobe's width and 1000 over `[0, 1]`.
fn decreasing_at(lobe: &Lobe) -> Option<f64> {
    let n = lobe.exponent().get();
    let mut ts: Vec<f64> = (0..=4000)
        .map(|k| (1.0 - 40.0 * f64::from(k) / 4000.0 / n).max(0.0))
        .chain((0..=1000).map(|k| f64::from(k) / 1000.0))
        .collect();
    ts.sort_by(f64::total_cmp);
    let values = lobe.eval_each(&ts);
    values
        .windows(2)
        .zip(&ts)
        .find(|(pair, _)| pair[1] < pair[0] - 1e-14)
        .map(|(_, &t)| t)
}
