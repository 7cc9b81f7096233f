//! The search's cache gives back the search bit for bit, the fit does not depend on the
//! epicentre's bound where the other bounds do not bind, and what the whole lobe's bound
//! removed is reported with a flag that admits it.

use indicatif::ProgressBar;
use specula::analysis::{error_figures, Precision};
use specula::{Exponent, Lobe};

use crate::hardware::SWEEP_SAMPLES;

use super::*;

fn request(target: Target, low: f64, high: f64, epicentre: f64, whole: f64) -> DesignRequest {
    DesignRequest {
        target,
        range: (Exponent::new(low), Exponent::new(high)),
        bounds: Bounds {
            epicentre,
            whole,
            energy: None,
        },
        no_transcendentals: false,
        also: Vec::new(),
    }
}

/// A searched lobe's formula, coefficients' and figures' bits, checks and reason.
type Found = (String, Vec<u64>, [u64; 3], bool, bool, String);

/// What a search found, without the registry's kind (compared field by field).
fn figures(lobes: &[DesignedLobe]) -> Vec<Found> {
    lobes
        .iter()
        .map(|d| {
            (
                d.formula.clone(),
                d.coefficients.iter().map(|c| c.to_bits()).collect(),
                [d.epicentre_error, d.whole_error, d.energy_deviation].map(f64::to_bits),
                d.verified,
                d.short_of_whole_only,
                d.why.clone(),
            )
        })
        .collect()
}

#[test]
fn a_stored_search_comes_back_bit_for_bit_and_other_bounds_miss_it() {
    let directory = tempfile::tempdir().unwrap();
    let cache = Cache::new(directory.path());
    let asked = request(Target::GpuAmd, 16.0, 128.0, 0.005, 0.01);
    let fresh = search(&asked, Some(&cache), &ProgressBar::hidden());
    let stored = std::fs::read_dir(directory.path()).unwrap().count();
    assert_eq!(stored, 1, "one entry");
    let again = search(&asked, Some(&cache), &ProgressBar::hidden());
    assert_eq!(figures(&again), figures(&fresh));
    // Loaded lobes are registered again: the same formula, so the same lobe.
    for (a, b) in again.iter().zip(&fresh) {
        assert_eq!(a.kind(), b.kind(), "{}", a.name);
    }
    // The figures kept beside a lobe, which a later process takes for its own, are the
    // analysis's at those exponents.
    let kept = cache::load(&cache, &cache::key(&asked), &asked).expect("the stored search");
    for lobe in kept.iter().filter(|lobe| lobe.verified) {
        let kind = lobe.kind().expect("a verified lobe is registered");
        let measured = crate::figures::measured(kind);
        assert!(
            measured.len() >= 2,
            "{}: {} exponents",
            lobe.name,
            measured.len()
        );
        for &(n, figures) in measured.iter().step_by(measured.len() / 2) {
            let at = Lobe::new(kind, Exponent::new(f64::from_bits(n)));
            let direct = error_figures(&at, &mut Precision::F64, SWEEP_SAMPLES);
            assert_eq!(
                figures,
                direct,
                "{} at n = {}",
                lobe.name,
                at.exponent().get()
            );
        }
    }
    let other = request(Target::GpuAmd, 16.0, 128.0, 0.005, 0.02);
    assert_ne!(cache::key(&other), cache::key(&asked));
    let _ = search(&other, Some(&cache), &ProgressBar::hidden());
    assert_eq!(std::fs::read_dir(directory.path()).unwrap().count(), 2);
    // The target plays no part in the search, so it shares the entry.
    let nvidia = request(Target::GpuNvidia, 16.0, 128.0, 0.005, 0.01);
    assert_eq!(cache::key(&nvidia), cache::key(&asked));
}

/// Two epicentre bounds with the same whole-lobe bound, neither binding the fit: the family's
/// coefficients are the same bit for bit, so the same lobe answers both.
#[test]
fn the_fit_does_not_scale_with_the_epicentre_bound() {
    let grids: Vec<fit::Grid> = log_spaced(Exponent::new(8.0), Exponent::new(512.0), 6)
        .into_iter()
        .map(|n| fit::Grid::new(n.get()))
        .collect();
    let family = Family::Exp2Poly { degree: 2 };
    let bounds = |epicentre| Bounds {
        epicentre,
        whole: 0.01,
        energy: None,
    };
    let (tight, tight_score) = fit::fit(family, &grids, bounds(0.001));
    let (loose, loose_score) = fit::fit(family, &grids, bounds(0.005));
    assert_eq!(
        tight.iter().map(|c| c.to_bits()).collect::<Vec<_>>(),
        loose.iter().map(|c| c.to_bits()).collect::<Vec<_>>()
    );
    // The scores are relative to each bound: five times apart.
    assert!(
        (tight_score / loose_score - 5.0).abs() < 1e-9,
        "{tight_score} {loose_score}"
    );
}

