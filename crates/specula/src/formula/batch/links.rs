//! What the tape's operations become in chains: links (one varying operand, scalars
//! otherwise), the saved-value links of Horner's rule, and the superinstructions that fuse a
//! link with the one before.

use super::chain::{Link, SavedOp};
use super::columns::LaneFunction;
use super::Role;
use crate::formula::compile::Op;

/// Appends `link`, fusing it with the last one where a superinstruction does both: each
/// link is a dispatch and a trip of the group through memory, so the common shapes of
/// lobes (a multiply-add of a difference, a power of two) are one link each.
pub(super) fn push_fused(links: &mut Vec<Link>, link: Link) {
    let fused = match (links.last(), link) {
        (Some(&Link::Mul(a)), Link::Add(b)) => Some(Link::Fma(a, b)),
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
