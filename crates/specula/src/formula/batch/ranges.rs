//! The range analysis of a chain: which of the shared rules ([`Rules`]) its output needs, from `[0,
//! 1]`
//! in, by interval ends evaluated as the lanes round them.

use super::chain::{Chain, EXP2_DOMAIN};
use super::links::{Link, SavedOp};
use super::{Rules, ACOS_DOMAIN, LOG2_DOMAIN};

impl Chain {
    /// The rules the chain's output needs, from `[0, 1]` in, with the batch's `values`: its
    /// range by evaluating monotone links at the interval's ends in `f32` (each rounded
    /// monotone operation keeps the order of its inputs; a polynomial is monotone on its
    /// domain, and proven there when the interval lies inside it), any other link needing
    /// every rule. After a polynomial the ends are the library's, which the vector polynomial
    /// matches only to a few ulps, so the clamp stays.
    pub(super) fn rules(&self, values: &[f32]) -> Rules {
        // Rust's min and max ignore a NaN that the vector instructions return: with one
        // among the constants, the scalar ends prove nothing.
        if values.iter().any(|v| !v.is_finite()) {
            return Rules::ALL;
        }
        let (mut low, mut high) = (0.0_f32, 1.0_f32);
        let mut saved_range = (0.0_f32, 1.0_f32);
        let mut approximate = false;
        for &link in &self.links {
            let (a, b) = match link {
                Link::Save => {
                    saved_range = (low, high);
                    continue;
                }
                Link::Saved(op) => op.range((low, high), saved_range, values),
                link => {
                    let monotone = match link {
                        Link::Add(_)
                        | Link::Sub(_)
                        | Link::SubFrom(_)
                        | Link::Min(_)
                        | Link::Max(_) => true,
                        Link::Mul(_)
                        | Link::Fma(..)
                        | Link::NegFma(..)
                        | Link::Affine(..)
                        | Link::Neg => true,
                        Link::Div(s) => values[s] != 0.0,
                        Link::DivInto(_) => low > 0.0 || high < 0.0,
                        Link::Sqrt => low >= 0.0,
                        Link::Squarings(_) | Link::Abs | Link::Powi(_) => low >= 0.0,
                        Link::Exp2(scale) => EXP2_DOMAIN.holds(low * scale, high * scale),
                        Link::Log2 | Link::Ln | Link::Pow(_) => LOG2_DOMAIN.holds(low, high),
                        Link::Acos => ACOS_DOMAIN.holds(low, high),
                        Link::Lane(_) | Link::Save | Link::Saved(_) => false,
                    };
                    if !monotone {
                        return Rules::ALL;
                    }
                    approximate |= link.checked();
                    // A monotone link's ends; the saved value plays no part.
                    let mut unused = 0.0;
                    (
                        link.scalar(low, &mut unused, values),
                        link.scalar(high, &mut unused, values),
                    )
                }
            };
            if a.is_nan() || b.is_nan() {
                return Rules::ALL;
            }
            (low, high) = (a.min(b), a.max(b));
            if !(low.is_finite() && high.is_finite()) {
                return Rules::ALL;
            }
        }
        let mut saved = 0.0;
        let at_zero = self
            .links
            .iter()
            .fold(0.0_f32, |v, link| link.scalar(v, &mut saved, values));
        Rules {
            clamp: approximate || !(low >= 0.0 && high <= 1.0),
            mask: at_zero.to_bits() != 0,
            checked: false,
        }
    }
}

impl SavedOp {
    /// The range of the result, from the ranges of the value and the saved value (every
    /// corner, each rounded as the lanes round it; rounding is monotone, so the rounded
    /// results of values inside lie between the rounded corners).
    /// A product plus a constant is monotone in each operand, so its extremes are corners too.
    fn range(
        self,
        (low, high): (f32, f32),
        (s_low, s_high): (f32, f32),
        values: &[f32],
    ) -> (f32, f32) {
        let corners = [
            self.scalar(low, s_low, values),
            self.scalar(low, s_high, values),
            self.scalar(high, s_low, values),
            self.scalar(high, s_high, values),
        ];
        corners
            .iter()
            .fold((f32::INFINITY, f32::NEG_INFINITY), |(a, b), &c| {
                (a.min(c), b.max(c))
            })
    }
}
