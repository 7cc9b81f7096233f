//! Operation counting: a [`Real`] that tallies what one evaluation does.
//!
//! [`count_ops`] runs a closure over [`Counted`] values and returns the tally. The counters are
//! thread-local, so counting is safe under parallel test runners and never observed by the
//! `f32`/`f64` paths, which do not touch this type at all.

use core::cell::Cell;
use core::ops::{Add, Div, Mul, Neg, Sub};

use serde::Serialize;

use crate::real::Real;

/// How many of each operation one evaluation performs.
///
/// `square` is kept apart from `mul` because the hardware models implement squarings with a
/// dedicated squarer; `cmp` counts comparisons and selects (`max`, `min`, branches).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, Serialize)]
pub struct OpCounts {
    /// Additions and subtractions.
    pub add: u32,
    /// General multiplications.
    pub mul: u32,
    /// Divisions.
    pub div: u32,
    /// Square roots.
    pub sqrt: u32,
    /// Base-2 logarithms.
    pub log2: u32,
    /// Base-2 exponentials.
    pub exp2: u32,
    /// Arc cosines.
    pub acos: u32,
    /// Cosines.
    pub cos: u32,
    /// General powers `x^y`.
    pub pow: u32,
    /// Squarings `x*x`.
    pub square: u32,
    /// Comparisons and selects.
    pub cmp: u32,
    /// Roundings to an integer (`ceil`).
    pub round: u32,
    /// Scalings by an integer power of two.
    pub shift: u32,
}

impl OpCounts {
    /// Each counter with its name, in a fixed order (for tables and serialisation).
    #[must_use]
    pub fn entries(&self) -> [(&'static str, u32); 13] {
        [
            ("add", self.add),
            ("mul", self.mul),
            ("div", self.div),
            ("sqrt", self.sqrt),
            ("log2", self.log2),
            ("exp2", self.exp2),
            ("acos", self.acos),
            ("cos", self.cos),
            ("pow", self.pow),
            ("square", self.square),
            ("cmp", self.cmp),
            ("round", self.round),
            ("shift", self.shift),
        ]
    }

    /// The total of all operations.
    #[must_use]
    pub fn total(&self) -> u32 {
        self.entries().iter().map(|(_, count)| count).sum()
    }
}

impl core::fmt::Display for OpCounts {
    /// The non-zero counters, e.g. `add 2, mul 1, div 1, cmp 2`.
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        let mut first = true;
        for (name, count) in self.entries() {
            if count > 0 {
                if !first {
                    f.write_str(", ")?;
                }
                write!(f, "{name} {count}")?;
                first = false;
            }
        }
        Ok(())
    }
}

thread_local! {
    static TALLY: Cell<OpCounts> = const { Cell::new(OpCounts {
        add: 0, mul: 0, div: 0, sqrt: 0, log2: 0, exp2: 0, acos: 0, cos: 0, pow: 0, square: 0,
        cmp: 0, round: 0, shift: 0,
    }) };
}

fn tally(record: impl FnOnce(&mut OpCounts)) {
    TALLY.with(|cell| {
        let mut counts = cell.get();
        record(&mut counts);
        cell.set(counts);
    });
}

/// Runs `evaluation` and returns the operations it performed on [`Counted`] values.
pub fn count_ops<T>(evaluation: impl FnOnce() -> T) -> (T, OpCounts) {
    let saved = TALLY.with(|cell| cell.replace(OpCounts::default()));
    let value = evaluation();
    let counts = TALLY.with(|cell| cell.replace(saved));
    (value, counts)
}

/// An `f64` that counts every operation performed on it (see [`count_ops`]).
#[derive(Clone, Copy, Debug)]
pub struct Counted(pub f64);

impl PartialEq for Counted {
    fn eq(&self, other: &Self) -> bool {
        tally(|c| c.cmp += 1);
        self.0 == other.0
    }
}

impl PartialOrd for Counted {
    fn partial_cmp(&self, other: &Self) -> Option<core::cmp::Ordering> {
        tally(|c| c.cmp += 1);
        self.0.partial_cmp(&other.0)
    }
}

macro_rules! counted_binary_op {
    ($trait:ident, $method:ident, $counter:ident) => {
        impl $trait for Counted {
            type Output = Counted;
            fn $method(self, rhs: Counted) -> Counted {
                tally(|c| c.$counter += 1);
                Counted(self.0.$method(rhs.0))
            }
        }
    };
}

