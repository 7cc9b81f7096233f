//! `specula diff`: how two images differ (PSNR, largest error, mean FLIP), with a heatmap.

use std::path::PathBuf;

use serde::Serialize;
use specula_render::metrics::compare;
use specula_render::{read_image, write_png_srgb8, Display, ToneMap};

use super::{print_json, CommandResult};
use crate::args::{choice, OutputFormat};
use crate::output::{number, Table};

/// Arguments of `specula diff`.
#[derive(Debug, clap::Args)]
pub struct Args {
    #[command(flatten)]
    input_limit: crate::args::InputLimit,
    /// The reference image (.png or .exr).
    reference: PathBuf,
    /// The image compared with it (.png or .exr).
    test: PathBuf,
    /// Write FLIP's per-pixel error, coloured with its magma map, to this PNG.
    #[arg(long)]
    heatmap: Option<PathBuf>,
    /// The FLIP value drawn at the heatmap's bright end (0 < S <= 1; above it, drawn there
    /// too): below 1 it shows differences FLIP's own scale leaves black, as the report's maps.
    #[arg(long, default_value_t = 1.0)]
    heatmap_scale: f32,
    /// Exposure applied to both images before comparison (matters for EXR input).
    #[arg(long, default_value_t = 1.0)]
    exposure: f32,
    /// Tone map applied to both images before comparison (matters for EXR input).
    #[arg(long, value_parser = choice(&ToneMap::ALL, ToneMap::id), default_value = "clamp")]
    tonemap: ToneMap,
    /// Output format (table or json).
    #[arg(long, value_enum, default_value_t)]
    format: OutputFormat,
}

#[derive(Serialize)]
struct Report {
    /// `null` in JSON when the images are identical (infinite PSNR).
    psnr_db: f64,
    max_abs_error: f64,
    mean_flip: f64,
    width: u32,
    height: u32,
}

/// Compares and prints.
pub fn run(args: &Args) -> CommandResult {
    args.input_limit.apply();
    if !(args.exposure.is_finite() && args.exposure > 0.0) {
        return Err(format!(
            "--exposure must be a positive number, got {}",
            args.exposure
        ));
    }
    if !(args.heatmap_scale > 0.0 && args.heatmap_scale <= 1.0) {
        return Err(format!(
            "--heatmap-scale must lie in (0, 1] (FLIP's range), got {}",
            args.heatmap_scale
        ));
    }
    let reference = read_image(&args.reference).map_err(|e| e.to_string())?;
    let test = read_image(&args.test).map_err(|e| e.to_string())?;
    let display = Display {
        exposure: args.exposure,
        tonemap: args.tonemap,
    };
    let difference = compare(&reference, &test, display).map_err(|e| e.to_string())?;
    if let Some(path) = &args.heatmap {
        write_png_srgb8(
            path,
            difference.width,
            difference.height,
            &difference.heatmap_srgb8_scaled(args.heatmap_scale),
        )
        .map_err(|e| e.to_string())?;
    }
    let report = Report {
        psnr_db: difference.psnr_db,
        max_abs_error: difference.max_abs_error,
        mean_flip: difference.mean_flip,
        width: difference.width,
        height: difference.height,
    };
    if args.format == OutputFormat::Json {
        return print_json(&report);
    }
    if args.format == OutputFormat::Csv {
        // Data alone: one row, every figure with all its digits; identical images' PSNR is
        // `inf` (what every CSV reader parses as infinity).
        let mut table = Table::new(&["psnr (dB)", "max abs error", "mean FLIP", "width", "height"]);
        table.push(vec![
            number(report.psnr_db),
            number(report.max_abs_error),
            number(report.mean_flip),
            report.width.to_string(),
            report.height.to_string(),
        ]);
        table.print(args.format);
        return Ok(());
    }
    let mut table = Table::new(&["metric", "value"]);
    table.push(vec![
        "size".into(),
        format!("{}x{}", report.width, report.height),
    ]);
    let psnr = if report.psnr_db.is_finite() {
        format!("{:.2}", report.psnr_db)
    } else {
        "identical".to_owned()
    };
    table.push(vec!["PSNR (dB)".into(), psnr]);
    table.push(vec![
        "max abs error".into(),
        format!("{:.4}", report.max_abs_error),
    ]);
    table.push(vec!["mean FLIP".into(), format!("{:.5}", report.mean_flip)]);
    table.print(args.format);
    Ok(())
}
