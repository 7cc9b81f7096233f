//! From a syntax tree to a program: names resolved, constants folded, and every operation
//! marked as *uniform* (a function of `n` and the parameters alone: computed once per
//! material) or *varying* (a function of `t`).

use super::op::Op;
use super::syntax::{Ast, AstKind, BinaryOp, Comparison, Program as Syntax};
use super::FormulaError;

/// The most per-material constants (`n`, parameters, `let`s and folded sub-expressions that
/// the formula reads): what a prepared lobe stores inline.
pub const MAX_SLOTS: usize = 16;

/// The largest integer power written as multiplications (`t^16` is four squarings, as
/// `cosquad` computes it); larger ones are `pow`.
const MAX_MULTIPLIED_POWER: f64 = 64.0;

/// A per-material constant the varying part reads: its name and the operation computing it.
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct Slot {
    pub name: String,
    pub op: usize,
}

/// A compiled formula (and its tail, when given).
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct Compiled {
    pub ops: Vec<Op>,
    pub varying: Vec<bool>,
    pub result: usize,
    pub tail: Option<usize>,
    pub slots: Vec<Slot>,
}

/// Every function, with its arguments, for errors and did-you-mean.
pub const FUNCTIONS: [(&str, &str); 18] = [
    ("pow", "pow(x, y)"),
    ("exp", "exp(x)"),
    ("exp2", "exp2(x)"),
    ("log", "log(x)"),
    ("log2", "log2(x)"),
    ("sqrt", "sqrt(x)"),
    ("acos", "acos(x)"),
    ("cos", "cos(x)"),
    ("sin", "sin(x)"),
    ("abs", "abs(x)"),
    ("floor", "floor(x)"),
    ("ceil", "ceil(x)"),
    ("min", "min(x, y)"),
    ("max", "max(x, y)"),
    ("clamp", "clamp(x, low, high)"),
    ("select", "select(a < b, then, otherwise)"),
    ("if", "if(a < b, then, otherwise)"),
    ("mix", "mix(x, y, s)"),
];

/// Names a user may not bind: the formula's own. (The generated languages' words need no
/// list: a per-material constant is written as `c_` and its name in every target, which no
/// keyword of WGSL, GLSL, HLSL, MSL, OSL or Python begins with.)
const RESERVED: [&str; 5] = ["t", "n", "pi", "e", "let"];

/// Whether `name` may be bound by a `let` or declared as a parameter, and why not.
pub(crate) fn check_user_name(name: &str) -> Result<(), String> {
    let bytes = name.as_bytes();
    // The generators name a constant's intermediate values `<constant>_v<digits>`.
    let generated_suffix = name
        .match_indices("_v")
        .any(|(at, _)| bytes.get(at + 2).is_some_and(u8::is_ascii_digit));
    if name.is_empty()
        || name.len() > 32
        || !bytes[0].is_ascii_lowercase()
        || !bytes
            .iter()
            .all(|b| b.is_ascii_lowercase() || b.is_ascii_digit() || *b == b'_')
    {
        Err(format!(
            "'{}' is not a valid name: a lowercase letter, then up to 31 lowercase letters, \
             digits or '_'",
            crate::excerpt(name)
        ))
    } else if RESERVED.contains(&name)
        || FUNCTIONS.iter().any(|(f, _)| *f == name)
        || generated_suffix
    {
        Err(format!(
            "'{name}' is reserved (t, n, pi, e, let, the functions, and names with _v and a \
             digit, which the generated code uses)"
        ))
    } else {
        Ok(())
    }
}

struct Compiler<'a> {
    ops: Vec<Op>,
    varying: Vec<bool>,
    parameters: &'a [String],
    lets: Vec<(String, usize)>,
}

