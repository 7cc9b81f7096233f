//! Running a compiled formula on any [`Real`]: the operations' meaning, written once.
//!
//! A *tape* is a straight list of operations whose operands index earlier entries and whose
//! last entry is the result; its leaves are `t`, `n`, parameters, constants and slots (the
//! per-material constants). The formula's varying part, its tail and each slot's preparation
//! are tapes cut from the compiled program ([`extract`]), so one loop runs them all.

use super::op::Op;
use crate::real::Real;

/// `op` applied to its operands' values (`at(i)` is operand `i`'s); leaves are the caller's.
#[inline]
pub(crate) fn apply<R: Real>(op: Op, at: impl Fn(usize) -> R) -> R {
    match op {
        Op::T | Op::N | Op::Param(_) | Op::Slot(_) => {
            unreachable!("leaves are read by the caller")
        }
        Op::Const(c) => R::from_f64(c),
        Op::Add(a, b) => at(a) + at(b),
        Op::Sub(a, b) => at(a) - at(b),
        Op::Mul(a, b) => at(a) * at(b),
        Op::Div(a, b) => at(a) / at(b),
        Op::Neg(a) => -at(a),
        Op::Sqrt(a) => at(a).sqrt(),
        Op::Log2(a) => at(a).log2(),
        Op::Exp2(a) => at(a).exp2(),
        Op::Exp(a) => at(a).exp(),
        Op::Ln(a) => at(a).log2() * R::from_f64(core::f64::consts::LN_2),
        Op::Acos(a) => at(a).acos(),
        Op::Cos(a) => at(a).cos(),
        Op::Sin(a) => at(a).sin(),
        Op::Abs(a) => at(a).max(-at(a)),
        Op::Floor(a) => -(-at(a)).ceil(),
        Op::Ceil(a) => at(a).ceil(),
        Op::Pow(a, b) => at(a).powf(at(b)),
        Op::Powi(a, k) => powi(at(a), k),
        Op::Min(a, b) => at(a).min(at(b)),
        Op::Max(a, b) => at(a).max(at(b)),
        Op::SelectLess {
            a,
            b,
            then,
            otherwise,
        } => at(a).select_less(at(b), at(then), at(otherwise)),
    }
}

/// `x^k` by squarings and multiplications (binary exponentiation): `x^16` is four squarings.
#[inline]
pub(crate) fn powi<R: Real>(x: R, k: i32) -> R {
    by_squaring(OfReal(x), k).0
}

/// What binary exponentiation needs: a product, a square and a reciprocal. Implemented for
/// the scalar path's [`Real`] and the columns' vectors, so both compute the same sequence of
/// roundings (methods, not closures: the columns call this from target-feature code).
pub(crate) trait Multiplies: Copy {
    fn times(self, other: Self) -> Self;
    fn squared(self) -> Self;
    fn reciprocal(self) -> Self;
    fn one(self) -> Self;
}

#[derive(Clone, Copy)]
struct OfReal<R>(R);

impl<R: Real> Multiplies for OfReal<R> {
    #[inline(always)]
    fn times(self, other: Self) -> Self {
        Self(self.0 * other.0)
    }
    #[inline(always)]
    fn squared(self) -> Self {
        Self(self.0.square())
    }
    #[inline(always)]
    fn reciprocal(self) -> Self {
        Self(R::from_f64(1.0) / self.0)
    }
    #[inline(always)]
    fn one(self) -> Self {
        Self(R::from_f64(1.0))
    }
}

/// Binary exponentiation.
#[inline(always)]
pub(crate) fn by_squaring<T: Multiplies>(x: T, k: i32) -> T {
    let mut remaining = k.unsigned_abs();
    if remaining == 0 {
        return x.one();
    }
    let mut base = x;
    let mut result: Option<T> = None;
    loop {
        if remaining & 1 == 1 {
            result = Some(match result {
                Some(r) => r.times(base),
                None => base,
            });
        }
        remaining >>= 1;
        if remaining == 0 {
            break;
        }
        base = base.squared();
    }
    let power = result.unwrap_or(base);
    if k < 0 {
        power.reciprocal()
    } else {
        power
    }
}

