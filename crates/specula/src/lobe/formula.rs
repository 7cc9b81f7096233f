//! # A lobe of yours, from a formula
//!
//! The model behind [`LobeKind::Formula`](super::LobeKind::Formula): a formula compiled by
//! [`crate::formula`] (whose page is the language's manual), prepared for one `n` by
//! computing its per-material constants in `f64`.
//!
//! - **Parameters**: `n`, and the formula's declared parameters (fixed per
//!   [`FormulaId`](super::FormulaId)).
//! - **Domain**: `t in (0, 1]`; the value is clamped to `[0, 1]` (NaN to 0), a net under
//!   the dense-grid check of [`Lobe::checked`](super::Lobe::checked).
//! - **Cost**: what the formula writes; integer powers up to 64 are multiplications.
//! - **Sampling**: Newton on the formula's own tail where it gives one, else a table.

use super::batch::{F32Bounds, LobeKernel, ModelF32, WithKernel};
use super::facts::ModelFacts;
use super::invert::NewtonStart;
use super::{with_shared_rules, Inverted, NewtonForm};
use crate::formula::batch::Rules;
use crate::formula::{registry, Instance, MAX_SLOTS};
use crate::real::Real;
use crate::simd::tally::Instructions;
use crate::simd::{Job, Kernel, Lanes, Level};
use crate::Exponent;

/// The prepared formula.
#[derive(Clone, Copy, Debug)]
pub(crate) struct FormulaLobe {
    instance: &'static Instance,
    slots: [f64; MAX_SLOTS],
    /// Which shared rules the batch's output needs at these constants.
    rules: Rules,
}

impl PartialEq for FormulaLobe {
    fn eq(&self, other: &Self) -> bool {
        core::ptr::eq(self.instance, other.instance) && self.slots == other.slots
    }
}

impl FormulaLobe {
    pub(crate) fn new(id: super::FormulaId, n: Exponent) -> Self {
        let instance = registry::get(id);
        let slots = instance.formula().prepare(n.get(), instance.values());
        Self {
            instance,
            slots,
            rules: instance.formula().plan().rules(&slots),
        }
    }

    /// Evaluates at `t in (0, 1]`, the value clamped to `[0, 1]`.
    #[inline]
    pub(crate) fn eval<R: Real>(&self, t: R) -> R {
        let value: R = self.instance.formula().raw(t, &self.slots);
        value.max(R::from_f64(0.0)).min(R::from_f64(1.0))
    }

    /// [`FormulaLobe::eval`] at each of `ts` (each in `(0, 1]`), into `out` (as long).
    pub(crate) fn eval_each(&self, ts: &[f64], out: &mut [f64]) {
        self.instance.formula().raw_each(ts, &self.slots, out);
        for value in out.iter_mut() {
            *value = Real::min(Real::max(*value, 0.0), 1.0);
        }
    }

    /// `int_t^1 lobe`, from the formula's tail.
    pub(crate) fn tail<R: Real>(&self, t: R) -> Option<R> {
        self.instance.formula().tail(t, &self.slots)
    }

    /// The cosine whose tail is the fraction `u` of the whole, by safeguarded Newton in
    /// `x = 1 - t`, where the tail `int_{1-x}^1 lobe` rises from 0 with slope `lobe(1 - x)`.
    pub(crate) fn tail_inverse(
        &self,
        u: f64,
        NewtonStart { near, resolution }: NewtonStart,
    ) -> Option<Inverted> {
        let total = self.tail(0.0)?;
        let rising = |x: f64| self.tail(1.0 - x).unwrap_or(f64::NAN);
        let found = super::invert::solve_increasing(
            rising,
            |x| self.eval(1.0 - x),
            u * total,
            (0.0, 1.0),
            (near.map_or(0.5, |t| 1.0 - t), resolution),
        );
        Some(Inverted {
            x: 1.0 - found.x,
            iterations: found.iterations,
        })
    }

    /// The tail in Newton's variable `x = 1 - t`.
    pub(crate) fn newton_sampling<R: Real>(&self, x: R) -> Option<NewtonForm<R>> {
        let one = R::from_f64(1.0);
        let zero = R::from_f64(0.0);
        let total = self.tail(zero)?;
        Some(NewtonForm {
            tail: self.tail(one - x)?,
            slope: self.eval(one - x),
            cosine: one - x,
            upper: one,
            total,
        })
    }

