//! # Your own lobe: a formula in, the whole workbench out
//!
//! A lobe written as text, in a small expression language, becomes a [`LobeKind`] like the
//! built-in ones: [`Lobe::new`] prepares it for an `n`, [`Lobe::eval`] runs it on any
//! [`Real`](crate::Real) (so `f64` is its reference, `f32` its fast path, and
//! [`Traced`](crate::expression::Traced) records it for every shading language), and
//! [`Lobe::eval_batch`] runs it compiled to columns of SIMD vectors.
//!
//! ```text
//! # K_4 written by hand
//! let a = (n + 1) / 17;          # a per-material constant: computed once from n
//! max(0, a * (t - 1) + 1) ^ 16   # the lobe, a function of the cosine t
//! ```
//!
//! - **Names**: `t` (the cosine, in `(0, 1]`), `n` (the exponent), the declared parameters,
//!   earlier `let`s, `pi`, `e`.
//! - **Operators**: `+ - * /`, `^` (right-associative; an integer power up to 64 is computed
//!   by squarings, as `cosquad` does), comparisons `< <= > >=` as the condition of
//!   `select(a < b, then, otherwise)` or its synonym `if(...)`.
//! - **Functions**: those of [`FUNCTIONS`]; `log` is the natural logarithm.
//! - **Constants**: every sub-expression of `n` and the parameters alone is a per-material
//!   constant, computed once in `f64` when the lobe is prepared (a `let`'s name names it);
//!   one of constants alone is folded. At most [`MAX_SLOTS`] constants reach the formula.
//! - **Tail** (optional): `int_t^1 lobe(s) ds` as a second formula (it sees the `let`s);
//!   with it, sampling inverts the tail by safeguarded Newton instead of a table.
//! - **Rules**: as every lobe, `t <= 0` (and NaN) gives 0 and `t > 1` counts as 1; the value
//!   is clamped to `[0, 1]` (NaN to 0), and [`Lobe::checked`] refuses a formula that leaves
//!   `[0, 1]` (or is not finite) anywhere on a dense grid of `t` at the requested `n`.
//! - **Limits**: [`MAX_SOURCE_BYTES`], [`MAX_DEPTH`], [`MAX_NODES`], [`MAX_LETS`],
//!   [`MAX_PARAMETERS`], checked before any work.

pub(crate) mod batch;
mod compile;
mod op;
pub(crate) mod program;
pub(crate) mod registry;
mod syntax;

use std::collections::BTreeMap;

pub use compile::{FUNCTIONS, MAX_SLOTS};
pub use registry::{define, instance, kinds, parse_values, Instance, Naming, MAX_FORMULAS};
pub use syntax::{MAX_DEPTH, MAX_LETS, MAX_NODES, MAX_SOURCE_BYTES};

use crate::{Error, Exponent, Lobe, LobeKind};
use op::Op;
use program::Leaves;

/// The most declared parameters.
pub const MAX_PARAMETERS: usize = 8;

/// A lobe as a user writes it (the fields of a lobe file, `mylobe.toml`).
#[derive(Clone, Debug, PartialEq, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Definition {
    /// The id tables and plots show: a lowercase letter, then letters, digits, `-` or `_`.
    pub name: String,
    /// One line on what it is.
    #[serde(default)]
    pub description: Option<String>,
    /// The lobe: `let` bindings, then an expression of `t`.
    pub formula: String,
    /// `int_t^1 lobe(s) ds`, for exact sampling.
    #[serde(default)]
    pub tail: Option<String>,
    /// Declared parameters besides `n`, by name.
    #[serde(default)]
    pub parameters: BTreeMap<String, ParameterDefinition>,
}

/// A declared parameter: its default and the range a value must lie in.
#[derive(Clone, Debug, PartialEq, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ParameterDefinition {
    /// The value when none is given.
    pub default: f64,
    /// The smallest valid value.
    pub min: f64,
    /// The largest valid value.
    pub max: f64,
    /// What it does.
    #[serde(default)]
    pub description: Option<String>,
}

/// A refused formula: the byte offset of the problem in its text, and what it is.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct FormulaError {
    /// Byte offset in the text.
    pub at: usize,
    /// What is wrong, and what is valid.
    pub message: String,
    /// Whether the offset is in the tail's text rather than the formula's.
    pub in_tail: bool,
}

