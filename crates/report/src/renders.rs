//! The report's render section: the default scene per lobe with FLIP against `pow`, the three
//! shading methods, CPU against GPU when an adapter exists, and the environment scene per
//! lobe lit by the sky, with FLIP against `pow`.

use rayon::prelude::*;
use specula::LobeKind;
use specula_gpu::{Gpu, GpuRenderer};
use specula_render::ibl::{render_ibl_grid, Environment, IblSettings, SKY_WIDTH};
use specula_render::metrics::compare;
use specula_render::{
    made_renders, render, render_grid_columns, write_png_srgb8, GridOptions, Image, Overrides,
    Scene, Shading,
};

use super::comparison::{self, Compared};
use super::html::{paragraph, table_with_files};
use super::prose;
use super::Context;
use crate::format::{psnr, psnr_db, sig};

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

/// Every lobe's render of `base` by `draw`, as a grid with FLIP against pow below each tile,
/// then a table whose rows each name their image file (`<prefix>-<lobe>.png`) and are
/// computed from that file's pixels (8-bit sRGB, as written; the grid's own comparisons), so
/// that `specula diff <prefix>-pow.png <prefix>-<lobe>.png` prints the same figures. Returns
/// the HTML and the reference's render.
fn lobe_table(
    context: &mut Context,
    base: &Scene,
    prefix: &str,
    header: &str,
    draw: &mut dyn FnMut(&Scene, usize) -> Result<Image, String>,
) -> Result<(String, Option<Image>), String> {
    let options = grid_options(context);
    // The grid draws the reference as render 0, and each other lobe as render `column + 1`.
    let mut reference = None;
    let grid = render_grid_columns(base, &options, &mut |variant, index| {
        let image = draw(variant, index)?;
        if index == 0 {
            reference = Some(image.clone());
        }
        Ok(image)
    })
    .map_err(|e| e.to_string())?;
    // The whole grid, one image to download; the page shows the lobes as tiles.
    let strip = format!("{prefix}s-lobes.png");
    context.write_png_file(
        &strip,
        grid.image.width,
        grid.image.height,
        &grid.image.bytes,
    )?;
    // Each lobe's file written on its own thread.
    let (width, height) = (base.settings.width, base.settings.height);
    let directory = &context.directory;
    let names = grid
        .columns
        .par_iter()
        .map(|column| {
            let name = format!("{prefix}-{}.png", column.lobe.id());
            write_png_srgb8(&directory.join(&name), width, height, &column.srgb8)
                .map_err(|e| e.to_string())?;
            Ok(name)
        })
        .collect::<Result<Vec<_>, String>>()?;
    context.files.extend(names.iter().cloned());
    let compared: Vec<Compared> = grid
        .columns
        .iter()
        .zip(&names)
        .map(|(column, name)| {
            Compared::new(
                column.lobe,
                name,
                &column.difference,
                column.lobe == options.reference,
            )
        })
        .collect();
    let mut html = comparison::grid(context, prefix, &options.reference.to_string(), &compared)?;
    html += &format!(
        "<p><a href=\"{strip}\">Every lobe in one image</a> (what specula render --grid \
            writes).</p>\n"
    );
    let rows: Vec<Vec<String>> = grid
        .columns
        .iter()
        .zip(&names)
        .filter(|(column, _)| column.lobe != options.reference)
        .map(|(column, name)| {
            let d = &column.difference;
            vec![
                column.lobe.to_string(),
                name.clone(),
                psnr(d.psnr_db),
                sig(d.max_abs_error),
                format!("{:.5}", d.mean_flip),
            ]
        })
        .collect();
    html += &table_with_files(
        &["lobe", "image", header, "max abs error", "mean FLIP"],
        &rows,
        &[1],
    );
    Ok((html, reference))
}

/// Every lobe against pow.
fn grid_options(context: &Context) -> GridOptions {
    GridOptions {
        lobes: context.lobes.clone(),
        reference: LobeKind::Pow,
    }
}

pub fn renders(context: &mut Context) -> Result<String, String> {
    // The environment-lit renders (most of the section's work) run beside the rest.
    let mut lit = context.sibling();
    let (html, environment) = rayon::join(|| default_scene(context), || environment_lit(&mut lit));
    context.absorb(lit);
    Ok(html? + &environment?)
}

/// The default scene: every lobe, the three shading methods, CPU against GPU.
fn default_scene(context: &mut Context) -> Result<String, String> {
    let base = scene(context, Overrides::default());
    let (width, height, samples) = context.sizes.render;
    let mut html = paragraph(&format!(
        "The default scene ({width}x{height}, {samples}x{samples} samples, classic model, Phong \
            shading) with every material's lobe replaced, and below each its FLIP error map \
            against pow. Look for where the highlights' size and falloff differ from pow's."
    ));
    let (table_html, reference_image) = lobe_table(
        context,
        &base,
        "render",
        "PSNR vs pow (dB)",
        &mut |scene, _| cpu(scene),
    )?;
    html += &table_html;
    // The reference render, kept for the CPU-against-GPU comparison below.
    let reference_image = reference_image.ok_or("the grid did not render pow")?;

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
        let image = GpuRenderer::new(&gpu).render(&base)?;
        Ok((gpu.adapter_name(), image))
    }) {
        Ok((adapter, image)) => {
            let d = compare(&reference_image, &image, base.display).map_err(|e| e.to_string())?;
            html += &paragraph(&format!(
                "CPU against GPU ({adapter}): PSNR {}, max abs error {}, mean FLIP {:.2e}.",
                psnr_db(d.psnr_db),
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
        Err(error) => {
            html += &paragraph(
                "CPU against GPU: not run (no GPU adapter here; see the notes on this machine).",
            );
            context.machine_note(format!(
                "No GPU adapter: the GPU renders and timings were not run ({error})."
            ));
        }
    }
    Ok(html)
}

/// Every lobe in the environment scene lit by the procedural sky: the same seed for every
/// lobe, so the environment's draws are shared (computed once, by [`render_ibl_grid`]) and
/// the differences are the lobes', not the noise's.
fn environment_lit(context: &mut Context) -> Result<String, String> {
    let (width, height, spp) = context.sizes.environment;
    let mut base = Scene::ibl_scene();
    base.apply(&Overrides {
        width: Some(width),
        height: Some(height),
        ..Overrides::default()
    });
    let sky = Environment::sky(SKY_WIDTH);
    let settings = IblSettings {
        spp,
        ..IblSettings::default()
    };
    let mut html = paragraph(&prose::fill(
        prose::ENVIRONMENT,
        &[("width", &width), ("height", &height), ("spp", &spp)],
    )?);
    let mut images = render_ibl_grid(&base, &grid_options(context), &sky, &settings, &|_, _| {})
        .map_err(|e| e.to_string())?;
    let (table_html, _) = lobe_table(
        context,
        &base,
        "environment",
        "PSNR vs pow, lit by the sky (dB)",
        &mut made_renders(&mut images),
    )?;
    html += &table_html;
    Ok(html)
}
