//! A quadratic in the angle, `C + B g + A g^2`, as a lobe: the shared evaluator of
//! `cheb2-thesis`, `cheb2` and `minimax2`, which differ only in their coefficients.
//!
//! A fitted quadratic is only meaningful up to its first zero past the peak; beyond that it
//! would go negative (concave fit) or climb again (convex fit). The zero, `cutoff`, is solved
//! once when the lobe is prepared; the evaluation returns 0 from there on and clamps to 1 in
//! case a fit overshoots the peak, so the lobe obeys SPEC section 1's range rule.
//!
//! **Sampling**: Newton in the angle. `int_t^1 lobe = int_0^g (C + B x + A x^2) sin x dx =
//! C (1 - cos g) + B (sin g - g cos g) + A (2 g sin g + (2 - g^2) cos g - 2)` in closed form
//! (a series below `g = 1/2`, where the brackets cancel), with no closed-form inverse;
//! safeguarded Newton solves it from the Gaussian guess `g = sqrt(2 u L / C)`. A fit that
//! overshoots 1 (clamped, so no longer the quadratic) is sampled from a table instead.

use super::batch::{clamp_unit, F32Bounds, LobeKernel, ModelF32, WithKernel, CLAMP};
use super::facts::ModelFacts;
use super::invert::{solve_increasing, Inverted, NewtonStart};
use super::NewtonForm;
use crate::real::Real;
use crate::simd::math::{acos, ACOS};
use crate::simd::tally::{Class, Instructions};
use crate::simd::{Kernel, Lanes};

/// A prepared quadratic-in-angle lobe.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AngleQuadratic {
    /// `[C, B, A]`.
    coeffs: [f64; 3],
    /// The first angle in `[0, pi/2]` at which the quadratic stops being positive.
    cutoff: f64,
    /// `int_0^1 lobe` in closed form, or `None` when the fit overshoots 1 and is clamped.
    total: Option<f64>,
}

impl AngleQuadratic {
    /// Prepares `C + B g + A g^2` (`coeffs = [C, B, A]`).
    pub(crate) fn new(coeffs: [f64; 3]) -> Self {
        let mut quadratic = Self {
            coeffs,
            cutoff: first_zero(coeffs),
            total: None,
        };
        quadratic.total = quadratic
            .stays_below_one()
            .then(|| quadratic.tail_angle(quadratic.cutoff));
        quadratic
    }

    /// `[C, B, A]`.
    #[must_use]
    pub fn coeffs(&self) -> [f64; 3] {
        self.coeffs
    }

    /// The angle past which the lobe is 0.
    #[must_use]
    pub fn cutoff(&self) -> f64 {
        self.cutoff
    }

    /// `[C, B, A]` as the named parameters `c`, `b`, `a` (numbers, except to a recorded
    /// expression).
    #[inline(always)]
    fn named_coeffs<R: Real>(&self) -> [R; 3] {
        let [c, b, a] = self.coeffs;
        [
            R::parameter("c", c),
            R::parameter("b", b),
            R::parameter("a", a),
        ]
    }

    /// Evaluates at the angle `g in [0, pi/2)`, by Horner: `C + g (B + A g)`.
    #[inline(always)]
    pub(crate) fn eval_angle<R: Real>(&self, g: R) -> R {
        let [c, b, a]: [R; 3] = self.named_coeffs();
        let value = (c + g * (b + a * g)).min(R::from_f64(1.0));
        g.select_less(self.cutoff_parameter(), value, R::from_f64(0.0))
    }

    /// Whether the quadratic stays at or below 1 before its cut-off, so that its closed-form
    /// integral is the lobe's.
    pub(crate) fn has_closed_form_tail(&self) -> bool {
        self.total.is_some()
    }

    fn stays_below_one(&self) -> bool {
        let [c, b, a] = self.coeffs;
        let vertex = -b / (2.0 * a);
        let peak = if a < 0.0 && vertex > 0.0 && vertex < self.cutoff {
            c - b * b / (4.0 * a)
        } else {
            c.max(c + self.cutoff * (b + a * self.cutoff))
        };
        peak <= 1.0
    }