impl Compiler<'_> {
    fn push(&mut self, op: Op) -> usize {
        if matches!(op, Op::T | Op::N | Op::Param(_)) {
            if let Some(existing) = self.ops.iter().position(|o| *o == op) {
                return existing;
            }
        }
        let operands = op.operands();
        let varying = matches!(op, Op::T) || operands.iter().any(|&i| self.varying[i]);
        let constant = !op.operands().is_empty()
            && operands
                .iter()
                .all(|&i| matches!(self.ops[i], Op::Const(_)));
        let op = if constant {
            Op::Const(super::program::fold(op, |i| match self.ops[i] {
                Op::Const(c) => c,
                _ => unreachable!("checked constant"),
            }))
        } else {
            op
        };
        self.ops.push(op);
        self.varying.push(varying);
        self.ops.len() - 1
    }

    fn names_in_scope(&self) -> Vec<&str> {
        let mut names = vec!["t", "n", "pi", "e"];
        names.extend(self.parameters.iter().map(String::as_str));
        names.extend(self.lets.iter().map(|(name, _)| name.as_str()));
        names
    }

    fn name(&mut self, at: usize, name: &str) -> Result<usize, FormulaError> {
        if let Some((_, op)) = self.lets.iter().rev().find(|(bound, _)| bound == name) {
            return Ok(*op);
        }
        if let Some(index) = self.parameters.iter().position(|p| p == name) {
            return Ok(self.push(Op::Param(index)));
        }
        let op = match name {
            "t" => Op::T,
            "n" => Op::N,
            "pi" => Op::Const(core::f64::consts::PI),
            "e" => Op::Const(core::f64::consts::E),
            _ => {
                let hint = if FUNCTIONS.iter().any(|(f, _)| *f == name) {
                    format!("; '{name}' is a function: write {name}(...)")
                } else {
                    crate::did_you_mean(name, self.names_in_scope())
                };
                return Err(FormulaError::at(
                    at,
                    format!(
                        "unknown name '{}'{hint} (names here: {})",
                        crate::excerpt(name),
                        self.names_in_scope().join(", ")
                    ),
                ));
            }
        };
        Ok(self.push(op))
    }

    fn expression(&mut self, ast: &Ast) -> Result<usize, FormulaError> {
        Ok(match &ast.kind {
            AstKind::Number(x) => self.push(Op::Const(*x)),
            AstKind::Name(name) => self.name(ast.at, name)?,
            AstKind::Neg(a) => {
                let a = self.expression(a)?;
                self.push(Op::Neg(a))
            }
            AstKind::Binary(op, a, b) => {
                let (a, b) = (self.expression(a)?, self.expression(b)?);
                match op {
                    BinaryOp::Add => self.push(Op::Add(a, b)),
                    BinaryOp::Sub => self.push(Op::Sub(a, b)),
                    BinaryOp::Mul => self.push(Op::Mul(a, b)),
                    BinaryOp::Div => self.push(Op::Div(a, b)),
                    BinaryOp::Pow => self.power(a, b),
                }
            }
            AstKind::Compare(..) => {
                return Err(FormulaError::at(
                    ast.at,
                    "a comparison is only valid as the condition of select(...) or if(...)"
                        .to_owned(),
                ))
            }
            AstKind::Call { name, args } => self.call(ast.at, name, args)?,
        })
    }

    fn power(&mut self, base: usize, exponent: usize) -> usize {
        match self.ops[exponent] {
            Op::Const(k) if k.fract() == 0.0 && k.abs() <= MAX_MULTIPLIED_POWER => {
                self.push(Op::Powi(base, k as i32))
            }
            _ => self.push(Op::Pow(base, exponent)),
        }
    }

    fn call(&mut self, at: usize, name: &str, args: &[Ast]) -> Result<usize, FormulaError> {
        let Some((_, usage)) = FUNCTIONS.iter().find(|(f, _)| *f == name) else {
            let hint = crate::did_you_mean(name, FUNCTIONS.iter().map(|(f, _)| *f));
            return Err(FormulaError::at(
                at,
                format!(
                    "unknown function '{}'{hint} (functions: {})",
                    crate::excerpt(name),
                    FUNCTIONS.map(|(f, _)| f).join(", ")
                ),
            ));
        };
        let arity = usage.matches(',').count() + 1;
        if args.len() != arity {
            return Err(FormulaError::at(
                at,
                format!(
                    "{name} takes {arity} argument{}, given {}: {usage}",
                    if arity == 1 { "" } else { "s" },
                    args.len()
                ),
            ));
        }
        if let "select" | "if" = name {
            let AstKind::Compare(comparison, a, b) = &args[0].kind else {
                return Err(FormulaError::at(
                    args[0].at,
                    format!("the condition of {name} must be a comparison: {usage}"),
                ));
            };
            let (a, b) = (self.expression(a)?, self.expression(b)?);
            let (then, otherwise) = (self.expression(&args[1])?, self.expression(&args[2])?);
            // Every comparison as `x < y` with the branches swapped where needed; NaN takes
            // the branch that `<` and `>` refuse and `<=` and `>=` accept.
            let select = |a, b, then, otherwise| Op::SelectLess {
                a,
                b,
                then,
                otherwise,
            };
            return Ok(self.push(match comparison {
                Comparison::Less => select(a, b, then, otherwise),
                Comparison::Greater => select(b, a, then, otherwise),
                Comparison::GreaterEqual => select(a, b, otherwise, then),
                Comparison::LessEqual => select(b, a, otherwise, then),
            }));
        }
        let mut values = Vec::with_capacity(args.len());
        for arg in args {
            values.push(self.expression(arg)?);
        }
        Ok(match (name, values.as_slice()) {
            ("pow", &[a, b]) => self.power(a, b),
            ("exp", &[a]) => self.push(Op::Exp(a)),
            ("exp2", &[a]) => self.push(Op::Exp2(a)),
            ("log", &[a]) => self.push(Op::Ln(a)),
            ("log2", &[a]) => self.push(Op::Log2(a)),
            ("sqrt", &[a]) => self.push(Op::Sqrt(a)),
            ("acos", &[a]) => self.push(Op::Acos(a)),
            ("cos", &[a]) => self.push(Op::Cos(a)),
            ("sin", &[a]) => self.push(Op::Sin(a)),
            ("abs", &[a]) => self.push(Op::Abs(a)),
            ("floor", &[a]) => self.push(Op::Floor(a)),
            ("ceil", &[a]) => self.push(Op::Ceil(a)),
            ("min", &[a, b]) => self.push(Op::Min(a, b)),
            ("max", &[a, b]) => self.push(Op::Max(a, b)),
            ("clamp", &[x, low, high]) => {
                let above = self.push(Op::Max(x, low));
                self.push(Op::Min(above, high))
            }
            ("mix", &[x, y, s]) => {
                let difference = self.push(Op::Sub(y, x));
                let step = self.push(Op::Mul(difference, s));
                self.push(Op::Add(x, step))
            }
            _ => unreachable!("arity checked against FUNCTIONS"),
        })
    }
}

