//! The datapaths against independent answers: the core's float models (a separate
//! implementation) at the same quantised inputs, the resource counts SPEC section 8 names,
//! and the range rules every lobe obeys.

use specula::{Exponent, Lobe};
use specula_hw::{verilog, HwLobe, BITS};

/// The float model's value at exactly the input the datapath sees (its quantised `t` or `g`).
fn float_at(lobe: HwLobe, bits: u32, x: f64, n: u32) -> f64 {
    let float = Lobe::new(lobe.float_kind(), Exponent::new(f64::from(n)));
    let unit = HwLobe::unit_format(bits);
    let quantised = unit.to_f64(unit.quantize(x, specula_hw::fixed::Rounding::HalfEven));
    if lobe.takes_angle() {
        float.eval_angle(quantised)
    } else {
        float.eval(quantised)
    }
}

/// The largest difference from the float model over inputs spread across the range.
fn worst_difference(lobe: HwLobe, bits: u32, n: u32) -> f64 {
    let datapath = lobe.build(bits).expect("valid width");
    let top = if lobe.takes_angle() {
        core::f64::consts::FRAC_PI_2
    } else {
        1.0
    };
    (0..=4000)
        .map(|i| {
            // Dense near the peak (t = 1, g = 0), where the lobes are steep.
            let s = (f64::from(i) / 4000.0).powi(3);
            let x = if lobe.takes_angle() { s * top } else { 1.0 - s };
            let hw = HwLobe::value(bits, datapath.eval(&lobe.inputs(bits, x, n)));
            (hw - float_at(lobe, bits, x, n)).abs()
        })
        .fold(0.0, f64::max)
}

/// One unit in the last place of a `W`-bit unit-range signal.
fn ulp(bits: u32) -> f64 {
    f64::from(bits - 1).exp2().recip()
}

/// At 24 bits each datapath is its float model up to its rounding, as amplified by its
/// structure (closed forms in the comments), except for the log2 unit's approximation.
#[test]
fn full_width_datapaths_follow_their_float_models() {
    let bits = 24;
    let table_error = {
        // Linear interpolation of log2(1 + f) over segments of h: h^2 / (8 ln 2).
        let h = 1.0 / 64.0;
        h * h / (8.0 * core::f64::consts::LN_2)
    };
    // Linear interpolation of 2^-f over the same segments: h^2 (ln 2)^2 / 8.
    let exp2_table_error = core::f64::consts::LN_2.powi(2) / 8.0 / 64.0_f64.powi(2);
    for n in [1, 8, 64, 512, 1000] {
        let squarings = (f64::from(n).log2().floor() - 2.0).clamp(0.0, 7.0);
        for lobe in HwLobe::ALL {
            let bound = match lobe {
                // A handful of roundings, none amplified.
                HwLobe::Schlick | HwLobe::Cheb2 => 4.0 * ulp(bits),
                // Each squaring doubles the relative error: 2^k of them, plus the divide.
                HwLobe::SchlickMod => (squarings.exp2() + 4.0) * ulp(bits),
                // Sixteen-fold through the squarings, plus a's and t's roundings.
                HwLobe::CosQuad => 32.0 * ulp(bits),
                // The first log2's error times n, through the outer slope 1 / (2 ln 2), and
                // half the second log2's.
                HwLobe::LogExp => {
                    (0.722 * f64::from(n) + 0.5) * (table_error + ulp(bits)) + 4.0 * ulp(bits)
                }
                // Mitchell's 0.0861 the same way: a bound only at small n.
                HwLobe::LogExpMitchell => (0.722 * f64::from(n) + 0.5) * 0.0861 + 4.0 * ulp(bits),
                // 2^y moves by ln 2 per unit of y <= 0: the log2 unit's error times n, the
                // product's rounding, then the exp2 table's own error and the roundings.
                HwLobe::Pow => {
                    core::f64::consts::LN_2 * (f64::from(n) * (table_error + ulp(bits)) + ulp(bits))
                        + exp2_table_error
                        + 4.0 * ulp(bits)
                }
                // The rate's and the product's roundings move y by one ulp.
                HwLobe::Sg => {
                    core::f64::consts::LN_2 * ulp(bits) + exp2_table_error + 4.0 * ulp(bits)
                }
                HwLobe::Formula(_) => unreachable!("HwLobe::ALL holds the built-ins"),
            };
            let worst = worst_difference(lobe, bits, n);
            assert!(
                worst <= bound,
                "{} at n = {n}: {worst:e} > {bound:e}",
                lobe.id()
            );
        }
        assert!(
            worst_difference(HwLobe::LogExpMitchell, bits, n)
                > 10.0 * worst_difference(HwLobe::LogExp, bits, n),
            "Mitchell's log2 is the crude one"
        );
    }
}

