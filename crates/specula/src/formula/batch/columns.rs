//! Column operations: one operation over a whole block of vectors before the next is
//! chosen, for the values that chains cannot carry (two varying values meeting), and the
//! vector operations and ranges chains and columns share.
//!
//! `log2`, `exp2` and `acos` are the built-in kernels' polynomials ([`crate::simd::math`]),
//! valid on the ranges the lobes use; a block where any lane falls outside them (an `exp2`
//! of a positive number, a `log2` of 0) is recomputed lane by lane with the standard library.

use super::{Source, Step};
use crate::formula::op::Op;
use crate::simd::{math, Lanes};

/// A function the columns compute lane by lane.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) enum LaneFunction {
    Cos,
    Sin,
    Floor,
    Ceil,
}

impl LaneFunction {
    pub(super) fn get(self) -> fn(f32) -> f32 {
        match self {
            LaneFunction::Cos => f32::cos,
            LaneFunction::Sin => f32::sin,
            LaneFunction::Floor => f32::floor,
            LaneFunction::Ceil => f32::ceil,
        }
    }
}

#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) enum Binary {
    Add,
    Sub,
    Mul,
    Div,
    Min,
    Max,
    Pow,
}

pub(super) fn binary(op: Op) -> Option<Binary> {
    Some(match op {
        Op::Add(..) => Binary::Add,
        Op::Sub(..) => Binary::Sub,
        Op::Mul(..) => Binary::Mul,
        Op::Div(..) => Binary::Div,
        Op::Min(..) => Binary::Min,
        Op::Max(..) => Binary::Max,
        Op::Pow(..) => Binary::Pow,
        _ => None?,
    })
}

/// An operation on `N` vectors, as a type: called from the level's target-feature function
/// and `#[inline(always)]`, so that its intrinsics are inlined (a closure here would be a
/// function of its own, compiled without the features, and every intrinsic in it a call).
pub(super) trait Map<const N: usize>: Copy {
    fn apply<V: Lanes>(self, x: [V; N]) -> V;
}

macro_rules! map {
    ($name:ident, $n:literal, |$x:ident $(, $field:ident: $ty:ty)*| $body:expr) => {
        #[derive(Clone, Copy)]
        pub(super) struct $name { $(pub(super) $field: $ty),* }
        impl Map<$n> for $name {
            #[inline(always)]
            #[allow(unused_variables)]
            fn apply<V: Lanes>(self, $x: [V; $n]) -> V {
                $(let $field = self.$field;)*
                $body
            }
        }
    };
}

map!(AddOp, 2, |x| x[0] + x[1]);
map!(SubOp, 2, |x| x[0] - x[1]);
map!(MulOp, 2, |x| x[0] * x[1]);
map!(DivOp, 2, |x| x[0] / x[1]);
map!(MinOp, 2, |x| x[0].min(x[1]));
map!(MaxOp, 2, |x| x[0].max(x[1]));
map!(FmaOp, 3, |x| x[0].mul_add(x[1], x[2]));
map!(SelectOp, 4, |x| x[2].select(x[0].lt(x[1]), x[3]));
map!(PowLogOp, 2, |x| x[1] * math::log2(x[0]));
map!(Exp2Op, 1, |x, scale: f32| math::exp2(
    x[0] * x[0].splat(scale)
));
// 1 where `low < scale x < high` (NaN fails both), else 0.
map!(Inside, 1, |x, scale: f32, low: f32, high: f32| {
    let (zero, one) = (x[0].splat(0.0), x[0].splat(1.0));
    let y = x[0] * x[0].splat(scale);
    one.select(y.gt(y.splat(low)), zero)
        .select(y.lt(y.splat(high)), zero)
});

impl Inside {
    /// Whether every value between `a` and `b` (either order) passes, by the same strict
    /// bounds as the lanes' test.
    pub(super) fn holds(self, a: f32, b: f32) -> bool {
        let (a, b) = (a * self.scale, b * self.scale);
        let (low, high) = (a.min(b), a.max(b));
        self.low < low && high < self.high
    }
}

/// `op` over every vector of the block: reads the operand columns, writes column `out`
/// (never one of them: the planner gives every result a register of its own at that step).
#[inline(always)]
fn columns<V: Lanes, const N: usize, M: Map<N>>(
    lanes: V,
    file: &mut [f32],
    operands: [usize; N],
    out: usize,
    block: usize,
    op: M,
) {
    let (before, rest) = file.split_at_mut(out);
    let (target, after) = rest.split_at_mut(block);
    let read = |column: usize| -> &[f32] {
        if column < out {
            &before[column..column + block]
        } else {
            &after[column - out - block..column - out]
        }
    };
    let mut sources: [&[f32]; N] = [&[]; N];
    for (source, &column) in sources.iter_mut().zip(&operands) {
        *source = read(column);
    }
    let width = V::WIDTH;
    for (i, chunk) in target.chunks_exact_mut(width).enumerate() {
        let mut values = [lanes; N];
        for (value, source) in values.iter_mut().zip(&sources) {
            *value = lanes.load(&source[i * width..(i + 1) * width]);
        }
        op.apply(values).store(chunk);
    }
}