/// `exp2-cubic` holds 0.5 % in the epicentre from n = 2 to 1000 but not the default 1 % over
/// the whole lobe, and on NVIDIA's model it is cheaper than the design that meets 1 %: the
/// answer names it apart with the flag that admits it, and that flag does.
#[test]
fn what_the_whole_lobe_bound_removed_is_named_with_the_flag_that_admits_it() {
    let directory = tempfile::tempdir().unwrap();
    let cache = Cache::new(directory.path());
    let answer = |whole| {
        let asked = request(Target::GpuNvidia, 2.0, 1000.0, 0.01, whole);
        let searched = search(&asked, Some(&cache), &ProgressBar::hidden());
        (
            rank(&asked, searched, &ProgressBar::hidden()).unwrap(),
            asked,
        )
    };
    let (strict, asked) = answer(default_whole_error(0.01));
    let removed_lobe = strict
        .designed
        .iter()
        .find(|d| d.short_of_whole_only)
        .expect("a design short of the whole lobe's bound alone");
    assert!(
        !removed_lobe.meets && removed_lobe.rate > 0.0,
        "{removed_lobe:?}"
    );
    assert!(removed_lobe.epicentre_error <= 0.01 && removed_lobe.whole_error > 0.01);
    assert_eq!(strict.removed_by_whole.first(), Some(&removed_lobe.name));
    let flag = strict.admit_whole.clone().expect("a flag");
    let note = removed(&strict, &asked).expect("a note");
    assert!(
        note.contains(&format!("--max-whole-error {flag}")),
        "{note}"
    );
    assert!(strict.verdict.contains(&note), "{}", strict.verdict);
    let admitted: f64 = flag.trim_end_matches('%').parse::<f64>().unwrap() / 100.0;
    let (loose, _) = answer(admitted);
    let family = &removed_lobe.family;
    let now = loose.designed.iter().find(|d| &d.family == family).unwrap();
    assert!(now.meets, "{now:?}");
}

/// A measured tie goes to the most accurate lobe of those whose spreads overlap the
/// fastest's; one clearly faster stands alone.
#[test]
fn a_tie_of_measured_designs_goes_to_the_most_accurate() {
    let lobe = |name: &str, error: f64, rate: f64, median: f64| DesignedLobe {
        name: name.to_owned(),
        epicentre_error: error,
        rate,
        spread: Some([median, rate]),
        meets: true,
        ..unmeasured(
            Family::Exp2Poly { degree: 1 },
            &[0.0],
            &request(Target::Cpu, 8.0, 8.0, 0.1, 0.1),
        )
    };
    let mut tied = vec![
        lobe("fast", 0.004, 3.0, 2.8),
        lobe("close", 0.001, 2.9, 2.7),
        lobe("slow", 0.0001, 2.0, 1.9),
    ];
    break_tie(&mut tied);
    let names: Vec<&str> = tied.iter().map(|d| d.name.as_str()).collect();
    assert_eq!(names, ["close", "fast", "slow"]);
    assert_eq!(tied[0].tied, ["close", "fast"]);
    let mut apart = vec![
        lobe("fast", 0.004, 3.0, 2.95),
        lobe("close", 0.001, 2.9, 2.7),
    ];
    break_tie(&mut apart);
    assert_eq!(apart[0].name, "fast");
    assert!(apart[0].tied.is_empty());
}

/// What the fit evaluates is what the written formula computes: every family's `eval` against
/// the core's compilation of its text, at coefficients beside the start, across `n` and `t`.
#[test]
fn every_familys_formula_computes_what_its_fit_evaluates() {
    for family in Family::all() {
        let beta: Vec<f64> = family
            .start()
            .iter()
            .enumerate()
            .map(|(k, b)| b + 0.01 * (k as f64 + 1.0))
            .collect();
        let definition = specula::formula::Definition {
            name: format!("check-{}", family.id()),
            description: None,
            formula: family.formula(&beta),
            tail: None,
            parameters: Default::default(),
        };
        let formula = specula::formula::define(definition, specula::formula::Naming::Unique)
            .unwrap_or_else(|e| panic!("{}: {e}", family.id()));
        let kind = specula::formula::instance(formula, &[]).unwrap();
        for n in [8.0, 64.0, 512.0] {
            let lobe = Lobe::new(kind, Exponent::new(n));
            // Above t = 0, where every lobe's rule gives 0 whatever its formula.
            for k in 0..200 {
                let t = 1.0 - (f64::from(k) / 200.0).powi(3);
                let expected = family.eval(&beta, n, 1.0 - t).clamp(0.0, 1.0);
                let written = lobe.eval(t);
                assert!(
                    (written - expected).abs() <= 1e-12,
                    "{} at n = {n}, t = {t}: {written} against {expected}",
                    family.id()
                );
            }
        }
    }
}

/// Schlick's lobe is the rational family's first member: `a = 1`, `b = n - 1`, no squaring.
#[test]
fn schlicks_lobe_is_a_member_of_the_rational_family() {
    let family = Family::RationalPow { squarings: 0 };
    for n in [2.0, 16.0, 300.0] {
        let schlick = Lobe::new(specula::LobeKind::Schlick, Exponent::new(n));
        for k in 0..=100 {
            let t = f64::from(k) / 100.0;
            let member = family.eval(&[0.0, 1.0, 1.0, -1.0], n, 1.0 - t);
            assert!(
                (member - schlick.eval(t)).abs() <= 1e-14,
                "n = {n}, t = {t}"
            );
        }
    }
}