/// An operation of constants, folded in `f64`.
pub(crate) fn fold(op: Op, at: impl Fn(usize) -> f64) -> f64 {
    apply(op, at)
}

/// The tape computing `root` from `ops`: the operations it needs, in order, where `leaf(i)`
/// replaces operation `i` (and everything below it) by a leaf when it returns one.
pub(crate) fn extract(ops: &[Op], root: usize, leaf: impl Fn(usize) -> Option<Op>) -> Vec<Op> {
    let mut needed = vec![false; ops.len()];
    let mut replaced: Vec<Option<Op>> = vec![None; ops.len()];
    needed[root] = true;
    for index in (0..=root).rev() {
        if !needed[index] {
            continue;
        }
        match leaf(index) {
            Some(op) => replaced[index] = Some(op),
            None => {
                for operand in ops[index].operands() {
                    needed[operand] = true;
                }
            }
        }
    }
    let mut renumber = vec![usize::MAX; ops.len()];
    let mut tape = Vec::new();
    for index in 0..=root {
        if needed[index] {
            renumber[index] = tape.len();
            tape.push(replaced[index].unwrap_or_else(|| remap(ops[index], |i| renumber[i])));
        }
    }
    tape
}

fn remap(op: Op, map: impl Fn(usize) -> usize) -> Op {
    match op {
        Op::T | Op::N | Op::Param(_) | Op::Const(_) | Op::Slot(_) => op,
        Op::Add(a, b) => Op::Add(map(a), map(b)),
        Op::Sub(a, b) => Op::Sub(map(a), map(b)),
        Op::Mul(a, b) => Op::Mul(map(a), map(b)),
        Op::Div(a, b) => Op::Div(map(a), map(b)),
        Op::Neg(a) => Op::Neg(map(a)),
        Op::Sqrt(a) => Op::Sqrt(map(a)),
        Op::Log2(a) => Op::Log2(map(a)),
        Op::Exp2(a) => Op::Exp2(map(a)),
        Op::Exp(a) => Op::Exp(map(a)),
        Op::Ln(a) => Op::Ln(map(a)),
        Op::Acos(a) => Op::Acos(map(a)),
        Op::Cos(a) => Op::Cos(map(a)),
        Op::Sin(a) => Op::Sin(map(a)),
        Op::Abs(a) => Op::Abs(map(a)),
        Op::Floor(a) => Op::Floor(map(a)),
        Op::Ceil(a) => Op::Ceil(map(a)),
        Op::Pow(a, b) => Op::Pow(map(a), map(b)),
        Op::Powi(a, k) => Op::Powi(map(a), k),
        Op::Min(a, b) => Op::Min(map(a), map(b)),
        Op::Max(a, b) => Op::Max(map(a), map(b)),
        Op::SelectLess {
            a,
            b,
            then,
            otherwise,
        } => Op::SelectLess {
            a: map(a),
            b: map(b),
            then: map(then),
            otherwise: map(otherwise),
        },
    }
}

/// The values a tape's leaves take.
pub(crate) struct Leaves<'a, R> {
    pub t: R,
    pub n: R,
    pub parameter: &'a dyn Fn(usize) -> R,
    pub slot: &'a dyn Fn(usize) -> R,
}

/// Runs `tape`; its result.
///
/// A lobe's scalar path runs this per evaluation (per sample of a volume, per path of an
/// environment render, per point of an accuracy check), so tapes of the usual size keep
/// their values on the stack, in the smallest of a few sizes: the buffer is filled before
/// the run, and filling 64 entries for a tape of 10 took longer than the tape.
pub(crate) fn run<R: Real>(tape: &[Op], leaves: &Leaves<'_, R>) -> R {
    match tape.len() {
        0..=16 => run_in(tape, leaves, &mut [leaves.t; 16]),
        17..=32 => run_in(tape, leaves, &mut [leaves.t; 32]),
        33..=64 => run_in(tape, leaves, &mut [leaves.t; 64]),
        _ => run_in(tape, leaves, &mut vec![leaves.t; tape.len()]),
    }
}

