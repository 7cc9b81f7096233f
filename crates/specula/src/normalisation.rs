//! Normalisation: the factor `N(n)` that turns a peak-1 lobe into an energy-conserving BRDF
//! term (SPEC section 5).
//!
//! | id             | `N(n)`                                 | makes ... integrate to 1           |
//! |----------------|----------------------------------------|------------------------------------|
//! | `none`         | `1`                                    | (peak 1, the classic model)        |
//! | `lobe`         | `(n+1)/(2 pi)` for `t^n`; in general   | the lobe over the hemisphere       |
//! |                | `1 / (2 pi int_0^1 lobe(t) dt)`        | around its axis                    |
//! | `thesis-phong` | `1.063 n / (2 pi)`                     | the thesis's coef1, as stated      |
//! | `lafortune`    | `(n+2)/(2 pi)`                         | `t^n cos(theta)`, normal incidence |
//! | `blinn`        | `(n+2)(n+4) / (8 pi (2^(-n/2) + n))`   | Blinn's `(N.H)^n (N.L)`, normal    |
//! |                |                                        | incidence                          |
//! | `blinn-approx` | `(n+8)/(8 pi)`                         | the usual approximation of `blinn` |
//!
//! `lobe` applied to an approximation uses *that lobe's own* constant, computed numerically,
//! so a white furnace holds for it; the analytic `(n+1)/(2 pi)` of `t^n` applied to an
//! approximation scales its energy by exactly its energy ratio, which the analysis reports.

use core::f64::consts::PI;

use serde::Serialize;

use crate::error::{parse_choice, Error, Result};
use crate::quadrature::{integral_of_pieces, Integral};
use crate::real::Real;
use crate::{zones, Exponent, Lobe};

/// A normalisation of the specular lobe.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum Normalisation {
    /// Peak 1: the classic illumination model.
    #[default]
    None,
    /// The lobe's own energy-conserving constant (`(n+1)/(2 pi)` for `t^n`).
    Lobe,
    /// The thesis's `coef1(n) = 1.063 n / (2 pi)`.
    ThesisPhong,
    /// Lafortune's `(n+2)/(2 pi)` for the cosine-weighted Phong lobe.
    Lafortune,
    /// The exact normalisation of Blinn's lobe with the cosine factor.
    Blinn,
    /// `(n+8)/(8 pi)`, the common approximation of [`Normalisation::Blinn`].
    BlinnApprox,
}

impl Normalisation {
    /// Every normalisation.
    pub const ALL: [Normalisation; 6] = [
        Normalisation::None,
        Normalisation::Lobe,
        Normalisation::ThesisPhong,
        Normalisation::Lafortune,
        Normalisation::Blinn,
        Normalisation::BlinnApprox,
    ];

    /// The name used on the command line.
    #[must_use]
    pub fn id(self) -> &'static str {
        match self {
            Normalisation::None => "none",
            Normalisation::Lobe => "lobe",
            Normalisation::ThesisPhong => "thesis-phong",
            Normalisation::Lafortune => "lafortune",
            Normalisation::Blinn => "blinn",
            Normalisation::BlinnApprox => "blinn-approx",
        }
    }

    /// Parses a name from [`Normalisation::ALL`].
    pub fn parse(text: &str) -> Result<Self> {
        parse_choice("normalisation", text, &Self::ALL, Normalisation::id)
    }

    /// The analytic constant, a function of `n` alone (`lobe` gives that of `t^n`).
    #[must_use]
    pub fn analytic(self, n: Exponent) -> f64 {
        self.formula(n.get())
    }

    /// [`Normalisation::analytic`] in any [`Real`], so that a target with `n` as an input
    /// records it ([`crate::expression`]) and computes it from `n`.
    #[must_use]
    pub fn formula<R: Real>(self, n: R) -> R {
        let c = R::from_f64;
        match self {
            Normalisation::None => c(1.0),
            Normalisation::Lobe => (n + c(1.0)) / c(2.0 * PI),
            Normalisation::ThesisPhong => c(1.063) * n / c(2.0 * PI),
            Normalisation::Lafortune => (n + c(2.0)) / c(2.0 * PI),
            Normalisation::Blinn => {
                (n + c(2.0)) * (n + c(4.0)) / (c(8.0 * PI) * ((-n / c(2.0)).exp2() + n))
            }
            Normalisation::BlinnApprox => (n + c(8.0)) / c(8.0 * PI),
        }
    }

    /// The constant applied to `lobe`: its own numerically computed one for `lobe`
    /// ([`lobe_constant`]), the analytic one otherwise.
    #[must_use]
    pub fn constant_for(self, lobe: &Lobe) -> f64 {
        match self {
            Normalisation::Lobe => lobe_constant(lobe),
            other => other.analytic(lobe.exponent()),
        }
    }
}

impl core::str::FromStr for Normalisation {
    type Err = Error;
    fn from_str(text: &str) -> Result<Self> {
        Self::parse(text)
    }
}

/// `int_0^{pi/2} lobe(cos g) sin g dg`, the lobe's energy per unit solid angle around its axis
/// divided by `2 pi` (`1/(n+1)` for `t^n`).
///
/// Integrated in the angle, where every lobe is smooth between its known kinks (zone edges,
/// the quadratic lobes' cut-off), to a relative accuracy of about `1e-12`. Lobes with kinks
/// of their own ([`Lobe::kinks`], the bit tricks) are integrated in the cosine instead, as
/// `int_0^1 lobe(t) dt`: their kinks are cosines, and `acos` of a cosine near 1 places them
/// only to `1e-12` rad, which leaves a jump straddling a panel that no refinement resolves.
#[must_use]
pub fn lobe_integral(lobe: &Lobe) -> f64 {
    lobe_integral_estimate(lobe).value
}

/// [`lobe_integral`] with its error estimate and whether it met its tolerance within the
/// quadrature's budget ([`crate::quadrature::MAX_PANELS`]): a formula whose `f64` values carry
/// cancellation noise may not.
#[must_use]
pub fn lobe_integral_estimate(lobe: &Lobe) -> Integral {
    let scale = 1.0 / (lobe.exponent().get() + 1.0);
    let kinks = lobe.kinks();
    if kinks.is_empty() {
        return integral_of_pieces(
            |g| lobe.eval_angle(g) * g.sin(),
            &zones::breakpoints(lobe),
            1e-13 * scale,
        );
    }
    let n = lobe.exponent();
    let mut cuts = vec![0.0, zones::bloom_cos(n), zones::epicentre_cos(n), 1.0];
    cuts.extend(kinks);
    integral_of_pieces(|t| lobe.eval(t), &cuts, 1e-13 * scale)
}

/// The constant that makes `lobe` integrate to 1 over the hemisphere around its axis:
/// `1 / (2 pi lobe_integral(lobe))`.
#[must_use]
pub fn lobe_constant(lobe: &Lobe) -> f64 {
    1.0 / (2.0 * PI * lobe_integral(lobe))
}
