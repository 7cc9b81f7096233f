//! A lobe as a recorded expression: the one description every shading language is
//! generated from.
//!
//! Every lobe is written once, generic over [`Real`]. [`Traced`] is one more reading of that
//! code: instead of computing, each operation appends a node to a tape, so running a prepared
//! lobe on a traced `t` ([`Lobe::expression`]) records its formula with the constants
//! [`Lobe::new`] prepared in `f64` folded in, operation for operation as the `f32` path
//! performs them. Code generators walk the [`Expression`]; [`Expression::eval`] runs it back
//! on any `Real`, which is how the tests prove a record equal to the lobe it came from.
//!
//! Models choose with [`Real::select_less`], never with `if` on a value: a comparison of
//! traced values cannot be recorded, so [`record`] refuses an evaluation that made one rather
//! than record half a formula.
//!
//! Targets without bit operations (OSL, MaterialX's node graphs) get the bit tricks rewritten
//! in arithmetic that gives the same `f32` bits ([`Expression::lowered`]).

mod lower;

use core::cell::RefCell;
use core::ops::{Add, Div, Mul, Neg, Sub};

use crate::real::Real;
use crate::Lobe;

/// One operation of a recorded expression; operands are indices of earlier nodes.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Node {
    /// The cosine `t`, already in `(0, 1]` (the shared rules are the caller's).
    Input,
    /// A constant, kept in `f64` as the model computed it; targets round it to `f32`.
    Constant(f64),
    /// A per-material constant prepared from `n` ([`Real::parameter`]): its name and its
    /// value for the lobe's `n`. A target writes the value, or exposes the name as an input
    /// and computes it from `n` ([`Lobe::preparation`]).
    Parameter {
        /// The model's name for it.
        name: &'static str,
        /// Its value for the recorded lobe.
        value: f64,
    },
    /// `a + b`.
    Add(usize, usize),
    /// `a - b`.
    Sub(usize, usize),
    /// `a * b`.
    Mul(usize, usize),
    /// `a / b`.
    Div(usize, usize),
    /// `-a`.
    Neg(usize),
    /// `a * a`.
    Square(usize),
    /// `sqrt(a)`.
    Sqrt(usize),
    /// `log2(a)`.
    Log2(usize),
    /// `exp2(a)`.
    Exp2(usize),
    /// `acos(a)`.
    Acos(usize),
    /// `cos(a)`.
    Cos(usize),
    /// `sin(a)`.
    Sin(usize),
    /// `e^a`.
    Exp(usize),
    /// `ln(1 + a)`.
    Ln1p(usize),
    /// `e^a - 1`.
    ExpM1(usize),
    /// `a^b`.
    Pow(usize, usize),
    /// `max(a, b)`.
    Max(usize, usize),
    /// `min(a, b)`.
    Min(usize, usize),
    /// `ceil(a)`.
    Ceil(usize),
    /// `a 2^k` for integer-valued `k`, 0 once `2^k` underflows ([`Real::shift`]).
    Shift(usize, usize),
    /// The mantissa `m` in `[1/2, 1)` of `frexp(a)`.
    Mantissa(usize),
    /// The exponent `e` of `frexp(a)`.
    Exponent(usize),
    /// [`Real::bits_exp2`].
    BitsExp2(usize),
    /// `then` where `a < b`, else `otherwise`.
    SelectLess {
        /// Compared value.
        a: usize,
        /// Bound.
        b: usize,
        /// Chosen where `a < b`.
        then: usize,
        /// Chosen otherwise (and for NaN).
        otherwise: usize,
    },
}

impl Node {
    /// The operands, in order.
    #[must_use]
    pub fn operands(&self) -> Vec<usize> {
        match *self {
            Node::Input | Node::Constant(_) | Node::Parameter { .. } => Vec::new(),
            Node::Neg(a)
            | Node::Square(a)
            | Node::Sqrt(a)
            | Node::Log2(a)
            | Node::Exp2(a)
            | Node::Acos(a)
            | Node::Cos(a)
            | Node::Sin(a)
            | Node::Exp(a)
            | Node::Ln1p(a)
            | Node::ExpM1(a)
            | Node::Ceil(a)
            | Node::Mantissa(a)
            | Node::Exponent(a)
            | Node::BitsExp2(a) => vec![a],
            Node::Add(a, b)
            | Node::Sub(a, b)
            | Node::Mul(a, b)
            | Node::Div(a, b)
            | Node::Pow(a, b)
            | Node::Max(a, b)
            | Node::Min(a, b)
            | Node::Shift(a, b) => vec![a, b],
            Node::SelectLess {
                a,
                b,
                then,
                otherwise,
            } => vec![a, b, then, otherwise],
        }
    }

