//! Reading a formula's text: tokens, then a syntax tree, within fixed limits.
//!
//! The grammar, loosest binding first:
//!
//! ```text
//! program    = { "let" name "=" expression ";" } expression
//! expression = sum [ ("<" | "<=" | ">" | ">=") sum ]
//! sum        = product { ("+" | "-") product }
//! product    = unary { ("*" | "/") unary }
//! unary      = "-" unary | power
//! power      = atom [ "^" unary ]            (right-associative; -t^2 is -(t^2))
//! atom       = number | name | name "(" expression { "," expression } ")" | "(" expression ")"
//! ```
//!
//! `#` starts a comment to the end of the line. The parser is recursive descent whose depth
//! is counted and bounded ([`MAX_DEPTH`]) before each descent, and the text's length is
//! checked before a single token is read, so neither a 10 MB formula nor 10,000 nested
//! parentheses costs more than a refusal.

use super::FormulaError;

/// The longest formula text, in bytes (a pasted file of 64 KiB is far beyond any lobe).
pub const MAX_SOURCE_BYTES: usize = 64 * 1024;
/// The deepest nesting of the grammar's levels: a parenthesis or a call takes two (the
/// expression inside, and the sign before it), so 64 parentheses fit.
pub const MAX_DEPTH: usize = 128;
/// The most nodes a formula's tree may have.
pub const MAX_NODES: usize = 4096;
/// The most `let` bindings.
pub const MAX_LETS: usize = 64;

/// A position in the text: a byte offset.
pub(crate) type At = usize;

/// A binary operator.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum BinaryOp {
    Add,
    Sub,
    Mul,
    Div,
    Pow,
}

/// A comparison (only a `select`/`if` condition may be one).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Comparison {
    Less,
    LessEqual,
    Greater,
    GreaterEqual,
}

/// A node of the syntax tree, with where it starts.
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct Ast {
    pub at: At,
    pub kind: AstKind,
}

#[derive(Clone, Debug, PartialEq)]
pub(crate) enum AstKind {
    Number(f64),
    Name(String),
    Call { name: String, args: Vec<Ast> },
    Neg(Box<Ast>),
    Binary(BinaryOp, Box<Ast>, Box<Ast>),
    Compare(Comparison, Box<Ast>, Box<Ast>),
}

/// A `let` binding.
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct Let {
    pub at: At,
    pub name: String,
    pub value: Ast,
}

/// A whole program: bindings, then the result.
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct Program {
    pub lets: Vec<Let>,
    pub result: Ast,
}

