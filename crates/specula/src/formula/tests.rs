//! The formula language against closed forms and the built-in lobes it can spell.

use std::collections::BTreeMap;

use super::*;
use crate::simd::{BatchLoop, Level};

fn definition(name: &str, formula: &str) -> Definition {
    Definition {
        name: name.to_owned(),
        description: None,
        formula: formula.to_owned(),
        tail: None,
        parameters: BTreeMap::new(),
    }
}

fn kind_of(definition: Definition) -> LobeKind {
    let formula = define(definition, Naming::Exact).expect("a valid formula");
    instance(formula, &[]).expect("default parameters")
}

const K4: &str = "let a = (n + 1) / 17;\nmax(0, a * (t - 1) + 1) ^ 16";

fn cosines() -> Vec<f32> {
    (0..=2000)
        .map(|i| 1.0 - (i as f32 / 2000.0).powi(2))
        .chain([0.0, -0.0, -1.0, f32::NAN, 1.5, f32::INFINITY, 1e-30])
        .collect()
}

/// K_4 written as a formula is the built-in `cosquad`: the same bits in `f64` and in the
/// scalar `f32` path, the same recorded operations, and the same bits from the columns as
/// from the built-in kernel (the multiply-add fused as it fuses it).
#[test]
fn cosquad_written_by_hand_is_the_built_in() {
    let kind = kind_of(definition("k4-by-hand", K4));
    for n in [1.0, 16.0, 64.0, 333.3, 1000.0] {
        let n = Exponent::new(n);
        let (mine, built_in) = (
            Lobe::checked(kind, n).unwrap(),
            Lobe::new(LobeKind::CosQuad { v: 4 }, n),
        );
        for i in 0..=1000 {
            let t = f64::from(i) / 1000.0;
            assert_eq!(
                mine.eval(t).to_bits(),
                built_in.eval(t).to_bits(),
                "n = {n} t = {t}"
            );
            let t = t as f32;
            assert_eq!(
                mine.eval(t).to_bits(),
                built_in.eval(t).to_bits(),
                "n = {n} t = {t}"
            );
        }
        let ts = cosines();
        for level in Level::available() {
            let (mut a, mut b) = (vec![0.0; ts.len()], vec![0.0; ts.len()]);
            mine.eval_batch_with(level, BatchLoop::Explicit, &ts, &mut a);
            built_in.eval_batch_with(level, BatchLoop::Explicit, &ts, &mut b);
            for ((t, x), y) in ts.iter().zip(&a).zip(&b) {
                assert_eq!(
                    x.to_bits(),
                    y.to_bits(),
                    "n = {n} {level:?} t = {t}: {x} vs {y}"
                );
            }
        }
        let (record, reference) = (mine.expression(), built_in.expression());
        for i in 1..=100 {
            let t = f64::from(i) / 100.0;
            assert_eq!(record.eval(t), reference.eval(t));
        }
        assert_eq!(
            mine.ops().total(),
            built_in.ops().total() + 2,
            "the clamp's min and max"
        );
    }
}

