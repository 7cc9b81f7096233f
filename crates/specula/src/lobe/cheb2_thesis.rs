//! # `cheb2-thesis`: the thesis's quadratic Chebyshev lobe, with the slide's coefficients
//!
//! ```text
//! cheb2-thesis(g) = max(0, C + B g + A g^2),   g = acos(t)
//! A = fra(n) = -0.272 n - 0.16
//! B = frb(n) = -0.018 n - 0.158   for  1 <= n < 32
//!              -0.010 n - 0.38    for 32 <= n < 64
//!              -0.005 n - 0.7     for 64 <= n < 256
//!              -0.003 n - 1.2     for 256 <= n <= 1000
//! C = 1
//! ```
//!
//! The thesis fits one quadratic per power by a 3-node Chebyshev series and then summarises the
//! coefficients as the linear functions of `n` above. The slide's ranges are integer
//! (`1..31`, `32..63`, ...); specula reads them as half-open intervals so that every real `n`
//! has exactly one piece. Both coefficients are negative, so the quadratic falls monotonically
//! from 1 at `g = 0` to its zero, beyond which the lobe is 0. Its input is the **angle**: with
//! angle interpolation (SPEC section 7) it needs no `acos`.
//!
//! - **Parameters**: the exponent `n`.
//! - **Domain**: `g in [0, pi/2)`; from a cosine, `g = acos(t)`.
//! - **Cost**: two multiplies, two adds (Horner), plus the `acos` when fed a cosine.
//! - **Sampling**: Newton on the quadratic's closed-form integral (see `quadratic.rs`), or
//!   a table when the fit overshoots 1 at the peak and is clamped.
//! - **Source**: the thesis, slide "Approximating the BRDF with Chebyshev polynomials".

use super::info::{LineStyle, LobeInfo, Origin};
use super::quadratic::AngleQuadratic;
use crate::Exponent;

/// The registry's entry for this lobe.
pub(super) const INFO: LobeInfo = LobeInfo {
    id: "cheb2-thesis",
    summary: "quadratic in the angle, the thesis's slide coefficients fra(n), frb(n)",
    formula: "max(0, 1 + frb(n) g + fra(n) g^2), g = acos t",
    takes_angle: true,
    params: &[],
    origin: Origin::Thesis,
};

/// How every plot draws this lobe (`LobeKind::line_style`).
pub(super) const STYLE: LineStyle = LineStyle {
    rgb: [51, 187, 238],
    dashed: true,
};

/// What this lobe prepares (its `Model` variant holds it).
pub(super) type Prepared = AngleQuadratic;

/// The slide's coefficients `[C, B, A]` for exponent `n`.
#[must_use]
pub fn thesis_coefficients(n: Exponent) -> [f64; 3] {
    let n = n.get();
    let a = -0.272 * n - 0.16;
    let b = if n < 32.0 {
        -0.018 * n - 0.158
    } else if n < 64.0 {
        -0.01 * n - 0.38
    } else if n < 256.0 {
        -0.005 * n - 0.7
    } else {
        -0.003 * n - 1.2
    };
    [1.0, b, a]
}

pub(super) fn prepare(n: Exponent) -> Prepared {
    AngleQuadratic::new(thesis_coefficients(n))
}
