//! The families `specula design` searches: shapes the formula language writes, each with a
//! few global coefficients `beta` from which every per-material constant is a closed form of
//! `n` (a shader computes them). With `u = 1 - t`, `t^n = exp(n ln(1 - u))`:
//!
//! - **`exp2-linear`, `exp2-quadratic`, `exp2-cubic`**: `exp(-u (k1 + k2 u + k3 u^2))`, the
//!   series `-ln(1 - u) = u + u^2/2 + u^3/3 + ...` truncated, its coefficients nudged by
//!   `beta` (`k1 = n + beta0 / n`, `k2 = n / 2 + beta1`, `k3 = n / 3 + beta2`; `k1 = n + beta0`
//!   alone for the linear one, the form of `sg-karis`). One `exp2`; positive coefficients make
//!   the lobe fall monotonically from 1 at `t = 1`.
//! - **`linear-powM`**: `max(0, 1 - s u)^M`, `M` a power of two (`cosquad`'s shape), with
//!   `s = beta0 n + beta1`: squarings only.
//! - **`quadratic-powM`**: `(1 - s v + c v^2)^M` with `v = min(u, u_stop)`, the quadratic's
//!   Taylor form of `t^(n/M)` (`s = beta0 n + beta1 / n`, `c = (beta2 s - beta3) s`) cut
//!   where it stops falling: at its first root when it has one, else at its vertex, so the
//!   lobe is monotone and in `[0, 1]` at every `n`. Written in Horner form, which stays exact
//!   where `c` crosses 0 (the vertex form's constants there run to infinity and cancel).
//!
//! - **`cubic-powM`**: `max(0, 1 - s v + c v^2 + d v^3)^M` with `v = min(u, u_stop)`, the
//!   cubic's Taylor form of `t^(n/M)` (`s`, `c` as the quadratic's, `d = -(beta4 s - beta5)
//!   s^2`) cut at its first stationary point, the smallest positive root of its derivative,
//!   `s / (c + sqrt(c^2 + 3 d s))` (1 where it has none below 1), and at 0: monotone and in
//!   `[0, 1]` at every `n`.
//! - **`hinge-powM`**: `max(0, 1 - s u + d max(0, u - k))^M`, a two-piece linear function
//!   (`select(u < k, 1 - s u, 1 - s u + d (u - k))`, written with `max` so that it compiles to
//!   one comparator and multiplexer) under squarings: a steeper slope `s = beta0 n + beta1`
//!   near the peak, flattened by `d = beta3 s` beyond the knot `k = beta2 / s`, following the
//!   convex `t^(n/M)` further than one line does.
//! - **`rational-powM`**: `(max(0, 1 - a u) / (1 + b u))^M`, the Padé `[1/1]` form of
//!   `t^(n/M)` (`a = beta0 n + beta1`, `b = beta2 n + beta3`, started at Padé's own
//!   `(n/M + 1) / 2` and `(n/M - 1) / 2`); `M = 1` is Schlick's shape, `t / (n (1 - t) + t)`
//!   being `a = 1`, `b = n - 1`. A divide and squarings, no transcendental.
//! - **`exp2-rational`**: `exp2(a1 u / (1 - b u))`, `-ln(1 - u)` by its Padé form
//!   `u / (1 - u / 2)` with `b` nudged (`a1 = -log2(e) (n + beta0 / n)`, `b = 1/2 + beta1`).
//!
//! [`Family::eval`] is the formula's own arithmetic in `f64`, operation for operation, so that
//! the fit sees what [`Family::formula`]'s text computes; the verification then runs the text
//! through the analysis.

use core::f64::consts::{LN_2, LOG2_E};

/// The largest power of the grammar is `2^MAX_SQUARINGS` (`cosquad`'s 128).
pub const MAX_SQUARINGS: u8 = 7;

/// A family, its structure fixed.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Family {
    /// `exp2` of a polynomial of `u` without constant term.
    Exp2Poly {
        /// 1 to 3.
        degree: u8,
    },
    /// A polynomial of `u`, cut where it stops falling, raised to `2^squarings`.
    PolyPow {
        /// 1 to 3.
        degree: u8,
        /// The power is `2^squarings`.
        squarings: u8,
    },
    /// A two-piece linear function of `u`, cut at 0, raised to `2^squarings`.
    HingePow {
        /// The power is `2^squarings`.
        squarings: u8,
    },
    /// `(max(0, 1 - a u) / (1 + b u))` raised to `2^squarings`.
    RationalPow {
        /// The power is `2^squarings`.
        squarings: u8,
    },
    /// `exp2(a1 u / (1 - b u))`.
    Exp2Rational,
}

