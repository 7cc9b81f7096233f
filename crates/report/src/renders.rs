//! The report's render section: the default scene per lobe with FLIP against `pow`, the three
//! shading methods, CPU against GPU when an adapter exists, and the environment scene per
//! lobe lit by the sky, with FLIP against `pow`.

use rayon::prelude::*;
use specula::LobeKind;
use specula_gpu::{Gpu, GpuError, GpuRenderer};
use specula_render::ibl::{render_ibl_grid, Environment, IblSettings, SKY_WIDTH};
use specula_render::metrics::compare;
use specula_render::{
    made_renders, render, render_grid_columns, write_png_srgb8, GridOptions, Image, Overrides,
    Scene, Shading, Srgb8Image,
};

use super::comparison::{self, Compared};
use super::html::{paragraph, table_with_files};
use super::prose;
use super::stored;
use super::{Context, RENDERS};
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
    let wrapped = wrap_columns(&grid.image, base.settings.width, GRID_PER_ROW);
    context.write_png_file(&strip, wrapped.width, wrapped.height, &wrapped.bytes)?;
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
            writes, its columns {GRID_PER_ROW} to a row).</p>\n"
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

/// The columns to a row of the one image of every lobe: `specula render --grid` writes its
/// thirteen columns side by side (6240 pixels wide at the full report's size), which no screen
/// shows whole; four to a row keeps each lobe's render above its FLIP map.
const GRID_PER_ROW: u32 = 4;

/// `grid`'s columns (each `column_width` wide, the full height) laid out `per_row` to a row,
/// in order, the rows below one another; the last row's gap left black.
fn wrap_columns(grid: &Srgb8Image, column_width: u32, per_row: u32) -> Srgb8Image {
    let columns = grid.width / column_width;
    let across = columns.min(per_row);
    let rows = columns.div_ceil(per_row);
    let (width, height) = (across * column_width, rows * grid.height);
    let mut bytes = vec![0; 3 * (width * height) as usize];
    let line = 3 * column_width as usize;
    for column in 0..columns {
        let (x0, y0) = (
            (column % per_row) * column_width,
            (column / per_row) * grid.height,
        );
        for y in 0..grid.height {
            let from = 3 * (y * grid.width + column * column_width) as usize;
            let to = 3 * ((y0 + y) * width + x0) as usize;
            bytes[to..to + line].copy_from_slice(&grid.bytes[from..from + line]);
        }
    }
    Srgb8Image {
        width,
        height,
        bytes,
    }
}

/// Every lobe against pow.
fn grid_options(context: &Context) -> GridOptions {
    GridOptions {
        lobes: context.lobes.clone(),
        reference: LobeKind::Pow,
    }
}

/// The section, or a run's of this build with the same sizes, lobes and adapter: the
/// renders are functions of those alone ([`stored`]).
pub fn renders(context: &mut Context) -> Result<String, String> {
    let gpu = Gpu::new();
    let adapter = match &gpu {
        Ok(gpu) => gpu.adapter_name(),
        Err(error) => format!("no adapter: {error}"),
    };
    stored::section(context, RENDERS, &adapter, |context| {
        // The environment-lit renders (most of the section's work) run beside the rest.
        let mut lit = context.sibling();
        let (html, environment) = rayon::join(
            || default_scene(context, &gpu),
            || environment_lit(&mut lit),
        );
        context.absorb(lit);
        Ok(html? + &environment?)
    })
}

/// The default scene: every lobe, the three shading methods, CPU against GPU.
fn default_scene(context: &mut Context, gpu: &Result<Gpu, GpuError>) -> Result<String, String> {
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

    let rendered = match gpu {
        Ok(gpu) => GpuRenderer::new(gpu)
            .render(&base)
            .map(|image| (gpu.adapter_name(), image))
            .map_err(|e| e.to_string()),
        Err(error) => Err(error.to_string()),
    };
    match rendered {
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

#[cfg(test)]
mod tests {
    use super::*;

    /// Five 2-pixel columns, each filled with its own index, wrapped two to a row: column k
    /// lands at row k / 2, place k % 2, whole; the sixth place stays black.
    #[test]
    fn wrapping_keeps_each_column_whole_in_order() {
        let (columns, column_width, height) = (5u32, 2u32, 3u32);
        let width = columns * column_width;
        let bytes = (0..width * height)
            .flat_map(|p| [(p % width / column_width + 1) as u8; 3])
            .collect();
        let grid = Srgb8Image {
            width,
            height,
            bytes,
        };
        let wrapped = wrap_columns(&grid, column_width, 2);
        assert_eq!((wrapped.width, wrapped.height), (4, 9));
        for y in 0..wrapped.height {
            for x in 0..wrapped.width {
                let place = (y / height) * 2 + x / column_width;
                let expected = if place < columns { place as u8 + 1 } else { 0 };
                let at = 3 * (y * wrapped.width + x) as usize;
                assert_eq!(wrapped.bytes[at], expected, "at ({x}, {y})");
            }
        }
    }
}