/// `op` over column `column`, in place.
#[inline(always)]
fn in_place<V: Lanes, M: Map<1>>(lanes: V, file: &mut [f32], column: usize, block: usize, op: M) {
    for chunk in file[column..column + block].chunks_exact_mut(V::WIDTH) {
        op.apply([lanes.load(chunk)]).store(chunk);
    }
}

/// Whether every lane of the block's column passes `inside` (which gives 1 or 0 per lane).
#[inline(always)]
fn all_inside<V: Lanes>(
    lanes: V,
    file: &[f32],
    column: usize,
    block: usize,
    inside: Inside,
) -> bool {
    let width = V::WIDTH;
    let mut worst = lanes.splat(1.0);
    let mut at = 0;
    while at < block {
        worst = worst.min(inside.apply([lanes.load(&file[column + at..column + at + width])]));
        at += width;
    }
    let mut lanes_out = [0.0_f32; 64];
    worst.store(&mut lanes_out[..width]);
    lanes_out[..width].iter().all(|&v| v == 1.0)
}

/// Positive, finite and normal: where the `log2` polynomial holds.
pub(super) const LOG2_DOMAIN: Inside = Inside {
    scale: 1.0,
    low: f32::MIN_POSITIVE,
    high: f32::MAX,
};

/// `[0, 1]` and a rounding either side: where the `acos` polynomial holds.
pub(super) const ACOS_DOMAIN: Inside = Inside {
    scale: 1.0,
    low: -f32::MIN_POSITIVE,
    high: 1.0 + f32::EPSILON,
};

#[inline(always)]
pub(super) fn run_step<V: Lanes>(
    lanes: V,
    step: &Step,
    file: &mut [f32],
    base: usize,
    block: usize,
) {
    let column = |source: Source| match source {
        Source::Register(r) => base + r * block,
        Source::Scalar(s) => s * block,
    };
    let out = |r: usize| base + r * block;
    match *step {
        Step::Chain(..) => unreachable!("chains run in run_block"),
        Step::Fma(a, b, c, r) => columns(
            lanes,
            file,
            [column(a), column(b), column(c)],
            out(r),
            block,
            FmaOp {},
        ),
        Step::SelectLess([a, b, then, otherwise], r) => {
            let operands = [column(a), column(b), column(then), column(otherwise)];
            columns(lanes, file, operands, out(r), block, SelectOp {});
        }
        Step::Binary(op, a, b, r) => {
            let (operands, r) = ([column(a), column(b)], out(r));
            match op {
                Binary::Add => columns(lanes, file, operands, r, block, AddOp {}),
                Binary::Sub => columns(lanes, file, operands, r, block, SubOp {}),
                Binary::Mul => columns(lanes, file, operands, r, block, MulOp {}),
                Binary::Div => columns(lanes, file, operands, r, block, DivOp {}),
                Binary::Min => columns(lanes, file, operands, r, block, MinOp {}),
                Binary::Max => columns(lanes, file, operands, r, block, MaxOp {}),
                Binary::Pow => {
                    // exp2(b log2 a), each half checked against its polynomial's range.
                    if all_inside(lanes, file, operands[0], block, LOG2_DOMAIN) {
                        columns(lanes, file, operands, r, block, PowLogOp {});
                    } else {
                        for i in 0..block {
                            file[r + i] = file[operands[1] + i] * file[operands[0] + i].log2();
                        }
                    }
                    exp2_column(lanes, file, r, r, block, 1.0);
                }
            }
        }
    }
}

/// `exp2(scale x)`: the polynomial on `(-inf, 0]` (0 below -127), the standard library
/// elsewhere.
#[inline(always)]
fn exp2_column<V: Lanes>(lanes: V, file: &mut [f32], a: usize, r: usize, block: usize, scale: f32) {
    let domain = Inside {
        scale,
        low: -f32::MAX,
        high: f32::MIN_POSITIVE,
    };
    if all_inside(lanes, file, a, block, domain) {
        if a == r {
            in_place(lanes, file, r, block, Exp2Op { scale });
        } else {
            columns(lanes, file, [a], r, block, Exp2Op { scale });
        }
    } else {
        for i in 0..block {
            file[r + i] = (file[a + i] * scale).exp2();
        }
    }
}

/// `x^k` in [`crate::formula::program::powi`]'s order (so `x^16` is the four squarings `cosquad`'s
/// kernel computes).
#[inline(always)]
pub(super) fn powi<V: Lanes>(x: V, k: i32) -> V {
    crate::formula::program::by_squaring(OfLanes(x), k).0
}

#[derive(Clone, Copy)]
struct OfLanes<V>(V);

impl<V: Lanes> crate::formula::program::Multiplies for OfLanes<V> {
    #[inline(always)]
    fn times(self, other: Self) -> Self {
        Self(self.0 * other.0)
    }
    #[inline(always)]
    fn squared(self) -> Self {
        Self(self.0 * self.0)
    }
    #[inline(always)]
    fn reciprocal(self) -> Self {
        Self(self.0.splat(1.0) / self.0)
    }
    #[inline(always)]
    fn one(self) -> Self {
        Self(self.0.splat(1.0))
    }
}
