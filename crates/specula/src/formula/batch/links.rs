//! What the tape's operations become in chains: links (one varying operand, scalars
//! otherwise), the saved-value links of Horner's rule, and the superinstructions that fuse a
//! link with the one before (a multiply and the add or subtraction reading it, a power of two
//! and the squarings before it).

use super::columns::LaneFunction;
use super::Role;
use crate::formula::op::Op;
use crate::simd::math;
use crate::simd::tally::{Class, Instructions};

/// One link: the value `x` and scalars (indices into the batch's constants).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) enum Link {
    Add(usize),
    /// `x - s`.
    Sub(usize),
    /// `s - x`.
    SubFrom(usize),
    Mul(usize),
    Div(usize),
    /// `s / x`.
    DivInto(usize),
    Min(usize),
    Max(usize),
    /// `x * a + b`, fused.
    Fma(usize, usize),
    /// `b - x * a`, fused (a Horner step of a falling polynomial: `s - c * v`).
    NegFma(usize, usize),
    Powi(i32),
    /// `x` squared this many times (an integer power of two, as `cosquad` computes it).
    Squarings(u32),
    /// `(x - c) * a + b`, the multiply-add fused: a subtraction and the multiply-add that
    /// reads it, in one link.
    Affine(usize, usize, usize),
    /// `x^s` as `exp2(s log2 x)`.
    Pow(usize),
    Neg,
    Abs,
    Sqrt,
    Log2,
    Ln,
    /// `exp2(scale x)`.
    Exp2(f32),
    Acos,
    /// A function without a vector form: the chain goes lane by lane.
    Lane(LaneFunction),
    /// Keeps the value, which a later link of the chain reads again (`u` in
    /// `u * (a + b * u)`): the chain's one saved value, held in registers beside it.
    Save,
    /// The value and the saved one combined: a polynomial of one value (Horner's rule)
    /// stays a chain.
    Saved(SavedOp),
}

/// How a chain's value meets its saved value.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum SavedOp {
    /// `x + saved`.
    Add,
    /// `x * saved`.
    Mul,
    /// `x - saved`.
    Sub,
    /// `saved - x`.
    SubFrom,
    /// `x * saved + b`, fused.
    MulAdd(usize),
    /// `b - x * saved`, fused.
    NegMulAdd(usize),
}

impl SavedOp {
    /// The operation in scalar `f32`, fused where the lanes fuse it.
    pub(super) fn scalar(self, x: f32, saved: f32, values: &[f32]) -> f32 {
        match self {
            SavedOp::Add => x + saved,
            SavedOp::Mul => x * saved,
            SavedOp::Sub => x - saved,
            SavedOp::SubFrom => saved - x,
            SavedOp::MulAdd(b) => x.mul_add(saved, values[b]),
            SavedOp::NegMulAdd(b) => (-x).mul_add(saved, values[b]),
        }
    }
}

impl Link {
    /// Whether the link's polynomial holds only on part of its inputs.
    pub(super) fn checked(self) -> bool {
        matches!(
            self,
            Link::Log2 | Link::Ln | Link::Pow(_) | Link::Exp2(_) | Link::Acos
        )
    }

    /// The link in scalar `f32`, as the formula's scalar path computes it; `saved` is the
    /// chain's saved value ([`Link::Save`] sets it).
    pub(super) fn scalar(self, x: f32, saved: &mut f32, values: &[f32]) -> f32 {
        match self {
            Link::Save => {
                *saved = x;
                x
            }
            Link::Saved(op) => op.scalar(x, *saved, values),
            Link::Add(s) => x + values[s],
            Link::Sub(s) => x - values[s],
            Link::SubFrom(s) => values[s] - x,
            Link::Mul(s) => x * values[s],
            Link::Div(s) => x / values[s],
            Link::DivInto(s) => values[s] / x,
            Link::Min(s) => x.min(values[s]),
            Link::Max(s) => x.max(values[s]),
            Link::Fma(a, b) => x.mul_add(values[a], values[b]),
            Link::NegFma(a, b) => (-x).mul_add(values[a], values[b]),
            Link::Powi(k) => crate::formula::program::powi(x, k),
            Link::Squarings(m) => (0..m).fold(x, |v, _| v * v),
            Link::Affine(c, a, b) => (x - values[c]).mul_add(values[a], values[b]),
            Link::Pow(s) => x.powf(values[s]),
            Link::Neg => -x,
            Link::Abs => x.max(-x),
            Link::Sqrt => x.sqrt(),
            Link::Log2 => x.log2(),
            Link::Ln => x.log2() * core::f32::consts::LN_2,
            Link::Exp2(scale) => (x * scale).exp2(),
            Link::Acos => x.acos(),
            Link::Lane(f) => f.get()(x),
        }
    }

