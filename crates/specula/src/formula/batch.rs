//! A formula over a batch of cosines: its tape compiled to *columns*.
//!
//! An interpreter that dispatches on every operation for every vector spends more time
//! choosing than computing. Here each operation runs over a whole block of
//! [`BLOCK_VECTORS`] vectors before the next is chosen, so the choice is paid once per block
//! and the loop inside is the kernel a compiler would write for that one operation (loads,
//! the instruction, a store, all in L1). The per-material constants are splatted into
//! registers once per batch; a multiply whose only use is an add becomes one fused
//! multiply-add, as the built-in kernels compute it; registers are reused once their last
//! reader has run.
//!
//! `log2`, `exp2` and `acos` are the built-in kernels' polynomials ([`crate::simd::math`]),
//! valid on the ranges the lobes use; a block where any lane falls outside them (an `exp2`
//! of a positive number, a `log2` of 0) is recomputed lane by lane with the standard library,
//! so the columns are fast where the lobes live and right everywhere. `cos`, `sin`, `floor`
//! and `ceil`, which no built-in lobe needs, always go lane by lane.

use super::compile::Op;
use crate::simd::tally::{Class, Instructions};
use crate::simd::{math, Lanes};

/// Vectors per block: 16 vectors of 8 lanes keep a register in 512 bytes, so a formula's
/// live registers stay in L1.
pub const BLOCK_VECTORS: usize = 16;

/// Where an operand comes from.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Source {
    /// A column register.
    Register(usize),
    /// A per-material constant (slot) or a folded constant, splatted.
    Scalar(usize),
}

/// A scalar the batch splats: a slot's value or a constant.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) enum Scalar {
    Slot(usize),
    Constant(f64),
}

/// One column operation.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Step {
    Unary(Unary, Source, usize),
    Binary(Binary, Source, Source, usize),
    Fma(Source, Source, Source, usize),
    Powi(Source, i32, usize),
    SelectLess([Source; 4], usize),
}

#[derive(Clone, Copy, Debug, PartialEq)]
enum Unary {
    Neg,
    Sqrt,
    Log2,
    Exp2,
    Exp,
    Ln,
    Acos,
    Abs,
    /// Lane by lane with the standard library.
    Scalar(LaneFunction),
}

/// A function the columns compute lane by lane.
#[derive(Clone, Copy, Debug, PartialEq)]
enum LaneFunction {
    Cos,
    Sin,
    Floor,
    Ceil,
}

impl LaneFunction {
    fn get(self) -> fn(f32) -> f32 {
        match self {
            LaneFunction::Cos => f32::cos,
            LaneFunction::Sin => f32::sin,
            LaneFunction::Floor => f32::floor,
            LaneFunction::Ceil => f32::ceil,
        }
    }
}

#[derive(Clone, Copy, Debug, PartialEq)]
enum Binary {
    Add,
    Sub,
    Mul,
    Div,
    Min,
    Max,
    Pow,
}

/// A tape compiled to column operations.
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct Plan {
    scalars: Vec<Scalar>,
    steps: Vec<Step>,
    registers: usize,
    result: Source,
}

