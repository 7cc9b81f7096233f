//! An [`Expression`] written as straight-line code in a C-like language.
//!
//! Every target writes the same statements: a node used more than once (or a select, whose
//! operands a reader wants named) becomes a local; a node used once is written in place,
//! fully parenthesised, so no target's precedence rules matter. A [`Dialect`] says how each
//! operation is spelled; constants are `f32`, as every target computes in `f32`.

use core::fmt::Write as _;

use specula::expression::{Expression, Node};

/// How one language spells the operations of an expression.
pub trait Dialect {
    /// A local definition of `name` as `value`, one line.
    fn local(&self, name: &str, value: &str) -> String;
    /// A function call (`log2`, `exp2`, `sqrt`, `acos`, `cos`, `pow`, `max`, `min`, `ceil`,
    /// and the bit-trick helpers `specula_shift`, `specula_mantissa`, `specula_exponent`,
    /// `specula_bits_exp2` for targets that keep them).
    fn call(&self, function: &str, arguments: &[String]) -> String {
        format!("{function}({})", arguments.join(", "))
    }
    /// `ln(1 + x)`: `log(1 + x)` unless the language has `log1p`.
    fn log1p(&self, x: &str) -> String {
        self.call("log", &[format!("(1.0 + {x})")])
    }
    /// `e^x - 1`: `exp(x) - 1` unless the language has `expm1`.
    fn expm1(&self, x: &str) -> String {
        format!("({} - 1.0)", self.call("exp", &[x.to_owned()]))
    }
    /// `a / b`, fully parenthesised.
    fn divide(&self, a: &str, b: &str) -> String {
        format!("({a} / {b})")
    }
    /// `then` where `a < b`, else `otherwise`.
    fn select_less(&self, a: &str, b: &str, then: &str, otherwise: &str) -> String;
    /// A constant, computed by the model in `f64`; targets in `f32` round it.
    fn constant(&self, value: f64) -> String {
        float_literal(value as f32)
    }
}

/// `value` in the shortest form that reads back as the same `f32`, always with a `.` or an
/// exponent, so every target reads it as a float.
#[must_use]
pub fn float_literal(value: f32) -> String {
    let text = format!("{value:?}");
    if text.contains(['.', 'e', 'E']) || !value.is_finite() {
        text
    } else {
        format!("{text}.0")
    }
}

/// How a named parameter ([`Node::Parameter`]) is written.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Parameters {
    /// As its value for the recorded `n` (a target with constants baked in).
    Baked,
    /// By its name (a target that takes it, or `n`, as an input).
    Named,
}

/// The statements computing `expression` of the variable `input`, and the expression of its
/// result.
#[must_use]
pub fn straight_line(
    expression: &Expression,
    input: &str,
    dialect: &dyn Dialect,
    parameters: Parameters,
) -> (Vec<String>, String) {
    straight_line_named(expression, input, dialect, parameters, "v")
}

/// [`straight_line`] with the locals named `prefix` and the node's index, so that two
/// expressions written into one scope keep theirs apart.
#[must_use]
pub fn straight_line_named(
    expression: &Expression,
    input: &str,
    dialect: &dyn Dialect,
    parameters: Parameters,
    prefix: &str,
) -> (Vec<String>, String) {
    let nodes = expression.nodes();
    let mut uses = expression.uses();
    // A square writes its operand twice.
    for node in nodes {
        if let Node::Square(a) = node {
            uses[*a] += 1;
        }
    }
    let mut text: Vec<String> = Vec::with_capacity(nodes.len());
    let mut statements = Vec::new();
    for (index, node) in nodes.iter().enumerate() {
        let at = |i: usize| text[i].clone();
        let call = |function: &str, operands: &[usize]| {
            dialect.call(
                function,
                &operands.iter().map(|&i| at(i)).collect::<Vec<_>>(),
            )
        };
        let written = match *node {
            Node::Input => input.to_owned(),
            Node::Constant(value) => dialect.constant(value),
            Node::Parameter { value, .. } if parameters == Parameters::Baked => {
                dialect.constant(value)
            }
            Node::Parameter { name, .. } => name.to_owned(),
            Node::Add(a, b) => format!("({} + {})", at(a), at(b)),
            Node::Sub(a, b) => format!("({} - {})", at(a), at(b)),
            Node::Mul(a, b) => format!("({} * {})", at(a), at(b)),
            Node::Div(a, b) => dialect.divide(&at(a), &at(b)),
            // `-x`, parenthesised where x is itself a negative literal.
            Node::Neg(a) if at(a).starts_with('-') => format!("(-({}))", at(a)),
            Node::Neg(a) => format!("(-{})", at(a)),
            Node::Square(a) => format!("({} * {})", at(a), at(a)),
            Node::Sqrt(a) => call("sqrt", &[a]),
            Node::Log2(a) => call("log2", &[a]),
            Node::Exp2(a) => call("exp2", &[a]),
            Node::Acos(a) => call("acos", &[a]),
            Node::Cos(a) => call("cos", &[a]),
            Node::Sin(a) => call("sin", &[a]),
            Node::Exp(a) => call("exp", &[a]),
            Node::Ln1p(a) => dialect.log1p(&at(a)),
            Node::ExpM1(a) => dialect.expm1(&at(a)),
            Node::Pow(a, b) => call("pow", &[a, b]),
            Node::Max(a, b) => call("max", &[a, b]),
            Node::Min(a, b) => call("min", &[a, b]),
            Node::Ceil(a) => call("ceil", &[a]),
            Node::Shift(a, k) => call("specula_shift", &[a, k]),
            Node::Mantissa(a) => call("specula_mantissa", &[a]),
            Node::Exponent(a) => call("specula_exponent", &[a]),
            Node::BitsExp2(a) => call("specula_bits_exp2", &[a]),
            Node::SelectLess {
                a,
                b,
                then,
                otherwise,
            } => dialect.select_less(&at(a), &at(b), &at(then), &at(otherwise)),
        };
        let leaf = matches!(
            node,
            Node::Input | Node::Constant(_) | Node::Parameter { .. }
        );
        let shared = uses[index] > 1 || matches!(node, Node::SelectLess { .. });
        if !leaf && shared && index + 1 < nodes.len() {
            let name = format!("{prefix}{index}");
            statements.push(dialect.local(&name, &written));
            text.push(name);
        } else {
            text.push(written);
        }
    }
    let result = text.pop().unwrap_or_else(|| input.to_owned());
    (statements, strip_outer_parentheses(result))
}

