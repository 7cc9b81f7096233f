//! WGSL: a prepared lobe as one function, with the bit tricks as bit casts (WGSL has them).
//! `specula-gpu`'s export builds on it and hands it to naga for GLSL, HLSL, MSL and SPIR-V.

use core::fmt::Write as _;

use specula::expression::record;
use specula::{Lobe, Normalisation};

use crate::code::{body, straight_line, straight_line_named, Dialect, Inputs, Parameters};

struct Wgsl;

impl Dialect for Wgsl {
    fn local(&self, name: &str, value: &str) -> String {
        format!("let {name} = {value};")
    }
    fn select_less(&self, a: &str, b: &str, then: &str, otherwise: &str) -> String {
        format!("select({otherwise}, {then}, {a} < {b})")
    }
}

/// The bit-trick helpers, as `Real`'s `f32` implementation computes them: once in a module
/// whose functions call them ([`lobe_function`] includes them; a library of several lobes
/// includes them itself).
pub const BIT_TRICKS: &str = "
// t = m 2^e with m in [1/2, 1), read off the bits (specula's Real::frexp).
fn specula_mantissa(t: f32) -> f32 {
    return bitcast<f32>((bitcast<u32>(t) & 0x007fffffu) | 0x3f000000u);
}

fn specula_exponent(t: f32) -> f32 {
    return f32((bitcast<u32>(t) >> 23u) & 0xffu) - 126.0;
}

// The float whose bits, read with 23 fraction bits, are x + 127 (Real::bits_exp2).
fn specula_bits_exp2(x: f32) -> f32 {
    return bitcast<f32>(u32(max(x, -127.0) * 8388608.0 + 1065353216.0));
}

// x 2^k for an integer-valued k, built from the exponent field; 0 once 2^k underflows the
// normal range (Real::shift).
fn specula_shift(x: f32, k: f32) -> f32 {
    let biased = i32(k) + 127;
    if biased <= 0 {
        return 0.0;
    }
    return x * bitcast<f32>(u32(biased) << 23u);
}
";

/// `fn {name}(n: f32, t: f32) -> f32`: the lobe for `t` in `(0, 1]` with its constants
/// computed from `n` in the shader (a renderer's material carries `n`, not the constants),
/// for a lobe whose every parameter follows from `n` ([`Inputs::of`]); `None` for the
/// fitted ones. Without the helpers: the module includes [`BIT_TRICKS`] once.
#[must_use]
pub fn lobe_function_of_n(lobe: &Lobe, name: &str) -> Option<String> {
    let inputs = Inputs::of(lobe);
    inputs.exponent?;
    let expression = lobe.expression();
    let (statements, result) = straight_line(&expression, "t", &Wgsl, Parameters::Named);
    let mut lines = inputs.preparation("n", &Wgsl);
    lines.extend(statements);
    let mut out = String::new();
    let _ = write!(
        out,
        "
// {} at cosine t in (0, 1], its constants computed from n; generated from specula's
// description of the lobe.
fn {name}(n: f32, t: f32) -> f32 {{
{}}}
",
        lobe.kind(),
        body(&lines, &result, "    ", |r| format!("return {r};")),
    );
    Some(out)
}