/// [`run`] with `values` (at least the tape's length) holding each entry's value.
#[inline]
fn run_in<R: Real>(tape: &[Op], leaves: &Leaves<'_, R>, values: &mut [R]) -> R {
    for (index, &op) in tape.iter().enumerate() {
        values[index] = match op {
            Op::T => leaves.t,
            Op::N => leaves.n,
            Op::Param(p) => (leaves.parameter)(p),
            Op::Slot(s) => (leaves.slot)(s),
            op => apply(op, |i| values[i]),
        };
    }
    values[tape.len() - 1]
}

/// [`run`] in `f64` over many `ts` at once (`out` as long), `slot(s)` each slot's value:
/// each operation over a chunk of lanes before the next, so the tape is walked once a chunk
/// rather than once a value, and the arithmetic runs as vector loops. Every lane computes
/// what [`run`] computes for its `t`, operation for operation (the same [`Real`] methods), so
/// the values agree to the bit. An analysis that scans a lobe over thousands of cosines (a
/// design's verification) takes this path.
pub(crate) fn run_each(tape: &[Op], ts: &[f64], slot: &dyn Fn(usize) -> f64, out: &mut [f64]) {
    const LANES: usize = 64;
    assert_eq!(ts.len(), out.len(), "one output per cosine");
    let Some(last) = tape.len().checked_sub(1) else {
        return;
    };
    let mut values = vec![[0.0_f64; LANES]; tape.len()];
    for (ts, out) in ts.chunks(LANES).zip(out.chunks_mut(LANES)) {
        let count = ts.len();
        for (index, &op) in tape.iter().enumerate() {
            let (before, rest) = values.split_at_mut(index);
            let value = &mut rest[0];
            let lanes = |operand: usize| &before[operand];
            // Lanes past `count` hold what earlier chunks left: computed and never read.
            match op {
                // `n` reaches a formula's body as a slot; the leaf stands for `t` as in
                // `Formula::run_tape`'s scalar leaves.
                Op::T | Op::N => value[..count].copy_from_slice(ts),
                Op::Param(_) => unreachable!("parameters reach a formula as slots"),
                Op::Slot(s) => value.fill(slot(s)),
                Op::Const(c) => value.fill(c),
                Op::Add(a, b) => lanewise(value, lanes(a), lanes(b), |x, y| x + y),
                Op::Sub(a, b) => lanewise(value, lanes(a), lanes(b), |x, y| x - y),
                Op::Mul(a, b) => lanewise(value, lanes(a), lanes(b), |x, y| x * y),
                Op::Div(a, b) => lanewise(value, lanes(a), lanes(b), |x, y| x / y),
                Op::Min(a, b) => lanewise(value, lanes(a), lanes(b), Real::min),
                Op::Max(a, b) => lanewise(value, lanes(a), lanes(b), Real::max),
                Op::Powi(a, k) => {
                    let x = lanes(a);
                    for lane in 0..LANES {
                        value[lane] = powi(x[lane], k);
                    }
                }
                op => {
                    for lane in 0..count {
                        value[lane] = apply(op, |operand| before[operand][lane]);
                    }
                }
            }
        }
        out.copy_from_slice(&values[last][..count]);
    }
}

/// `value[k] = f(a[k], b[k])` for every lane.
#[inline(always)]
fn lanewise<const L: usize>(
    value: &mut [f64; L],
    a: &[f64; L],
    b: &[f64; L],
    f: impl Fn(f64, f64) -> f64,
) {
    for lane in 0..L {
        value[lane] = f(a[lane], b[lane]);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn integer_powers_are_squarings_and_products() {
        for k in -9..=64 {
            let x = 0.93_f64;
            let expected = x.powi(k);
            assert!(
                (powi(x, k) - expected).abs() <= 1e-14 * expected,
                "{k}: {} vs {expected}",
                powi(x, k)
            );
        }
        // x^16 is exactly four squarings.
        let x = 0.987_654_f32;
        let squared = |v: f32| v * v;
        assert_eq!(powi(x, 16), squared(squared(squared(squared(x)))));
        let ops = crate::ops::count_ops(|| powi(crate::ops::Counted(0.5), 16)).1;
        assert_eq!(ops.total(), 4, "{ops:?}");
    }
}