    /// The constant `name` computed from `n` as the preparation computes it.
    pub(crate) fn preparation<R: Real>(&self, name: &str, n: R) -> Option<R> {
        if name == "n" {
            return Some(n);
        }
        self.instance
            .formula()
            .preparation_of(name, n, self.instance.values())
    }

    /// The batch through the compiled chains and columns.
    pub(crate) fn eval_compiled(&self, level: Level, ts: &[f32], out: &mut [f32]) {
        crate::simd::dispatch(
            level,
            Columns {
                lobe: self,
                ts,
                out,
            },
        );
    }

    /// What the compiled batch executes per vector, with the rules it applies.
    pub(crate) fn instructions(&self) -> Instructions {
        self.instance.formula().plan().instructions(self.rules)
    }

    /// The plain loop's kernel: the formula one lane at a time under the shared rules.
    pub(crate) fn kernel(&self) -> FormulaKernel {
        FormulaKernel {
            formula: *self,
            stated: self.instructions(),
        }
    }
}

struct Columns<'a> {
    lobe: &'a FormulaLobe,
    ts: &'a [f32],
    out: &'a mut [f32],
}

impl Job for Columns<'_> {
    type Output = ();
    #[inline(always)]
    fn run<V: Lanes>(self, lanes: V) {
        self.lobe.instance.formula().plan().run(
            lanes,
            (&self.lobe.slots, self.lobe.rules),
            self.ts,
            self.out,
        );
    }
}

/// The formula one lane at a time in scalar `f32`, under the shared rules as
/// [`Lobe::eval`](super::Lobe::eval) applies them: the plain loop the compiled batch is
/// measured against.
#[derive(Clone, Copy, Debug)]
pub(crate) struct FormulaKernel {
    formula: FormulaLobe,
    stated: Instructions,
}

impl Kernel for FormulaKernel {
    fn eval_lanes<V: Lanes>(self, t: V) -> V {
        let mut lanes = [0.0_f32; 64];
        t.store(&mut lanes[..V::WIDTH]);
        for value in &mut lanes[..V::WIDTH] {
            *value = with_shared_rules(*value, |t| self.formula.eval(t));
        }
        t.load(&lanes[..V::WIDTH])
    }
}

impl LobeKernel for FormulaKernel {
    fn instructions(self) -> Instructions {
        self.stated
    }
}

/// A user's lobe states what its formula has: a tail and its Newton form where the formula
/// integrates in closed form.
impl ModelFacts for FormulaLobe {
    #[inline]
    fn lobe_eval_unit<R: Real>(&self, t: R) -> R {
        self.eval(t)
    }

    fn lobe_tail(&self, t: f64) -> Option<f64> {
        self.tail(t)
    }

    fn lobe_tail_inverse(&self, u: f64, start: NewtonStart) -> Option<Inverted> {
        self.tail_inverse(u, start)
    }

    fn lobe_newton_sampling<R: Real>(&self, x: R) -> Option<NewtonForm<R>> {
        self.newton_sampling(x)
    }

    fn lobe_preparation<R: Real>(&self, name: &str, n: R) -> Option<R> {
        self.preparation(name, n)
    }
}

/// Its `f32` paths: the batch kernel and how far each `f32` evaluation may stray.
impl ModelF32 for FormulaLobe {
    fn with_kernel<F: WithKernel>(&self, f: F) -> F::Output {
        f.call(self.kernel())
    }

    fn bounds(&self, n: f64) -> F32Bounds {
        // The columns' fused multiply-adds and polynomials against libm, and a driver's
        // functions, through whatever the formula does with them: a statement for formulas
        // of the shapes the lobes have (a power of a base, an exponential of a multiple of
        // t - 1), whose errors grow with n as theirs do; tested on them.
        F32Bounds {
            batch_ulps: 64.0 + 4.0 * n,
            gpu_ulps: 64.0 + 2.0 * n,
            ..F32Bounds::EXACT
        }
    }
}