#[derive(Clone, Debug, PartialEq)]
enum Token {
    Number(f64),
    Name(String),
    Let,
    Symbol(&'static str),
    End,
}

impl Token {
    fn describe(&self) -> String {
        match self {
            Token::Number(x) => format!("the number {x}"),
            Token::Name(name) => format!("'{}'", crate::excerpt(name)),
            Token::Let => "'let'".to_owned(),
            Token::Symbol(s) => format!("'{s}'"),
            Token::End => "the end of the formula".to_owned(),
        }
    }
}

const SYMBOLS: [&str; 14] = [
    "<=", ">=", "<", ">", "+", "-", "*", "/", "^", "(", ")", ",", "=", ";",
];

fn tokens(source: &str) -> Result<Vec<(At, Token)>, FormulaError> {
    let bytes = source.as_bytes();
    let mut out = Vec::new();
    let mut i = 0;
    while i < bytes.len() {
        let c = bytes[i];
        if c.is_ascii_whitespace() {
            i += 1;
        } else if c == b'#' {
            while i < bytes.len() && bytes[i] != b'\n' {
                i += 1;
            }
        } else if c.is_ascii_digit()
            || (c == b'.' && bytes.get(i + 1).is_some_and(u8::is_ascii_digit))
        {
            let start = i;
            while i < bytes.len() && (bytes[i].is_ascii_digit() || bytes[i] == b'.') {
                i += 1;
            }
            if i < bytes.len() && (bytes[i] == b'e' || bytes[i] == b'E') {
                let sign = usize::from(matches!(bytes.get(i + 1), Some(b'+' | b'-')));
                if bytes.get(i + 1 + sign).is_some_and(u8::is_ascii_digit) {
                    i += 1 + sign;
                    while i < bytes.len() && bytes[i].is_ascii_digit() {
                        i += 1;
                    }
                }
            }
            let text = &source[start..i];
            let value: f64 = text.parse().map_err(|_| {
                FormulaError::at(start, format!("'{}' is not a number", crate::excerpt(text)))
            })?;
            if !value.is_finite() {
                return Err(FormulaError::at(
                    start,
                    format!("{text} is too large a number"),
                ));
            }
            out.push((start, Token::Number(value)));
        } else if c.is_ascii_alphabetic() || c == b'_' {
            let start = i;
            while i < bytes.len() && (bytes[i].is_ascii_alphanumeric() || bytes[i] == b'_') {
                i += 1;
            }
            let word = &source[start..i];
            out.push((
                start,
                if word == "let" {
                    Token::Let
                } else {
                    Token::Name(word.to_owned())
                },
            ));
        } else if let Some(symbol) = SYMBOLS.iter().find(|s| source[i..].starts_with(**s)) {
            out.push((i, Token::Symbol(symbol)));
            i += symbol.len();
        } else {
            let ch = source[i..].chars().next().unwrap_or('?');
            return Err(FormulaError::at(
                i,
                format!(
                    "unexpected character '{}'; a formula uses numbers, names, + - * / ^ ( ) , \
                     < <= > >= and 'let NAME = ...;'",
                    ch.escape_default()
                ),
            ));
        }
        if out.len() > 4 * MAX_NODES {
            return Err(FormulaError::at(i, format!("more than {MAX_NODES} terms")));
        }
    }
    out.push((source.len(), Token::End));
    Ok(out)
}

/// Parses `source` as a program.
pub(crate) fn parse(source: &str) -> Result<Program, FormulaError> {
    if source.len() > MAX_SOURCE_BYTES {
        return Err(FormulaError::at(
            0,
            format!(
                "the formula is {} bytes long; the limit is {MAX_SOURCE_BYTES}",
                source.len()
            ),
        ));
    }
    let mut parser = Parser {
        tokens: tokens(source)?,
        next: 0,
        depth: 0,
        nodes: 0,
    };
    let mut lets = Vec::new();
    while parser.peek() == &Token::Let {
        let at = parser.at();
        parser.advance();
        let name = match parser.advance() {
            Token::Name(name) => name,
            other => {
                return Err(FormulaError::at(
                    at,
                    format!("expected a name after 'let', found {}", other.describe()),
                ))
            }
        };
        parser.expect("=", "after the name of a 'let'")?;
        let value = parser.expression()?;
        parser.expect(";", "to end the 'let'")?;
        lets.push(Let { at, name, value });
        if lets.len() > MAX_LETS {
            return Err(FormulaError::at(
                at,
                format!("more than {MAX_LETS} 'let' bindings"),
            ));
        }
    }
    if parser.peek() == &Token::End {
        return Err(FormulaError::at(
            parser.at(),
            "the formula is empty: write an expression of t (and n), e.g. 't^n'".to_owned(),
        ));
    }
    let result = parser.expression()?;
    match parser.peek() {
        Token::End => Ok(Program { lets, result }),
        Token::Symbol(";") => Err(FormulaError::at(
            parser.at(),
            "';' after the result: only 'let' bindings end with ';'".to_owned(),
        )),
        other => Err(FormulaError::at(
            parser.at(),
            format!(
                "expected an operator or the end, found {}",
                other.describe()
            ),
        )),
    }
}

struct Parser {
    tokens: Vec<(At, Token)>,
    next: usize,
    depth: usize,
    nodes: usize,
}

impl Parser {
    fn peek(&self) -> &Token {
        &self.tokens[self.next].1
    }

    fn at(&self) -> At {
        self.tokens[self.next].0
    }

    fn advance(&mut self) -> Token {
        let token = self.tokens[self.next].1.clone();
        if token != Token::End {
            self.next += 1;
        }
        token
    }

