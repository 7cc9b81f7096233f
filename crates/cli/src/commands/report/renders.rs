//! The report's render section: the default scene per lobe with FLIP against `pow`, the three
//! shading methods, and CPU against GPU when an adapter exists.

use specula::LobeKind;
use specula_gpu::{Gpu, GpuRenderer};
use specula_render::metrics::compare;
use specula_render::{render, render_grid_with, GridOptions, Image, Overrides, Scene, Shading};

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
    let mut images = Vec::new();
    let grid = render_grid_with(&base, &options, &mut |variant, _| {
        let image = cpu(variant)?;
        images.push(image.clone());
        Ok(image)
    })
    .map_err(|e| e.to_string())?;
    let (width, height, samples) = context.sizes.render;
    let mut html = paragraph(&format!(
        "The default scene ({width}x{height}, {samples}x{samples} samples, classic model, Phong shading) with every material's lobe replaced, and below each its FLIP error map against pow."
    ));
    html += &context.png_srgb8(
        "renders-lobes.png",
        grid.width,
        grid.height,
        &grid.bytes,
        "every lobe, FLIP against pow below",
    )?;
    let reference = &images[0];
    let rows: Vec<Vec<String>> = options
        .lobes
        .iter()
        .zip(&images[1..])
        .filter(|(kind, _)| **kind != LobeKind::Pow)
        .map(|(kind, image)| {
            let d = compare(reference, image, base.display).map_err(|e| e.to_string())?;
            Ok(vec![
                kind.to_string(),
                format!("{:.1}", d.psnr_db.min(999.0)),
                sig(d.max_abs_error),
                format!("{:.5}", d.mean_flip),
            ])
        })
        .collect::<Result<_, String>>()?;
    html += &table(
        &["lobe", "PSNR vs pow (dB)", "max abs error", "mean FLIP"],
        &rows,
    );

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
            let d = compare(reference, &image, base.display).map_err(|e| e.to_string())?;
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