impl FormulaError {
    pub(crate) fn at(at: usize, message: String) -> Self {
        Self {
            at,
            message,
            in_tail: false,
        }
    }

    /// `field`, line and column (or column alone for one line), then the message: one line.
    #[must_use]
    pub fn locate(&self, field: &str, source: &str) -> String {
        let (line, column) = crate::line_column(source, self.at);
        if source.contains('\n') {
            format!("{field}, line {line}, column {column}: {}", self.message)
        } else {
            format!("{field}, column {column}: {}", self.message)
        }
    }
}

/// A declared parameter, checked.
#[derive(Clone, Debug, PartialEq)]
pub struct Parameter {
    /// Its name in the formula.
    pub name: String,
    /// The value when none is given.
    pub default: f64,
    /// The valid range.
    pub range: [f64; 2],
}

/// A formula compiled: what [`define`] registers, shared by every [`Instance`] of it.
#[derive(Debug)]
pub struct Formula {
    definition: Definition,
    parameters: Vec<Parameter>,
    body: Vec<Op>,
    tail: Option<Vec<Op>>,
    slot_names: Vec<&'static str>,
    slot_tapes: Vec<Vec<Op>>,
    plan: batch::Plan,
}

impl Formula {
    /// Parses and compiles `definition`; the error names the field, the position and the
    /// problem in one line.
    pub fn compile(definition: Definition) -> Result<Self, Error> {
        let refuse = |message: String| Error::Formula {
            lobe: crate::excerpt(&definition.name),
            message,
        };
        registry::check_name(&definition.name).map_err(refuse)?;
        if definition.parameters.len() > MAX_PARAMETERS {
            return Err(refuse(format!(
                "{} parameters declared; the limit is {MAX_PARAMETERS}",
                definition.parameters.len()
            )));
        }
        let mut parameters = Vec::new();
        for (name, declared) in &definition.parameters {
            compile::check_user_name(name).map_err(|m| refuse(format!("parameter {m}")))?;
            let ParameterDefinition {
                default, min, max, ..
            } = *declared;
            if !(min.is_finite() && max.is_finite() && min <= max && (min..=max).contains(&default))
            {
                return Err(refuse(format!(
                    "parameter '{name}': min = {min}, max = {max}, default = {default} must be \
                     finite with min <= default <= max"
                )));
            }
            parameters.push(Parameter {
                name: name.clone(),
                default,
                range: [min, max],
            });
        }
        let names: Vec<String> = parameters.iter().map(|p| p.name.clone()).collect();
        let program = syntax::parse(&definition.formula)
            .map_err(|e| refuse(e.locate("formula", &definition.formula)))?;
        let tail_program = match &definition.tail {
            Some(text) => {
                let parsed = syntax::parse(text).map_err(|e| refuse(e.locate("tail", text)))?;
                if !parsed.lets.is_empty() {
                    return Err(refuse(
                        "tail: write the 'let's in the formula; the tail sees them".to_owned(),
                    ));
                }
                Some(parsed.result)
            }
            None => None,
        };
        let compiled =
            compile::compile(&program, tail_program.as_ref(), &names).map_err(|e| {
                match (&definition.tail, e.in_tail) {
                    (Some(text), true) => refuse(e.locate("tail", text)),
                    _ => refuse(e.locate("formula", &definition.formula)),
                }
            })?;
        let slot_of = |index: usize| compiled.slots.iter().position(|s| s.op == index);
        let leaf = |index: usize| match compiled.ops[index] {
            Op::Const(c) => Some(Op::Const(c)),
            _ if !compiled.varying[index] => slot_of(index).map(Op::Slot),
            _ => None,
        };
        let body = program::extract(&compiled.ops, compiled.result, leaf);
        let tail = compiled
            .tail
            .map(|root| program::extract(&compiled.ops, root, leaf));
        // A constant folded to NaN or infinity would make every value of the lobe depend on
        // how each backend's min and max treat it.
        for (field, tape) in [("formula", Some(&body)), ("tail", tail.as_ref())] {
            if tape.is_some_and(|ops| {
                ops.iter()
                    .any(|op| matches!(op, Op::Const(c) if !c.is_finite()))
            }) {
                return Err(refuse(format!(
                    "{field}: a sub-expression of numbers alone is NaN or infinite (as 0/0 or \
                     log(0)); write a finite number"
                )));
            }
        }
        let slot_tapes = compiled
            .slots
            .iter()
            .map(|slot| program::extract(&compiled.ops, slot.op, |_| None))
            .collect();
        let slot_names = compiled
            .slots
            .iter()
            .map(|slot| &*Box::leak(slot.name.clone().into_boxed_str()))
            .collect();
        let plan = batch::Plan::new(&body);
        Ok(Self {
            definition,
            parameters,
            body,
            tail,
            slot_names,
            slot_tapes,
            plan,
        })
    }

