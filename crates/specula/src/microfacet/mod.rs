//! The lobes as microfacet distributions: the thesis's approximations inside physically based
//! shading.
//!
//! A microfacet BRDF is `f(wo, wi) = D(h) G2(wo, wi) F(wo . h) / (4 cos theta_o cos theta_i)`
//! (z is the normal, `h` the half vector). Walter et al. (2007) read the Phong lobe as one of
//! its normal distributions, `D(h) = (n + 2) / (2 pi) cos^n theta_h`, matched to Beckmann's by
//! `alpha = sqrt(2 / (n + 2))`; every lobe of specula approximates that `cos^n`, so each is a
//! candidate distribution `D(h) = C(n) lobe(cos theta_h)`:
//!
//! - **`C(n)`** makes the projected microfacet area one, `int D cos theta_h dw = 1`
//!   (`(n + 2) / (2 pi)` for `pow`, by quadrature for the others: [`tabulated`]);
//! - **`G1 = 1 / (1 + Lambda)`**, Smith's masking, with `Lambda` from the distribution's own
//!   projected area (tabulated per lobe and `n`; Walter's approximation is the check for `pow`);
//! - **`G2 = 1 / (1 + Lambda(wo) + Lambda(wi))`**, the height-correlated masking-shadowing;
//! - **`F`**, Schlick's Fresnel, `F0 + (1 - F0) (1 - cos)^5`.
//!
//! Beckmann's and GGX's distributions stand beside them in closed form ([`closed`]). The
//! microfacet model is a model beside the classic `ks N(n) lobe(t)`, not a replacement.

pub mod closed;
pub mod energy;
pub mod tabulated;

use std::sync::Arc;

use glam::DVec3;

use crate::{Exponent, Lobe, LobeKind};

pub use tabulated::TableIndex;
use tabulated::Tabulated;

/// A normal distribution, its parameter set.
#[derive(Clone, Debug)]
pub enum Distribution {
    /// A lobe of specula as `C(n) lobe(cos theta_h)`, tabulated at its `n`.
    Lobe {
        /// The lobe at its exponent.
        lobe: Lobe,
        /// Its normalisation, masking and sampling tables.
        table: Arc<Tabulated>,
    },
    /// Beckmann's distribution of roughness `alpha`.
    Beckmann {
        /// The roughness (RMS slope).
        alpha: f64,
    },
    /// GGX (Trowbridge-Reitz) of roughness `alpha`.
    Ggx {
        /// The roughness.
        alpha: f64,
    },
}

impl Distribution {
    /// `kind` at `n` as a normal distribution.
    #[must_use]
    pub fn lobe(kind: LobeKind, n: Exponent) -> Self {
        Self::lobe_within(kind, n, tabulated::TOLERANCE)
    }

    /// [`Distribution::lobe`] with its normalisation and `Lambda` integrated to within
    /// `tolerance` ([`Tabulated::with_tolerance`]).
    #[must_use]
    pub fn lobe_within(kind: LobeKind, n: Exponent, tolerance: f64) -> Self {
        let lobe = Lobe::new(kind, n);
        let table = Tabulated::with_tolerance(
            move |c| lobe.eval(c),
            tabulated::lobe_width(n.get()),
            tolerance,
        );
        Self::Lobe {
            lobe,
            table: Arc::new(table),
        }
    }

    /// A short name: `cosquad`, `beckmann`, `ggx`.
    #[must_use]
    pub fn label(&self) -> String {
        match self {
            Self::Lobe { lobe, .. } => lobe.kind().to_string(),
            Self::Beckmann { .. } => "beckmann".to_owned(),
            Self::Ggx { .. } => "ggx".to_owned(),
        }
    }

    /// The angle (radians) its peak spans, where quadratures place their breakpoints: a
    /// lobe's Walter width `sqrt(2 / (n + 2))`, Beckmann's and GGX's `alpha`.
    #[must_use]
    pub fn width(&self) -> f64 {
        match self {
            Self::Lobe { lobe, .. } => tabulated::lobe_width(lobe.exponent().get()),
            Self::Beckmann { alpha } | Self::Ggx { alpha } => *alpha,
        }
    }

    /// `D` at the half vector's cosine `cos_h` (0 at or below the horizon).
    #[must_use]
    pub fn d(&self, cos_h: f64) -> f64 {
        if cos_h <= 0.0 {
            return 0.0;
        }
        match self {
            Self::Lobe { lobe, table } => table.normaliser() * lobe.eval(cos_h.min(1.0)),
            Self::Beckmann { alpha } => closed::beckmann_d(*alpha, cos_h),
            Self::Ggx { alpha } => closed::ggx_d(*alpha, cos_h),
        }
    }

