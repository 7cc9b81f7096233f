//! The recorded expression is the lobe: run back in `f32` it gives the fast path's bits, in
//! `f64` the reference's, and its bit-trick-free lowering gives the same `f32` bits.

use specula::expression::{record, Branched, Node};
use specula::lobe::Warp;
use specula::{Lobe, LobeKind, Real};

const EXPONENTS: [f64; 8] = [1.0, 2.5, 8.0, 16.0, 64.0, 100.0, 512.0, 1000.0];

fn kinds() -> Vec<LobeKind> {
    let mut kinds = LobeKind::ALL.to_vec();
    kinds.extend([0u8, 1, 7, 10].map(|v| LobeKind::CosQuad { v }));
    kinds
}

/// Cosines spread over every scale a lobe sees: log-spaced from the smallest normal `f32` to
/// 1, linear over (0, 1], every power of two and its neighbours (the bit tricks' binade
/// edges), and 1.
fn cosines() -> Vec<f32> {
    let mut t: Vec<f32> = (0..=4000)
        .map(|k| (f64::from(f32::MIN_POSITIVE).ln() * (1.0 - f64::from(k) / 4000.0)).exp() as f32)
        .collect();
    t.extend((1..=20000).map(|k| k as f32 / 20000.0));
    for e in 0..126 {
        let p = (-(e as f32)).exp2();
        t.extend([
            p,
            f32::from_bits(p.to_bits() - 1),
            f32::from_bits(p.to_bits() + 1),
        ]);
    }
    t.retain(|t| *t >= f32::MIN_POSITIVE && *t <= 1.0);
    t
}

#[test]
fn the_record_evaluates_to_the_lobes_own_bits() {
    let cosines = cosines();
    for kind in kinds() {
        for n in EXPONENTS {
            let lobe = Lobe::try_new(kind, n).unwrap();
            let expression = lobe.expression();
            let lowered = expression.lowered();
            assert!(
                !lowered.has_bit_tricks(),
                "{kind} n = {n}: lowering left a bit trick"
            );
            for &t in &cosines {
                let fast = lobe.eval(t);
                assert_eq!(
                    expression.eval(t).to_bits(),
                    fast.to_bits(),
                    "{kind} n = {n} t = {t:e}: record {} vs lobe {fast}",
                    expression.eval(t)
                );
                assert_eq!(
                    lowered.eval(t).to_bits(),
                    fast.to_bits(),
                    "{kind} n = {n} t = {t:e}: lowered {} vs lobe {fast}",
                    lowered.eval(t)
                );
                let reference = lobe.eval(f64::from(t));
                assert_eq!(
                    expression.eval(f64::from(t)).to_bits(),
                    reference.to_bits(),
                    "{kind} n = {n} t = {t:e} in f64"
                );
            }
        }
    }
}

#[test]
fn only_the_bit_trick_lobes_need_lowering() {
    for kind in kinds() {
        let lobe = Lobe::try_new(kind, 64.0).unwrap();
        let expected = matches!(
            kind,
            LobeKind::FastPow | LobeKind::FasterPow | LobeKind::LogExpRr
        );
        assert_eq!(lobe.expression().has_bit_tricks(), expected, "{kind}");
    }
}

#[test]
fn constants_are_folded_in_and_unused_nodes_dropped() {
    let lobe = Lobe::try_new(LobeKind::Pow, 64.0).unwrap();
    assert_eq!(
        lobe.expression().nodes(),
        [
            Node::Input,
            Node::Parameter {
                name: "n",
                value: 64.0
            },
            Node::Pow(0, 1)
        ]
    );
    let cosquad = Lobe::try_new(LobeKind::CosQuad { v: 4 }, 16.0).unwrap();
    let squarings = cosquad
        .expression()
        .nodes()
        .iter()
        .filter(|node| matches!(node, Node::Square(_)))
        .count();
    assert_eq!(squarings, 4, "K_4 squares four times");
    let unused = record(|t| {
        let _discarded = t.log2();
        t + t
    })
    .unwrap();
    assert_eq!(unused.nodes(), [Node::Input, Node::Add(0, 0)]);
}

#[test]
fn a_branch_on_a_traced_value_is_refused() {
    let branching = record(|t| {
        if t > Real::from_f64(0.5) {
            t
        } else {
            t.square()
        }
    });
    assert_eq!(branching, Err(Branched));
}

/// Every named parameter's recorded preparation gives, from `n`, the value the lobe was
/// prepared with; only the fitted angle quadratics have none.
#[test]
fn parameters_follow_from_n_as_prepared() {
    for kind in kinds() {
        for n in EXPONENTS {
            let lobe = Lobe::try_new(kind, n).unwrap();
            let parameters = lobe.parameters();
            assert!(!parameters.is_empty(), "{kind}: no named parameter");
            for parameter in parameters {
                match &parameter.preparation {
                    Some(preparation) => assert_eq!(
                        preparation.eval(n).to_bits(),
                        parameter.value.to_bits(),
                        "{kind} n = {n}: {}",
                        parameter.name
                    ),
                    None => assert!(
                        lobe.angle_quadratic().is_some(),
                        "{kind}: {} has no preparation",
                        parameter.name
                    ),
                }
            }
        }
    }
}

/// A lobe's recorded operations, its parameters' values left out.
fn shape(lobe: &Lobe) -> Vec<Node> {
    lobe.expression().operations()
}