impl Plan {
    /// Compiles `tape` (the formula's varying part; its `t` is register 0).
    pub(crate) fn new(tape: &[Op]) -> Self {
        let mut uses = vec![0usize; tape.len()];
        let mut last_use = vec![0usize; tape.len()];
        for (index, op) in tape.iter().enumerate() {
            for operand in op.operands() {
                uses[operand] += 1;
                last_use[operand] = index;
            }
        }
        let mut scalars = Vec::new();
        let mut source: Vec<Option<Source>> = vec![None; tape.len()];
        let mut free: Vec<usize> = Vec::new();
        let mut registers = 1;
        let mut steps = Vec::new();
        // A multiply read only by the add that follows it is fused into that add.
        let fused_into_add = |index: usize| {
            matches!(tape[index], Op::Mul(..))
                && uses[index] == 1
                && matches!(tape[last_use[index]], Op::Add(a, b) if a == index || b == index)
        };
        for (index, &op) in tape.iter().enumerate() {
            let scalar = match op {
                Op::Slot(s) => Some(Scalar::Slot(s)),
                Op::Const(c) => Some(Scalar::Constant(c)),
                _ => None,
            };
            if let Some(scalar) = scalar {
                source[index] = Some(Source::Scalar(scalars.len()));
                scalars.push(scalar);
                continue;
            }
            if op == Op::T {
                source[index] = Some(Source::Register(0));
                continue;
            }
            if fused_into_add(index) {
                continue;
            }
            let at = |i: usize| source[i].unwrap_or(Source::Scalar(usize::MAX));
            // Operands whose last reader this is give their registers back first, so that
            // the result may take one of them (each lane is read before it is written).
            let release = |i: usize, reader: usize, free: &mut Vec<usize>| {
                if last_use[i] == reader && !fused_into_add(i) {
                    if let Some(Source::Register(r)) = source[i] {
                        if r != 0 && !free.contains(&r) {
                            free.push(r);
                        }
                    }
                }
            };
            let operands = op.operands();
            let mut fused = None;
            if let Op::Add(a, b) = op {
                if fused_into_add(a) || fused_into_add(b) {
                    let (product, addend) = if fused_into_add(a) { (a, b) } else { (b, a) };
                    let Op::Mul(x, y) = tape[product] else {
                        unreachable!("fused_into_add holds multiplies")
                    };
                    for i in [x, y] {
                        release(i, product, &mut free);
                    }
                    release(addend, index, &mut free);
                    fused = Some((at(x), at(y), at(addend)));
                }
            }
            if fused.is_none() {
                for &i in &operands {
                    release(i, index, &mut free);
                }
            }
            let out = free.pop().unwrap_or_else(|| {
                registers += 1;
                registers - 1
            });
            let step = match (fused, op) {
                (Some((x, y, addend)), _) => Step::Fma(x, y, addend, out),
                (None, Op::Powi(a, k)) => Step::Powi(at(a), k, out),
                (
                    None,
                    Op::SelectLess {
                        a,
                        b,
                        then,
                        otherwise,
                    },
                ) => Step::SelectLess([at(a), at(b), at(then), at(otherwise)], out),
                (None, op) => match (unary(op), binary(op)) {
                    (Some(u), _) => Step::Unary(u, at(operands[0]), out),
                    (_, Some(b)) => Step::Binary(b, at(operands[0]), at(operands[1]), out),
                    _ => unreachable!("every operation of a tape is a step: {op:?}"),
                },
            };
            steps.push(step);
            source[index] = Some(Source::Register(out));
        }
        let result = source[tape.len() - 1].unwrap_or(Source::Register(0));
        Self {
            scalars,
            steps,
            registers,
            result,
        }
    }

    /// The scalars to splat, in order.
    pub(crate) fn scalars(&self) -> &[Scalar] {
        &self.scalars
    }

    /// The instructions one vector costs in the column operations (the loads and stores
    /// between columns aside), plus the shared rules.
    pub(crate) fn instructions(&self) -> Instructions {
        let rules = Instructions::of(&[(Class::MinMax, 4), (Class::Compare, 1), (Class::Logic, 1)]);
        self.steps.iter().fold(rules, |total, step| {
            total.and(match *step {
                Step::Fma(..) => Instructions::of(&[(Class::Fma, 1)]),
                Step::Powi(_, k, _) => {
                    let bits = 32 - k.unsigned_abs().leading_zeros();
                    let multiplies = bits.saturating_sub(1) + k.unsigned_abs().count_ones() - 1;
                    let inverse = u32::from(k < 0);
                    Instructions::of(&[(Class::Mul, multiplies), (Class::Div, inverse)])
                }
                Step::SelectLess(..) => Instructions::of(&[(Class::Compare, 1), (Class::Blend, 1)]),
                Step::Binary(b, ..) => match b {
                    Binary::Add | Binary::Sub => Instructions::of(&[(Class::Add, 1)]),
                    Binary::Mul => Instructions::of(&[(Class::Mul, 1)]),
                    Binary::Div => Instructions::of(&[(Class::Div, 1)]),
                    Binary::Min | Binary::Max => Instructions::of(&[(Class::MinMax, 1)]),
                    Binary::Pow => math::LOG2.and(math::EXP2).plus(Class::Mul, 1),
                },
                Step::Unary(u, ..) => match u {
                    Unary::Neg => Instructions::of(&[(Class::Mul, 1)]),
                    Unary::Abs => Instructions::of(&[(Class::Mul, 1), (Class::MinMax, 1)]),
                    Unary::Sqrt => Instructions::of(&[(Class::Sqrt, 1)]),
                    Unary::Log2 => math::LOG2,
                    Unary::Exp2 => math::EXP2,
                    Unary::Exp => math::EXP2.plus(Class::Mul, 1),
                    Unary::Ln => math::LOG2.plus(Class::Mul, 1),
                    Unary::Acos => math::ACOS,
                    // Lane by lane: a call per lane, counted as one division's worth.
                    Unary::Scalar(_) => Instructions::of(&[(Class::Div, 8)]),
                },
            })
        })
    }