    /// Smith's `Lambda` at a direction of cosine `cos_theta`.
    #[must_use]
    pub fn lambda(&self, cos_theta: f64) -> f64 {
        match self {
            Self::Lobe { table, .. } => table.lambda(cos_theta),
            Self::Beckmann { alpha } => closed::beckmann_lambda(*alpha, cos_theta),
            Self::Ggx { alpha } => closed::ggx_lambda(*alpha, cos_theta),
        }
    }

    /// Smith's masking of a direction of cosine `cos_theta`, `1 / (1 + Lambda)`.
    #[must_use]
    pub fn g1(&self, cos_theta: f64) -> f64 {
        1.0 / (1.0 + self.lambda(cos_theta))
    }

    /// The height-correlated masking-shadowing of `wo` and `wi`.
    #[must_use]
    pub fn g2(&self, cos_o: f64, cos_i: f64) -> f64 {
        1.0 / (1.0 + self.lambda(cos_o) + self.lambda(cos_i))
    }

    /// [`Distribution::g2`] of two directions placed in the lobes' `Lambda` table once (a
    /// fit evaluates hundreds of distributions at the same directions).
    #[must_use]
    pub fn g2_at(&self, wo: &TableIndex, wi: &TableIndex) -> f64 {
        let lambda = |index: &TableIndex| match self {
            Self::Lobe { table, .. } => table.lambda_at(index),
            _ => self.lambda(index.cos_theta()),
        };
        1.0 / (1.0 + lambda(wo) + lambda(wi))
    }

    /// A normal drawn with density `D(h) cos theta_h` from `u` in `[0, 1)^2`.
    #[must_use]
    pub fn sample_normal(&self, u: [f64; 2]) -> DVec3 {
        let cos_theta = match self {
            Self::Lobe { table, .. } => table.sample_theta(u[0]).cos(),
            Self::Beckmann { alpha } => closed::beckmann_sample_cos(*alpha, u[0]),
            Self::Ggx { alpha } => closed::ggx_sample_cos(*alpha, u[0]),
        };
        let sin_theta = (1.0 - cos_theta * cos_theta).max(0.0).sqrt();
        let (s, c) = (core::f64::consts::TAU * u[1]).sin_cos();
        DVec3::new(sin_theta * c, sin_theta * s, cos_theta)
    }

    /// The density [`Distribution::sample_normal`] draws `h` with, per solid angle.
    #[must_use]
    pub fn pdf_normal(&self, h: DVec3) -> f64 {
        self.d(h.z) * h.z.max(0.0)
    }
}

/// Schlick's Fresnel at the cosine between the view and the half vector.
#[must_use]
pub fn fresnel_schlick(f0: f64, cos: f64) -> f64 {
    let m = (1.0 - cos.clamp(0.0, 1.0)).powi(5);
    f0 + (1.0 - f0) * m
}

/// The microfacet BRDF of a distribution with Schlick's Fresnel.
#[derive(Clone, Debug)]
pub struct MicrofacetBrdf {
    /// The normal distribution.
    pub distribution: Distribution,
    /// Fresnel's reflectance at normal incidence (1: no Fresnel, a conductor's white).
    pub f0: f64,
}

impl MicrofacetBrdf {
    /// `f(wo, wi)` in the local frame; 0 where either direction is at or below the horizon.
    #[must_use]
    pub fn f(&self, wo: DVec3, wi: DVec3) -> f64 {
        if wo.z <= 0.0 || wi.z <= 0.0 {
            return 0.0;
        }
        let h = (wo + wi).normalize();
        self.distribution.d(h.z)
            * self.distribution.g2(wo.z, wi.z)
            * fresnel_schlick(self.f0, wo.dot(h))
            / (4.0 * wo.z * wi.z)
    }

    /// `wi` drawn by sampling `h` with density `D cos theta_h` and reflecting `wo` about it,
    /// with its density per solid angle, `D(h) cos theta_h / (4 |wo . h|)`; `None` where the
    /// reflection falls below the horizon.
    #[must_use]
    pub fn sample(&self, wo: DVec3, u: [f64; 2]) -> Option<(DVec3, f64)> {
        let h = self.distribution.sample_normal(u);
        let cos = wo.dot(h);
        if cos <= 0.0 {
            return None;
        }
        let wi = 2.0 * cos * h - wo;
        (wi.z > 0.0).then(|| (wi, self.pdf(wo, wi)))
    }

    /// The density [`MicrofacetBrdf::sample`] draws `wi` with.
    #[must_use]
    pub fn pdf(&self, wo: DVec3, wi: DVec3) -> f64 {
        if wo.z <= 0.0 || wi.z <= 0.0 {
            return 0.0;
        }
        let h = (wo + wi).normalize();
        self.distribution.pdf_normal(h) / (4.0 * wo.dot(h).abs())
    }
}