    /// `int_0^g (C + B x + A x^2) sin x dx`, `g` capped at the cut-off (generic, so that a
    /// target that samples records it).
    pub(crate) fn tail_angle<R: Real>(&self, g: R) -> R {
        let [c, b, a]: [R; 3] = self.named_coeffs();
        let k = R::from_f64;
        let g = g.max(k(0.0)).min(self.cutoff_parameter());
        // C (1 - cos g), as 2 C sin^2(g / 2): no cancellation near the peak.
        let constant = c * (k(2.0) * (k(0.5) * g).sin().square());
        // One choice for both moments, so that a recording keeps one `sin`, one `cos` and one
        // series, and a float computes only the side it takes.
        g.branch_less(
            k(0.5),
            || {
                // int_0^g x sin x = sum_j (-1)^j g^(2j+3) / ((2j+1)! (2j+3)), and the x^2
                // moment with (2j+4) in place of (2j+3), where the closed forms cancel.
                let mut term = g; // (-1)^j g^(2j+1) / (2j+1)!
                let (mut first, mut second) = (k(0.0), k(0.0));
                for j in 0..10 {
                    let j = f64::from(j);
                    first = first + term * g * g / k(2.0 * j + 3.0);
                    second = second + term * g * g * g / k(2.0 * j + 4.0);
                    term = term * (-g * g / k((2.0 * j + 2.0) * (2.0 * j + 3.0)));
                }
                constant + b * first + a * second
            },
            || {
                let (sin, cos) = (g.sin(), g.cos());
                let first = sin - g * cos;
                let second = k(2.0) * g * sin + (k(2.0) - g * g) * cos - k(2.0);
                constant + b * first + a * second
            },
        )
    }

    /// `int_t^1 lobe(s) ds` (valid when [`Self::has_closed_form_tail`]).
    pub(crate) fn tail(&self, t: f64) -> f64 {
        self.tail_angle(t.clamp(0.0, 1.0).acos())
    }

    /// The quadratic's slope of the tail in the angle, `max(0, C + B g + A g^2) sin g`.
    pub(crate) fn tail_slope<R: Real>(&self, g: R) -> R {
        let [c, b, a]: [R; 3] = self.named_coeffs();
        (c + g * (b + a * g)).max(R::from_f64(0.0)) * g.sin()
    }

    /// The cut-off, as a named parameter.
    pub(crate) fn cutoff_parameter<R: Real>(&self) -> R {
        R::parameter("cutoff", self.cutoff)
    }

    /// The cosine whose tail is the fraction `u` of the whole, by Newton in the angle, from
    /// the cosine `near` when given, to `resolution`.
    pub(crate) fn tail_inverse(
        &self,
        u: f64,
        NewtonStart { near, resolution }: NewtonStart,
    ) -> Inverted {
        let c = self.coeffs[0];
        let target = u * self.total.unwrap_or(0.0);
        let root = solve_increasing(
            |g: f64| self.tail_angle(g),
            |g: f64| self.tail_slope(g),
            target,
            (0.0, self.cutoff),
            (
                near.map_or_else(
                    || (2.0 * target / c.max(f64::MIN_POSITIVE)).sqrt(),
                    |t| t.clamp(-1.0, 1.0).acos(),
                ),
                resolution,
            ),
        );
        Inverted {
            x: root.x.cos(),
            ..root
        }
    }
}

/// The smallest `g` in `[0, pi/2]` with `C + B g + A g^2 <= 0`, or `pi/2` if there is none.
fn first_zero([c, b, a]: [f64; 3]) -> f64 {
    let quarter = core::f64::consts::FRAC_PI_2;
    if c <= 0.0 {
        return 0.0;
    }
    let root = if a == 0.0 {
        (b < 0.0).then(|| -c / b)
    } else {
        let discriminant = b * b - 4.0 * a * c;
        (discriminant >= 0.0)
            .then(|| {
                // Stable roots: q = -(b + sign(b) sqrt(disc)) / 2; roots q/a and c/q.
                let q = -0.5 * (b + b.signum() * discriminant.sqrt());
                [q / a, c / q]
                    .into_iter()
                    .filter(|r| *r > 0.0)
                    .fold(f64::INFINITY, f64::min)
            })
            .filter(|r| r.is_finite())
    };
    root.map_or(quarter, |r| r.min(quarter))
}

/// The batch kernel: `min(1, C + g (B + A g))` with `g = acos t` by the vector `acos`, zero
/// from the cut-off on. `t` clamped to `[0, 1]` makes `t <= 0` and NaN give `g = pi/2`, which
/// is never below the cut-off.
#[derive(Clone, Copy, Debug)]
pub(crate) struct AngleQuadraticKernel {
    coeffs: [f32; 3],
    cutoff: f32,
}

impl AngleQuadratic {
    pub(crate) fn kernel(&self) -> AngleQuadraticKernel {
        AngleQuadraticKernel {
            coeffs: self.coeffs.map(|c| c as f32),
            cutoff: self.cutoff as f32,
        }
    }
}