impl Family {
    /// Every family the grammar writes (`grammar.rs`): `exp2` of each inner function that is
    /// a series of `n ln t`, then each peak-shaped one under every power up to
    /// `2^MAX_SQUARINGS`, the transcendental-free ones last. What is searched is the part of it
    /// within the cost bound.
    #[must_use]
    pub fn all() -> Vec<Family> {
        let mut all: Vec<Family> = (1..=3).map(|degree| Family::Exp2Poly { degree }).collect();
        all.push(Family::Exp2Rational);
        for squarings in 0..=MAX_SQUARINGS {
            all.extend((1..=3).map(|degree| Family::PolyPow { degree, squarings }));
            all.push(Family::HingePow { squarings });
            all.push(Family::RationalPow { squarings });
        }
        all
    }

    /// The id tables show: `exp2-quadratic`, `linear-pow64`, `quadratic-pow8`.
    #[must_use]
    pub fn id(self) -> String {
        match self {
            Family::Exp2Poly { degree } => format!("exp2-{}", degree_name(degree)),
            Family::PolyPow {
                degree,
                squarings: 0,
            } => degree_name(degree).to_owned(),
            Family::PolyPow { degree, squarings } => {
                format!("{}-pow{}", degree_name(degree), 1u32 << squarings)
            }
            Family::HingePow { squarings: 0 } => "hinge".to_owned(),
            Family::HingePow { squarings } => format!("hinge-pow{}", 1u32 << squarings),
            Family::RationalPow { squarings: 0 } => "rational".to_owned(),
            Family::RationalPow { squarings } => format!("rational-pow{}", 1u32 << squarings),
            Family::Exp2Rational => "exp2-rational".to_owned(),
        }
    }

    /// Whether an evaluation calls a transcendental function (`exp2`); the constants'
    /// `sqrt` is per material, not per evaluation.
    #[must_use]
    pub fn transcendental(self) -> bool {
        matches!(self, Family::Exp2Poly { .. } | Family::Exp2Rational)
    }

    /// The coefficients the fit starts from: the truncated series, nudged by nothing.
    #[must_use]
    pub fn start(self) -> Vec<f64> {
        match self {
            Family::Exp2Poly { degree } => vec![0.0; usize::from(degree)],
            Family::PolyPow { degree, squarings } => {
                let m = f64::from(1u32 << squarings);
                match degree {
                    1 => vec![1.0 / m, 0.0],
                    2 => vec![1.0 / m, 0.0, 0.5, 0.5],
                    _ => vec![1.0 / m, 0.0, 0.5, 0.5, 1.0 / 6.0, 0.5],
                }
            }
            Family::HingePow { squarings } => {
                let m = f64::from(1u32 << squarings);
                vec![1.0 / m, 0.0, 1.0 / m, 0.1]
            }
            Family::RationalPow { squarings } => {
                let half = 0.5 / f64::from(1u32 << squarings);
                vec![half, 0.5, half, -0.5]
            }
            Family::Exp2Rational => vec![0.0, 0.0],
        }
    }

    /// The lobe at `u = 1 - t` for `n`, with the formula's operations in its order.
    #[must_use]
    pub fn eval(self, beta: &[f64], n: f64, u: f64) -> f64 {
        self.at(beta, n).eval(u)
    }

    /// The family's constants at `n`, as the formula's `let`s compute them: what a fit
    /// evaluating many `u` at one `n` computes once rather than per point.
    #[must_use]
    pub fn at(self, beta: &[f64], n: f64) -> AtN {
        let constants = match self {
            Family::Exp2Poly { degree } => {
                let [a1, a2, a3] = exp2_coefficients(degree, beta, n);
                [a1, a2, a3, 0.0]
            }
            Family::PolyPow { degree: 1, .. } => [beta[0] * n + beta[1], 0.0, 0.0, 0.0],
            Family::PolyPow { degree: 2, .. } => {
                let (s, c, stop) = quadratic_constants(beta, n);
                [s, c, 0.0, stop]
            }
            Family::PolyPow { .. } => {
                let (s, c, d, stop) = cubic_constants(beta, n);
                [s, c, d, stop]
            }
            Family::HingePow { .. } => {
                let s = beta[0] * n + beta[1];
                [s, beta[2] / s, beta[3] * s, 0.0]
            }
            Family::RationalPow { .. } => [beta[0] * n + beta[1], beta[2] * n + beta[3], 0.0, 0.0],
            Family::Exp2Rational => [-LOG2_E * (n + beta[0] / n), 0.5 + beta[1], 0.0, 0.0],
        };
        AtN {
            family: self,
            constants,
        }
    }