    /// The formula at every cosine of `ts` into `out` (`scalars` the splatted values, in
    /// [`Plan::scalars`]' order), with the shared rules: `t` clamped to `[0, 1]`, the value
    /// clamped to `[0, 1]` (NaN to 0), and 0 where `t <= 0` or NaN.
    #[inline(always)]
    pub(crate) fn run<V: Lanes>(&self, lanes: V, scalars: &[f32], ts: &[f32], out: &mut [f32]) {
        let width = V::WIDTH;
        let block = BLOCK_VECTORS * width;
        let splats = scalars.len();
        let mut file = vec![0.0_f32; (splats + self.registers) * block];
        for (s, &value) in scalars.iter().enumerate() {
            file[s * block..(s + 1) * block].fill(value);
        }
        let base = splats * block;
        let column = |source: Source| match source {
            Source::Register(r) => base + r * block,
            Source::Scalar(s) => s * block,
        };
        let (zero, one) = (lanes.splat(0.0), lanes.splat(1.0));
        let mut padded = vec![0.0_f32; block];
        for (t_block, out_block) in ts.chunks(block).zip(out.chunks_mut(block)) {
            let count = t_block.len();
            padded[..count].copy_from_slice(t_block);
            padded[count..].fill(1.0);
            for (i, t) in padded.chunks_exact(width).enumerate() {
                let clamped = one.min(lanes.load(t)).max(zero);
                clamped.store(&mut file[base + i * width..base + (i + 1) * width]);
            }
            for &step in &self.steps {
                run_step(lanes, step, &mut file, &column, block);
            }
            let result = column(self.result);
            for i in 0..BLOCK_VECTORS {
                let t = lanes.load(&padded[i * width..(i + 1) * width]);
                let value = lanes.load(&file[result + i * width..result + (i + 1) * width]);
                let value = value.max(zero).min(one).keep(t.gt(zero));
                value.store(&mut padded[i * width..(i + 1) * width]);
            }
            out_block.copy_from_slice(&padded[..count]);
        }
    }
}

fn unary(op: Op) -> Option<Unary> {
    Some(match op {
        Op::Neg(_) => Unary::Neg,
        Op::Sqrt(_) => Unary::Sqrt,
        Op::Log2(_) => Unary::Log2,
        Op::Exp2(_) => Unary::Exp2,
        Op::Exp(_) => Unary::Exp,
        Op::Ln(_) => Unary::Ln,
        Op::Acos(_) => Unary::Acos,
        Op::Abs(_) => Unary::Abs,
        Op::Cos(_) => Unary::Scalar(LaneFunction::Cos),
        Op::Sin(_) => Unary::Scalar(LaneFunction::Sin),
        Op::Floor(_) => Unary::Scalar(LaneFunction::Floor),
        Op::Ceil(_) => Unary::Scalar(LaneFunction::Ceil),
        _ => return None,
    })
}

