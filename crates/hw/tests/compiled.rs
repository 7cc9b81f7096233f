//! Lobes of yours compiled to datapaths, against independent answers: the float model the
//! formula compiles to (the core's own evaluation), the hand-written `cosquad` datapath for the
//! same `K_4` written as a formula, and the range rules every lobe obeys.

use specula::{Exponent, Lobe};
use specula_hw::{HwError, HwLobe, Op};

/// The thesis's `K_4` written by hand as a formula: `cosquad`'s own arithmetic.
const K4: &str = "=let a = (n + 1) / 17; max(0, a * (t - 1) + 1) ^ 16";

/// `specula design`'s quadratic family raised to 8, its coefficients the fit's start.
const QUADRATIC_POW8: &str = "=let s = 0.125 * n + 0.5 / n; let c = (0.5 * s - 0.5) * s; \
    let disc = s * s - 4 * c; \
    let stop = select(disc < 0, s / (2 * c), 2 / (s + sqrt(max(disc, 0)))); \
    let v = min(1 - t, stop); (1 - v * (s - c * v)) ^ 8";

fn compiled(formula: &str) -> HwLobe {
    HwLobe::parse(formula).expect("a transcendental-free formula compiles")
}

fn ulp(bits: u32) -> f64 {
    f64::from(bits - 1).exp2().recip()
}

/// The largest difference from the float model at the quantised inputs, dense near the peak.
fn worst_difference(lobe: HwLobe, bits: u32, n: u32) -> f64 {
    let datapath = lobe.build(bits).expect("valid width");
    let float = Lobe::new(lobe.float_kind(), Exponent::new(f64::from(n)));
    let unit = HwLobe::unit_format(bits);
    (0..=4000)
        .map(|i| {
            let t = 1.0 - (f64::from(i) / 4000.0).powi(3);
            let quantised = unit.to_f64(unit.quantize(t, specula_hw::fixed::Rounding::HalfEven));
            let hw = HwLobe::value(bits, datapath.eval(&lobe.inputs(bits, t, n)));
            (hw - float.eval(quantised)).abs()
        })
        .fold(0.0, f64::max)
}

/// At 24 bits a compiled lobe is its formula up to its roundings, amplified by the squarings:
/// sixteen-fold for `K_4` (the bound the hand-written `cosquad` is held to), eight-fold for the
/// quadratic (three roundings in its base).
#[test]
fn full_width_compiled_datapaths_follow_their_formulas() {
    let bits = 24;
    for (formula, bound) in [(K4, 32.0 * ulp(bits)), (QUADRATIC_POW8, 64.0 * ulp(bits))] {
        let lobe = compiled(formula);
        for n in [1, 8, 64, 512, 1000] {
            let worst = worst_difference(lobe, bits, n);
            assert!(
                worst <= bound,
                "{formula} at n = {n}: {worst:e} > {bound:e}"
            );
        }
    }
}

/// The same `K_4` from its formula and from the hand-written datapath: the same values within
/// the two datapaths' roundings (their formats differ: the hand-written slope is `UQ6`, the
/// compiled one as wide as its measured range), at every input of a 12-bit word.
#[test]
fn k4_from_its_formula_matches_the_hand_written_cosquad() {
    let bits = 12;
    let (formula, by_hand) = (compiled(K4), HwLobe::CosQuad);
    let (a, b) = (formula.build(bits).unwrap(), by_hand.build(bits).unwrap());
    let unit = HwLobe::unit_format(bits);
    for n in [2, 16, 64, 300, 1000] {
        let mut worst = 0.0_f64;
        for raw in 0..=unit.max_raw() {
            let t = unit.to_f64(raw);
            let value = |lobe: HwLobe, datapath: &specula_hw::Datapath| {
                HwLobe::value(bits, datapath.eval(&lobe.inputs(bits, t, n)))
            };
            worst = worst.max((value(formula, &a) - value(by_hand, &b)).abs());
        }
        assert!(worst <= 32.0 * ulp(bits), "n = {n}: {worst:e}");
    }
}

/// The compiled `K_4` is `cosquad`'s structure: one multiplier, four squarers, and no table,
/// divider or other multiplier (the slope is prepared on the host).
#[test]
fn k4_compiles_to_one_multiplier_and_four_squarers() {
    let datapath = compiled(K4).build(16).unwrap();
    let resources = datapath.resources();
    assert_eq!(resources.multipliers.len(), 1, "{resources:?}");
    assert_eq!(resources.squarers.len(), 4, "{resources:?}");
    assert!(resources.dividers.is_empty() && resources.rom_bits == 0);
    let inputs: Vec<&str> = datapath.input_ports().iter().map(|(n, _)| *n).collect();
    assert_eq!(inputs.len(), 2, "t and the slope: {inputs:?}");
    assert_eq!(inputs[0], "t");
    assert!(datapath
        .nodes()
        .iter()
        .any(|node| matches!(node.op, Op::Max(..))));
}

/// Every input of 8- to 12-bit compiled datapaths gives a lobe value in [0, 1]; the peak is 1
/// and `t = 0` gives 0.
#[test]
fn every_input_at_small_widths_gives_a_lobe_value() {
    for formula in [K4, QUADRATIC_POW8] {
        let lobe = compiled(formula);
        for bits in 8..=12 {
            let datapath = lobe.build(bits).unwrap();
            let one = 1_i64 << (bits - 1);
            for n in [1, 3, 16, 100, 1000] {
                let at = |t: f64| datapath.eval(&lobe.inputs(bits, t, n));
                let unit = HwLobe::unit_format(bits);
                for raw in 0..=unit.max_raw() {
                    let value = at(unit.to_f64(raw));
                    assert!((0..=one).contains(&value), "{formula} {bits} bits n={n}");
                }
                assert_eq!(at(1.0), one, "{formula} peak at n = {n}");
                assert_eq!(at(0.0), 0, "{formula} at t = 0, n = {n}");
            }
        }
    }
}

/// A power above 64 (recorded as `pow` of a constant) is squarings: `^ 128` is seven squarers
/// and follows its formula at 24 bits within its 128-fold amplified roundings.
#[test]
fn a_whole_power_above_64_is_squarings() {
    let lobe = compiled("=max(0, 1 - (n / 128 + 0.25) * (1 - t)) ^ 128");
    let resources = lobe.build(16).unwrap().resources();
    assert_eq!(resources.squarers.len(), 7, "{resources:?}");
    assert!(resources.multipliers.len() == 1, "{resources:?}");
    for n in [1, 64, 1000] {
        let worst = worst_difference(lobe, 24, n);
        assert!(worst <= 256.0 * ulp(24), "n = {n}: {worst:e}");
    }
}

/// A transcendental per evaluation is refused, naming it; a built-in without a datapath too.
#[test]
fn what_no_stage_computes_is_refused_by_name() {
    let refused = HwLobe::parse("=exp2(1.4427 * n * (t - 1))").unwrap_err();
    assert!(matches!(refused, HwError::NotCompiled { .. }), "{refused}");
    assert!(refused.to_string().contains("exp2"), "{refused}");
    let no_datapath = HwLobe::of_kind(specula::LobeKind::Minimax2).unwrap_err();
    assert!(no_datapath.to_string().contains("valid:"), "{no_datapath}");
}