/// Compiles `formula` (and `tail`, which sees the formula's `let`s) with the declared
/// `parameters`.
pub(crate) fn compile(
    formula: &Syntax,
    tail: Option<&Ast>,
    parameters: &[String],
) -> Result<Compiled, FormulaError> {
    let mut compiler = Compiler {
        ops: Vec::new(),
        varying: Vec::new(),
        parameters,
        lets: Vec::new(),
    };
    for binding in &formula.lets {
        check_user_name(&binding.name).map_err(|message| FormulaError::at(binding.at, message))?;
        if compiler.lets.iter().any(|(name, _)| *name == binding.name)
            || parameters.contains(&binding.name)
        {
            return Err(FormulaError::at(
                binding.at,
                format!("'{}' is already defined", binding.name),
            ));
        }
        let value = compiler.expression(&binding.value)?;
        compiler.lets.push((binding.name.clone(), value));
    }
    let result = compiler.expression(&formula.result)?;
    if !compiler.varying[result] {
        return Err(FormulaError::at(
            formula.result.at,
            "the formula does not depend on t, the cosine".to_owned(),
        ));
    }
    let tail = match tail {
        Some(ast) => {
            let index = compiler
                .expression(ast)
                .map_err(|e| FormulaError { in_tail: true, ..e })?;
            if !compiler.varying[index] {
                return Err(FormulaError {
                    in_tail: true,
                    ..FormulaError::at(ast.at, "the tail does not depend on t".to_owned())
                });
            }
            Some(index)
        }
        None => None,
    };
    let slots = slots(&compiler)?;
    Ok(Compiled {
        ops: compiler.ops,
        varying: compiler.varying,
        result,
        tail,
        slots,
    })
}

/// The uniform operations the varying ones read, each named: `n`, or `c_` and a parameter's
/// or a `let`'s name, or `c_0`, `c_1`, ... for an unnamed sub-expression (the prefix keeps
/// every name clear of every generated language's keywords).
fn slots(compiler: &Compiler) -> Result<Vec<Slot>, FormulaError> {
    let mut slots: Vec<Slot> = Vec::new();
    for (index, op) in compiler.ops.iter().enumerate() {
        if !compiler.varying[index] {
            continue;
        }
        for operand in op.operands() {
            let uniform = !compiler.varying[operand];
            let folded = matches!(compiler.ops[operand], Op::Const(_));
            if uniform && !folded && slots.iter().all(|s| s.op != operand) {
                let name = match compiler.ops[operand] {
                    Op::N => "n".to_owned(),
                    Op::Param(p) => format!("c_{}", compiler.parameters[p]),
                    _ => compiler
                        .lets
                        .iter()
                        .find(|(_, op)| *op == operand)
                        .map_or_else(
                            || format!("c_{}", slots.len()),
                            |(name, _)| format!("c_{name}"),
                        ),
                };
                slots.push(Slot { name, op: operand });
            }
        }
    }
    if slots.len() > MAX_SLOTS {
        return Err(FormulaError::at(
            0,
            format!(
                "the formula reads {} per-material constants (n, parameters, lets and \
                 sub-expressions of n); the limit is {MAX_SLOTS}",
                slots.len()
            ),
        ));
    }
    Ok(slots)
}