fn binary(op: Op) -> Option<Binary> {
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

/// `f` over every vector of the block: reads the operand columns, writes column `out`.
#[inline(always)]
fn columns<V: Lanes, const N: usize>(
    lanes: V,
    file: &mut [f32],
    operands: [usize; N],
    out: usize,
    block: usize,
    f: impl Fn([V; N]) -> V,
) {
    let width = V::WIDTH;
    for i in 0..block / width {
        let at = i * width;
        let mut values = [lanes; N];
        for (value, &column) in values.iter_mut().zip(&operands) {
            *value = lanes.load(&file[column + at..column + at + width]);
        }
        f(values).store(&mut file[out + at..out + at + width]);
    }
}

/// A lane-by-lane pass with the standard library, for what the polynomials do not cover.
fn lane_by_lane(file: &mut [f32], operand: usize, out: usize, block: usize, f: fn(f32) -> f32) {
    for i in 0..block {
        file[out + i] = f(file[operand + i]);
    }
}

/// Whether every lane of the block's column lies where `inside` holds.
#[inline(always)]
fn all_inside<V: Lanes>(
    lanes: V,
    file: &[f32],
    column: usize,
    block: usize,
    inside: impl Fn(V) -> V,
) -> bool {
    let width = V::WIDTH;
    let mut worst = lanes.splat(1.0);
    for i in 0..block / width {
        let x = lanes.load(&file[column + i * width..column + (i + 1) * width]);
        worst = worst.min(inside(x));
    }
    let mut lanes_out = [0.0_f32; 64];
    worst.store(&mut lanes_out[..width]);
    lanes_out[..width].iter().all(|&v| v == 1.0)
}

#[inline(always)]
fn run_step<V: Lanes>(
    lanes: V,
    step: Step,
    file: &mut [f32],
    column: &impl Fn(Source) -> usize,
    block: usize,
) {
    let (zero, one) = (lanes.splat(0.0), lanes.splat(1.0));
    let out = |r: usize| column(Source::Register(r));
    // 1 where `low < x < high` (NaN fails both), else 0.
    let between = move |low: f32, high: f32| {
        move |x: V| {
            one.select(x.gt(lanes.splat(low)), zero)
                .select(x.lt(lanes.splat(high)), zero)
        }
    };
    match step {
        Step::Fma(a, b, c, r) => columns(
            lanes,
            file,
            [column(a), column(b), column(c)],
            out(r),
            block,
            |[a, b, c]| a.mul_add(b, c),
        ),
        Step::Powi(a, k, r) => columns(lanes, file, [column(a)], out(r), block, |[x]| powi(x, k)),
        Step::SelectLess([a, b, then, otherwise], r) => columns(
            lanes,
            file,
            [column(a), column(b), column(then), column(otherwise)],
            out(r),
            block,
            |[a, b, then, otherwise]| then.select(a.lt(b), otherwise),
        ),
        Step::Binary(op, a, b, r) => {
            let operands = [column(a), column(b)];
            match op {
                Binary::Add => columns(lanes, file, operands, out(r), block, |[a, b]| a + b),
                Binary::Sub => columns(lanes, file, operands, out(r), block, |[a, b]| a - b),
                Binary::Mul => columns(lanes, file, operands, out(r), block, |[a, b]| a * b),
                Binary::Div => columns(lanes, file, operands, out(r), block, |[a, b]| a / b),
                Binary::Min => columns(lanes, file, operands, out(r), block, |[a, b]| a.min(b)),
                Binary::Max => columns(lanes, file, operands, out(r), block, |[a, b]| a.max(b)),
                Binary::Pow => {
                    // exp2(b log2 a), each half checked against its polynomial's range.
                    let log = out(r);
                    if all_inside(
                        lanes,
                        file,
                        operands[0],
                        block,
                        between(f32::MIN_POSITIVE, f32::MAX),
                    ) {
                        columns(lanes, file, [operands[0]], log, block, |[a]| math::log2(a));
                    } else {
                        lane_by_lane(file, operands[0], log, block, f32::log2);
                    }
                    columns(lanes, file, [log, operands[1]], log, block, |[l, b]| l * b);
                    exp2_column(lanes, file, log, log, block, 1.0);
                }
            }
        }
        Step::Unary(op, a, r) => {
            let (a, r) = (column(a), out(r));
            match op {
                Unary::Neg => columns(lanes, file, [a], r, block, |[x]| x * lanes.splat(-1.0)),
                Unary::Abs => columns(lanes, file, [a], r, block, |[x]| {
                    x.max(x * lanes.splat(-1.0))
                }),
                Unary::Sqrt => columns(lanes, file, [a], r, block, |[x]| x.sqrt()),
                Unary::Log2 | Unary::Ln => {
                    if all_inside(lanes, file, a, block, between(f32::MIN_POSITIVE, f32::MAX)) {
                        columns(lanes, file, [a], r, block, |[x]| math::log2(x));
                    } else {
                        lane_by_lane(file, a, r, block, f32::log2);
                    }
                    if op == Unary::Ln {
                        let ln2 = lanes.splat(core::f32::consts::LN_2);
                        columns(lanes, file, [r], r, block, |[x]| x * ln2);
                    }
                }
                Unary::Exp2 => exp2_column(lanes, file, a, r, block, 1.0),
                Unary::Exp => exp2_column(lanes, file, a, r, block, core::f32::consts::LOG2_E),
                Unary::Acos => {
                    if all_inside(
                        lanes,
                        file,
                        a,
                        block,
                        between(-f32::MIN_POSITIVE, 1.0 + f32::EPSILON),
                    ) {
                        columns(lanes, file, [a], r, block, |[x]| math::acos(x));
                    } else {
                        lane_by_lane(file, a, r, block, f32::acos);
                    }
                }
                Unary::Scalar(f) => lane_by_lane(file, a, r, block, f.get()),
            }
        }
    }
}

/// `exp2(scale x)`: the polynomial on `[-127, 0]`, the standard library elsewhere.
#[inline(always)]
fn exp2_column<V: Lanes>(lanes: V, file: &mut [f32], a: usize, r: usize, block: usize, scale: f32) {
    let s = lanes.splat(scale);
    let (zero, one) = (lanes.splat(0.0), lanes.splat(1.0));
    let low = lanes.splat(-f32::MAX);
    let high = lanes.splat(f32::MIN_POSITIVE);
    let inside = |x: V| {
        let y = x * s;
        one.select(y.gt(low), zero).select(y.lt(high), zero)
    };
    if all_inside(lanes, file, a, block, inside) {
        columns(lanes, file, [a], r, block, |[x]| math::exp2(x * s));
    } else {
        for i in 0..block {
            file[r + i] = (file[a + i] * scale).exp2();
        }
    }
}

/// `x^k` in [`super::program::powi`]'s order (so `x^16` is the four squarings `cosquad`'s
/// kernel computes).
#[inline(always)]
fn powi<V: Lanes>(x: V, k: i32) -> V {
    super::program::by_squaring(x, k, x.splat(1.0), |a, b| a * b, |a| a * a, |a, b| a / b)
}