    fn expect(&mut self, symbol: &'static str, why: &str) -> Result<(), FormulaError> {
        if self.peek() == &Token::Symbol(symbol) {
            self.advance();
            Ok(())
        } else {
            Err(FormulaError::at(
                self.at(),
                format!(
                    "expected '{symbol}' {why}, found {}",
                    self.peek().describe()
                ),
            ))
        }
    }

    fn node(&mut self, at: At, kind: AstKind) -> Result<Ast, FormulaError> {
        self.nodes += 1;
        if self.nodes > MAX_NODES {
            return Err(FormulaError::at(at, format!("more than {MAX_NODES} terms")));
        }
        Ok(Ast { at, kind })
    }

    /// Runs `parse` one level deeper, refusing beyond [`MAX_DEPTH`].
    fn deeper(
        &mut self,
        parse: impl FnOnce(&mut Self) -> Result<Ast, FormulaError>,
    ) -> Result<Ast, FormulaError> {
        self.depth += 1;
        if self.depth > MAX_DEPTH {
            return Err(FormulaError::at(
                self.at(),
                format!("nested more than {MAX_DEPTH} levels deep"),
            ));
        }
        let result = parse(self);
        self.depth -= 1;
        result
    }

    fn expression(&mut self) -> Result<Ast, FormulaError> {
        self.deeper(|p| {
            let left = p.sum()?;
            let comparison = match p.peek() {
                Token::Symbol("<") => Comparison::Less,
                Token::Symbol("<=") => Comparison::LessEqual,
                Token::Symbol(">") => Comparison::Greater,
                Token::Symbol(">=") => Comparison::GreaterEqual,
                _ => return Ok(left),
            };
            let at = p.at();
            p.advance();
            let right = p.sum()?;
            p.node(
                at,
                AstKind::Compare(comparison, Box::new(left), Box::new(right)),
            )
        })
    }

    fn sum(&mut self) -> Result<Ast, FormulaError> {
        self.left_associative(&[("+", BinaryOp::Add), ("-", BinaryOp::Sub)], Self::product)
    }

    fn product(&mut self) -> Result<Ast, FormulaError> {
        self.left_associative(&[("*", BinaryOp::Mul), ("/", BinaryOp::Div)], Self::unary)
    }

    /// `operand { op operand }` for the operators `ops`, grouped from the left.
    fn left_associative(
        &mut self,
        ops: &[(&str, BinaryOp)],
        operand: fn(&mut Self) -> Result<Ast, FormulaError>,
    ) -> Result<Ast, FormulaError> {
        let mut left = operand(self)?;
        loop {
            let Token::Symbol(symbol) = self.peek() else {
                return Ok(left);
            };
            let Some(&(_, op)) = ops.iter().find(|(s, _)| s == symbol) else {
                return Ok(left);
            };
            let at = self.at();
            self.advance();
            let right = operand(self)?;
            left = self.node(at, AstKind::Binary(op, Box::new(left), Box::new(right)))?;
        }
    }

    fn unary(&mut self) -> Result<Ast, FormulaError> {
        self.deeper(|p| {
            if p.peek() == &Token::Symbol("-") {
                let at = p.at();
                p.advance();
                let operand = p.unary()?;
                p.node(at, AstKind::Neg(Box::new(operand)))
            } else {
                p.power()
            }
        })
    }

    fn power(&mut self) -> Result<Ast, FormulaError> {
        let base = self.atom()?;
        if self.peek() != &Token::Symbol("^") {
            return Ok(base);
        }
        let at = self.at();
        self.advance();
        let exponent = self.unary()?;
        self.node(
            at,
            AstKind::Binary(BinaryOp::Pow, Box::new(base), Box::new(exponent)),
        )
    }

