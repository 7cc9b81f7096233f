//! The lobe functions: every approximation of `t^n` that specula knows (SPEC section 2).
//!
//! A [`Lobe`] is a model *prepared* for one exponent: everything that depends only on `n`
//! (Schlick's power, the Chebyshev coefficients, the cosine-quadratic slope) is computed once
//! in `f64` when it is built, the way a renderer would upload it per material. Evaluation is a
//! `match` over a closed set of models (static dispatch, no trait objects), each written once
//! over [`Real`] and thereby available in `f64` (reference), `f32` (fast path) and
//! [`Counted`] (operation counts).
//!
//! Rules every lobe obeys (SPEC section 1), enforced here in one place: `t <= 0` (and NaN)
//! gives 0; `t > 1` is treated as 1 (dot products of unit vectors overshoot by an ulp); the
//! value is never NaN, negative, or above 1.

#[macro_use]
mod registry;

// The registry: a line per lobe, its file beside (`registry.rs` says what a line makes).
lobes! { $
    Pow => pow,
    Schlick => schlick,
    SchlickMod => schlick_mod,
    Cheb2Thesis => cheb2_thesis,
    Cheb2 => cheb2,
    Minimax2 => minimax2,
    LogExp => logexp,
    LogExpRr => logexp_rr,
    CosQuad { v: u8 = CosQuad::DEFAULT_V } => cosquad,
    Sg => sg,
    SgKaris => sg_karis,
    FastPow => fastpow,
    FasterPow => fasterpow,
    #[cfg(feature = "example-lobe")] Example => example,
}

mod batch;
mod draw_batch;
mod facts;
mod formula;
mod info;
mod invert;
mod kind;
mod quadratic;

pub use cheb2_thesis::thesis_coefficients;
pub use cosquad::CosQuad;
use facts::ModelFacts;
pub use info::{LineStyle, LobeInfo, Origin, ParamInfo};
use invert::NewtonStart;
pub use invert::{Inverted, F32_RESOLUTION, F64_RESOLUTION};
pub use kind::FormulaId;
pub use quadratic::AngleQuadratic;
pub use sg_karis::KARIS_OFFSET;

use crate::error::{Error, Result};
use crate::ops::{count_ops, Counted, OpCounts};
use crate::real::Real;
use crate::Exponent;

/// How a lobe's cosine is drawn from a uniform number for importance sampling: each lobe's
/// manual page says which, and why.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum Warp {
    /// The closed-form integral `int_t^1 lobe` inverted in closed form.
    Analytic,
    /// The closed-form integral inverted by safeguarded Newton iterations.
    Newton,
    /// A tabulated inverse CDF, built when the sampler is prepared
    /// (`CosineDistribution`, `sampling/cosine.rs`).
    Table,
}

impl Warp {
    /// The name tables print.
    #[must_use]
    pub fn id(self) -> &'static str {
        match self {
            Warp::Analytic => "analytic",
            Warp::Newton => "newton",
            Warp::Table => "table",
        }
    }
}

/// A lobe's tail as Newton's method inverts it ([`Lobe::newton_sampling`]): at the solver's
/// variable `x`, in `[0, upper]`, where `tail` rises from 0 to `total` with slope `slope`, and
/// the cosine that `x` stands for.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct NewtonForm<R> {
    /// `int` of the lobe from the peak to `x`.
    pub tail: R,
    /// Its derivative in `x`.
    pub slope: R,
    /// The cosine `t` at `x`.
    pub cosine: R,
    /// The end of `x`'s range.
    pub upper: R,
    /// The tail at `upper`: the lobe's whole integral.
    pub total: R,
}

/// `lobe` at `t` under the rules every lobe shares: `t <= 0` or NaN gives 0, `t > 1` counts
/// as 1 (SPEC section 1); `lobe` sees `t` in `(0, 1]` only.
#[inline]
pub(crate) fn with_shared_rules<R: Real>(t: R, lobe: impl FnOnce(R) -> R) -> R {
    let zero = R::from_f64(0.0);
    if t > zero {
        lobe(t.min(R::from_f64(1.0)))
    } else {
        zero
    }
}

/// A lobe function prepared for one exponent `n`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Lobe {
    kind: LobeKind,
    n: Exponent,
    model: Model,
}

impl Lobe {
    /// Prepares `kind` for exponent `n`.
    #[must_use]
    pub fn new(kind: LobeKind, n: Exponent) -> Self {
        let model = prepare(kind, n);
        Self { kind, n, model }
    }

