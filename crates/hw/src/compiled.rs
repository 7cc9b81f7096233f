//! A lobe of yours compiled to a datapath: the recorded expression of a transcendental-free
//! formula (`specula design`'s polynomial families, a lobe file) becomes one hardware stage per
//! operation, so a designed lobe reaches silicon the way the built-ins do, without a datapath
//! written by hand.
//!
//! **What is compiled.** [`Lobe::expression`] at every integer `n` in `[1, 1000]` (what the
//! hardware's `n` input takes, as for the built-ins): the operations must be the same at every
//! `n` (only the named parameters' values change), and each must be one the stages have:
//! `+`, `-`, `*`, squaring (integer powers are recorded as squarings and products), `/` of
//! non-negative operands, `min`, `max` and negation. A transcendental (`exp2`, `log2`, `pow`
//! of a real), a square root per evaluation or a bit trick is refused with its name: such a
//! lobe is one of the built-in table units' (`pow`, `sg`), not a formula's.
//!
//! **Formats.** Every signal keeps the built-ins' least significant bit `2^-(W-1)` and as
//! many integer bits as its range needs, signed where it goes below 0. The range of each
//! signal is measured, not bounded by interval arithmetic (which multiplies independent
//! worst cases, `v` at its widest by `s` at its largest, and would widen every multiplier):
//! the expression is run in `f64` at every integer `n` over a grid of cosines dense near 1,
//! and the largest magnitude gets a sixteenth of headroom. A signal too large to keep that
//! least significant bit within a stage's [`MAX_WIDTH`] (a quadratic's curvature grows as
//! `n^2`) gives up fraction bits instead: it still holds more significant bits than `W`.
//! Inputs between the grid's points that would go beyond saturate, as every stage does; the
//! sweeps then measure the datapath bit for bit at every representable input of the exponents
//! they sample, so such a loss shows in its error.
//!
//! **Per-material constants.** The expression's named parameters (the formula's `let`s of
//! `n`: a slope, a curvature, a cut) are module inputs prepared on the host, exactly as the
//! built-ins' `a` and `rate` are, from [`Lobe::new`]'s preparation at that `n`.

use std::sync::{Arc, Mutex, PoisonError};

use specula::expression::Node as Traced;
use specula::lobe::FormulaId;
use specula::{Exponent, Lobe, LobeKind};

use crate::datapath::{Builder, Datapath, NodeId, Op};
use crate::fixed::{FixedPoint, Rounding, MAX_WIDTH};

/// The exponents a compiled datapath is laid out for: every integer the `n` input takes.
const EXPONENTS: core::ops::RangeInclusive<u32> = 1..=1000;

/// Headroom on each signal's measured largest magnitude.
const HEADROOM: f64 = 1.0 / 16.0;

/// A formula's datapath before the word length is chosen: each operation and its range.
#[derive(Debug)]
pub(crate) struct Layout {
    /// One step per recorded node, in order.
    steps: Vec<Step>,
    /// The named parameters, in order of first use: the module's inputs after `t`.
    parameters: Vec<&'static str>,
}

/// One recorded operation, with the range its value took.
#[derive(Debug)]
struct Step {
    node: Traced,
    low: f64,
    high: f64,
}

/// A formula's layout, or why it has none, laid out once per process.
type Laid = Result<Arc<Layout>, String>;

/// The layout of the formula lobe `id`, measured on first use and kept; `Err` says why it
/// has none (the caller names the lobe).
pub(crate) fn layout(id: FormulaId) -> Laid {
    static LAID: Mutex<Vec<(FormulaId, Laid)>> = Mutex::new(Vec::new());
    let known = |laid: &[(FormulaId, Laid)]| {
        laid.iter()
            .find(|(at, _)| *at == id)
            .map(|(_, result)| result.clone())
    };
    if let Some(found) = known(&LAID.lock().unwrap_or_else(PoisonError::into_inner)) {
        return found;
    }
    // Measured without the lock: two threads asking at once both measure, the first kept.
    let measured = measure(LobeKind::Formula(id)).map(Arc::new);
    let mut laid = LAID.lock().unwrap_or_else(PoisonError::into_inner);
    if known(&laid).is_none() {
        laid.push((id, measured));
    }
    known(&laid).unwrap_or_else(|| unreachable!("just laid out"))
}

