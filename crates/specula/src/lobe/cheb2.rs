//! # `cheb2`: the thesis's Chebyshev method, applied per `n` by specula
//!
//! ```text
//! cheb2(g) = max(0, C + B g + A g^2),   g = acos(t)
//! [C, B, A] = power basis of the 3-node Chebyshev series of cos^n(g) on [0, g_half(n)]
//! g_half(n) = acos(2^(-1/n))   (the epicentre, SPEC section 3)
//! ```
//!
//! Where `cheb2-thesis` uses the slide's linear summaries of the coefficients, `cheb2` runs the
//! thesis's own fitting procedure ([`ChebyshevSeries`](crate::fit::ChebyshevSeries), `N = 3`)
//! for the exact `n` requested, over the epicentre, the zone the thesis's 0.5 % claim is about.
//! The fit is computed once per `n` and cached. Past the epicentre the quadratic is an
//! extrapolation; it is cut to 0 at its first zero.
//!
//! - **Parameters**: the exponent `n`.
//! - **Domain**: `g in [0, pi/2)`; from a cosine, `g = acos(t)`.
//! - **Cost**: two multiplies, two adds (Horner), plus the `acos` when fed a cosine; the
//!   coefficients come from a table indexed by `n` (a ROM in hardware).
//! - **Sampling**: Newton on the quadratic's closed-form integral (see `quadratic.rs`), or
//!   a table when the fit overshoots 1 at the peak and is clamped.
//! - **Source**: the thesis's method; coefficients computed by specula.

use super::info::{LineStyle, LobeInfo, Origin};
use super::quadratic::AngleQuadratic;
use crate::fit::{cached_angle_quadratic, AngleFit};
use crate::Exponent;

/// The registry's entry for this lobe.
pub(super) const INFO: LobeInfo = LobeInfo {
    id: "cheb2",
    summary: "quadratic in the angle, 3-node Chebyshev fit of cos^n over the epicentre",
    formula: "max(0, C + B g + A g^2), g = acos t, fitted per n",
    takes_angle: true,
    params: &[],
    origin: Origin::Thesis,
};

/// How every plot draws this lobe (`LobeKind::line_style`).
pub(super) const STYLE: LineStyle = LineStyle {
    rgb: [0, 103, 165],
    dashed: false,
};

/// What this lobe prepares (its `Model` variant holds it).
pub(super) type Prepared = AngleQuadratic;

pub(super) fn prepare(n: Exponent) -> Prepared {
    AngleQuadratic::new(cached_angle_quadratic(AngleFit::Chebyshev3, n))
}