    /// The lobe as formula text, `beta` written out (shortest round-trip decimals).
    #[must_use]
    pub fn formula(self, beta: &[f64]) -> String {
        match self {
            Family::Exp2Poly { degree: 1 } => format!(
                "let a1 = -{LOG2_E} * (n {});\nexp2(a1 * (1 - t))",
                signed(beta[0])
            ),
            Family::Exp2Poly { degree } => {
                let mut text = format!("let a1 = -{LOG2_E} * (n {} / n);\n", signed(beta[0]));
                text += &format!("let a2 = -{LOG2_E} * (n / 2 {});\n", signed(beta[1]));
                if degree == 3 {
                    text += &format!("let a3 = -{LOG2_E} * (n / 3 {});\n", signed(beta[2]));
                }
                text += "let u = 1 - t;\n";
                text += if degree == 3 {
                    "exp2(u * (a1 + u * (a2 + u * a3)))"
                } else {
                    "exp2(u * (a1 + u * a2))"
                };
                text
            }
            Family::PolyPow {
                degree: 1,
                squarings,
            } => format!(
                "let s = {} * n {};\n{}",
                beta[0],
                signed(beta[1]),
                powered("max(0, 1 - s * (1 - t))", squarings)
            ),
            Family::PolyPow {
                degree: 2,
                squarings,
            } => format!(
                "let s = {} * n {} / n;\n\
                 let c = ({} * s {}) * s;\n\
                 let disc = s * s - 4 * c;\n\
                 let stop = select(disc < 0, s / (2 * c), 2 / (s + sqrt(max(disc, 0))));\n\
                 let v = min(1 - t, stop);\n{}",
                beta[0],
                signed(beta[1]),
                beta[2],
                signed(-beta[3]),
                powered("(1 - v * (s - c * v))", squarings)
            ),
            Family::PolyPow { squarings, .. } => format!(
                "let s = {} * n {} / n;\n\
                 let c = ({} * s {}) * s;\n\
                 let d = ({} {} * s) * s * s;\n\
                 let disc = c * c + 3 * d * s;\n\
                 let stop = select(disc < 0, 1, s / max(c + sqrt(max(disc, 0)), s));\n\
                 let v = min(1 - t, stop);\n{}",
                beta[0],
                signed(beta[1]),
                beta[2],
                signed(-beta[3]),
                beta[5],
                signed(-beta[4]),
                powered("max(0, 1 - v * (s - v * (c + v * d)))", squarings)
            ),
            Family::HingePow { squarings } => format!(
                "let s = {} * n {};\nlet k = {} / s;\nlet d = {} * s;\nlet u = 1 - t;\n{}",
                beta[0],
                signed(beta[1]),
                beta[2],
                beta[3],
                powered("max(0, 1 - s * u + d * max(0, u - k))", squarings)
            ),
            Family::RationalPow { squarings } => {
                format!(
                    "let a = {} * n {};\nlet b = {} * n {};\nlet u = 1 - t;\n{}",
                    beta[0],
                    signed(beta[1]),
                    beta[2],
                    signed(beta[3]),
                    powered("(max(0, 1 - a * u) / (1 + b * u))", squarings)
                )
            }
            Family::Exp2Rational => format!(
                "let a1 = -{LOG2_E} * (n {} / n);\nlet b = {};\nlet u = 1 - t;\n\
                 exp2(a1 * u / (1 - b * u))",
                signed(beta[0]),
                0.5 + beta[1]
            ),
        }
    }

    /// `int_t^1 lobe(x) dx` as formula text, where it has a closed form in the language (it
    /// reads the formula's `let`s, so the coefficients are not written again).
    #[must_use]
    pub fn tail(self) -> Option<String> {
        match self {
            Family::Exp2Poly { degree: 1 } => {
                Some(format!("(1 - exp2(a1 * (1 - t))) / (-a1 * {LN_2})"))
            }
            Family::PolyPow {
                degree: 1,
                squarings,
            } => {
                let m1 = (1u32 << squarings) + 1;
                Some(format!(
                    "(1 - pow(max(0, 1 - s * (1 - t)), {m1})) / (s * {m1})"
                ))
            }
            _ => None,
        }
    }

    /// One line on the family, for the lobe file's description.
    #[must_use]
    pub fn description(self) -> String {
        match self {
            Family::Exp2Poly { degree } => format!(
                "exp2 of a {} polynomial of 1 - t (the series of n ln t, its coefficients fitted)",
                degree_name(degree)
            ),
            Family::PolyPow { degree, squarings } => format!(
                "a {} polynomial of 1 - t raised to {} (squarings), cut where it stops falling",
                degree_name(degree),
                1u32 << squarings
            ),
            Family::HingePow { squarings } => format!(
                "a two-piece linear function of 1 - t (a select at a knot, written with max) \
                 raised to {}, cut at 0",
                1u32 << squarings
            ),
            Family::RationalPow { squarings } => format!(
                "a ratio of linear functions of 1 - t (Padé's form of t^(n/{}), Schlick's \
                 shape) raised to {} (squarings), cut at 0",
                1u32 << squarings,
                1u32 << squarings
            ),
            Family::Exp2Rational => "exp2 of a ratio of linear functions of 1 - t (Padé's form \
                of n ln t, its coefficients fitted)"
                .to_owned(),
        }
    }
}