    fn atom(&mut self) -> Result<Ast, FormulaError> {
        let at = self.at();
        match self.advance() {
            Token::Number(value) => self.node(at, AstKind::Number(value)),
            Token::Name(name) => {
                if self.peek() != &Token::Symbol("(") {
                    return self.node(at, AstKind::Name(name));
                }
                self.advance();
                let mut args = Vec::new();
                if self.peek() != &Token::Symbol(")") {
                    loop {
                        args.push(self.expression()?);
                        if self.peek() == &Token::Symbol(",") {
                            self.advance();
                        } else {
                            break;
                        }
                    }
                }
                self.expect(")", &format!("to close the call of '{name}'"))?;
                self.node(at, AstKind::Call { name, args })
            }
            Token::Symbol("(") => {
                let inner = self.expression()?;
                self.expect(")", "to close the '('")?;
                Ok(inner)
            }
            other => Err(FormulaError::at(
                at,
                format!(
                    "expected a number, a name or '(', found {}",
                    other.describe()
                ),
            )),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn number(at: At, x: f64) -> Ast {
        Ast {
            at,
            kind: AstKind::Number(x),
        }
    }

    #[test]
    fn precedence_and_associativity_follow_the_grammar() {
        // 1 - 2 - 3 is (1 - 2) - 3; 2 ^ 3 ^ 2 is 2 ^ (3 ^ 2); -2 ^ 2 is -(2 ^ 2).
        let p = parse("1 - 2 - 3").unwrap();
        let AstKind::Binary(BinaryOp::Sub, left, right) = p.result.kind else {
            panic!("{p:?}")
        };
        assert_eq!(*right, number(8, 3.0));
        assert!(matches!(left.kind, AstKind::Binary(BinaryOp::Sub, ..)));
        let p = parse("2 ^ 3 ^ 2").unwrap();
        let AstKind::Binary(BinaryOp::Pow, base, exponent) = p.result.kind else {
            panic!()
        };
        assert_eq!(*base, number(0, 2.0));
        assert!(matches!(exponent.kind, AstKind::Binary(BinaryOp::Pow, ..)));
        let p = parse("-2 ^ 2").unwrap();
        assert!(matches!(p.result.kind, AstKind::Neg(_)));
    }

    #[test]
    fn lets_comments_and_numbers() {
        let p = parse("# K_4\nlet a = (n + 1) / 17; # the slope\nmax(0, a * (t - 1) + 1) ^ 16")
            .unwrap();
        assert_eq!(p.lets.len(), 1);
        assert_eq!(p.lets[0].name, "a");
        for (text, value) in [
            ("1.5e-3", 1.5e-3),
            (".25", 0.25),
            ("3E2", 300.0),
            ("7.", 7.0),
        ] {
            assert_eq!(
                parse(text).unwrap().result.kind,
                AstKind::Number(value),
                "{text}"
            );
        }
    }

    #[test]
    fn limits_are_refused_before_they_cost() {
        let long = "t+".repeat(MAX_SOURCE_BYTES) + "t";
        assert!(parse(&long).unwrap_err().message.contains("bytes long"));
        let deep = "(".repeat(10_000) + "t" + &")".repeat(10_000);
        assert!(parse(&deep).is_err());
        let deep = "(".repeat(MAX_DEPTH + 1) + "t" + &")".repeat(MAX_DEPTH + 1);
        assert!(parse(&deep).unwrap_err().message.contains("nested"));
        let call = "sqrt(".repeat(MAX_DEPTH + 1) + "t" + &")".repeat(MAX_DEPTH + 1);
        assert!(parse(&call).unwrap_err().message.contains("nested"));
        let negations = "-".repeat(10_000) + "t";
        assert!(parse(&negations).unwrap_err().message.contains("nested"));
        let powers = "t^".repeat(MAX_DEPTH + 1) + "t";
        assert!(parse(&powers).unwrap_err().message.contains("nested"));
    }

    #[test]
    fn errors_point_at_the_problem() {
        for (text, at, says) in [
            ("t +", 3, "expected a number"),
            ("(t", 2, "expected ')'"),
            ("t $ 2", 2, "unexpected character"),
            ("let = 2; t", 0, "expected a name"),
            ("let a = 2 t", 10, "expected ';'"),
            ("t;", 1, "only 'let'"),
            ("t t", 2, "expected an operator"),
            ("", 0, "empty"),
            ("1e999", 0, "too large"),
        ] {
            let error = parse(text).unwrap_err();
            assert_eq!(error.at, at, "{text}: {error:?}");
            assert!(error.message.contains(says), "{text}: {error:?}");
        }
    }
}