/// The operations of `kind`'s expression and each one's range over every `n` and cosine.
fn measure(kind: LobeKind) -> Result<Layout, String> {
    let records: Vec<_> = EXPONENTS
        .map(|n| Lobe::new(kind, Exponent::new(f64::from(n))).expression())
        .collect();
    let first = &records[0];
    if let Some(n) = EXPONENTS
        .zip(&records)
        .find(|(_, record)| record.operations() != first.operations())
        .map(|(n, _)| n)
    {
        return Err(format!(
            "its operations change with n (at n = {n} they differ from n = 1's), so one \
             circuit cannot serve every n"
        ));
    }
    let mut steps: Vec<Step> = first
        .nodes()
        .iter()
        .map(|&node| {
            supported(&node, first.nodes())?;
            Ok(Step {
                node,
                low: f64::INFINITY,
                high: f64::NEG_INFINITY,
            })
        })
        .collect::<Result<_, String>>()?;
    let cosines = cosine_grid();
    let mut values = vec![0.0; steps.len()];
    for (n, record) in EXPONENTS.zip(&records) {
        for &t in &cosines {
            run(record.nodes(), t, &mut values);
            for (step, &value) in steps.iter_mut().zip(&values) {
                if !value.is_finite() {
                    return Err(format!(
                        "a step ({}) is not finite at n = {n}, t = {t}",
                        describe(&step.node)
                    ));
                }
                step.low = step.low.min(value);
                step.high = step.high.max(value);
            }
        }
    }
    Ok(Layout {
        steps,
        parameters: first
            .parameters()
            .into_iter()
            .map(|(name, _)| name)
            .collect(),
    })
}

/// Cosines in `(0, 1]`: 1024 even steps and `1 - 2^-k` down to the 24-bit input's resolution,
/// where every lobe changes fastest.
fn cosine_grid() -> Vec<f64> {
    (1..=1024)
        .map(|k| f64::from(k) / 1024.0)
        .chain((1..=24).map(|k| 1.0 - f64::from(k).exp2().recip()))
        .collect()
}

/// The largest integer power a compiled datapath raises to, by squarings and products.
const MAX_POWER: u32 = 1024;

/// The power `exponent` (a `pow`'s second operand) raises to, where it is a whole constant
/// from 1 to [`MAX_POWER`] (the formula records powers above 64 as `pow`).
fn whole_power(exponent: &Traced) -> Option<u32> {
    match *exponent {
        Traced::Constant(k) if k.fract() == 0.0 && (1.0..=f64::from(MAX_POWER)).contains(&k) => {
            Some(k as u32)
        }
        _ => None,
    }
}

/// Whether a stage computes `node` of `nodes`; `Err` names the operation it does not.
fn supported(node: &Traced, nodes: &[Traced]) -> Result<(), String> {
    match node {
        Traced::Pow(_, exponent) if whole_power(&nodes[*exponent]).is_some() => Ok(()),
        Traced::Input
        | Traced::Constant(_)
        | Traced::Parameter { .. }
        | Traced::Add(..)
        | Traced::Sub(..)
        | Traced::Mul(..)
        | Traced::Div(..)
        | Traced::Neg(_)
        | Traced::Square(_)
        | Traced::Max(..)
        | Traced::Min(..) => Ok(()),
        other => Err(format!(
            "it computes {} per evaluation, which no fixed-point stage does (the stages are \
             +, -, *, squaring, / of non-negative values, min and max; a transcendental is a \
             table unit's, as in the built-in pow and sg datapaths)",
            describe(other)
        )),
    }
}

/// An operation's name for messages.
fn describe(node: &Traced) -> &'static str {
    match node {
        Traced::Input => "the input t",
        Traced::Constant(_) => "a constant",
        Traced::Parameter { name, .. } => name,
        Traced::Add(..) => "a sum",
        Traced::Sub(..) => "a difference",
        Traced::Mul(..) => "a product",
        Traced::Div(..) => "a quotient",
        Traced::Neg(_) => "a negation",
        Traced::Square(_) => "a square",
        Traced::Sqrt(_) => "sqrt",
        Traced::Log2(_) => "log2",
        Traced::Exp2(_) => "exp2",
        Traced::Acos(_) => "acos",
        Traced::Cos(_) => "cos",
        Traced::Sin(_) => "sin",
        Traced::Exp(_) => "exp",
        Traced::Ln1p(_) => "ln",
        Traced::ExpM1(_) => "exp",
        Traced::Pow(..) => "pow of a real exponent",
        Traced::Max(..) => "max",
        Traced::Min(..) => "min",
        Traced::Ceil(_) => "ceil",
        Traced::Shift(..) | Traced::Mantissa(_) | Traced::Exponent(_) | Traced::BitsExp2(_) => {
            "a float bit trick"
        }
        Traced::SelectLess { .. } => "a comparison (select)",
    }
}

