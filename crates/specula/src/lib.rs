//! # specula: specular lobes of the Phong/Blinn family
//!
//! The core of the specula workbench: every model of the thesis and SPEC (`pow`, `schlick`,
//! `schlick-mod`, `cheb2-thesis`, `cheb2`, `logexp`, `cosquad`, and measured variants), the
//! geometries and normalisations that turn a lobe into a BRDF, and the analysis that measures
//! each model against `t^n`. No I/O: renderers, GPU code, hardware models and the CLI build on
//! this crate.
//!
//! ## Design
//! - **One formula, three arithmetics.** Each lobe is written once, generic over [`Real`]:
//!   `f64` is the reference, `f32` the fast path, [`ops::Counted`] counts operations (so the
//!   registry's cost column is measured, not typed).
//! - **Closed set, static dispatch.** [`LobeKind`] enumerates the models; [`Lobe`] is one
//!   prepared for an exponent, evaluated through a `match` (the shape of a WGSL `switch`).
//! - **Validated once.** [`Exponent`] holds an `n` in `[1, 1000]`; nothing downstream
//!   re-checks or clamps it.
//! - **Vocabulary** (pbrt's): directions `wo` (towards the viewer) and `wi` (towards the light)
//!   in a local frame whose `z` axis is the normal; angles in radians; `t` is the cosine the
//!   lobe is a function of (`R.V` for Phong, `N.H` for Blinn).
//!
//! ```
//! use specula::{Brdf, Exponent, Geometry, Lobe, LobeKind, Normalisation, Rgb};
//! # fn main() -> specula::Result<()> {
//! let n = Exponent::try_new(64.0)?; // validated once: [1, 1000]
//! let lobe = Lobe::new(LobeKind::CosQuad { v: 4 }, n); // prepared: `a` computed here
//! let value: f32 = lobe.eval(0.99_f32); // fast path
//! let reference: f64 = lobe.eval(0.99_f64); // reference path, same formula
//! assert!((f64::from(value) - reference).abs() < 1e-6);
//! assert_eq!(lobe.eval(-0.3_f64), 0.0);
//! let (kd, ks) = (Rgb::splat(0.2), Rgb::splat(0.8));
//! let brdf = Brdf::new(kd, ks, lobe, Geometry::Blinn, Normalisation::Lobe);
//! assert!(brdf.f(Rgb::Z, Rgb::Z).x > 0.0);
//! # Ok(())
//! # }
//! ```

pub mod analysis;
pub mod brdf;
pub mod claims;
mod error;
mod exponent;
pub mod expression;
pub mod fit;
pub mod formula;
pub mod geometry;
pub mod gpu_cost;
pub mod gpus;
pub mod lobe;
pub mod measured;
pub mod microfacet;
pub mod normalisation;
pub mod ops;
pub mod quadrature;
mod real;
pub mod sampling;
pub mod simd;
pub mod zones;

pub use brdf::{Brdf, ClassicModel, Rgb};
pub use error::{
    choose, did_you_mean, excerpt, line_column, nearest, Error, Result, QUOTED_CHARACTERS,
};
pub use exponent::Exponent;
pub use geometry::Geometry;
pub use lobe::{LineStyle, Lobe, LobeKind};
pub use normalisation::Normalisation;
pub use real::Real;
pub use zones::Zone;