    /// The instructions one vector costs.
    pub(super) fn instructions(self) -> Instructions {
        let one = |class| Instructions::of(&[(class, 1)]);
        match self {
            Link::Add(_) | Link::Sub(_) | Link::SubFrom(_) => one(Class::Add),
            Link::Save => Instructions::NONE,
            Link::Saved(SavedOp::Mul) => one(Class::Mul),
            Link::Saved(SavedOp::MulAdd(_) | SavedOp::NegMulAdd(_)) => one(Class::Fma),
            Link::Saved(_) => one(Class::Add),
            Link::Mul(_) | Link::Neg => one(Class::Mul),
            Link::Squarings(m) => Instructions::of(&[(Class::Mul, m)]),
            Link::Affine(..) => Instructions::of(&[(Class::Add, 1), (Class::Fma, 1)]),
            Link::Div(_) | Link::DivInto(_) => one(Class::Div),
            Link::Min(_) | Link::Max(_) => one(Class::MinMax),
            Link::Fma(..) | Link::NegFma(..) => one(Class::Fma),
            Link::Powi(k) => {
                let bits = 32 - k.unsigned_abs().leading_zeros();
                let multiplies = bits.saturating_sub(1) + k.unsigned_abs().count_ones().max(1) - 1;
                Instructions::of(&[(Class::Mul, multiplies), (Class::Div, u32::from(k < 0))])
            }
            Link::Pow(_) => math::LOG2.and(math::EXP2).plus(Class::Mul, 1),
            Link::Abs => Instructions::of(&[(Class::Mul, 1), (Class::MinMax, 1)]),
            Link::Sqrt => one(Class::Sqrt),
            Link::Log2 => math::LOG2,
            Link::Ln => math::LOG2.plus(Class::Mul, 1),
            Link::Exp2(_) => math::EXP2.plus(Class::Mul, 1),
            Link::Acos => math::ACOS,
            // A call per lane, counted as a division's worth each.
            Link::Lane(_) => Instructions::of(&[(Class::Div, 8)]),
        }
    }
}

/// Appends `link`, fusing it with the last one where a superinstruction does both: each
/// link is a dispatch and a trip of the group through memory, so the common shapes of
/// lobes (a multiply-add of a difference, a power of two) are one link each.
pub(super) fn push_fused(links: &mut Vec<Link>, link: Link) {
    let fused = match (links.last(), link) {
        (Some(&Link::Mul(a)), Link::Add(b)) => Some(Link::Fma(a, b)),
        (Some(&Link::Mul(a)), Link::SubFrom(b)) => Some(Link::NegFma(a, b)),
        // Horner's step on the saved value: `x * u + b` and `b - x * u`, one link each.
        (Some(&Link::Saved(SavedOp::Mul)), Link::Add(b)) => Some(Link::Saved(SavedOp::MulAdd(b))),
        (Some(&Link::Saved(SavedOp::Mul)), Link::SubFrom(b)) => {
            Some(Link::Saved(SavedOp::NegMulAdd(b)))
        }
        (Some(&Link::Sub(c)), Link::Fma(a, b)) => Some(Link::Affine(c, a, b)),
        (Some(&Link::Squarings(m)), Link::Powi(k)) if k > 0 && k.count_ones() == 1 => {
            Some(Link::Squarings(m + k.trailing_zeros()))
        }
        _ => None,
    };
    match fused {
        Some(fused) => {
            links.pop();
            // The fused link may fuse again with the one before (`Sub` then `Mul`, `Add`).
            push_fused(links, fused);
        }
        None => match link {
            // A positive power of two is squarings, as `cosquad` computes it.
            Link::Powi(k) if k > 0 && k.count_ones() == 1 => {
                links.push(Link::Squarings(k.trailing_zeros()));
            }
            link => links.push(link),
        },
    }
}