/// The spherical Gaussian with its tail: the check accepts the true integral, sampling
/// inverts it to the closed form's quantiles, and targets see `n` and the rate as
/// parameters computed from `n`.
#[test]
fn a_tail_samples_exactly() {
    let mut d = definition(
        "sg-with-tail",
        "let rate = n * 1.4426950408889634; exp2(rate * (t - 1))",
    );
    d.tail = Some("(1 - exp2(rate * (t - 1))) / (rate * 0.6931471805599453)".to_owned());
    let kind = kind_of(d);
    let n = Exponent::new(40.0);
    let lobe = Lobe::checked(kind, n).unwrap();
    assert_eq!(lobe.warp(), crate::lobe::Warp::Newton);
    let whole = (1.0 - (-40.0_f64).exp()) / 40.0;
    for u in [0.0, 0.1, 0.5, 0.9, 0.999] {
        let t = lobe.tail_inverse(u).unwrap().x;
        // int_t^1 e^(n(s-1)) ds = u * whole, solved for t.
        let expected = 1.0 + (1.0 - u * whole * 40.0).ln() / 40.0;
        assert!((t - expected).abs() < 1e-9, "u = {u}: {t} vs {expected}");
    }
    let names: Vec<&str> = lobe.parameters().iter().map(|p| p.name).collect();
    assert_eq!(names, ["c_rate"]);
    let prepared = lobe.preparation::<f64>("c_rate", 40.0).unwrap();
    assert_eq!(prepared, 40.0 * core::f64::consts::LOG2_E);

    let mut wrong = definition("sg-wrong-tail", "exp2(n * 1.4426950408889634 * (t - 1))");
    wrong.tail = Some("1 - t".to_owned());
    let message = Lobe::checked(kind_of(wrong), n).unwrap_err().to_string();
    assert!(
        message.contains("the tail is") && message.contains("n = 40"),
        "{message}"
    );
}

/// Values outside `[0, 1]` are refused at the `n` where they happen, and only there.
#[test]
fn values_outside_the_unit_interval_are_refused_at_their_n() {
    let kind = kind_of(definition(
        "above-one-below-n-4",
        "(1 + max(0, 4 - n)) * t ^ n",
    ));
    let message = Lobe::checked(kind, Exponent::new(2.0))
        .unwrap_err()
        .to_string();
    assert!(
        message.contains("above 1") && message.contains("n = 2"),
        "{message}"
    );
    assert!(Lobe::checked(kind, Exponent::new(4.0)).is_ok());
    for (name, text, says) in [
        ("negative-somewhere", "t - 0.5", "negative"),
        ("infinite-at-zero", "1 / t", "not finite"),
        ("nan-at-zero", "log(t) * 0", "not finite"),
    ] {
        let message = Lobe::checked(kind_of(definition(name, text)), Exponent::new(8.0))
            .unwrap_err()
            .to_string();
        assert!(
            message.contains(says) && !message.contains('\n'),
            "{name}: {message}"
        );
    }
}

/// Every refusal is one line naming the position and the problem.
#[test]
fn bad_formulas_get_one_line_each() {
    for (text, says) in [
        ("tt ^ n", "column 1: unknown name 'tt'; did you mean 't'?"),
        (
            "expp(t)",
            "column 1: unknown function 'expp'; did you mean 'exp'?",
        ),
        ("t ^ n +", "column 8: expected a number"),
        ("pow(t)", "pow takes 2 arguments, given 1"),
        ("select(t, 1, 0)", "must be a comparison"),
        ("t < 1", "only valid as the condition"),
        ("let t = 2; t", "reserved"),
        ("0.5", "does not depend on t"),
        ("max", "is a function"),
    ] {
        let message = define(definition("bad", text), Naming::Unique)
            .unwrap_err()
            .to_string();
        assert!(
            message.contains(says) && !message.contains('\n'),
            "{text}: {message}"
        );
    }
    let message = define(
        definition("bad", "let a = 2;\nlet b = a +;\nt"),
        Naming::Unique,
    )
    .unwrap_err()
    .to_string();
    assert!(message.contains("line 2, column 12"), "{message}");
    let message = define(definition("pow", "t"), Naming::Unique)
        .unwrap_err()
        .to_string();
    assert!(message.contains("built-in"), "{message}");
    // A constant of numbers alone that is NaN is refused (min and max treat NaN apart).
    let message = define(definition("bad", "min(t, 0 / 0)"), Naming::Unique)
        .unwrap_err()
        .to_string();
    assert!(message.contains("NaN or infinite"), "{message}");
    // An error in the tail points into the tail's text, one in the formula into its own.
    let mut with_tail = definition("bad", "let a = n;\nt ^ a");
    with_tail.tail = Some("(1 - t) / aa".to_owned());
    let message = define(with_tail, Naming::Unique).unwrap_err().to_string();
    assert!(
        message.contains("tail, column 11: unknown name 'aa'"),
        "{message}"
    );
    let message = define(definition("bad", "t ^ tail"), Naming::Unique)
        .unwrap_err()
        .to_string();
    assert!(message.contains("formula, column 5"), "{message}");
}