    /// The lobe's name.
    #[must_use]
    pub fn name(&self) -> &str {
        &self.definition.name
    }

    /// What it was defined from.
    #[must_use]
    pub fn definition(&self) -> &Definition {
        &self.definition
    }

    /// The declared parameters, in the order values are given.
    #[must_use]
    pub fn parameters(&self) -> &[Parameter] {
        &self.parameters
    }

    /// The per-material constants' names, in slot order.
    #[must_use]
    pub fn constants(&self) -> &[&'static str] {
        &self.slot_names
    }

    /// Operations of the varying part (what one evaluation runs once `n` is prepared), a whole
    /// power `x^k` counted as the multiplications it takes: `floor(log2 |k|)` squarings and a
    /// product per further bit of `|k|` (a negative power's reciprocal one more), and a real
    /// power as the three it runs (`exp2(y log2 x)`).
    #[must_use]
    pub fn operations(&self) -> usize {
        self.body
            .iter()
            .map(|op| match *op {
                Op::Powi(_, k) => {
                    let magnitude = k.unsigned_abs().max(1);
                    let multiplications = magnitude.ilog2() + magnitude.count_ones() - 1;
                    (multiplications + u32::from(k < 0)).max(1) as usize
                }
                Op::Pow(..) => 3,
                ref op => usize::from(!op.operands().is_empty()),
            })
            .sum()
    }

    /// Whether it has a closed-form tail.
    #[must_use]
    pub fn has_tail(&self) -> bool {
        self.tail.is_some()
    }

    /// The per-material constants for `n` and parameter `values`, in `f64`.
    pub(crate) fn prepare(&self, n: f64, values: &[f64]) -> [f64; MAX_SLOTS] {
        let mut slots = [0.0; MAX_SLOTS];
        for (slot, tape) in slots.iter_mut().zip(&self.slot_tapes) {
            *slot = self.preparation(tape, n, values);
        }
        slots
    }

    fn preparation<R: crate::Real>(&self, tape: &[Op], n: R, values: &[f64]) -> R {
        let parameter = |p: usize| R::from_f64(values[p]);
        let unused = |_: usize| unreachable!("a preparation reads no slots");
        program::run(
            tape,
            &Leaves {
                t: n,
                n,
                parameter: &parameter,
                slot: &unused,
            },
        )
    }

    /// The slot named `name` computed from `n` over any `Real` (what targets record).
    pub(crate) fn preparation_of<R: crate::Real>(
        &self,
        name: &str,
        n: R,
        values: &[f64],
    ) -> Option<R> {
        let slot = self.slot_names.iter().position(|s| *s == name)?;
        Some(self.preparation(&self.slot_tapes[slot], n, values))
    }

    fn run_tape<R: crate::Real>(&self, tape: &[Op], t: R, slots: &[f64; MAX_SLOTS]) -> R {
        let slot = |s: usize| R::parameter(self.slot_names[s], slots[s]);
        let unused = |_: usize| unreachable!("n and parameters reach the formula as slots");
        program::run(
            tape,
            &Leaves {
                t,
                n: t,
                parameter: &unused,
                slot: &slot,
            },
        )
    }

    /// The formula as written, at `t` (no clamping).
    pub(crate) fn raw<R: crate::Real>(&self, t: R, slots: &[f64; MAX_SLOTS]) -> R {
        self.run_tape(&self.body, t, slots)
    }

