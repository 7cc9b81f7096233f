//! The explorer's "lit by the environment" view: the environment scene (a sphere and the
//! teapot) lit by the procedural sky, as `specula render --env sky` draws it, at a size and
//! sample count that answer in about a second on a laptop's cores.
//!
//! The sky is made once, at its first request. Every render uses seed 0, so two lobes' images
//! share their random numbers and their difference is the lobes', not the noise's.

use std::sync::OnceLock;

use specula::{Exponent, Geometry, LobeKind, Normalisation};
use specula_render::ibl::{render_ibl, Environment, IblSettings, Strategy, SKY_WIDTH};
use specula_render::{Overrides, Scene};

/// The largest environment render width, in pixels (the height is 9/16 of it).
pub const MAX_ENVIRONMENT_SIZE: u32 = 768;

/// The most samples per pixel the explorer asks the server for.
pub const MAX_ENVIRONMENT_SPP: u32 = 256;

/// One environment render.
#[derive(Clone, Copy, Debug)]
pub struct EnvironmentRequest {
    pub kind: LobeKind,
    pub n: Exponent,
    pub geometry: Geometry,
    pub normalisation: Normalisation,
    pub size: u32,
    pub spp: u32,
}

/// The environment scene with the request's lobe and size.
fn scene(request: &EnvironmentRequest) -> Scene {
    let mut scene = Scene::ibl_scene();
    scene.apply(&Overrides {
        lobe: Some(request.kind),
        n: Some(request.n),
        geometry: Some(request.geometry),
        normalisation: Some(request.normalisation),
        width: Some(request.size),
        height: Some((request.size * 9 / 16).max(1)),
        ..Overrides::default()
    });
    scene
}

/// The procedural sky, made at its first use (the measured materials' renders share it).
pub fn sky() -> &'static Environment {
    static SKY: OnceLock<Environment> = OnceLock::new();
    SKY.get_or_init(|| Environment::sky(SKY_WIDTH))
}

/// The render as an sRGB PNG.
pub fn environment_png(request: &EnvironmentRequest) -> Result<Vec<u8>, String> {
    let sky = sky();
    let scene = scene(request);
    let settings = IblSettings {
        spp: request.spp,
        seed: 0,
        strategy: Strategy::Mis,
    };
    let image = render_ibl(&scene, sky, &settings, &|_, _| {}).map_err(|e| e.to_string())?;
    specula_render::encode_png_srgb8(
        image.width(),
        image.height(),
        &image.to_srgb8(scene.display),
    )
    .map_err(|e| e.to_string())
}