/// Declared parameters: defaults, values in range, the id showing what differs.
#[test]
fn parameters_have_ranges_and_appear_in_the_id() {
    let mut d = definition("with-sharpness", "t ^ (n * k)");
    d.parameters.insert(
        "k".to_owned(),
        ParameterDefinition {
            default: 1.0,
            min: 0.5,
            max: 2.0,
            description: None,
        },
    );
    let formula = define(d, Naming::Exact).unwrap();
    let default = instance(formula, &[]).unwrap();
    assert_eq!(default.to_string(), "with-sharpness");
    let sharper = LobeKind::parse("with-sharpness:k=2").unwrap();
    assert_eq!(sharper.to_string(), "with-sharpness:k=2");
    assert_eq!(LobeKind::parse(&sharper.to_string()).unwrap(), sharper);
    let lobe = Lobe::new(sharper, Exponent::new(10.0));
    assert!((lobe.eval(0.9_f64) - 0.9_f64.powf(20.0)).abs() < 1e-15);
    let message = LobeKind::parse("with-sharpness:k=3")
        .unwrap_err()
        .to_string();
    assert!(message.contains("[0.5, 2]"), "{message}");
    let message = LobeKind::parse("with-sharpness:q=1")
        .unwrap_err()
        .to_string();
    assert!(message.contains("unknown parameter 'q'"), "{message}");
}

/// The columns agree with the scalar `f32` path within the stated bound on formulas of every
/// function, including lanes outside the polynomials' ranges (which go lane by lane).
#[test]
fn columns_match_the_scalar_path_for_every_function() {
    let formulas = [
        ("col-exp2", "exp2(n * (t - 1) * 1.4427)"),
        ("col-exp", "exp(n * (t - 1))"),
        ("col-pow", "pow(t, n)"),
        ("col-log", "max(0, 1 + log(t) * n / 50)"),
        (
            "col-log2-acos",
            "clamp(1 - acos(t) * sqrt(n) / 3 + log2(1 + t) * 0, 0, 1)",
        ),
        ("col-select", "if(t > 0.5, t ^ 3, 0.125 * (2 * t) ^ 4)"),
        ("col-mix", "mix(t ^ n, exp(n * (t - 1)), 0.5)"),
        (
            "col-trig",
            "abs(cos(acos(t))) ^ n * (floor(t) * 0 + 1) * min(1, ceil(t))",
        ),
        (
            "col-quartic",
            "let c = n / 8; max(0, 1 - c * (1 - t) + c * (1 - t) ^ 2 / 4) ^ 4",
        ),
        ("col-grows", "exp(t * 2) / exp(2) * t ^ -2 * t ^ 2"),
        ("col-sin", "sin(t * pi / 2) ^ n"),
        ("col-neg", "-(-t) ^ 2 * -1 * t ^ n / e * e"),
        // Whole chains whose rules the range analysis drops (the first) or keeps (the mask
        // for the second, which is not 0 at t = 0; the clamp for the third, above 1).
        ("col-rules-dropped", "max(0, 2 * t - 1) ^ 2"),
        ("col-rules-mask", "(1 - t) ^ 2 * 0.5 + 0.25"),
        ("col-rules-clamp", "min(1, t * 1.5)"),
        // Two multiplies meeting in one add (one of them fused); a chain whose head a
        // column reads after the chain starts (its register must outlive both).
        ("col-two-products", "(t * t + t * t) * 0.5"),
        // A chain's value meeting a value saved earlier in it (Horner's rule): from t
        // itself, nested twice, subtracted either way round.
        ("col-saved-t", "t * (0.5 + t * 0.5)"),
        (
            "col-saved-cubic",
            "let u = 1 - t; exp2(u * (-n - u * (n / 2 + u * n / 3)) * 1.4427)",
        ),
        (
            "col-saved-quadratic-pow",
            "let s = n / 8; let c = (0.48 * s - 0.47) * s; let v = min(1 - t, 0.9); \
             max(0, 1 - v * (s - c * v)) ^ 8",
        ),
        (
            "col-saved-sub",
            "let u = 1 - t; max(0, 1 - (u * 3 - u) * 0.5 - u)",
        ),
        (
            "col-head-read-later",
            "let c = t * t; let p = c * 2; let d = c + t; let q = d * t; (p + 1) * q / 6",
        ),
    ];
    let ts = cosines();
    for (name, text) in formulas {
        let kind = kind_of(definition(name, text));
        for n in [1.0, 9.5, 100.0] {
            let lobe = Lobe::new(kind, Exponent::new(n));
            let bound = lobe.batch_ulp_bound() * f64::from(f32::EPSILON);
            for level in Level::available() {
                let mut out = vec![0.0; ts.len()];
                lobe.eval_batch_with(level, BatchLoop::Explicit, &ts, &mut out);
                for (&t, &value) in ts.iter().zip(&out) {
                    let scalar: f32 = lobe.eval(t);
                    assert!(
                        f64::from((value - scalar).abs()) <= bound && (0.0..=1.0).contains(&value),
                        "{text} n = {n} {level:?} t = {t}: {value} vs {scalar}"
                    );
                }
            }
        }
    }
}