/// Every node's `f64` value at `t`, into `values` (the supported operations only).
fn run(nodes: &[Traced], t: f64, values: &mut [f64]) {
    for (k, node) in nodes.iter().enumerate() {
        let v = |i: usize| values[i];
        values[k] = match *node {
            Traced::Input => t,
            Traced::Constant(c) => c,
            Traced::Parameter { value, .. } => value,
            Traced::Add(a, b) => v(a) + v(b),
            Traced::Sub(a, b) => v(a) - v(b),
            Traced::Mul(a, b) => v(a) * v(b),
            Traced::Div(a, b) => v(a) / v(b),
            Traced::Neg(a) => -v(a),
            Traced::Square(a) => v(a) * v(a),
            Traced::Max(a, b) => v(a).max(v(b)),
            Traced::Min(a, b) => v(a).min(v(b)),
            Traced::Pow(a, b) => v(a).powf(v(b)),
            _ => f64::NAN,
        };
    }
}

impl Layout {
    /// The format of a signal whose values lie in `[low, high]`, with `frac` fraction bits.
    fn format(low: f64, high: f64, frac: u32) -> FixedPoint {
        let magnitude = low.abs().max(high.abs()) * (1.0 + HEADROOM);
        // The fewest integer bits (at least one, as the unit signals have) holding it.
        let mut int_bits = 1;
        while f64::from(int_bits).exp2() <= magnitude {
            int_bits += 1;
        }
        let signed = low < 0.0;
        // A signal too large for the least significant bit within a stage's width gives up
        // fraction bits: it keeps at least as many significant bits as the narrower ones.
        let frac = frac.min(MAX_WIDTH.saturating_sub(int_bits + u32::from(signed)));
        FixedPoint {
            signed,
            int_bits,
            frac_bits: frac,
        }
    }

    /// The format of each named parameter at word length `bits`.
    pub(crate) fn parameter_formats(&self, bits: u32) -> Vec<FixedPoint> {
        self.parameters
            .iter()
            .map(|&wanted| {
                let named = |step: &&Step| {
                    matches!(step.node, Traced::Parameter { name, .. } if name == wanted)
                };
                self.steps
                    .iter()
                    .find(named)
                    .map_or(FixedPoint::unsigned(1, bits - 1), |step| {
                        Self::format(step.low, step.high, bits - 1)
                    })
            })
            .collect()
    }

    /// The datapath at word length `bits`, named `name`: `t` and the parameters in, the
    /// lobe's value in `UQ1.(W-1)` out, 0 at `t = 0` as every lobe is there.
    pub(crate) fn build(&self, name: &str, bits: u32) -> Result<Datapath, String> {
        let frac = bits - 1;
        let unit = FixedPoint::unsigned(1, frac);
        let mut b = Builder::new(Rounding::HalfEven);
        let t = b.input("t", unit);
        let formats = self.parameter_formats(bits);
        let parameters: Vec<NodeId> = self
            .parameters
            .iter()
            .zip(&formats)
            .map(|(name, &format)| b.input(name, format))
            .collect();
        let too_wide = |what: &str, format: FixedPoint| {
            format!(
                "{what} needs {} ({} bits) at W = {bits}, wider than the {MAX_WIDTH} bits a \
                 stage may have",
                format.name(),
                format.width()
            )
        };
        if let Some((name, &format)) = self
            .parameters
            .iter()
            .zip(&formats)
            .find(|(_, format)| format.width() > MAX_WIDTH)
        {
            return Err(too_wide(name, format));
        }
        let mut ids: Vec<NodeId> = Vec::with_capacity(self.steps.len());
        for (k, step) in self.steps.iter().enumerate() {
            let format = Self::format(step.low, step.high, frac);
            if format.width() > MAX_WIDTH {
                return Err(too_wide(describe(&step.node), format));
            }
            let at = |i: usize| ids[i];
            let label = |what: &str| format!("{what}_{k}");
            let id = match step.node {
                Traced::Input => t,
                Traced::Parameter { name, .. } => {
                    let index = self.parameters.iter().position(|&p| p == name);
                    parameters[index.unwrap_or_else(|| unreachable!("{name} is a parameter"))]
                }
                Traced::Constant(c) => {
                    let format = Self::format(c.min(0.0), c.max(0.0), frac);
                    b.node(
                        &label("constant"),
                        Op::Const(format.quantize(c, Rounding::HalfEven)),
                        format,
                    )
                }
                Traced::Add(x, y) => b.node(&label("sum"), Op::Add(at(x), at(y)), format),
                Traced::Sub(x, y) => b.node(&label("difference"), Op::Sub(at(x), at(y)), format),
                Traced::Mul(x, y) => b.node(&label("product"), Op::Mul(at(x), at(y)), format),
                Traced::Square(x) => b.node(&label("square"), Op::Square(at(x)), format),
                Traced::Min(x, y) => b.node(&label("min"), Op::Min(at(x), at(y)), format),
                Traced::Max(x, y) => b.node(&label("max"), Op::Max(at(x), at(y)), format),
                Traced::Neg(x) => {
                    let zero = b.node(&label("zero"), Op::Const(0), unit);
                    b.node(&label("negation"), Op::Sub(zero, at(x)), format)
                }
                Traced::Pow(x, y) => {
                    let power = whole_power(&self.steps[y].node)
                        .unwrap_or_else(|| unreachable!("a real power was refused when laid out"));
                    raise(
                        &mut b,
                        at(x),
                        (self.steps[x].low, self.steps[x].high),
                        power,
                        k,
                        frac,
                    )?
                }
                Traced::Div(x, y) => {
                    if self.steps[x].low < 0.0 || self.steps[y].low < 0.0 {
                        return Err("it divides by or into a value that goes below 0, and the \
                                    divider is unsigned"
                            .to_owned());
                    }
                    b.node(&label("quotient"), Op::Div(at(x), at(y)), format)
                }
                other => {
                    unreachable!("{} was refused when laid out", describe(&other))
                }
            };
            ids.push(id);
        }
        let result = *ids.last().unwrap_or(&t);
        // The formula's own clamp to [0, 1] is usually its last step; where it is not, one.
        let clamped = match self.steps.last() {
            Some(last) if Self::format(last.low, last.high, frac) == unit && last.high <= 1.0 => {
                result
            }
            _ => {
                let one = b.node("one", Op::Const(1 << frac), unit);
                b.node("clamped", Op::Min(result, one), unit)
            }
        };
        let output = b.zero_at_t_zero(t, clamped, unit);
        Ok(b.finish(name, output))
    }

