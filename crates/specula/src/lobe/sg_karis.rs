//! # `sg-karis`: the spherical Gaussian with a fitted rate
//!
//! ```text
//! sg-karis(t) = exp2(r (t - 1)),   r = (n + 0.775) log2(e)
//! ```
//!
//! The plain Gaussian `exp(n (t - 1))` is wider than `t^n` everywhere; sharpening it by a
//! constant offset to the exponent trades an undershoot near the peak (where the offset makes
//! it narrower) for a smaller overshoot at the epicentre's edge. The relative error against
//! `t^n` is `exp(f(t)) - 1` with `f(t) = (n + c)(t - 1) - n ln t`, whose extremes over the
//! epicentre are at its edge `t = 2^(-1/n)` and at `t = n / (n + c)`, where
//! `f = n ln((n + c)/n) - c`: both closed forms are tested. The offset 0.775 is the published
//! one, kept because it is what engines ship; for the epicentre's largest relative error it is
//! not the best: it is worse than no offset (0.46 % against 0.37 % at `n = 64`), and the
//! best constant, about 0.288 at every `n`, would cut the error sixfold (docs/decisions.md).
//!
//! - **Parameters**: the exponent `n`.
//! - **Domain**: `t in (0, 1]`; the value lies in `(0, 1]`.
//! - **Cost**: as `sg`; the offset is folded into the rate.
//! - **Source**: the `(n + 0.775)` rate of the spherical-Gaussian Blinn-Phong used in Unreal
//!   Engine 4's shading (B. Karis, "Real Shading in Unreal Engine 4", 2013, and its mobile
//!   path), after S. Lagarde (2012).

use super::info::{LineStyle, LobeInfo, Origin};
use super::sg::Sg;
use crate::Exponent;

/// The registry's entry for this lobe.
pub(super) const INFO: LobeInfo = LobeInfo {
    id: "sg-karis",
    summary: "the spherical Gaussian with the fitted rate n + 0.775 (UE4)",
    formula: "exp((n + 0.775) (t - 1))",
    takes_angle: false,
    params: &[],
    origin: Origin::Literature,
};

/// How every plot draws this lobe (`LobeKind::line_style`).
pub(super) const STYLE: LineStyle = LineStyle {
    rgb: [249, 147, 121],
    dashed: true,
};

/// What this lobe prepares (its `Model` variant holds it).
pub(super) type Prepared = Sg;

/// The published offset added to `n`.
pub const KARIS_OFFSET: f64 = 0.775;

pub(super) fn prepare(n: Exponent) -> Prepared {
    Sg::new(n, KARIS_OFFSET)
}