/// A polynomial of one value inside a chain (the designed lobes' Horner forms) compiles to
/// one chain, not to columns.
#[test]
fn horner_forms_are_one_chain() {
    for (name, text) in [
        (
            "one-chain-exp2",
            "let u = 1 - t; exp2(u * (-n - u * n / 2))",
        ),
        (
            "one-chain-pow",
            "let v = min(1 - t, 0.9); (1 - v * (n / 8 - 0.1 * v)) ^ 8",
        ),
    ] {
        let LobeKind::Formula(id) = kind_of(definition(name, text)) else {
            unreachable!("a formula")
        };
        assert!(
            super::registry::get(id).formula().plan.is_one_chain(),
            "{text}"
        );
    }
    let kind = kind_of(definition("two-values", "t * t + (1 - t) * (1 - t) * 0"));
    let LobeKind::Formula(id) = kind else {
        unreachable!("a formula")
    };
    assert!(!super::registry::get(id).formula().plan.is_one_chain());
}

/// A Horner step of a falling polynomial (`s - c * v`, then `1 - v * (...)`) is one fused
/// link each, so the designed quadratics cost a dispatch per step, not two.
#[test]
fn horner_steps_are_one_link_each() {
    let kind = kind_of(definition(
        "horner-steps",
        "let v = min(1 - t, 0.9); (1 - v * (n / 8 - 0.1 * v)) ^ 8",
    ));
    let LobeKind::Formula(id) = kind else {
        unreachable!("a formula")
    };
    // 1 - t, min, keep v, n/8 - 0.1 v, 1 - v (...), three squarings: six links for the
    // formula's nine operations.
    assert_eq!(
        super::registry::get(id).formula().plan.one_chain_links(),
        Some(6)
    );
    // And the fused steps compute what the formula says, at every level.
    let lobe = Lobe::new(kind, Exponent::new(40.0));
    let ts = cosines();
    for level in Level::available() {
        let mut out = vec![0.0; ts.len()];
        lobe.eval_batch_with(level, BatchLoop::Explicit, &ts, &mut out);
        for (&t, &value) in ts.iter().zip(&out) {
            let v = (1.0 - f64::from(t)).min(0.9);
            // The shared rules: the value clamped to [0, 1], and 0 where t <= 0.
            let exact = if t > 0.0 {
                (1.0 - v * (5.0 - 0.1 * v)).powi(8).clamp(0.0, 1.0)
            } else {
                0.0
            };
            assert!(
                (f64::from(value) - exact).abs() <= 1e-5,
                "t = {t}: {value} vs {exact}"
            );
        }
    }
}