    /// The parameters' raw inputs for integer exponent `n` at word length `bits`, as the host
    /// prepares them.
    pub(crate) fn material_inputs(&self, kind: LobeKind, bits: u32, n: u32) -> Vec<i64> {
        let prepared = Lobe::new(kind, Exponent::new(f64::from(n)))
            .expression()
            .parameters();
        self.parameters
            .iter()
            .zip(self.parameter_formats(bits))
            .map(|(&name, format)| {
                let value = prepared
                    .iter()
                    .find(|(p, _)| *p == name)
                    .map_or(0.0, |(_, value)| *value);
                format.quantize(value, Rounding::HalfEven)
            })
            .collect()
    }
}

/// `x^power` by binary exponentiation, squarers and multipliers whose formats follow the
/// powers of `x`'s range `(low, high)`; the nodes are named after step `k`.
fn raise(
    b: &mut Builder,
    x: NodeId,
    (low, high): (f64, f64),
    power: u32,
    k: usize,
    frac: u32,
) -> Result<NodeId, String> {
    // The range of x^e: a power of the range, from 0 where an even power crosses it.
    let range = |e: u32| {
        let (a, b) = (low.powi(e as i32), high.powi(e as i32));
        if e.is_multiple_of(2) && low < 0.0 && high > 0.0 {
            (0.0, a.max(b))
        } else {
            (a.min(b), a.max(b))
        }
    };
    let mut result: Option<(NodeId, u32)> = None;
    let (mut base, mut exponent, mut remaining) = (x, 1_u32, power);
    loop {
        if remaining & 1 == 1 {
            result = Some(match result {
                None => (base, exponent),
                Some((product, e)) => {
                    let (lo, hi) = range(e + exponent);
                    let format = Layout::format(lo, hi, frac);
                    let name = format!("power_{k}_{}", e + exponent);
                    (b.node(&name, Op::Mul(product, base), format), e + exponent)
                }
            });
        }
        remaining >>= 1;
        if remaining == 0 {
            break;
        }
        exponent *= 2;
        let (lo, hi) = range(exponent);
        let format = Layout::format(lo, hi, frac);
        if format.width() > MAX_WIDTH {
            return Err(format!(
                "a power {exponent} needs {} bits, wider than the {MAX_WIDTH} a stage may \
                 have",
                format.width()
            ));
        }
        base = b.node(&format!("square_{k}_{exponent}"), Op::Square(base), format);
    }
    Ok(result.map_or(x, |(node, _)| node))
}
