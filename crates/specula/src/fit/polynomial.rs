//! Polynomials in the power basis.

use serde::Serialize;

/// `sum_k coeffs[k] * x^k`, coefficients in ascending powers.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Polynomial {
    coeffs: Vec<f64>,
}

impl Polynomial {
    /// The polynomial with the given ascending coefficients (an empty slice is the zero
    /// polynomial).
    #[must_use]
    pub fn new(coeffs: Vec<f64>) -> Self {
        Self { coeffs }
    }

    /// The coefficients in ascending powers: `[c0, c1, c2, ...]`.
    #[must_use]
    pub fn coeffs(&self) -> &[f64] {
        &self.coeffs
    }

    /// The number of coefficients less one (the zero polynomial reports 0).
    #[must_use]
    pub fn degree(&self) -> usize {
        self.coeffs.len().saturating_sub(1)
    }

    /// Evaluates by Horner's rule.
    #[must_use]
    pub fn eval(&self, x: f64) -> f64 {
        self.coeffs.iter().rev().fold(0.0, |acc, &c| acc * x + c)
    }

    /// `q(x) = p(scale * x + offset)`, the change of variable that maps a fit made on a
    /// normalised interval back to the caller's variable.
    #[must_use]
    pub fn compose_linear(&self, scale: f64, offset: f64) -> Polynomial {
        // Horner over polynomials: q = (...(c_d * u + c_{d-1}) * u + ...) with u = scale*x +
        // offset.
        let mut result: Vec<f64> = Vec::with_capacity(self.coeffs.len());
        for &c in self.coeffs.iter().rev() {
            let mut next = vec![0.0; result.len() + 1];
            for (power, &r) in result.iter().enumerate() {
                next[power] += r * offset;
                next[power + 1] += r * scale;
            }
            next[0] += c;
            result = next;
        }
        Polynomial::new(result)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn horner_matches_the_expanded_form() {
        let p = Polynomial::new(vec![1.0, -2.0, 3.0]);
        assert_eq!(p.eval(2.0), 1.0 - 4.0 + 12.0);
        assert_eq!(p.degree(), 2);
    }

    #[test]
    fn composition_is_substitution() {
        let p = Polynomial::new(vec![0.5, -1.0, 2.0, 0.25]);
        let q = p.compose_linear(3.0, -0.5);
        for x in [-1.0, 0.0, 0.3, 2.0] {
            assert!((q.eval(x) - p.eval(3.0 * x - 0.5)).abs() < 1e-12);
        }
    }
}
