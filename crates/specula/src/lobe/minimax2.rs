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

use super::info::{LineStyle, LobeInfo, Origin};
use super::quadratic::AngleQuadratic;
use crate::fit::{cached_angle_quadratic, AngleFit};
use crate::Exponent;

/// The registry's entry for this lobe.
pub(super) const INFO: LobeInfo = LobeInfo {
    id: "minimax2",
    summary: "quadratic in the angle, minimax relative error over the epicentre",
    formula: "max(0, C + B g + A g^2), g = acos t, Remez per n",
    takes_angle: true,
    params: &[],
    origin: Origin::Specula,
};

/// How every plot draws this lobe (`LobeKind::line_style`).
pub(super) const STYLE: LineStyle = LineStyle {
    rgb: [96, 78, 151],
    dashed: false,
};

/// What this lobe prepares (its `Model` variant holds it).
pub(super) type Prepared = AngleQuadratic;

pub(super) fn prepare(n: Exponent) -> Prepared {
    AngleQuadratic::new(cached_angle_quadratic(AngleFit::MinimaxRelative, n))
}