fn degree_name(degree: u8) -> &'static str {
    match degree {
        1 => "linear",
        2 => "quadratic",
        _ => "cubic",
    }
}

/// `base` raised to `2^squarings` as formula text (`base` parenthesised or a call).
fn powered(base: &str, squarings: u8) -> String {
    if squarings == 0 {
        base.to_owned()
    } else {
        format!("{base} ^ {}", 1u32 << squarings)
    }
}

/// `+ x` or `- |x|`, for a coefficient written after an operand.
fn signed(x: f64) -> String {
    if x.is_sign_negative() {
        format!("- {}", -x)
    } else {
        format!("+ {x}")
    }
}

/// A family at one `n`: its constants computed, the lobe evaluated per `u`.
#[derive(Clone, Copy, Debug)]
pub struct AtN {
    family: Family,
    /// The `let`s' values, in the order [`Family::at`] lists them.
    constants: [f64; 4],
}

impl AtN {
    /// The lobe at `u = 1 - t`, with the formula's operations in its order.
    #[must_use]
    #[inline]
    pub fn eval(self, u: f64) -> f64 {
        let [k0, k1, k2, k3] = self.constants;
        match self.family {
            Family::Exp2Poly { degree } => match degree {
                1 => (k0 * u).exp2(),
                2 => (u * (k0 + u * k1)).exp2(),
                _ => (u * (k0 + u * (k1 + u * k2))).exp2(),
            },
            Family::PolyPow { degree, squarings } => {
                let base = match degree {
                    1 => (1.0 - k0 * u).max(0.0),
                    2 => {
                        let v = u.min(k3);
                        1.0 - v * (k0 - k1 * v)
                    }
                    _ => {
                        let v = u.min(k3);
                        (1.0 - v * (k0 - v * (k1 + v * k2))).max(0.0)
                    }
                };
                squared(base, squarings)
            }
            Family::HingePow { squarings } => {
                squared((1.0 - k0 * u + k2 * (u - k1).max(0.0)).max(0.0), squarings)
            }
            Family::RationalPow { squarings } => {
                squared((1.0 - k0 * u).max(0.0) / (1.0 + k1 * u), squarings)
            }
            Family::Exp2Rational => (k0 * u / (1.0 - k1 * u)).exp2(),
        }
    }
}

/// `x` squared `squarings` times.
#[inline]
fn squared(x: f64, squarings: u8) -> f64 {
    (0..squarings).fold(x, |x, _| x * x)
}

/// `a1, a2, a3` of an `exp2` family at `n` (log2 units), as the formula's `let`s compute them.
fn exp2_coefficients(degree: u8, beta: &[f64], n: f64) -> [f64; 3] {
    if degree == 1 {
        return [-LOG2_E * (n + beta[0]), 0.0, 0.0];
    }
    let third = if degree == 3 {
        -LOG2_E * (n / 3.0 + beta[2])
    } else {
        0.0
    };
    [
        -LOG2_E * (n + beta[0] / n),
        -LOG2_E * (n / 2.0 + beta[1]),
        third,
    ]
}

/// `s`, `c` and the cut `stop` of a quadratic family at `n`, as the formula's `let`s compute
/// them.
fn quadratic_constants(beta: &[f64], n: f64) -> (f64, f64, f64) {
    let s = beta[0] * n + beta[1] / n;
    let c = (beta[2] * s - beta[3]) * s;
    let disc = s * s - 4.0 * c;
    let stop = if disc < 0.0 {
        s / (2.0 * c)
    } else {
        2.0 / (s + disc.max(0.0).sqrt())
    };
    (s, c, stop)
}

/// `s`, `c`, `d` and the cut `stop` of a cubic family at `n`, as the formula's `let`s compute
/// them: `stop` is the cubic's first stationary point, `s / (c + sqrt(c^2 + 3 d s))` (the
/// smaller positive root of `3 d v^2 + 2 c v - s`, in the form without cancellation), or 1
/// where that lies beyond 1 or does not exist.
pub(super) fn cubic_constants(beta: &[f64], n: f64) -> (f64, f64, f64, f64) {
    let s = beta[0] * n + beta[1] / n;
    let c = (beta[2] * s - beta[3]) * s;
    let d = (beta[5] - beta[4] * s) * s * s;
    let disc = c * c + 3.0 * d * s;
    let stop = if disc < 0.0 {
        1.0
    } else {
        s / (c + disc.max(0.0).sqrt()).max(s)
    };
    (s, c, d, stop)
}