    /// Whether the node reads a float's bits (`frexp`, the bit-pattern `exp2`) or builds one
    /// from bits (`shift`).
    #[must_use]
    pub fn is_bit_trick(&self) -> bool {
        matches!(
            self,
            Node::Shift(..) | Node::Mantissa(_) | Node::Exponent(_) | Node::BitsExp2(_)
        )
    }
}

/// A recorded expression of one input `t`: nodes in evaluation order, the last the result.
#[derive(Clone, Debug, PartialEq)]
pub struct Expression {
    nodes: Vec<Node>,
}

/// An evaluation that compared traced values (an `if` on the value instead of
/// [`Real::select_less`]) or read one's number, so its formula cannot be recorded.
#[derive(Clone, Copy, Debug, PartialEq, Eq, thiserror::Error)]
#[error(
    "the evaluation branched on (or read) a traced value; write choices with Real::select_less"
)]
pub struct Branched;

thread_local! {
    static TAPE: RefCell<Tape> = const {
        RefCell::new(Tape {
            nodes: Vec::new(),
            branched: false,
        })
    };
}

struct Tape {
    nodes: Vec<Node>,
    branched: bool,
}

/// A value being recorded: the index of its node on the current thread's tape.
#[derive(Clone, Copy, Debug)]
pub struct Traced(usize);

fn push(node: Node) -> Traced {
    TAPE.with(|tape| {
        let mut tape = tape.borrow_mut();
        tape.nodes.push(node);
        Traced(tape.nodes.len() - 1)
    })
}

/// Records `evaluation` applied to the input `t`, dropping nodes the result does not use.
pub fn record(evaluation: impl FnOnce(Traced) -> Traced) -> Result<Expression, Branched> {
    let saved = TAPE.with(|tape| {
        core::mem::replace(
            &mut *tape.borrow_mut(),
            Tape {
                nodes: Vec::new(),
                branched: false,
            },
        )
    });
    let output = evaluation(push(Node::Input));
    let tape = TAPE.with(|tape| core::mem::replace(&mut *tape.borrow_mut(), saved));
    if tape.branched {
        return Err(Branched);
    }
    Ok(Expression::pruned(tape.nodes, output.0))
}

impl PartialEq for Traced {
    fn eq(&self, _: &Self) -> bool {
        TAPE.with(|tape| tape.borrow_mut().branched = true);
        false
    }
}

impl PartialOrd for Traced {
    fn partial_cmp(&self, _: &Self) -> Option<core::cmp::Ordering> {
        TAPE.with(|tape| tape.borrow_mut().branched = true);
        None
    }
}

macro_rules! traced_binary_op {
    ($trait:ident, $method:ident, $node:ident) => {
        impl $trait for Traced {
            type Output = Traced;
            fn $method(self, rhs: Traced) -> Traced {
                push(Node::$node(self.0, rhs.0))
            }
        }
    };
}

traced_binary_op!(Add, add, Add);
traced_binary_op!(Sub, sub, Sub);
traced_binary_op!(Mul, mul, Mul);
traced_binary_op!(Div, div, Div);

impl Neg for Traced {
    type Output = Traced;
    fn neg(self) -> Traced {
        push(Node::Neg(self.0))
    }
}

macro_rules! traced_unary_fn {
    ($method:ident, $node:ident) => {
        fn $method(self) -> Self {
            push(Node::$node(self.0))
        }
    };
}