    /// Prepares `kind` for exponent `n`, validating `n` (see [`Exponent::try_new`]).
    pub fn try_new(kind: LobeKind, n: f64) -> crate::Result<Self> {
        Ok(Self::new(kind, Exponent::try_new(n)?))
    }

    /// Which model this is.
    #[must_use]
    pub fn kind(&self) -> LobeKind {
        self.kind
    }

    /// The exponent it was prepared for.
    #[must_use]
    pub fn exponent(&self) -> Exponent {
        self.n
    }

    /// The coefficients `[C, B, A]` of a quadratic-in-angle lobe, `None` for the others.
    #[must_use]
    pub fn angle_quadratic(&self) -> Option<AngleQuadratic> {
        each_model!(&self.model, m => m.lobe_angle_quadratic())
    }

    /// How many times the lobe squares (`schlick-mod`'s `log2 a`, `cosquad`'s `v`); `None`
    /// for a model that does not.
    #[must_use]
    pub fn squarings(&self) -> Option<u32> {
        each_model!(&self.model, m => m.lobe_squarings())
    }

    /// The least exponent of each of the model's shapes, ascending: lobes of one kind whose
    /// exponents fall between two of them record the same operations, only their named
    /// parameters' values differ ([`Lobe::expression`]). One entry for most models;
    /// `schlick-mod` squares once more at every power of two from 8.
    #[must_use]
    pub fn shape_exponents(&self) -> &'static [f64] {
        each_model!(&self.model, m => m.lobe_shape_exponents())
    }

    /// Which of [`Lobe::shape_exponents`]'s shapes this lobe's exponent selects: how a backend
    /// that generates one function per shape finds this lobe's.
    #[must_use]
    pub fn shape(&self) -> u32 {
        let starts = self.shape_exponents();
        let n = self.n.get();
        (starts
            .iter()
            .take_while(|&&start| start <= n)
            .count()
            .max(1)
            - 1) as u32
    }

    /// Cosines in `(0, 1)` where the lobe's value is not smooth beyond what
    /// [`zones::breakpoints`](crate::zones::breakpoints) lists: the bit-trick lobes' binade
    /// boundaries and integer crossings. Empty for the others.
    #[must_use]
    pub fn kinks(&self) -> Vec<f64> {
        each_model!(&self.model, m => m.lobe_kinks())
    }

    /// How the lobe's cosine is sampled, from what its model states: in closed form where it
    /// inverts its tail so, by Newton where it integrates in closed form only, else from a
    /// table.
    #[must_use]
    pub fn warp(&self) -> Warp {
        if self.closed_form_sampling(0.5f64).is_some() {
            Warp::Analytic
        } else if self.tail(0.5).is_some() {
            Warp::Newton
        } else {
            Warp::Table
        }
    }

    /// `int_t^1 lobe(s) ds` for `t` in `[0, 1]`, in closed form; `None` for a lobe sampled
    /// from a table.
    #[must_use]
    pub fn tail(&self, t: f64) -> Option<f64> {
        let t = t.clamp(0.0, 1.0);
        each_model!(&self.model, m => m.lobe_tail(t))
    }

    /// The cosine `t` with `tail(t) = u tail(0)`, `u` in `[0, 1]`, and the iterations it
    /// took (0 for a closed form); `None` for a lobe sampled from a table.
    #[must_use]
    pub fn tail_inverse(&self, u: f64) -> Option<Inverted> {
        self.tail_inverse_from(
            u,
            NewtonStart {
                near: None,
                resolution: F64_RESOLUTION,
            },
        )
    }

    /// [`Lobe::tail_inverse`] for a renderer that rounds the cosine to `f32`: Newton starts
    /// from the cosine `near` (a table's draw for the same `u`, say) rather than the model's
    /// own first guess, and stops once its step is below [`F32_RESOLUTION`] of the root, so
    /// that it takes about half the iterations. Closed forms ignore `near`.
    #[must_use]
    pub fn tail_inverse_f32(&self, u: f64, near: f64) -> Option<Inverted> {
        self.tail_inverse_from(
            u,
            NewtonStart {
                near: Some(near),
                resolution: F32_RESOLUTION,
            },
        )
    }

    fn tail_inverse_from(&self, u: f64, start: NewtonStart) -> Option<Inverted> {
        let u = u.clamp(0.0, 1.0);
        each_model!(&self.model, m => m.lobe_tail_inverse(u, start))
    }

    /// The lobe at cosine `t` (any value; see the module docs for the rules).
    #[inline]
    #[must_use]
    pub fn eval<R: Real>(&self, t: R) -> R {
        with_shared_rules(t, |unit| self.eval_unit(unit))
    }

    /// [`Lobe::eval`] in `f64` at each of `ts`, the same values to the bit: a formula lobe
    /// runs its tape over all of them at once (`formula`'s `run_each`), which an analysis that
    /// scans a lobe over thousands of cosines needs; the others evaluate one by one.
    #[must_use]
    pub fn eval_each(&self, ts: &[f64]) -> Vec<f64> {
        let Model::Formula(formula) = &self.model else {
            return ts.iter().map(|&t| self.eval(t)).collect();
        };
        // The shared rules around the batch: the formula sees `t` in (0, 1] only (1 where
        // the rules answer 0 without it), and `t <= 0` or NaN is 0.
        let units: Vec<f64> = ts
            .iter()
            .map(|&t| if t > 0.0 { t.min(1.0) } else { 1.0 })
            .collect();
        let mut values = vec![0.0; ts.len()];
        formula.eval_each(&units, &mut values);
        for (value, &t) in values.iter_mut().zip(ts) {
            if t.partial_cmp(&0.0) != Some(core::cmp::Ordering::Greater) {
                *value = 0.0;
            }
        }
        values
    }

    /// The model's own formula, for `t` in `(0, 1]` (what [`Lobe::expression`] records).
    #[inline]
    pub(crate) fn eval_unit<R: Real>(&self, t: R) -> R {
        each_model!(&self.model, m => m.lobe_eval_unit(t))
    }

    /// The lobe at angle `g` (radians) from its axis. Lobes whose native input is the angle
    /// (`cheb2`, `cheb2-thesis`, `minimax2`) skip the `acos`; the others take `cos g`.
    #[inline]
    #[must_use]
    pub fn eval_angle<R: Real>(&self, g: R) -> R {
        each_model!(&self.model, m => m.lobe_eval_angle(g)).unwrap_or_else(|| self.eval(g.cos()))
    }

    /// For a lobe sampled in closed form ([`Warp::Analytic`]): the inverse of its tail,
    /// `t(u)` with `int_t^1 lobe = u int_0^1 lobe`, and the whole `int_0^1 lobe`, written once
    /// over [`Real`] so that a target that samples records them (`expression/mod.rs`).
    pub fn closed_form_sampling<R: Real>(&self, u: R) -> Option<(R, R)> {
        each_model!(&self.model, m => m.lobe_closed_form_sampling(u))
    }

    /// For a lobe sampled by Newton on a closed-form tail ([`Warp::Newton`]), in the variable
    /// `x` its solver works in (`d = 1 - t` for `schlick`, the angle for the quadratics),
    /// written once over [`Real`] so that a target that samples records it.
    pub fn newton_sampling<R: Real>(&self, x: R) -> Option<NewtonForm<R>> {
        each_model!(&self.model, m => m.lobe_newton_sampling(x))
    }

    /// The named parameter `name` of [`Lobe::expression`] computed from the exponent `n`, as
    /// the preparation computes it; `None` where specula prepares it numerically (a fit),
    /// so that a target cannot derive it from `n`.
    pub fn preparation<R: Real>(&self, name: &str, n: R) -> Option<R> {
        each_model!(&self.model, m => m.lobe_preparation(name, n))
    }

    /// The exponents whose lobes share this one's recorded operations (only the named
    /// parameters differ), as `[low, high]`: a target with `n` as an input keeps it there.
    /// `schlick-mod`'s squarings change at every power of two from 8 on; the fitted lobes'
    /// constants cannot follow `n` at all, so their range is this `n` alone.
    #[must_use]
    pub fn structural_range(&self) -> [f64; 2] {
        each_model!(&self.model, m => m.lobe_structural_range(self.n.get()))
    }

    /// The operations one evaluation from a cosine performs, counted by running
    /// [`Lobe::eval`] on [`Counted`] at a cosine inside the epicentre.
    #[must_use]
    pub fn ops(&self) -> OpCounts {
        let t = (0.5 * crate::zones::epicentre_angle(self.n)).cos();
        count_ops(|| self.eval(Counted(t))).1
    }
}
