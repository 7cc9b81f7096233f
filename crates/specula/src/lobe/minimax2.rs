//! # `minimax2`: the best quadratic in the angle for the epicentre (beyond the thesis)
//!
//! ```text
//! minimax2(g) = max(0, C + B g + A g^2),   g = acos(t)
//! [C, B, A] = argmin max_{g in [0, g_half(n)]} |q(g) - cos^n g| / cos^n g   (Remez exchange)
//! ```
//!
//! The same datapath as `cheb2` (same cost, same ROM), with the coefficients that minimise the
//! epicentre's largest *relative* error instead of interpolating at Chebyshev nodes. It answers
//! "how good can a quadratic in the angle be?", the bound against which `cheb2` and
//! `cheb2-thesis` are judged. Cached per `n` like `cheb2`.
//!
//! - **Parameters**: the exponent `n`.
//! - **Domain**: `g in [0, pi/2)`; from a cosine, `g = acos(t)`.
//! - **Cost**: as `cheb2`.
//! - **Sampling**: Newton on the quadratic's closed-form integral (see `quadratic.rs`), or
//!   a table when the fit overshoots 1 at the peak and is clamped.
//! - **Source**: specula (a variant measured like the thesis's models, SPEC section 2).

use super::quadratic::AngleQuadratic;
use crate::fit::{cached_angle_quadratic, AngleFit};
use crate::Exponent;

pub(crate) fn new(n: Exponent) -> AngleQuadratic {
    AngleQuadratic::new(cached_angle_quadratic(AngleFit::MinimaxRelative, n))
}