impl Real for Traced {
    fn from_f64(x: f64) -> Self {
        push(Node::Constant(x))
    }
    fn parameter(name: &'static str, value: f64) -> Self {
        push(Node::Parameter { name, value })
    }
    /// A traced value has no number until a target computes it: an evaluation that asks for
    /// one is refused, as a branch is.
    fn to_f64(self) -> f64 {
        TAPE.with(|tape| tape.borrow_mut().branched = true);
        f64::NAN
    }
    traced_unary_fn!(square, Square);
    traced_unary_fn!(sqrt, Sqrt);
    traced_unary_fn!(log2, Log2);
    traced_unary_fn!(exp2, Exp2);
    traced_unary_fn!(acos, Acos);
    traced_unary_fn!(cos, Cos);
    traced_unary_fn!(sin, Sin);
    traced_unary_fn!(exp, Exp);
    traced_unary_fn!(ln_1p, Ln1p);
    traced_unary_fn!(exp_m1, ExpM1);
    traced_unary_fn!(ceil, Ceil);
    traced_unary_fn!(bits_exp2, BitsExp2);
    fn powf(self, exponent: Self) -> Self {
        push(Node::Pow(self.0, exponent.0))
    }
    fn max(self, other: Self) -> Self {
        push(Node::Max(self.0, other.0))
    }
    fn min(self, other: Self) -> Self {
        push(Node::Min(self.0, other.0))
    }
    fn shift(self, k: Self) -> Self {
        push(Node::Shift(self.0, k.0))
    }
    fn frexp(self) -> (Self, Self) {
        (push(Node::Mantissa(self.0)), push(Node::Exponent(self.0)))
    }
    fn select_less(self, bound: Self, then: Self, otherwise: Self) -> Self {
        push(Node::SelectLess {
            a: self.0,
            b: bound.0,
            then: then.0,
            otherwise: otherwise.0,
        })
    }
}

impl Expression {
    /// Keeps the nodes `output` depends on, renumbered in order, `output` last.
    fn pruned(nodes: Vec<Node>, output: usize) -> Self {
        let mut used = vec![false; nodes.len()];
        used[output] = true;
        for index in (0..=output).rev() {
            if used[index] {
                for operand in nodes[index].operands() {
                    used[operand] = true;
                }
            }
        }
        let mut renumber = vec![usize::MAX; nodes.len()];
        let mut kept = Vec::new();
        for (index, node) in nodes.into_iter().enumerate().take(output + 1) {
            if used[index] {
                renumber[index] = kept.len();
                kept.push(remap(node, |i| renumber[i]));
            }
        }
        Self { nodes: kept }
    }

    /// The nodes in evaluation order; the last is the result.
    #[must_use]
    pub fn nodes(&self) -> &[Node] {
        &self.nodes
    }

    /// How many times each node is an operand (a generator names the shared ones).
    #[must_use]
    pub fn uses(&self) -> Vec<usize> {
        let mut uses = vec![0; self.nodes.len()];
        for node in &self.nodes {
            for operand in node.operands() {
                uses[operand] += 1;
            }
        }
        uses
    }

    /// The nodes with the named parameters' values left out: what the lobes of one shape
    /// share ([`Lobe::shape_exponents`]), so that two records compare by their operations.
    #[must_use]
    pub fn operations(&self) -> Vec<Node> {
        let erase = |node: &Node| match *node {
            Node::Parameter { name, .. } => Node::Parameter { name, value: 0.0 },
            other => other,
        };
        self.nodes.iter().map(erase).collect()
    }

    /// Whether any node is a bit trick ([`Node::is_bit_trick`]).
    #[must_use]
    pub fn has_bit_tricks(&self) -> bool {
        self.nodes.iter().any(Node::is_bit_trick)
    }

    /// Evaluates the record at `t` in `R`, node by node through `R`'s own operations (so in
    /// `f32` it is the fast path's arithmetic, and on [`Traced`] it copies the record).
    #[must_use]
    pub fn eval<R: Real>(&self, t: R) -> R {
        self.run(t, false)
    }

    /// The same expression with every bit trick rewritten as arithmetic, `floor` and
    /// selects, for targets that cannot read or build a float's bits. In `f32` it gives the
    /// same bits as the original for every normal `t` (tested); it needs `exp2` exact at
    /// integers, as IEEE libraries and GPUs give it.
    #[must_use]
    pub fn lowered(&self) -> Expression {
        record(|t| self.run(t, true))
            .unwrap_or_else(|_| unreachable!("the lowering chooses with select_less"))
    }

