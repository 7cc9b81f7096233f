//! The claims' figures against values derived here from closed forms.

use specula::claims::{claim_exponents, evaluate, evaluate_all, ClaimId, ClaimOptions, Verdict};

fn options() -> ClaimOptions {
    ClaimOptions {
        exponents: claim_exponents(12),
        samples_per_zone: 20_001,
        reciprocity_pairs: 5_000,
        seed: 7,
    }
}

fn figure(id: ClaimId, name: &str) -> f64 {
    let result = evaluate(id, &options());
    result
        .figures
        .iter()
        .find(|f| f.name == name)
        .map(|f| f.value)
        .unwrap_or_else(|| panic!("{name} missing from {:?}", result.figures))
}

/// In the epicentre `y = n log2 t` runs over `[-1, 0]`, so logexp's relative error there is
/// that of `1 - log2(1 - y)/2` against `2^y`, whatever `n` is.
#[test]
fn logexp_delta_is_the_relative_error_of_the_two_to_the_y_approximation() {
    let steps = 1_000_000;
    let scanned = (0..=steps)
        .map(|i| -f64::from(i) / f64::from(steps))
        .map(|y: f64| ((1.0 - 0.5 * (1.0 - y).log2()) - y.exp2()).abs() / y.exp2())
        .fold(0.0, f64::max);
    let measured = figure(ClaimId::LogExpDelta, "logexp epicentre max rel");
    assert!((measured - scanned).abs() < 1e-6, "{measured} vs {scanned}");
}

/// coef1 / ((n+1)/(2 pi)) = 1.063 n / (n + 1), increasing in n: its extremes are at n = 1
/// and n = 1000.
#[test]
fn coef1_ratio_extremes_follow_the_closed_form() {
    let low = figure(ClaimId::ThesisPhongCoefficient, "coef1 / exact, min");
    let high = figure(ClaimId::ThesisPhongCoefficient, "coef1 / exact, max");
    assert!((low - 1.063 / 2.0).abs() < 1e-9, "{low}");
    assert!((high - 1.063 * 1000.0 / 1001.0).abs() < 1e-9, "{high}");
}

/// K_4 with coef2 is pow-like: its largest albedo is below 1; pow with coef1 reflects
/// `1.063 n / (n + 2)` at normal incidence, above 1 for large n.
#[test]
fn energy_correct_model_figures() {
    let result = evaluate(ClaimId::EnergyCorrectModel, &options());
    let get = |name: &str| {
        result
            .figures
            .iter()
            .find(|f| f.name == name)
            .unwrap()
            .value
    };
    assert!(get("K_4 + coef2 max albedo") <= 1.0);
    assert_eq!(get("K_4 + coef2 reciprocity error"), 0.0);
    assert!(get("classic implied BRDF reciprocity error") > 0.1);
    let coef1_albedo = get("pow + coef1 max albedo");
    assert!(
        (coef1_albedo - 1.063 * 1000.0 / 1002.0).abs() < 1e-6,
        "{coef1_albedo}"
    );
    assert_eq!(result.verdict, Verdict::Holds);
}

/// K_4 at n >= 16 integrates exactly to 1/(n+1) (closed form); below, less.
#[test]
fn cosquad_energy_claim_is_qualified_at_small_n() {
    let result = evaluate(ClaimId::CosQuadEnergy, &options());
    assert_eq!(result.verdict, Verdict::HoldsWithQualification);
    assert!(result.figures[0].value < 1e-9);
    assert!(result.figures[1].value < 1.0);
}

/// The shared error table changes nothing: all claims at once are each claim alone.
#[test]
fn evaluating_every_claim_at_once_gives_each_claims_own_result() {
    let options = ClaimOptions {
        exponents: claim_exponents(4),
        samples_per_zone: 2_001,
        reciprocity_pairs: 1_000,
        seed: 7,
    };
    let all = evaluate_all(&options);
    assert_eq!(all.len(), ClaimId::ALL.len());
    for (id, result) in ClaimId::ALL.into_iter().zip(&all) {
        assert_eq!(result.id, id);
        assert_eq!(*result, evaluate(id, &options), "{id:?}");
    }
}
