//! The explorer's one lit sphere, described once: the camera, the material and the lighting
//! the CPU renders (`explorer::scene`), the reference the browser check compares against
//! (`live.rs`) and the page's WebGL2 views (`live.js`, from `/api/models`' `live`) share.

use serde::Serialize;
use specula::Normalisation;
use specula_render::ToneMap;

/// The lit sphere of the explorer: the camera, the material and the lighting the CPU renders
/// (`explorer::scene`) and the live views (`live.js`, from `/api/models`' `live`) share.
#[derive(Clone, Copy, Debug, Serialize)]
pub struct LiveScene {
    /// The camera sits at `(0, -eye_distance, 0)`, looks at the origin with `z` up.
    pub eye_distance: f32,
    /// The vertical field of view, degrees.
    pub fov_y_deg: f32,
    /// The diffuse and ambient colour, linear RGB (the specular colour is white).
    pub colour: [f32; 3],
    /// The ambient coefficient.
    pub ka: f32,
    /// The diffuse coefficient.
    pub kd: f32,
    /// The specular coefficient (times `N(n)` and the lobe).
    pub ks: f32,
    /// The ambient light, linear RGB.
    pub ambient: [f32; 3],
    /// The radiance where the ray misses the sphere.
    pub background: [f32; 3],
}

/// The one sphere setup.
pub const LIVE_SCENE: LiveScene = LiveScene {
    eye_distance: 4.2,
    fov_y_deg: 32.0,
    colour: [0.7, 0.25, 0.2],
    ka: 0.1,
    kd: 0.5,
    ks: 0.5,
    ambient: [0.04, 0.04, 0.045],
    background: [0.12, 0.12, 0.13],
};

/// The tone map of a render with `normalisation`: a normalised lobe's peak is far above 1, so
/// it is compressed rather than clipped.
#[must_use]
pub fn tonemap_for(normalisation: Normalisation) -> ToneMap {
    if normalisation == Normalisation::None {
        ToneMap::Clamp
    } else {
        ToneMap::Reinhard
    }
}

/// The direction towards a light at polar angle `theta` from the camera's axis (`-y`, the
/// camera looks along `+y`) and azimuth `phi`, radians.
#[must_use]
pub fn light_towards(theta: f64, phi: f64) -> [f64; 3] {
    let (st, ct) = theta.sin_cos();
    let (sp, cp) = phi.sin_cos();
    [st * cp, -ct, st * sp]
}