/// Turns into links the operations where a chain's value meets a value earlier in the same
/// chain (`u * (a + b * u)`: the product reads `u`, and the chain from `u`), with that value
/// saved; returns how many saved reads each value has. Such a value's readers are then its
/// chain's next link and the saved reads, and every value between is read once, so one
/// chain carries it all.
pub(super) fn save_values(tape: &[Op], roles: &mut [Role], uses: &[usize]) -> Vec<usize> {
    let mut saved_refs = vec![0usize; tape.len()];
    let mut saves: Vec<Option<usize>> = vec![None; tape.len()];
    for index in 0..tape.len() {
        if roles[index] != Role::Column {
            continue;
        }
        let (a, b, kind) = match tape[index] {
            Op::Add(a, b) => (a, b, [SavedOp::Add, SavedOp::Add]),
            Op::Mul(a, b) => (a, b, [SavedOp::Mul, SavedOp::Mul]),
            // a - b: with b's chain from a, saved - x; with a's chain from b, x - saved.
            Op::Sub(a, b) => (a, b, [SavedOp::SubFrom, SavedOp::Sub]),
            _ => continue,
        };
        // From `from`, back along single-reader links (or saved reads of `to`), to `to`.
        let reaches = |from: usize, to: usize| {
            let mut at = from;
            loop {
                if at == to {
                    return true;
                }
                match roles[at] {
                    Role::Link(x, _) if uses[at] == 1 && saves[at].is_none_or(|s| s == to) => {
                        at = x;
                    }
                    _ => return false,
                }
            }
        };
        let shape = if a != b && reaches(b, a) {
            Some((b, a, kind[0]))
        } else if a != b && reaches(a, b) {
            Some((a, b, kind[1]))
        } else {
            None
        };
        if let Some((x, saved, op)) = shape {
            roles[index] = Role::Link(x, Link::Saved(op));
            saves[index] = Some(saved);
            saved_refs[saved] += 1;
        }
    }
    saved_refs
}

/// `op` as a link: its one varying operand and the link, when its other operands are
/// scalars and it has one.
pub(super) fn link(op: Op, roles: &[Role]) -> Option<(usize, Link)> {
    let scalar = |i: usize| match roles[i] {
        Role::Scalar(s) => Some(s),
        _ => None,
    };
    let varying = |i: usize| scalar(i).is_none();
    Some(match op {
        Op::Add(a, b) if varying(a) => (a, Link::Add(scalar(b)?)),
        Op::Add(a, b) => (b, Link::Add(scalar(a)?)),
        Op::Sub(a, b) if varying(a) => {
            // x - s as x + (-s) would round the constant: keep a subtraction.
            (a, Link::Sub(scalar(b)?))
        }
        Op::Sub(a, b) => (b, Link::SubFrom(scalar(a)?)),
        Op::Mul(a, b) if varying(a) => (a, Link::Mul(scalar(b)?)),
        Op::Mul(a, b) => (b, Link::Mul(scalar(a)?)),
        Op::Div(a, b) if varying(a) => (a, Link::Div(scalar(b)?)),
        Op::Div(a, b) => (b, Link::DivInto(scalar(a)?)),
        Op::Min(a, b) if varying(a) => (a, Link::Min(scalar(b)?)),
        Op::Min(a, b) => (b, Link::Min(scalar(a)?)),
        Op::Max(a, b) if varying(a) => (a, Link::Max(scalar(b)?)),
        Op::Max(a, b) => (b, Link::Max(scalar(a)?)),
        Op::Pow(a, b) if varying(a) => (a, Link::Pow(scalar(b)?)),
        Op::Powi(a, k) => (a, Link::Powi(k)),
        Op::Neg(a) => (a, Link::Neg),
        Op::Abs(a) => (a, Link::Abs),
        Op::Sqrt(a) => (a, Link::Sqrt),
        Op::Log2(a) => (a, Link::Log2),
        Op::Ln(a) => (a, Link::Ln),
        Op::Exp2(a) => (a, Link::Exp2(1.0)),
        Op::Exp(a) => (a, Link::Exp2(core::f32::consts::LOG2_E)),
        Op::Acos(a) => (a, Link::Acos),
        Op::Cos(a) => (a, Link::Lane(LaneFunction::Cos)),
        Op::Sin(a) => (a, Link::Lane(LaneFunction::Sin)),
        Op::Floor(a) => (a, Link::Lane(LaneFunction::Floor)),
        Op::Ceil(a) => (a, Link::Lane(LaneFunction::Ceil)),
        _ => return None,
    })
}
