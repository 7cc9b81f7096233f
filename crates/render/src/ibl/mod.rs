//! Image-based lighting: a scene lit by an environment map, rendered by Monte Carlo
//! integration with multiple importance sampling (`specula render --env FILE|sky --spp N`).
//!
//! The radiance leaving a visible point towards the camera is
//! `Lo(wo) = integral over the hemisphere of f(wo, wi) L(wi) cos(theta_i) dwi`, with the
//! physical model's BRDF `f = kd C / pi + ks S N(n) lobe(t)` (SPEC section 6) and `L` the
//! environment. Each sample takes two directions (Veach's multiple importance sampling, one
//! sample per strategy, power heuristic):
//! - one from the **environment** ([`Environment::sample`]: in proportion to luminance times
//!   solid angle), which finds the sun whatever the lobe;
//! - one from the **BRDF**: the lobe's own sampler ([`specula::sampling::SpecularSampler`])
//!   or the cosine, picked in proportion to the specular and diffuse colours' luminance,
//!   which finds a narrow highlight whatever the map.
//!
//! Either alone is unbiased too ([`Strategy`]); the tests use that to check one against the
//! other, and a white furnace (a constant environment) against the lobe's quadrature albedo.
//!
//! **Scope.** The environment is at infinity and unoccluded: a surface sees the whole map
//! (no shadows, no interreflection), which is what an engine's image-based specular term
//! computes, and keeps every difference between two renders the lobe's. Primary visibility
//! is the rasterizer's (`pipeline.rs`), so IBL renders line up pixel for pixel with the
//! rasterized ones; a pixel's `spp` samples cycle through its `samples x samples` positions,
//! which antialiases edges at no extra cost. Random numbers are a function of (seed, pixel
//! sample, dimension), so an image is identical on any number of threads.
//!
//! Two estimators compute this: the plain one in `f64` (`trace.rs`, through
//! [`Environment::sample`] and [`specula::sampling::SpecularSampler`], for any
//! [`Reflectance`]: measured and fitted materials), and, for the scene's own materials, the
//! same estimator over packets of samples in `f32` (`packet.rs`: the map drawn by its alias
//! table a run of pixels ahead (`ahead.rs`), tabulated lobes from `f32` tables, several
//! lobes' images from one pass).

mod ahead;
mod angles;
mod draws;
mod environment;
mod lane_geometry;
mod lanes;
mod packet;
mod sky;
mod trace;
mod weights;

pub use crate::pipeline::MAX_SPP;
pub use environment::{Environment, EnvironmentError, EnvironmentSample};
pub use sky::{sun_direction, SKY_WIDTH, SUN_RADIANCE, SUN_RADIUS};
pub use trace::{
    cosine_direction, render_ibl, render_ibl_each, render_ibl_grid, render_ibl_lobes,
    render_ibl_with, MaterialReflectance, Reflectance,
};

/// How each sample of the reflected radiance is drawn.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Strategy {
    /// One direction from each strategy, weighted by the power heuristic.
    #[default]
    Mis,
    /// Directions from the BRDF only (noisy where a small bright source meets a broad lobe).
    Brdf,
    /// Directions from the environment only (noisy where a narrow lobe meets a broad sky).
    Environment,
}

/// How an environment-lit render samples.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct IblSettings {
    /// Samples per pixel, in `[1, MAX_SPP]`.
    pub spp: u32,
    /// The stream of uniform numbers: renders with different seeds are independent.
    pub seed: u64,
    /// The sampling strategy.
    pub strategy: Strategy,
}

impl Default for IblSettings {
    fn default() -> Self {
        Self {
            spp: 64,
            seed: 0,
            strategy: Strategy::Mis,
        }
    }
}