    /// [`Formula::raw`] in `f64` at each of `ts`, into `out` (as long).
    pub(crate) fn raw_each(&self, ts: &[f64], slots: &[f64; MAX_SLOTS], out: &mut [f64]) {
        let slot = |s: usize| <f64 as crate::Real>::parameter(self.slot_names[s], slots[s]);
        program::run_each(&self.body, ts, &slot, out);
    }

    /// The tail as written, at `t`.
    pub(crate) fn tail<R: crate::Real>(&self, t: R, slots: &[f64; MAX_SLOTS]) -> Option<R> {
        Some(self.run_tape(self.tail.as_ref()?, t, slots))
    }

    pub(crate) fn plan(&self) -> &batch::Plan {
        &self.plan
    }
}

/// Points of `t` a formula is checked at: a uniform grid, the endpoints, and a geometric
/// approach to the peak (where narrow lobes live).
fn check_points() -> impl Iterator<Item = f64> {
    const GRID: u32 = 4096;
    (0..=GRID)
        .map(|i| f64::from(i) / f64::from(GRID))
        .chain((1..=40).map(|k| 1.0 - 2f64.powi(-k)))
        .chain([f64::MIN_POSITIVE, 1e-9])
}

impl Lobe {
    /// Prepares `kind` for `n`, refusing a user lobe whose formula is not finite or leaves
    /// `[0, 1]` anywhere on a dense grid of `t in [0, 1]` at this `n`, or whose tail is not
    /// its integral. Built-in lobes are always accepted.
    pub fn checked(kind: LobeKind, n: Exponent) -> crate::Result<Self> {
        let lobe = Self::new(kind, n);
        let LobeKind::Formula(id) = kind else {
            return Ok(lobe);
        };
        let instance = registry::get(id);
        let formula = instance.formula();
        let slots = formula.prepare(n.get(), instance.values());
        let refuse = |message: String| Error::Formula {
            lobe: kind.to_string(),
            message: format!("at n = {n}: {message}"),
        };
        for (slot, value) in formula.slot_names.iter().zip(&slots) {
            if !value.is_finite() {
                return Err(refuse(format!("the constant '{slot}' is {value}")));
            }
        }
        // The whole grid at once: the batch interpreter is the scalar one lane by lane.
        let points: Vec<f64> = check_points().collect();
        let mut values = vec![0.0; points.len()];
        formula.raw_each(&points, &slots, &mut values);
        for (&t, &value) in points.iter().zip(&values) {
            let problem = if !value.is_finite() {
                Some("not finite")
            } else if value < -1e-12 {
                Some("negative")
            } else if value > 1.0 + 1e-12 {
                Some("above 1")
            } else {
                None
            };
            if let Some(problem) = problem {
                return Err(refuse(format!(
                    "the formula is {value} ({problem}) at t = {t}; a lobe's value must lie \
                     in [0, 1] for every t in [0, 1]"
                )));
            }
        }
        if formula.has_tail() {
            check_tail(formula, &slots, &lobe).map_err(refuse)?;
        }
        Ok(lobe)
    }
}

/// The tail is `int_t^1` of the formula: 0 at the peak, and equal to the integral computed
/// by quadrature (relative to the whole) at several cosines.
fn check_tail(formula: &Formula, slots: &[f64; MAX_SLOTS], lobe: &Lobe) -> Result<(), String> {
    let tail = |t: f64| formula.tail(t, slots).unwrap_or(f64::NAN);
    // Pieces closing in on the peak geometrically: a narrow lobe lives in the last few.
    let integral = |from: f64| {
        let mut points = vec![from];
        points.extend(
            (1..=52)
                .rev()
                .map(|k| 1.0 - 2f64.powi(-k))
                .filter(|&p| p > from),
        );
        points.push(1.0);
        crate::quadrature::integrate_pieces(|t| lobe.eval(t), &points, 1e-13)
    };
    let whole = integral(0.0);
    for t in [0.0, 0.1, 0.3, 0.5, 0.7, 0.9, 0.99, 0.999, 1.0] {
        let (given, expected) = (tail(t), integral(t));
        if !(given.is_finite() && (given - expected).abs() <= 1e-6 * whole.max(1e-300)) {
            return Err(format!(
                "the tail is {given} at t = {t}, but the formula's integral from t to 1 is \
                 {expected}; the tail must be int_t^1 lobe(s) ds"
            ));
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests;