impl Kernel for AngleQuadraticKernel {
    #[inline(always)]
    fn eval_lanes<V: Lanes>(self, t: V) -> V {
        let [c, b, a] = self.coeffs.map(|value| t.splat(value));
        let g = acos(clamp_unit(t));
        let value = a.mul_add(g, b).mul_add(g, c).min(t.splat(1.0));
        value.keep(g.lt(t.splat(self.cutoff)))
    }
}

impl LobeKernel for AngleQuadraticKernel {
    fn instructions(self) -> Instructions {
        CLAMP
            .and(ACOS)
            .plus(Class::Fma, 2)
            .plus(Class::MinMax, 1)
            .plus(Class::Compare, 1)
            .plus(Class::Logic, 1)
    }
}

/// Native in the angle; sampled by Newton in the angle where its tail has a closed form; its
/// fitted constants follow no `n` but its own.
impl ModelFacts for AngleQuadratic {
    #[inline]
    fn lobe_eval_unit<R: Real>(&self, t: R) -> R {
        self.eval_angle(t.acos())
    }

    fn lobe_angle_quadratic(&self) -> Option<AngleQuadratic> {
        Some(*self)
    }

    /// Its coefficients are fitted per `n`: none follows from `n` in closed form.
    fn lobe_preparation<R: Real>(&self, _name: &str, _n: R) -> Option<R> {
        None
    }

    fn lobe_tail(&self, t: f64) -> Option<f64> {
        self.has_closed_form_tail().then(|| self.tail(t))
    }

    fn lobe_tail_inverse(&self, u: f64, start: NewtonStart) -> Option<Inverted> {
        self.has_closed_form_tail()
            .then(|| self.tail_inverse(u, start))
    }

    fn lobe_newton_sampling<R: Real>(&self, x: R) -> Option<NewtonForm<R>> {
        self.has_closed_form_tail().then(|| NewtonForm {
            tail: self.tail_angle(x),
            slope: self.tail_slope(x),
            cosine: x.cos(),
            upper: self.cutoff_parameter(),
            total: self.tail_angle(self.cutoff_parameter()),
        })
    }

    fn lobe_eval_angle<R: Real>(&self, g: R) -> Option<R> {
        let g = g.max(-g);
        Some(if g < R::from_f64(core::f64::consts::FRAC_PI_2) {
            self.eval_angle(g)
        } else {
            R::from_f64(0.0)
        })
    }

    fn lobe_structural_range(&self, n: f64) -> [f64; 2] {
        [n, n]
    }
}

/// Its `f32` paths: the batch kernel and how far each `f32` evaluation may stray.
impl ModelF32 for AngleQuadratic {
    fn with_kernel<F: WithKernel>(&self, f: F) -> F::Output {
        f.call(self.kernel())
    }

    fn bounds(&self, n: f64) -> F32Bounds {
        F32Bounds {
            // acos within 2.5e-7 rad, times the quadratic's slope (at most ~2n^(1/2) per rad).
            batch_ulps: 16.0 + 8.0 * n.sqrt(),
            // The driver's acos is an approximation (lavapipe's is good to about 2e-4 rad
            // near the peak): about 1e-3.
            gpu_ulps: 8192.0,
            ..F32Bounds::EXACT
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cutoff_is_the_first_positive_root() {
        // 1 - g^2: root at 1.
        assert!((first_zero([1.0, 0.0, -1.0]) - 1.0).abs() < 1e-15);
        // (g - 0.5)(g - 1.0) = 0.5 - 1.5 g + g^2: convex, first root 0.5.
        assert!((first_zero([0.5, -1.5, 1.0]) - 0.5).abs() < 1e-15);
        // 1 + g^2 never vanishes.
        assert_eq!(first_zero([1.0, 0.0, 1.0]), core::f64::consts::FRAC_PI_2);
        // Linear 1 - 2 g.
        assert!((first_zero([1.0, -2.0, 0.0]) - 0.5).abs() < 1e-15);
    }

    #[test]
    fn is_zero_past_the_cutoff_and_never_above_one() {
        let q = AngleQuadratic::new([0.5, -1.5, 1.0]);
        assert_eq!(q.eval_angle(0.75f64), 0.0);
        assert_eq!(
            q.eval_angle(1.2f64),
            0.0,
            "a convex fit must not climb again"
        );
        let overshoot = AngleQuadratic::new([1.01, 0.5, -10.0]);
        assert_eq!(overshoot.eval_angle(0.01f64), 1.0);
    }
}