    fn run<R: Real>(&self, t: R, lower_bit_tricks: bool) -> R {
        let mut values: Vec<R> = Vec::with_capacity(self.nodes.len());
        // A lowered frexp, computed once for its mantissa and exponent nodes.
        let mut split: Option<(usize, (R, R))> = None;
        let mut lowered_frexp = |a: usize, x: R| match split {
            Some((operand, parts)) if operand == a => parts,
            _ => {
                let parts = lower::frexp(x);
                split = Some((a, parts));
                parts
            }
        };
        for &node in &self.nodes {
            let at = |i: usize| values[i];
            let value = match node {
                Node::Input => t,
                Node::Constant(c) => R::from_f64(c),
                Node::Parameter { name, value } => R::parameter(name, value),
                Node::Add(a, b) => at(a) + at(b),
                Node::Sub(a, b) => at(a) - at(b),
                Node::Mul(a, b) => at(a) * at(b),
                Node::Div(a, b) => at(a) / at(b),
                Node::Neg(a) => -at(a),
                Node::Square(a) => at(a).square(),
                Node::Sqrt(a) => at(a).sqrt(),
                Node::Log2(a) => at(a).log2(),
                Node::Exp2(a) => at(a).exp2(),
                Node::Acos(a) => at(a).acos(),
                Node::Cos(a) => at(a).cos(),
                Node::Sin(a) => at(a).sin(),
                Node::Exp(a) => at(a).exp(),
                Node::Ln1p(a) => at(a).ln_1p(),
                Node::ExpM1(a) => at(a).exp_m1(),
                Node::Pow(a, b) => at(a).powf(at(b)),
                Node::Max(a, b) => at(a).max(at(b)),
                Node::Min(a, b) => at(a).min(at(b)),
                Node::Ceil(a) => at(a).ceil(),
                Node::Shift(a, k) if lower_bit_tricks => lower::shift(at(a), at(k)),
                Node::Shift(a, k) => at(a).shift(at(k)),
                Node::Mantissa(a) if lower_bit_tricks => lowered_frexp(a, at(a)).0,
                Node::Mantissa(a) => at(a).frexp().0,
                Node::Exponent(a) if lower_bit_tricks => lowered_frexp(a, at(a)).1,
                Node::Exponent(a) => at(a).frexp().1,
                Node::BitsExp2(a) if lower_bit_tricks => lower::bits_exp2(at(a)),
                Node::BitsExp2(a) => at(a).bits_exp2(),
                Node::SelectLess {
                    a,
                    b,
                    then,
                    otherwise,
                } => at(a).select_less(at(b), at(then), at(otherwise)),
            };
            values.push(value);
        }
        values[values.len() - 1]
    }
}

fn remap(node: Node, map: impl Fn(usize) -> usize) -> Node {
    match node {
        Node::Input => Node::Input,
        Node::Constant(c) => Node::Constant(c),
        Node::Parameter { name, value } => Node::Parameter { name, value },
        Node::Add(a, b) => Node::Add(map(a), map(b)),
        Node::Sub(a, b) => Node::Sub(map(a), map(b)),
        Node::Mul(a, b) => Node::Mul(map(a), map(b)),
        Node::Div(a, b) => Node::Div(map(a), map(b)),
        Node::Neg(a) => Node::Neg(map(a)),
        Node::Square(a) => Node::Square(map(a)),
        Node::Sqrt(a) => Node::Sqrt(map(a)),
        Node::Log2(a) => Node::Log2(map(a)),
        Node::Exp2(a) => Node::Exp2(map(a)),
        Node::Acos(a) => Node::Acos(map(a)),
        Node::Cos(a) => Node::Cos(map(a)),
        Node::Sin(a) => Node::Sin(map(a)),
        Node::Exp(a) => Node::Exp(map(a)),
        Node::Ln1p(a) => Node::Ln1p(map(a)),
        Node::ExpM1(a) => Node::ExpM1(map(a)),
        Node::Pow(a, b) => Node::Pow(map(a), map(b)),
        Node::Max(a, b) => Node::Max(map(a), map(b)),
        Node::Min(a, b) => Node::Min(map(a), map(b)),
        Node::Ceil(a) => Node::Ceil(map(a)),
        Node::Shift(a, k) => Node::Shift(map(a), map(k)),
        Node::Mantissa(a) => Node::Mantissa(map(a)),
        Node::Exponent(a) => Node::Exponent(map(a)),
        Node::BitsExp2(a) => Node::BitsExp2(map(a)),
        Node::SelectLess {
            a,
            b,
            then,
            otherwise,
        } => Node::SelectLess {
            a: map(a),
            b: map(b),
            then: map(then),
            otherwise: map(otherwise),
        },
    }
}

