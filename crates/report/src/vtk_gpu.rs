//! The medical section's lobe inside VTK's GPU ray caster (what 3D Slicer and ParaView draw
//! with): the first real scan drawn by `vtkGPUVolumeRayCastMapper` with [`LOBE`] in place of
//! its `pow` (the module of `specula shader --lang vtk`), beside specula's marcher set up for
//! that caster ([`vtk::alike_gpu_settings`]), and how far apart they are.

use std::path::Path;

use specula::{Exponent, Geometry, Lobe, LobeKind, Normalisation};
use specula_gpu::export::Engine;
use specula_render::Display;
use specula_volume::dvr::{render_dvr_prepared, DvrSettings, View};
use specula_volume::march::PreparedVolume;
use specula_volume::transfer::TransferFunction;
use specula_volume::{vtk, Volume};

use super::html::paragraph;
use super::Context;
use crate::medical::EXPONENT;
use crate::vtk_peer;

/// The lobe VTK draws with: the thesis's cosine-quadratic, the section's own images' lobe.
const LOBE: LobeKind = LobeKind::CosQuad {
    v: specula::lobe::CosQuad::DEFAULT_V,
};

/// specula's settings for the GPU caster and VTK's job for them, writing the lobe's module
/// and VTK's image into `folder`; `file` is the NIfTI file VTK reads.
pub(crate) fn setup(
    volume: &Volume,
    file: &Path,
    transfer: &TransferFunction,
    side: u32,
    sample_distance: f32,
    folder: &Path,
) -> Result<(DvrSettings, vtk::VtkJob), String> {
    let lobe = Lobe::new(LOBE, Exponent::new(EXPONENT));
    let settings =
        vtk::alike_gpu_settings(volume, side, side, View::Anterior, lobe, sample_distance)
            .map_err(|e| e.to_string())?;
    let module = folder.join("specula_lobe_vtk.py");
    let text = Engine::Vtk
        .write(&lobe, Geometry::Phong, Normalisation::None)
        .map_err(|e| e.to_string())?;
    std::fs::write(&module, text).map_err(|e| format!("{}: {e}", module.display()))?;
    let job = vtk::job(
        volume,
        file,
        transfer,
        &settings,
        &folder.join("vtk-gpu.png"),
        rayon::current_num_threads(),
        1,
    )
    .map_err(|e| e.to_string())?
    .on_gpu(Some(module));
    Ok((settings, job))
}

/// The part of the page: both images and their agreement, or why VTK did not draw.
pub(crate) fn section(
    context: &mut Context,
    (name, key): (&str, &str),
    (volume, prepared, transfer): (&Volume, &PreparedVolume, &TransferFunction),
    (settings, job): &(DvrSettings, vtk::VtkJob),
    run: Result<vtk_peer::VtkTimes, String>,
) -> Result<String, String> {
    let mut html = format!("<h3>The lobe inside VTK's GPU ray caster ({LOBE})</h3>\n");
    html += &paragraph(&format!(
        "3D Slicer and ParaView draw volumes with VTK's GPU ray caster. Here it draws the real \
         {name} with {LOBE} in place of its pow (the module of specula shader --lang vtk, one \
         call: apply_to_volume), beside specula's marcher set up for that caster: its Phong \
         R.V, its early termination at 1 - 1/255, and a sample with no gradient lit by the \
         ambient term alone, as that caster's zero normal leaves it. Their remaining \
         differences are how each computes: VTK's gradients, taken from the 3D texture at \
         each sample, and its sample lattice."
    ));
    let times = match run {
        Ok(times) => times,
        Err(why) => {
            html += &paragraph(&format!("VTK's GPU ray caster did not draw here: {why}"));
            return Ok(html);
        }
    };
    let side = settings.width;
    let vtk_image = match vtk_peer::read_png_image(&job.output) {
        Ok(image) if (image.width(), image.height()) == (side, settings.height) => image,
        Ok(image) => {
            html += &paragraph(&format!(
                "VTK's GPU ray caster drew {} x {} pixels, not {side} x {}.",
                image.width(),
                image.height(),
                settings.height
            ));
            return Ok(html);
        }
        Err(why) => {
            html += &paragraph(&format!(
                "VTK's GPU ray caster's image is unreadable: {why}"
            ));
            return Ok(html);
        }
    };
    let ours = render_dvr_prepared(volume, prepared, transfer, settings, &|| {})
        .map_err(|e| e.to_string())?;
    let theirs: Vec<[f32; 3]> = vtk_image.pixels().iter().map(|p| p.to_array()).collect();
    let (mean, off) = vtk_peer::agreement(&ours, &theirs);
    html += &paragraph(&format!(
        "Mean |specula - VTK| {:.4} (linear, of 1), {:.2} % of the pixels off by more than 0.1; \
         VTK {} on this machine's OpenGL (llvmpipe where there is no GPU), {:.0} ms for the \
         frame. specula bench vtk-lobes times every lobe there against VTK's own pow.",
        mean,
        100.0 * off,
        times.version,
        times.median_draw * 1e3,
    ));
    html += &context.png_srgb8(
        &format!("real-{key}-gpu-specula.png"),
        side,
        side,
        &ours.to_srgb8(Display::default()),
        &format!("real {name}, {LOBE}: specula set up as VTK's GPU ray caster"),
    )?;
    html += &context.png_srgb8(
        &format!("real-{key}-gpu-vtk.png"),
        side,
        side,
        &vtk_image.to_srgb8(Display::default()),
        &format!(
            "real {name}, {LOBE}: VTK {}'s GPU ray caster with specula's module (its linear \
             values shown in sRGB)",
            times.version
        ),
    )?;
    Ok(html)
}