/// Inline formulas get numbered names; the same text is the same lobe.
#[test]
fn inline_formulas_are_named_and_shared() {
    let a = LobeKind::parse("=t ^ (n / 2)").unwrap();
    let b = LobeKind::parse("= t ^ (n / 2)").unwrap();
    let c = LobeKind::parse("=t ^ (n / 3)").unwrap();
    assert_ne!(a, c);
    assert_ne!(a.to_string(), c.to_string());
    assert_eq!(LobeKind::parse(&c.to_string()).unwrap(), c);
    assert_ne!(
        a.to_string(),
        b.to_string(),
        "texts differ in a space: two definitions"
    );
    assert_eq!(LobeKind::parse("=t ^ (n / 2)").unwrap(), a);
}

/// A whole power counts the multiplications of binary exponentiation, a real one the three
/// operations of `exp2(y log2 x)`; the per-material `let`s of `n` count nothing.
#[test]
fn operations_count_what_an_evaluation_multiplies() {
    let count = |text: &str| {
        Formula::compile(definition("counted", text))
            .expect("a valid formula")
            .operations()
    };
    // t^8: three squarings; t^7: t^2, t^4, then t^4 t^2 and that times t.
    assert_eq!(count("t ^ 8"), 3);
    assert_eq!(count("t ^ 7"), 4);
    assert_eq!(count("t ^ -4"), 3);
    // `1 - t`, `s * u`, `1 - su`, `max`, then four squarings; `s` is prepared once per n.
    assert_eq!(count("let s = n / 16;\nmax(0, 1 - s * (1 - t)) ^ 16"), 8);
    assert_eq!(count("pow(t, n)"), 3);
}

/// A formula lobe evaluated over many cosines at once (the tape walked per chunk of lanes)
/// gives what it gives one cosine at a time, to the bit: formulas using every operation, with
/// slots, selects and integer powers, over cosines inside `(0, 1]` and the shared rules'
/// edges (0, negatives, NaN, above 1), more of them than one chunk holds.
#[test]
fn a_lobe_over_many_cosines_is_the_lobe_at_each() {
    let formulas = [
        ("each-k4", K4),
        (
            "each-ops",
            "let a = sqrt(t) * log2(t + 1) + exp2(t) - exp(-t) + log(t + 2);\n\
             let b = acos(t) + cos(t) * sin(t) + abs(t - 0.5) + floor(4 * t) / 4 + ceil(t);\n\
             min(1, max(0, (a * b) / (n + 3) + t ^ 2.5 + t ^ 7 - t ^ (n / 9)))",
        ),
        (
            "each-select",
            "let s = 1 - 2 * (1 - t) * (n + 2) / 8;\n\
             select(s < 0.25, mix(0, clamp(s, 0, 1), 0.5), clamp(s, 0, 1) ^ 8)",
        ),
    ];
    let mut ts: Vec<f64> = (0..=1500)
        .map(|i| 1.0 - (f64::from(i) / 1500.0).powi(3))
        .collect();
    ts.extend([0.0, -0.0, -1.0, f64::NAN, 1.5, f64::INFINITY, 1e-300, 0.5]);
    for (name, text) in formulas {
        let kind = kind_of(definition(name, text));
        for n in [1.0, 7.5, 64.0, 1000.0] {
            let lobe = Lobe::checked(kind, Exponent::new(n)).unwrap();
            let each = lobe.eval_each(&ts);
            assert_eq!(each.len(), ts.len());
            for (&t, value) in ts.iter().zip(&each) {
                assert_eq!(
                    value.to_bits(),
                    lobe.eval(t).to_bits(),
                    "{name} n = {n} t = {t}"
                );
            }
        }
    }
}