/// Every input of 8- to 12-bit datapaths: outputs are lobe values in [0, 1], the peak is 1
/// and `t = 0` gives 0, for exponents across the range.
#[test]
fn every_input_at_small_widths_gives_a_lobe_value() {
    for bits in 8..=12 {
        let unit = HwLobe::unit_format(bits);
        let one = 1_i64 << (bits - 1);
        for lobe in HwLobe::ALL {
            let datapath = lobe.build(bits).expect("valid width");
            for n in [1, 3, 16, 100, 999, 1000] {
                for raw in 0..=unit.max_raw() {
                    let x = unit.to_f64(raw);
                    let value = datapath.eval(&lobe.inputs(bits, x, n));
                    assert!(
                        (0..=one).contains(&value),
                        "{} {bits} bits n={n} x={x}: {value}",
                        lobe.id()
                    );
                }
                let at = |x: f64| datapath.eval(&lobe.inputs(bits, x, n));
                if lobe.takes_angle() {
                    assert_eq!(at(core::f64::consts::FRAC_PI_2), 0, "{} n={n}", lobe.id());
                } else {
                    assert_eq!(
                        (at(1.0), at(0.0)),
                        (one, 0),
                        "{} {bits} bits n={n}",
                        lobe.id()
                    );
                }
            }
        }
    }
}

/// The counts SPEC section 8 gives for each structural scheme.
#[test]
fn resources_are_the_structural_schemes_of_spec_section_8() {
    let count = |lobe: HwLobe| lobe.build(16).expect("valid width").resources();
    // cosquad: subtract, one multiply by a, add (1 - a u), then v = 4 squarings.
    let r = count(HwLobe::CosQuad);
    assert_eq!(
        (
            r.multipliers.len(),
            r.adders.len(),
            r.squarers.len(),
            r.dividers.len()
        ),
        (1, 2, 4, 0)
    );
    // schlick: one multiply, two adds (1 - t, n u + t), one divide.
    let r = count(HwLobe::Schlick);
    assert_eq!(
        (
            r.multipliers.len(),
            r.adders.len(),
            r.squarers.len(),
            r.dividers.len()
        ),
        (1, 2, 0, 1)
    );
    // schlick-mod: log2(a) <= 7 squarings more (and the clamp's comparator).
    let r = count(HwLobe::SchlickMod);
    assert_eq!(
        (
            r.multipliers.len(),
            r.adders.len(),
            r.squarers.len(),
            r.dividers.len()
        ),
        (1, 3, 7, 1)
    );
    // cheb2: ROM, two multiplies, two adds (and the clamp's comparator).
    let cheb2 = HwLobe::Cheb2.build(16).expect("valid width");
    let r = cheb2.resources();
    assert_eq!(
        (r.multipliers.len(), r.adders.len(), r.squarers.len()),
        (2, 3, 0)
    );
    let word_bits: u64 = cheb2
        .nodes()
        .iter()
        .filter(|node| matches!(node.op, specula_hw::Op::Rom { .. }))
        .map(|node| u64::from(node.format.width()))
        .sum();
    assert_eq!(
        r.rom_bits,
        1001 * word_bits,
        "three coefficient words for each n in 0..=1000"
    );
    // logexp: two log2 units, one multiply by n, 1 - y, a shift, a subtract (plus the
    // negation of log2 t); the table adds an interpolation multiplier and adder per unit.
    let r = count(HwLobe::LogExpMitchell);
    assert_eq!(
        (
            r.leading_one_detectors.len(),
            r.multipliers.len(),
            r.adders.len(),
            r.rom_bits
        ),
        (2, 1, 3, 0)
    );
    let r = count(HwLobe::LogExp);
    assert_eq!(
        (
            r.leading_one_detectors.len(),
            r.multipliers.len(),
            r.adders.len()
        ),
        (2, 3, 5)
    );
    assert_eq!(
        r.rom_bits,
        2 * 65 * (15 + 2 + 1),
        "two 65-entry tables with two guard bits"
    );
    // pow: a log2 unit, the multiply by n, an exp2 unit; each unit interpolates its table
    // with a multiplier and an adder, and shifts.
    let r = count(HwLobe::Pow);
    assert_eq!(
        (
            r.leading_one_detectors.len(),
            r.shifters.len(),
            r.multipliers.len(),
            r.rom_bits
        ),
        (1, 2, 3, 2 * 65 * (15 + 2 + 1))
    );
    // sg: 1 - t, the multiply by the rate, an exp2 unit.
    let r = count(HwLobe::Sg);
    assert_eq!(
        (
            r.leading_one_detectors.len(),
            r.shifters.len(),
            r.multipliers.len(),
            r.adders.len(),
            r.rom_bits
        ),
        (0, 1, 2, 2, 65 * (15 + 2 + 1))
    );
    // Latency: the input registers plus the longest chain of stages.
    assert_eq!(count(HwLobe::CosQuad).latency, 1 + 3 + 4 + 1);
    assert_eq!(count(HwLobe::Schlick).latency, 1 + 4);
}

