//! The report's render section: the default scene per lobe with FLIP against `pow`, the three
//! shading methods, and CPU against GPU when an adapter exists.

use specula::LobeKind;
use specula_gpu::{Gpu, GpuRenderer};
use specula_render::metrics::compare;
use specula_render::{
    render, render_grid_with, Display, GridOptions, Image, Overrides, Scene, Shading,
};

use super::html::{paragraph, table};
use super::Context;
use crate::output::sig;

fn scene(context: &Context, overrides: Overrides) -> Scene {
    let (width, height, samples) = context.sizes.render;
    let mut scene = Scene::default_scene();
    scene.apply(&Overrides {
        width: Some(width),
        height: Some(height),
        samples: Some(samples),
        ..overrides
    });
    scene
}

fn cpu(scene: &Scene) -> Result<Image, String> {
    render(scene, &|_, _| {}).map_err(|e| e.to_string())
}

pub fn renders(context: &mut Context) -> Result<String, String> {
    let base = scene(context, Overrides::default());
    let options = GridOptions {
        lobes: LobeKind::ALL.to_vec(),
        reference: LobeKind::Pow,
    };
    // The grid draws the reference as render 0 and each other lobe as render `column + 1`;
    // keeping them by that index (not by arrival) ties every image to its lobe.
    let mut renders: Vec<Option<Image>> = vec![None; 1 + options.lobes.len()];
    let grid = render_grid_with(&base, &options, &mut |variant, index| {
        let image = cpu(variant)?;
        renders[index] = Some(image.clone());
        Ok(image)
    })
    .map_err(|e| e.to_string())?;
    let (width, height, samples) = context.sizes.render;
    let mut html = paragraph(&format!(
        "The default scene ({width}x{height}, {samples}x{samples} samples, classic model, Phong shading) with every material's lobe replaced, and below each its FLIP error map against pow. Look for where the highlights' size and falloff differ from pow's."
    ));
    html += &context.png_srgb8(
        "renders-lobes.png",
        grid.width,
        grid.height,
        &grid.bytes,
        "every lobe, FLIP against pow below",
    )?;
    // Each row names its image file and is computed from that file's pixels (8-bit sRGB, as
    // written), so `specula diff render-pow.png render-<lobe>.png` prints the same figures.
    let mut written = Vec::new();
    for (column, &kind) in options.lobes.iter().enumerate() {
        let index = if kind == options.reference {
            0
        } else {
            column + 1
        };
        let image = renders[index]
            .as_ref()
            .ok_or_else(|| format!("the grid did not render {kind}"))?;
        let name = format!("render-{}.png", kind.id());
        let bytes = image.to_srgb8(base.display);
        context.write_png_file(&name, image.width(), image.height(), &bytes)?;
        let decoded = Image::from_srgb8(image.width(), image.height(), &bytes)
            .ok_or("inconsistent image size")?;
        written.push((kind, name, decoded));
    }
    let reference = written
        .iter()
        .find(|(kind, ..)| *kind == options.reference)
        .map(|(_, name, image)| (name.clone(), image.clone()))
        .ok_or("no reference render")?;
    let rows: Vec<Vec<String>> = written
        .iter()
        .filter(|(kind, ..)| *kind != options.reference)
        .map(|(kind, name, image)| {
            let d = compare(&reference.1, image, Display::default()).map_err(|e| e.to_string())?;
            Ok(vec![
                kind.to_string(),
                name.clone(),
                format!("{:.1}", d.psnr_db.min(999.0)),
                sig(d.max_abs_error),
                format!("{:.5}", d.mean_flip),
            ])
        })
        .collect::<Result<_, String>>()?;
    html += &table(
        &[
            "lobe",
            "image",
            "PSNR vs pow (dB)",
            "max abs error",
            "mean FLIP",
        ],
        &rows,
    );
    // The reference render, kept for the CPU-against-GPU comparison below.
    let reference_image = renders[0].take().ok_or("the grid did not render pow")?;

    html += &paragraph("The same scene under the three shading methods (pow):");
    for shading in Shading::ALL {
        let image = cpu(&scene(
            context,
            Overrides {
                shading: Some(shading),
                ..Overrides::default()
            },
        ))?;
        html += &context.png(
            &format!("shading-{}.png", shading.id()),
            &image,
            &base,
            &format!("{} shading", shading.id()),
        )?;
    }

    match Gpu::new().and_then(|gpu| {
        let image = GpuRenderer::new(&gpu)?.render(&base)?;
        Ok((gpu.adapter_name(), image))
    }) {
        Ok((adapter, image)) => {
            let d = compare(&reference_image, &image, base.display).map_err(|e| e.to_string())?;
            html += &paragraph(&format!(
                "CPU against GPU ({adapter}): PSNR {:.1} dB, max abs error {}, mean FLIP {:.2e}.",
                d.psnr_db.min(999.0),
                sig(d.max_abs_error),
                d.mean_flip
            ));
            html += &context.png("gpu.png", &image, &base, "the GPU's render")?;
            html += &context.png_srgb8(
                "gpu-flip.png",
                d.width,
                d.height,
                &d.heatmap_srgb8(),
                "FLIP, CPU against GPU",
            )?;
        }
        Err(error) => html += &paragraph(&format!("CPU against GPU: not run ({error}).")),
    }
    Ok(html)
}
