//! The operation a compiled formula is made of: the compiler (`compile.rs`) emits it, the
//! tapes (`program.rs`) and the batch plans (`batch/`) run it. It has a module of its own so
//! that each of them depends on it rather than on one another.

/// One operation; operands are indices of earlier operations.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) enum Op {
    T,
    N,
    Param(usize),
    Const(f64),
    /// A per-material constant, by its index in `Compiled::slots` (`compile.rs`; only in
    /// tapes).
    Slot(usize),
    Add(usize, usize),
    Sub(usize, usize),
    Mul(usize, usize),
    Div(usize, usize),
    Neg(usize),
    Sqrt(usize),
    Log2(usize),
    Exp2(usize),
    Exp(usize),
    Ln(usize),
    Acos(usize),
    Cos(usize),
    Sin(usize),
    Abs(usize),
    Floor(usize),
    Ceil(usize),
    Pow(usize, usize),
    /// An integer power by multiplications (squarings for the powers of two).
    Powi(usize, i32),
    Min(usize, usize),
    Max(usize, usize),
    /// `then` where `a < b`, else `otherwise` (NaN included).
    SelectLess {
        a: usize,
        b: usize,
        then: usize,
        otherwise: usize,
    },
}

impl Op {
    pub(crate) fn operands(self) -> Vec<usize> {
        match self {
            Op::T | Op::N | Op::Param(_) | Op::Const(_) | Op::Slot(_) => Vec::new(),
            Op::Neg(a)
            | Op::Sqrt(a)
            | Op::Log2(a)
            | Op::Exp2(a)
            | Op::Exp(a)
            | Op::Ln(a)
            | Op::Acos(a)
            | Op::Cos(a)
            | Op::Sin(a)
            | Op::Abs(a)
            | Op::Floor(a)
            | Op::Ceil(a)
            | Op::Powi(a, _) => vec![a],
            Op::Add(a, b)
            | Op::Sub(a, b)
            | Op::Mul(a, b)
            | Op::Div(a, b)
            | Op::Pow(a, b)
            | Op::Min(a, b)
            | Op::Max(a, b) => vec![a, b],
            Op::SelectLess {
                a,
                b,
                then,
                otherwise,
            } => vec![a, b, then, otherwise],
        }
    }
}