/// `fn {name}(n: f32) -> f32`: `normalisation`'s constant `N(n)` for `lobe`, computed from `n`
/// in the shader beside [`lobe_function_of_n`]. The analytic normalisations are their recorded
/// formulas; the lobe's own (`1 / (2 pi int_0^1 lobe)`) needs the lobe's integral in closed
/// form of its parameters, which the lobes sampled in closed form or by Newton's method record
/// ([`Lobe::sampling_expressions`], [`Lobe::newton_expressions`]). `Err` says why not: a
/// fitted lobe, or a lobe whose integral is only numerical.
pub fn normalisation_function_of_n(
    lobe: &Lobe,
    normalisation: Normalisation,
    name: &str,
) -> Result<String, String> {
    let inputs = Inputs::of(lobe);
    if inputs.exponent.is_none() {
        return Err(format!(
            "{}'s constants are fitted for n = {} and do not follow n",
            lobe.kind(),
            lobe.exponent()
        ));
    }
    let mut lines = Vec::new();
    let result = if normalisation == Normalisation::Lobe {
        let total = lobe
            .sampling_expressions()
            .map(|(_, total)| total)
            .or_else(|| lobe.newton_expressions().map(|[.., total]| total))
            .ok_or_else(|| {
                format!(
                    "{}'s own normalisation (lobe) is its integral computed numerically, not a \
                        closed form of n",
                    lobe.kind()
                )
            })?;
        lines = inputs.preparation("n", &Wgsl);
        let (statements, total) = straight_line_named(&total, "0.0", &Wgsl, Parameters::Named, "w");
        lines.extend(statements);
        let two_pi = crate::code::float_literal(core::f32::consts::TAU);
        format!("1.0 / ({two_pi} * ({total}))")
    } else {
        let formula = record(|n| normalisation.formula(n))
            .unwrap_or_else(|_| unreachable!("the normalisations' formulas have no branch"));
        let (statements, result) = straight_line(&formula, "n", &Wgsl, Parameters::Baked);
        lines.extend(statements);
        result
    };
    Ok(format!(
        "
// The normalisation {} of {} for the exponent n; generated from specula's description.
fn {name}(n: f32) -> f32 {{
{}}}
",
        normalisation.id(),
        lobe.kind(),
        body(&lines, &result, "    ", |r| format!("return {r};")),
    ))
}

/// `fn {name}(t: f32) -> f32`: the lobe for `t` in `(0, 1]`, generated from
/// [`Lobe::expression`], preceded by the bit-trick helpers it calls.
#[must_use]
pub fn lobe_function(lobe: &Lobe, name: &str) -> String {
    let expression = lobe.expression();
    let (statements, result) = straight_line(&expression, "t", &Wgsl, Parameters::Baked);
    let mut out = String::new();
    if expression.has_bit_tricks() {
        out.push_str(BIT_TRICKS);
    }
    let _ = write!(
        out,
        "
// {} at cosine t in (0, 1] (n = {}), generated from specula's description of the lobe.
fn {name}(t: f32) -> f32 {{
{}}}
",
        lobe.kind(),
        lobe.exponent(),
        body(&statements, &result, "    ", |r| format!("return {r};")),
    );
    out
}

/// The components of a `vec4<f32>`, in order.
const COMPONENTS: [&str; 4] = ["x", "y", "z", "w"];

/// How many named parameters [`lobe_function_of_slots`] takes from its `vec4<f32>`.
pub const SLOTS: usize = COMPONENTS.len();

/// `fn {name}(parameters: vec4<f32>, t: f32) -> f32`: the lobe for `t` in `(0, 1]` with its
/// named parameters read from `parameters` in order of first use
/// ([`Expression::parameters`](specula::expression::Expression::parameters)), for a renderer
/// that uploads each material's prepared constants; the other constants are baked in, so the
/// function serves every lobe of the same recorded operations. `None` for a lobe with more
/// than [`SLOTS`] parameters. Without the helpers: the module includes [`BIT_TRICKS`] once.
#[must_use]
pub fn lobe_function_of_slots(lobe: &Lobe, name: &str) -> Option<String> {
    let expression = lobe.expression();
    let parameters = expression.parameters();
    if parameters.len() > SLOTS {
        return None;
    }
    let mut lines: Vec<String> = parameters
        .iter()
        .zip(COMPONENTS)
        .map(|((parameter, _), component)| {
            Wgsl.local(parameter, &format!("parameters.{component}"))
        })
        .collect();
    let (statements, result) = straight_line(&expression, "t", &Wgsl, Parameters::Named);
    lines.extend(statements);
    Some(format!(
        "
// {} at cosine t in (0, 1], its parameters ({}) from the material; generated from
// specula's description of the lobe.
fn {name}(parameters: vec4<f32>, t: f32) -> f32 {{
{}}}
",
        lobe.kind(),
        if parameters.is_empty() {
            "none".to_owned()
        } else {
            parameters
                .iter()
                .map(|(p, _)| *p)
                .collect::<Vec<_>>()
                .join(", ")
        },
        body(&lines, &result, "    ", |r| format!("return {r};")),
    ))
}