counted_binary_op!(Add, add, add);
counted_binary_op!(Sub, sub, add);
counted_binary_op!(Mul, mul, mul);
counted_binary_op!(Div, div, div);

impl Neg for Counted {
    type Output = Counted;
    /// A sign flip is free in every datapath (a wire), so it is not counted.
    fn neg(self) -> Counted {
        Counted(-self.0)
    }
}

macro_rules! counted_unary_fn {
    ($method:ident, $counter:ident) => {
        fn $method(self) -> Self {
            tally(|c| c.$counter += 1);
            Counted(self.0.$method())
        }
    };
}

impl Real for Counted {
    fn from_f64(x: f64) -> Self {
        Counted(x)
    }
    fn to_f64(self) -> f64 {
        self.0
    }
    fn square(self) -> Self {
        tally(|c| c.square += 1);
        Counted(self.0 * self.0)
    }
    counted_unary_fn!(sqrt, sqrt);
    counted_unary_fn!(log2, log2);
    counted_unary_fn!(exp2, exp2);
    counted_unary_fn!(acos, acos);
    counted_unary_fn!(cos, cos);
    /// Counted as a cosine (the same unit, a quarter turn apart).
    fn sin(self) -> Self {
        tally(|c| c.cos += 1);
        Counted(self.0.sin())
    }
    /// Counted as an `exp2` (a scaling of the argument is free in a datapath's table).
    fn exp(self) -> Self {
        tally(|c| c.exp2 += 1);
        Counted(self.0.exp())
    }
    /// Counted as a `log2` and an add.
    fn ln_1p(self) -> Self {
        tally(|c| {
            c.log2 += 1;
            c.add += 1;
        });
        Counted(self.0.ln_1p())
    }
    /// Counted as an `exp2` and an add.
    fn exp_m1(self) -> Self {
        tally(|c| {
            c.exp2 += 1;
            c.add += 1;
        });
        Counted(self.0.exp_m1())
    }
    fn powf(self, exponent: Self) -> Self {
        tally(|c| c.pow += 1);
        Counted(self.0.powf(exponent.0))
    }
    fn max(self, other: Self) -> Self {
        tally(|c| c.cmp += 1);
        Counted(self.0.max(other.0))
    }
    fn min(self, other: Self) -> Self {
        tally(|c| c.cmp += 1);
        Counted(self.0.min(other.0))
    }
    fn ceil(self) -> Self {
        tally(|c| c.round += 1);
        Counted(self.0.ceil())
    }
    fn shift(self, k: Self) -> Self {
        tally(|c| c.shift += 1);
        Counted(self.0.shift(k.0))
    }
    /// Field extraction: counted as one shift (the exponent field moved into place).
    fn frexp(self) -> (Self, Self) {
        tally(|c| c.shift += 1);
        let (m, e) = self.0.frexp();
        (Counted(m), Counted(e))
    }
    /// A multiply-add into the bit pattern and its conversion to an integer.
    fn bits_exp2(self) -> Self {
        tally(|c| {
            c.mul += 1;
            c.add += 1;
            c.round += 1;
        });
        Counted(self.0.bits_exp2())
    }
    fn select_less(self, bound: Self, then: Self, otherwise: Self) -> Self {
        tally(|c| c.cmp += 1);
        Counted(self.0.select_less(bound.0, then.0, otherwise.0))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn counts_each_operation_once() {
        let (value, counts) = count_ops(|| {
            let x = Counted(0.5);
            let y = (x + x) * x - x / Counted(2.0);
            y.square().log2().max(Counted(-10.0))
        });
        assert_eq!(value.0, (0.25f64).square().log2());
        assert_eq!(
            counts,
            OpCounts {
                add: 2,
                mul: 1,
                div: 1,
                log2: 1,
                square: 1,
                cmp: 1,
                ..OpCounts::default()
            }
        );
    }

    #[test]
    fn nested_counts_do_not_leak() {
        let (_, outer) = count_ops(|| {
            let (_, inner) = count_ops(|| Counted(1.0) + Counted(2.0));
            assert_eq!(inner.add, 1);
            Counted(1.0) * Counted(2.0)
        });
        assert_eq!(
            outer,
            OpCounts {
                mul: 1,
                ..OpCounts::default()
            }
        );
    }
}
