//! What a model states about itself beyond its formula: the tail it integrates in closed form
//! and how that tail is inverted, where its value has kinks, the exponents its recorded
//! operations hold for. Each model's file implements [`ModelFacts`] for what it has; the
//! defaults say "not this model", so a model states only its own facts and `Lobe` dispatches
//! through `each_model!`, which the registry (`lobes!`) writes from its one list, with no
//! catch-all arm anywhere.

use super::invert::{Inverted, NewtonStart};
use super::{AngleQuadratic, NewtonForm};
use crate::{Exponent, Real};

/// A model's facts; every method's default is the answer for a model without the fact, but
/// the formula's, which every model states.
pub(crate) trait ModelFacts {
    /// The model's own formula at `t` in `(0, 1]` (what `Lobe::expression` records).
    fn lobe_eval_unit<R: Real>(&self, t: R) -> R;

    /// The coefficients of a quadratic-in-angle lobe.
    fn lobe_angle_quadratic(&self) -> Option<AngleQuadratic> {
        None
    }

    /// Cosines in `(0, 1)` where the value is not smooth beyond the zones' breakpoints.
    fn lobe_kinks(&self) -> Vec<f64> {
        Vec::new()
    }

    /// `int_t^1 lobe(s) ds` in closed form, `t` in `[0, 1]`.
    fn lobe_tail(&self, _t: f64) -> Option<f64> {
        None
    }

    /// The cosine whose tail is `u` of the whole (`u` in `[0, 1]`), and the iterations it took.
    fn lobe_tail_inverse(&self, _u: f64, _start: NewtonStart) -> Option<Inverted> {
        None
    }

    /// For a closed-form sampler: the tail's inverse at `u` and the whole integral.
    fn lobe_closed_form_sampling<R: Real>(&self, _u: R) -> Option<(R, R)> {
        None
    }

    /// For a Newton sampler: the tail in the solver's variable `x`.
    fn lobe_newton_sampling<R: Real>(&self, _x: R) -> Option<NewtonForm<R>> {
        None
    }

    /// The value at angle `g` from the axis, for a model whose native input is the angle.
    fn lobe_eval_angle<R: Real>(&self, _g: R) -> Option<R> {
        None
    }

    /// The exponents whose lobes share this one's recorded operations, for the model
    /// prepared at `n`.
    fn lobe_structural_range(&self, _n: f64) -> [f64; 2] {
        [Exponent::MIN, Exponent::MAX]
    }

    /// The least exponent of each of the model's shapes (its recorded operations, parameter
    /// values aside), ascending: a model whose operations change with `n` lists where.
    fn lobe_shape_exponents(&self) -> &'static [f64] {
        &[Exponent::MIN]
    }

    /// The named parameter `name` of the model's expression computed from the exponent `n`, as
    /// the preparation computes it; `None` where it is prepared numerically (a fit). By
    /// default a model's one parameter is `n` itself.
    fn lobe_preparation<R: Real>(&self, name: &str, n: R) -> Option<R> {
        (name == "n").then_some(n)
    }

    /// How many times the model squares: its cost and its hardware's select input.
    fn lobe_squarings(&self) -> Option<u32> {
        None
    }
}

/// The facts of a model sampled in closed form, from its own `tail`, `tail_inverse` and
/// `total`: the tail, its exact inverse, and both over any `Real` for a target that samples;
/// the model's other facts follow in braces.
macro_rules! closed_form_facts {
    ($model:ty) => {
        closed_form_facts!($model, {});
    };
    ($model:ty, { $($other:item)* }) => {
        impl super::facts::ModelFacts for $model {
            #[inline]
            fn lobe_eval_unit<R: Real>(&self, t: R) -> R {
                self.eval(t)
            }

            $($other)*

            fn lobe_tail(&self, t: f64) -> Option<f64> {
                Some(self.tail(t))
            }

            fn lobe_tail_inverse(
                &self,
                u: f64,
                _start: super::invert::NewtonStart,
            ) -> Option<super::invert::Inverted> {
                Some(super::invert::Inverted {
                    x: self.tail_inverse(u),
                    iterations: 0,
                })
            }

            fn lobe_closed_form_sampling<R: Real>(&self, u: R) -> Option<(R, R)> {
                Some((self.tail_inverse(u), self.total()))
            }
        }
    };
}

pub(crate) use closed_form_facts;