/// Narrower words cannot be more accurate, on average over the epicentre and bloom.
#[test]
fn error_falls_as_words_widen() {
    for lobe in HwLobe::ALL {
        let sweep = specula_hw::analysis::sweep(lobe, 64, [8, 12, 16, 24], 2000, &mut |_| {})
            .expect("valid sweep");
        let rms: Vec<f64> = sweep.rows.iter().map(|row| row.errors.rms).collect();
        assert!(
            rms.windows(2).all(|w| w[1] <= w[0] * 1.05),
            "{}: {rms:?}",
            lobe.id()
        );
        assert!(rms[3] < rms[0], "{}: {rms:?}", lobe.id());
    }
}

/// Every datapath at every width has Verilog whose exact intermediates fit 64 bits (the
/// emitter checks and would panic).
#[test]
fn verilog_is_emitted_for_every_lobe_and_width() {
    for lobe in HwLobe::ALL {
        for bits in BITS {
            let datapath = lobe.build(bits).expect("valid width");
            let text = verilog::module(&datapath, lobe, bits);
            assert!(text.contains(&format!("module {} (", datapath.name)));
            assert!(text.matches("endmodule").count() >= 2);
        }
    }
}

#[test]
fn bad_requests_are_refused_with_the_valid_choices() {
    let unknown = HwLobe::parse("sg-karis")
        .expect_err("pow has no datapath")
        .to_string();
    assert!(
        unknown.contains("valid: schlick, schlick-mod, cheb2, logexp, logexp-mitchell, cosquad"),
        "{unknown}"
    );
    assert!(HwLobe::CosQuad.build(7).is_err() && HwLobe::CosQuad.build(25).is_err());
    assert!(specula_hw::integer_exponent(64.5).is_err());
    assert!(specula_hw::integer_exponent(0.0).is_err());
    assert!(specula_hw::integer_exponent(f64::NAN).is_err());
    assert_eq!(specula_hw::integer_exponent(1000.0), Ok(1000));
}

/// Any raw inputs, in range or not (inputs saturate into their formats), give a lobe value in
/// [0, 1] at every width: the fixed-point models have no NaN to produce, and no overflow.
#[test]
fn any_raw_inputs_give_a_lobe_value() {
    use rand::{RngExt, SeedableRng};
    let mut rng = rand_pcg::Pcg64::seed_from_u64(9);
    for lobe in HwLobe::ALL {
        for bits in BITS.step_by(4) {
            let datapath = lobe.build(bits).expect("valid width");
            let one = 1_i64 << (bits - 1);
            for _ in 0..2000 {
                let inputs: Vec<i64> = datapath
                    .inputs()
                    .iter()
                    .map(|_| match rng.random_range(0..4) {
                        0 => rng.random_range(i64::MIN..=i64::MAX),
                        1 => -rng.random_range(0..1_i64 << 40),
                        _ => rng.random_range(0..1_i64 << 32),
                    })
                    .collect();
                let value = datapath.eval(&inputs);
                assert!(
                    (0..=one).contains(&value),
                    "{} {bits} bits {inputs:?}: {value}",
                    lobe.id()
                );
            }
        }
    }
}