/// A named parameter of a lobe's expression.
#[derive(Clone, Debug, PartialEq)]
pub struct Parameter {
    /// Its name ([`Real::parameter`]).
    pub name: &'static str,
    /// Its value for the recorded lobe.
    pub value: f64,
    /// How it follows from `n`, an expression whose input is `n`; `None` for a fitted one.
    pub preparation: Option<Expression>,
}

impl Expression {
    /// The named parameters, each once, in order of first use.
    #[must_use]
    pub fn parameters(&self) -> Vec<(&'static str, f64)> {
        let mut found: Vec<(&'static str, f64)> = Vec::new();
        for node in &self.nodes {
            if let Node::Parameter { name, value } = *node {
                if found.iter().all(|(seen, _)| *seen != name) {
                    found.push((name, value));
                }
            }
        }
        found
    }
}

impl Lobe {
    /// The named parameters of [`Lobe::expression`] with their preparation from `n`.
    #[must_use]
    pub fn parameters(&self) -> Vec<Parameter> {
        self.expression()
            .parameters()
            .into_iter()
            .map(|(name, value)| {
                let derived = self.preparation::<f64>(name, 0.0).is_some();
                let preparation = derived
                    .then(|| record(|n| self.preparation(name, n).unwrap_or(n)).ok())
                    .flatten();
                Parameter {
                    name,
                    value,
                    preparation,
                }
            })
            .collect()
    }

    /// For a lobe sampled in closed form: the recorded inverse of its tail (an expression of
    /// the uniform number `u`) and its whole integral `int_0^1 lobe` (an expression of
    /// nothing but its parameters) ([`Lobe::closed_form_sampling`]).
    #[must_use]
    pub fn sampling_expressions(&self) -> Option<(Expression, Expression)> {
        self.closed_form_sampling(0.5f64)?;
        let part = |first: bool| {
            record(|u| {
                let (inverse, total) = self
                    .closed_form_sampling(u)
                    .unwrap_or_else(|| unreachable!("checked above"));
                if first {
                    inverse
                } else {
                    total
                }
            })
            .unwrap_or_else(|_| unreachable!("the closed forms choose with max"))
        };
        Some((part(true), part(false)))
    }

    /// For a lobe sampled by Newton ([`Lobe::newton_sampling`]): its tail, slope and cosine as
    /// expressions of the solver's variable, and its bracket's end and whole integral as
    /// expressions of its parameters alone, in that order.
    #[must_use]
    pub fn newton_expressions(&self) -> Option<[Expression; 5]> {
        self.newton_sampling(0.5f64)?;
        let part = |pick: fn(crate::lobe::NewtonForm<Traced>) -> Traced| {
            record(|x| {
                pick(
                    self.newton_sampling(x)
                        .unwrap_or_else(|| unreachable!("checked above")),
                )
            })
            .unwrap_or_else(|_| unreachable!("the tails choose with select_less"))
        };
        Some([
            part(|form| form.tail),
            part(|form| form.slope),
            part(|form| form.cosine),
            part(|form| form.upper),
            part(|form| form.total),
        ])
    }

    /// The lobe's formula for `t` in `(0, 1]` as a recorded [`Expression`], its constants
    /// for this `n` folded in. The shared rules (`t <= 0` or NaN gives 0, `t > 1` counts as
    /// 1) are not part of it: every target writes them once around it.
    #[must_use]
    pub fn expression(&self) -> Expression {
        record(|t| self.eval_unit(t))
            .unwrap_or_else(|_| unreachable!("every model chooses with select_less"))
    }
}
