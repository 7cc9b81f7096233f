//! Counting what a kernel executes: [`Tally`] is a one-lane [`Lanes`] that adds one to its
//! instruction's [`Class`] per call, so [`count`] of a kernel is its instruction count per
//! vector on the explicit levels (constants are hoisted out of loops, so `splat` is free).

use core::cell::Cell;
use core::ops::{Add, Div, Mul, Sub};

use serde::Serialize;

use super::scalar::Scalar;
use super::{Kernel, Lanes};

/// Instruction classes, grouped by the execution resource they compete for.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum Class {
    /// `vfmadd`, `vfnmadd`.
    Fma,
    /// `vmulps`.
    Mul,
    /// `vaddps`, `vsubps`.
    Add,
    /// `vdivps`.
    Div,
    /// `vsqrtps`.
    Sqrt,
    /// `vminps`, `vmaxps`.
    MinMax,
    /// `vcmpps`.
    Compare,
    /// `vblendvps`.
    Blend,
    /// `vandps` (with a constant or a mask).
    Logic,
    /// `vpaddd`.
    IntAdd,
    /// `vpslld`, `vpsrad`.
    Shift,
    /// `vcvtdq2ps`, `vcvttps2dq`.
    Convert,
}

impl Class {
    /// Every class, in table order.
    pub const ALL: [Class; CLASSES] = [
        Class::Fma,
        Class::Mul,
        Class::Add,
        Class::Div,
        Class::Sqrt,
        Class::MinMax,
        Class::Compare,
        Class::Blend,
        Class::Logic,
        Class::IntAdd,
        Class::Shift,
        Class::Convert,
    ];

    /// A short name for tables.
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            Class::Fma => "fma",
            Class::Mul => "mul",
            Class::Add => "add",
            Class::Div => "div",
            Class::Sqrt => "sqrt",
            Class::MinMax => "min/max",
            Class::Compare => "cmp",
            Class::Blend => "blend",
            Class::Logic => "and",
            Class::IntAdd => "int add",
            Class::Shift => "shift",
            Class::Convert => "cvt",
        }
    }
}

/// How many classes there are.
const CLASSES: usize = 12;

/// Instructions per vector, by class.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub struct Instructions([u32; CLASSES]);

impl Instructions {
    /// No instructions.
    pub const NONE: Instructions = Instructions([0; CLASSES]);

    /// These counts, as `(class, count)` pairs.
    #[must_use]
    pub const fn of(pairs: &[(Class, u32)]) -> Self {
        let mut counts = [0; CLASSES];
        let mut i = 0;
        while i < pairs.len() {
            counts[pairs[i].0 as usize] += pairs[i].1;
            i += 1;
        }
        Instructions(counts)
    }

    /// The count of one class.
    #[must_use]
    pub fn get(&self, class: Class) -> u32 {
        self.0[class as usize]
    }

    /// Every instruction.
    #[must_use]
    pub fn total(&self) -> u32 {
        self.0.iter().sum()
    }

    /// `self` plus `count` of `class`.
    #[must_use]
    pub const fn plus(mut self, class: Class, count: u32) -> Self {
        self.0[class as usize] += count;
        self
    }

    /// Both counts added.
    #[must_use]
    pub const fn and(mut self, other: Instructions) -> Self {
        let mut i = 0;
        while i < CLASSES {
            self.0[i] += other.0[i];
            i += 1;
        }
        self
    }
}

impl core::fmt::Display for Instructions {
    /// The non-zero classes, e.g. `fma 9, add 2, div 1`.
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        let parts: Vec<String> = Class::ALL
            .iter()
            .filter(|&&c| self.get(c) > 0)
            .map(|&c| format!("{} {}", c.name(), self.get(c)))
            .collect();
        f.write_str(&parts.join(", "))
    }
}

impl Serialize for Instructions {
    fn serialize<S: serde::Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        use serde::ser::SerializeMap;
        let mut map = serializer.serialize_map(None)?;
        for class in Class::ALL {
            map.serialize_entry(class.name(), &self.get(class))?;
        }
        map.end()
    }
}

thread_local! {
    static COUNTS: Cell<Instructions> = const { Cell::new(Instructions::NONE) };
}

fn record(class: Class) {
    COUNTS.with(|c| c.set(c.get().plus(class, 1)));
}

/// A one-lane vector that records each instruction it executes (computing as [`Scalar`]).
#[derive(Clone, Copy, Debug)]
pub struct Tally(Scalar);

/// The instructions one application of `kernel` executes, on a lane holding `t`.
#[must_use]
pub fn count<K: Kernel>(kernel: K, t: f32) -> Instructions {
    COUNTS.with(|c| c.set(Instructions::NONE));
    let _ = kernel.eval_lanes(Tally(Scalar(t)));
    COUNTS.with(Cell::get)
}

macro_rules! binary {
    ($trait:ident, $method:ident, $class:expr) => {
        impl $trait for Tally {
            type Output = Self;
            fn $method(self, other: Self) -> Self {
                record($class);
                Tally(self.0.$method(other.0))
            }
        }
    };
}

binary!(Add, add, Class::Add);
binary!(Sub, sub, Class::Add);
binary!(Mul, mul, Class::Mul);
binary!(Div, div, Class::Div);

/// A one-instruction method: record `$class`, then compute as [`Scalar`].
macro_rules! counted {
    ($class:expr, $value:expr) => {{
        record($class);
        Tally($value)
    }};
}

impl Lanes for Tally {
    type Mask = bool;
    const WIDTH: usize = 1;

    fn splat(self, value: f32) -> Self {
        Tally(Scalar(value))
    }
    fn load(self, src: &[f32]) -> Self {
        Tally(Scalar(src[0]))
    }
    fn store(self, dst: &mut [f32]) {
        dst[0] = self.0 .0;
    }
    fn mul_add(self, b: Self, c: Self) -> Self {
        counted!(Class::Fma, self.0.mul_add(b.0, c.0))
    }
    fn neg_mul_add(self, b: Self, c: Self) -> Self {
        counted!(Class::Fma, self.0.neg_mul_add(b.0, c.0))
    }
    fn sqrt(self) -> Self {
        counted!(Class::Sqrt, self.0.sqrt())
    }
    fn min(self, other: Self) -> Self {
        counted!(Class::MinMax, self.0.min(other.0))
    }
    fn max(self, other: Self) -> Self {
        counted!(Class::MinMax, self.0.max(other.0))
    }
    fn lt(self, other: Self) -> bool {
        record(Class::Compare);
        self.0.lt(other.0)
    }
    fn gt(self, other: Self) -> bool {
        record(Class::Compare);
        self.0.gt(other.0)
    }
    fn select(self, mask: bool, other: Self) -> Self {
        counted!(Class::Blend, self.0.select(mask, other.0))
    }
    fn keep(self, mask: bool) -> Self {
        counted!(Class::Logic, self.0.keep(mask))
    }
    fn bits_and(self, bits: u32) -> Self {
        counted!(Class::Logic, self.0.bits_and(bits))
    }
    fn bits_add(self, bits: u32) -> Self {
        counted!(Class::IntAdd, self.0.bits_add(bits))
    }
    fn bits_shl<const S: i32>(self) -> Self {
        counted!(Class::Shift, self.0.bits_shl::<S>())
    }
    fn bits_shr_signed<const S: i32>(self) -> Self {
        counted!(Class::Shift, self.0.bits_shr_signed::<S>())
    }
    fn int_to_float(self) -> Self {
        counted!(Class::Convert, self.0.int_to_float())
    }
    fn float_to_int(self) -> Self {
        counted!(Class::Convert, self.0.float_to_int())
    }
}
