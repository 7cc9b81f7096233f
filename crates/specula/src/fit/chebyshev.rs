//! Chebyshev series fits, the thesis's method (Numerical Recipes' `chebft`, `chebev`, `chebpc`).
//!
//! With `N` nodes on `[a, b]`:
//!
//! ```text
//! x_k   = cos(pi (k - 1/2) / N) (b-a)/2 + (b+a)/2
//! c_j   = 2/N * sum_{k=1..N} f(x_k) cos(pi j (k - 1/2) / N)
//! ap(x) = sum_{j<N} c_j T_j(y) - c_0 / 2,                      y = (x - (b+a)/2) / ((b-a)/2)
//! ```
//!
//! Keeping all `N` terms interpolates `f` at the `N` Chebyshev nodes; keeping fewer
//! ("economisation") gives a near-minimax polynomial of lower degree. The thesis uses `N = 3`
//! and converts to `A x^2 + B x + C` by hand; [`ChebyshevSeries::to_power_basis`] does the same
//! conversion for any degree.

use serde::Serialize;

use super::Polynomial;

/// A Chebyshev series on an interval, in the `c_0 / 2` convention of Numerical Recipes.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct ChebyshevSeries {
    coeffs: Vec<f64>,
    lower: f64,
    upper: f64,
}

impl ChebyshevSeries {
    /// Fits `f` on `[lower, upper]` from its values at `nodes` Chebyshev nodes.
    ///
    /// # Panics
    /// If `nodes` is zero or the interval is empty or not finite.
    #[must_use]
    pub fn fit(f: impl Fn(f64) -> f64, lower: f64, upper: f64, nodes: usize) -> Self {
        assert!(nodes > 0, "a Chebyshev fit needs at least one node");
        assert!(
            lower.is_finite() && upper.is_finite() && lower < upper,
            "empty interval"
        );
        let half_width = 0.5 * (upper - lower);
        let centre = 0.5 * (upper + lower);
        let count = nodes as f64;
        let samples: Vec<f64> = (0..nodes)
            .map(|k| {
                let theta = core::f64::consts::PI * (k as f64 + 0.5) / count;
                f(theta.cos() * half_width + centre)
            })
            .collect();
        let coeffs = (0..nodes)
            .map(|j| {
                let sum: f64 = samples
                    .iter()
                    .enumerate()
                    .map(|(k, &value)| {
                        let theta = core::f64::consts::PI * (k as f64 + 0.5) / count;
                        value * (j as f64 * theta).cos()
                    })
                    .sum();
                2.0 / count * sum
            })
            .collect();
        Self {
            coeffs,
            lower,
            upper,
        }
    }

    /// The series coefficients `c_0 .. c_{N-1}`.
    #[must_use]
    pub fn coeffs(&self) -> &[f64] {
        &self.coeffs
    }

    /// The fitted interval `[lower, upper]`.
    #[must_use]
    pub fn interval(&self) -> (f64, f64) {
        (self.lower, self.upper)
    }

    /// The series truncated to its first `terms` coefficients (economisation).
    #[must_use]
    pub fn truncated(&self, terms: usize) -> Self {
        Self {
            coeffs: self.coeffs[..terms.min(self.coeffs.len())].to_vec(),
            lower: self.lower,
            upper: self.upper,
        }
    }

    /// Evaluates the series by Clenshaw's recurrence (`chebev`).
    #[must_use]
    pub fn eval(&self, x: f64) -> f64 {
        let y = self.normalise(x);
        let (mut d, mut dd) = (0.0, 0.0);
        for &c in self.coeffs.iter().skip(1).rev() {
            (d, dd) = (2.0 * y * d - dd + c, d);
        }
        y * d - dd + 0.5 * self.coeffs.first().copied().unwrap_or(0.0)
    }

    /// The same polynomial in the power basis of `x` (`chebpc` then `pcshft`).
    #[must_use]
    pub fn to_power_basis(&self) -> Polynomial {
        // Monomial coefficients of T_j(y) by T_{j+1} = 2y T_j - T_{j-1}.
        let terms = self.coeffs.len();
        let mut in_y = vec![0.0; terms.max(1)];
        let (mut previous, mut current) = (vec![1.0], vec![0.0, 1.0]);
        for (j, &c) in self.coeffs.iter().enumerate() {
            let t_j: &[f64] = match j {
                0 => &previous,
                _ => &current,
            };
            for (power, &m) in t_j.iter().enumerate() {
                in_y[power] += c * m;
            }
            if j >= 1 {
                let mut next = vec![0.0; current.len() + 1];
                for (power, &m) in current.iter().enumerate() {
                    next[power + 1] += 2.0 * m;
                }
                for (power, &m) in previous.iter().enumerate() {
                    next[power] -= m;
                }
                previous = core::mem::replace(&mut current, next);
            }
        }
        in_y[0] -= 0.5 * self.coeffs.first().copied().unwrap_or(0.0);
        let half_width = 0.5 * (self.upper - self.lower);
        let centre = 0.5 * (self.upper + self.lower);
        Polynomial::new(in_y).compose_linear(1.0 / half_width, -centre / half_width)
    }

    fn normalise(&self, x: f64) -> f64 {
        (2.0 * x - self.lower - self.upper) / (self.upper - self.lower)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn all_nodes_interpolate_a_polynomial_exactly() {
        let cubic = |x: f64| 0.3 - 1.2 * x + 0.7 * x * x - 0.05 * x * x * x;
        let series = ChebyshevSeries::fit(cubic, -0.5, 2.0, 4);
        let power = series.to_power_basis();
        for x in [-0.5, 0.1, 1.3, 2.0] {
            assert!((series.eval(x) - cubic(x)).abs() < 1e-13);
            assert!((power.eval(x) - cubic(x)).abs() < 1e-13);
        }
        let expected = [0.3, -1.2, 0.7, -0.05];
        for (got, want) in power.coeffs().iter().zip(expected) {
            assert!((got - want).abs() < 1e-12, "{got} vs {want}");
        }
    }

    /// The thesis's hand conversion of a 3-node series to `A x^2 + B x + C`.
    #[test]
    fn quadratic_conversion_matches_the_thesis_closed_form() {
        let f = |x: f64| x.cos().powi(8);
        let (a, b) = (0.0, 0.6);
        let series = ChebyshevSeries::fit(f, a, b, 3);
        let c = series.coeffs();
        let (tm, tp) = ((b - a) / 2.0, (b + a) / 2.0);
        let thesis_a = 2.0 * c[2] / (tm * tm);
        let thesis_b = (c[1] * tm - 4.0 * c[2] * tp) / (tm * tm);
        let thesis_c = (2.0 * c[2] * tp * tp - c[1] * tp * tm) / (tm * tm) + c[0] / 2.0 - c[2];
        let power = series.to_power_basis();
        for (got, want) in power.coeffs().iter().zip([thesis_c, thesis_b, thesis_a]) {
            assert!((got - want).abs() < 1e-12, "{got} vs {want}");
        }
    }

    #[test]
    fn interpolates_at_the_nodes_and_truncation_keeps_leading_terms() {
        let series = ChebyshevSeries::fit(f64::exp, 0.0, 1.0, 8);
        let node = (core::f64::consts::PI * 0.5 / 8.0).cos() * 0.5 + 0.5;
        assert!((series.eval(node) - node.exp()).abs() < 1e-14);
        let short = series.truncated(3);
        assert_eq!(short.coeffs(), &series.coeffs()[..3]);
        assert!((short.eval(0.5) - 0.5f64.exp()).abs() < 1e-2);
    }
}
