//! The explorer's volume view: a built-in volume ray marched with a chosen lobe, shaded as
//! `specula volume --mode dvr` shades it (with the volume's default transfer function).
//!
//! Each built-in volume is made once, at its first request, on a grid small enough to ray
//! march at interactive rates on a laptop's cores: the Shepp-Logan head at 64^3, the
//! Marschner-Lobb signal on its classic 41^3 grid.

use std::sync::OnceLock;

use specula::{Exponent, Geometry, Lobe, LobeKind, Normalisation};
use specula_render::volume::phantom::BuiltIn;
use specula_render::volume::raymarch::{render_dvr, DvrSettings, Shading, View};
use specula_render::volume::Volume;
use specula_render::Display;

/// The largest volume render side, in pixels.
pub const MAX_VOLUME_SIZE: u32 = 512;

/// The explorer's grid side of a built-in volume.
fn side(volume: BuiltIn) -> usize {
    match volume {
        BuiltIn::SheppLogan => 64,
        BuiltIn::MarschnerLobb => 41,
    }
}

/// The volume, made at its first request.
fn made(volume: BuiltIn) -> Result<&'static Volume, String> {
    static MADE: [OnceLock<Result<Volume, String>>; BuiltIn::ALL.len()] =
        [const { OnceLock::new() }; BuiltIn::ALL.len()];
    MADE[volume as usize]
        .get_or_init(|| volume.make(side(volume)).map_err(|e| e.to_string()))
        .as_ref()
        .map_err(Clone::clone)
}

/// One volume render.
#[derive(Clone, Copy, Debug)]
pub struct VolumeRequest {
    pub volume: BuiltIn,
    pub view: View,
    pub kind: LobeKind,
    pub n: Exponent,
    pub geometry: Geometry,
    pub normalisation: Normalisation,
    pub size: u32,
}

/// The render as an sRGB PNG.
pub fn volume_png(request: &VolumeRequest) -> Result<Vec<u8>, String> {
    let volume = made(request.volume)?;
    let transfer = request.volume.transfer().for_volume(volume);
    let shading = Shading::new(
        Lobe::new(request.kind, request.n),
        request.geometry,
        request.normalisation,
    );
    let settings = DvrSettings::new(request.size, request.size, request.view, Some(shading));
    let image = render_dvr(volume, &transfer, &settings, &|| {}).map_err(|e| e.to_string())?;
    let display = Display::default();
    specula_render::encode_png_srgb8(image.width(), image.height(), &image.to_srgb8(display))
        .map_err(|e| e.to_string())
}