/// `(a + b)` as `a + b` where the outer pair encloses the whole text.
fn strip_outer_parentheses(text: String) -> String {
    let bytes = text.as_bytes();
    if bytes.first() != Some(&b'(') || bytes.last() != Some(&b')') {
        return text;
    }
    let mut depth = 0;
    for (i, byte) in bytes.iter().enumerate() {
        match byte {
            b'(' => depth += 1,
            b')' => {
                depth -= 1;
                if depth == 0 && i + 1 < bytes.len() {
                    return text;
                }
            }
            _ => {}
        }
    }
    text[1..text.len() - 1].to_owned()
}

/// The statements and the result as a function body: each statement on its own line with
/// `indent`, then `return_keyword result terminator`.
#[must_use]
pub fn body(
    statements: &[String],
    result: &str,
    indent: &str,
    return_line: impl Fn(&str) -> String,
) -> String {
    let mut out = String::new();
    for statement in statements {
        let _ = writeln!(out, "{indent}{statement}");
    }
    let _ = writeln!(out, "{indent}{}", return_line(result));
    out
}

/// `[low, high]` as a reader wants it: `[1, 1000]`, or `[64, 128)` where the range stops
/// just below a power of two.
#[must_use]
pub fn describe_range([low, high]: [f64; 2]) -> String {
    if high.fract() == 0.0 {
        format!("[{low}, {high}]")
    } else {
        format!("[{low}, {})", high.ceil())
    }
}

/// A lobe's name in the identifier alphabet of every target: `specula_` and its id with
/// `-` and `:` as `_` (`specula_cosquad`, `specula_sg_karis`).
#[must_use]
pub fn identifier(lobe: &specula::Lobe) -> String {
    format!(
        "specula_{}",
        lobe.kind()
            .to_string()
            .replace(|c: char| !c.is_ascii_alphanumeric(), "_")
    )
}

/// What a target with inputs (a node's sockets, a plugin's properties) exposes for a lobe.
#[derive(Clone, Debug, PartialEq)]
pub struct Inputs {
    /// `n` as an input, kept within `[low, high]` (the lobe's structural range), when every
    /// parameter follows from it; `None` for a fitted lobe, whose constants are inputs.
    pub exponent: Option<[f64; 2]>,
    /// The parameters given as inputs, with their values for the exported `n` as defaults.
    pub fitted: Vec<(&'static str, f64)>,
    /// The parameters computed from `n`, other than `n` itself, with their preparation.
    pub derived: Vec<(&'static str, Expression)>,
    /// Every parameter's name, in the order the lobe function takes them.
    pub order: Vec<&'static str>,
}

impl Inputs {
    /// The inputs of `lobe`.
    #[must_use]
    pub fn of(lobe: &specula::Lobe) -> Self {
        let parameters = lobe.parameters();
        let order = parameters.iter().map(|p| p.name).collect();
        if parameters.iter().all(|p| p.preparation.is_some()) {
            Self {
                exponent: Some(lobe.structural_range()),
                fitted: Vec::new(),
                derived: parameters
                    .into_iter()
                    .filter(|p| p.name != "n")
                    .filter_map(|p| p.preparation.map(|e| (p.name, e)))
                    .collect(),
                order,
            }
        } else {
            Self {
                exponent: None,
                fitted: parameters.iter().map(|p| (p.name, p.value)).collect(),
                derived: Vec::new(),
                order,
            }
        }
    }

    /// The local definitions of the derived parameters from the variable `exponent`.
    #[must_use]
    pub fn preparation(&self, exponent: &str, dialect: &dyn Dialect) -> Vec<String> {
        let mut lines = Vec::new();
        for (name, expression) in &self.derived {
            let (statements, result) = straight_line_named(
                expression,
                exponent,
                dialect,
                Parameters::Baked,
                &format!("{name}_v"),
            );
            lines.extend(statements);
            lines.push(dialect.local(name, &result));
        }
        lines
    }

    /// The arguments of a call to the lobe function: each parameter's variable, with `n`
    /// read from `exponent`.
    #[must_use]
    pub fn arguments(&self, exponent: &str) -> Vec<String> {
        self.order
            .iter()
            .map(|name| {
                if *name == "n" {
                    exponent.to_owned()
                } else {
                    (*name).to_owned()
                }
            })
            .collect()
    }
}