/// Across its structural range a lobe's record differs only in its parameters' values, so a
/// target that takes `n` as an input and prepares the parameters computes the lobe at that
/// `n`.
#[test]
fn within_the_structural_range_only_parameters_change() {
    for kind in kinds() {
        for n in EXPONENTS {
            let lobe = Lobe::try_new(kind, n).unwrap();
            let [low, high] = lobe.structural_range();
            assert!(
                low <= n && n <= high,
                "{kind} n = {n}: outside [{low}, {high}]"
            );
            for other in [low, high, 0.5 * (low + high)] {
                let moved = Lobe::try_new(kind, other).unwrap();
                assert_eq!(
                    shape(&moved),
                    shape(&lobe),
                    "{kind}: n = {n} against {other}"
                );
            }
        }
    }
    let schlick_mod = |n| Lobe::try_new(LobeKind::SchlickMod, n).unwrap();
    assert_eq!(schlick_mod(100.0).structural_range()[0], 64.0);
    assert_ne!(
        shape(&schlick_mod(100.0)),
        shape(&schlick_mod(128.0)),
        "the range must end where the squarings change"
    );
}

/// A model's stated shapes are its records': every lobe records the operations of the lobe
/// at its shape's least exponent (so a backend's function per shape computes it), and two
/// neighbouring shapes differ (none is listed twice). Every variant of every registry entry,
/// at exponents spread over the range, integers and not.
#[test]
fn a_lobe_records_the_operations_of_its_shape() {
    let exponents = (0..=400).map(|i| 1.0 + 999.0 * (f64::from(i) / 400.0).powi(2));
    for kind in LobeKind::ALL.into_iter().flat_map(LobeKind::variants) {
        let starts = Lobe::try_new(kind, 1.0).unwrap().shape_exponents();
        assert_eq!(
            starts[0], 1.0,
            "{kind}: the first shape starts at the least exponent"
        );
        for pair in starts.windows(2) {
            let [a, b] = [pair[0], pair[1]].map(|n| shape(&Lobe::try_new(kind, n).unwrap()));
            assert_ne!(
                a, b,
                "{kind}: shapes from {} and {} are one",
                pair[0], pair[1]
            );
        }
        for n in exponents
            .clone()
            .chain(starts.iter().map(|s| s.next_down().max(1.0)))
        {
            let lobe = Lobe::try_new(kind, n).unwrap();
            let start = starts[lobe.shape() as usize];
            assert!(start <= n, "{kind} n = {n}: shape from {start}");
            let first = Lobe::try_new(kind, start).unwrap();
            assert_eq!(
                shape(&lobe),
                shape(&first),
                "{kind} n = {n} against {start}"
            );
        }
    }
}

/// The recorded closed-form sampling is the sampler's: its inverse gives `Lobe::tail_inverse`'s
/// bits, its total the tail from 0.
#[test]
fn recorded_sampling_is_the_samplers() {
    for kind in kinds() {
        for n in EXPONENTS {
            let lobe = Lobe::try_new(kind, n).unwrap();
            let Some((inverse, total)) = lobe.sampling_expressions() else {
                assert_ne!(
                    lobe.warp(),
                    Warp::Analytic,
                    "{kind}: sampled in closed form, not recorded"
                );
                continue;
            };
            for k in 0..=1000 {
                let u = f64::from(k) / 1000.0;
                let expected = lobe.tail_inverse(u).unwrap().x;
                assert_eq!(
                    inverse.eval(u).to_bits(),
                    expected.to_bits(),
                    "{kind} n = {n} u = {u}"
                );
            }
            let whole = lobe.tail(0.0).unwrap();
            let recorded: f64 = total.eval(0.0);
            assert!(
                (recorded / whole - 1.0).abs() < 1e-13,
                "{kind} n = {n}: {recorded} against {whole}"
            );
        }
    }
}

/// The recorded Newton forms are the solver's: the tail and slope at any `x` are the `f64`
/// functions `Lobe::tail` inverts (so solving the record's tail gives `tail_inverse`'s root),
/// and the cosine at the root is the drawn cosine.
#[test]
fn recorded_newton_forms_are_the_solvers() {
    for kind in kinds() {
        for n in EXPONENTS {
            let lobe = Lobe::try_new(kind, n).unwrap();
            let Some([tail, slope, cosine, upper, total]) = lobe.newton_expressions() else {
                assert_ne!(
                    lobe.warp(),
                    Warp::Newton,
                    "{kind} n = {n}: Newton, not recorded"
                );
                continue;
            };
            let (upper, total): (f64, f64) = (upper.eval(0.0), total.eval(0.0));
            assert!(
                (total / lobe.tail(0.0).unwrap() - 1.0).abs() < 1e-12,
                "{kind} n = {n}"
            );
            for k in 0..=200 {
                let x = upper * f64::from(k) / 200.0;
                let t: f64 = cosine.eval(x);
                // The tail from the peak to x is the lobe's tail from t.
                let expected = lobe.tail(t).unwrap();
                let recorded: f64 = tail.eval(x);
                assert!(
                    (recorded - expected).abs() <= 1e-12 * total,
                    "{kind} n = {n} x = {x}"
                );
                // The slope is the tail's derivative (a central difference, where smooth).
                let h = 1e-6 * upper;
                if x > h && x < upper - h {
                    let numeric = (tail.eval(x + h) - tail.eval(x - h)) / (2.0 * h);
                    let analytic: f64 = slope.eval(x);
                    assert!(
                        (numeric - analytic).abs() <= 1e-5 * analytic.abs().max(total),
                        "{kind} n = {n} x = {x}: {numeric} {analytic}"
                    );
                }
            }
        }
    }
}
