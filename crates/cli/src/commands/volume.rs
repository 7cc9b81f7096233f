//! `specula volume`: direct volume rendering of a built-in volume with any lobe.

use std::path::PathBuf;
use std::time::Instant;

use glam::Vec3;
use indicatif::{ProgressBar, ProgressStyle};
use specula::{Exponent, Geometry, Lobe, LobeKind, Normalisation};
use specula_render::volume::raymarch::{render_dvr, DvrSettings, Shading, View};
use specula_render::volume::transfer::TransferFunction;
use specula_render::volume::{phantom, Volume};
use specula_render::{check_output_path, write_image, Display};

use super::CommandResult;
use crate::args::{choice, parse_exponent, LobeParser};

/// The volumes built in.
const BUILT_IN: [&str; 2] = ["phantom", "marschner-lobb"];

/// Arguments of `specula volume`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// The volume: `phantom` (the 3D Shepp-Logan head) or `marschner-lobb` (the test signal).
    #[arg(long, default_value = "phantom")]
    input: String,
    /// Voxels along each side of a built-in volume.
    #[arg(long, default_value_t = 128, value_parser = clap::value_parser!(u32).range(8..=512))]
    size: u32,
    /// The transfer function: a preset (ct-bone, ct-soft-tissue, mr) or a .toml file; by
    /// default ct-bone for CT and mr otherwise.
    #[arg(long)]
    transfer: Option<String>,
    /// The specular lobe.
    #[arg(long, value_parser = LobeParser, default_value = "pow")]
    lobe: LobeKind,
    /// The lobe's exponent, in [1, 1000].
    #[arg(long, value_parser = parse_exponent, allow_hyphen_values = true, default_value = "32")]
    n: Exponent,
    /// How the lobe's cosine is formed.
    #[arg(long, value_parser = choice(&Geometry::ALL, Geometry::id), default_value = "blinn")]
    geometry: Geometry,
    /// The specular normalisation (the thesis's is thesis-phong).
    #[arg(long, value_parser = choice(&Normalisation::ALL, Normalisation::id), default_value = "none")]
    normalisation: Normalisation,
    /// The view: axial (from the feet), sagittal (from the left) or coronal (from the front).
    #[arg(long, value_parser = choice(&View::STANDARD, View::id), default_value = "coronal", conflicts_with = "eye")]
    view: View,
    /// A perspective view from this point (millimetres, `x,y,z`) towards the volume's centre.
    #[arg(long, value_parser = parse_point, allow_hyphen_values = true)]
    eye: Option<Vec3>,
    /// Image width in pixels.
    #[arg(long, default_value_t = 384, value_parser = clap::value_parser!(u32).range(1..=8192))]
    width: u32,
    /// Image height in pixels.
    #[arg(long, default_value_t = 384, value_parser = clap::value_parser!(u32).range(1..=8192))]
    height: u32,
    /// Output image: .png (8-bit sRGB) or .exr (linear f32).
    #[arg(short, long, default_value = "volume.png")]
    output: PathBuf,
}

fn parse_point(text: &str) -> Result<Vec3, String> {
    let numbers: Vec<f32> = text
        .split(',')
        .map(|part| part.trim().parse::<f32>())
        .collect::<Result<_, _>>()
        .map_err(|_| {
            format!(
                "'{}' must be three numbers x,y,z (millimetres)",
                specula::excerpt(text)
            )
        })?;
    match numbers[..] {
        [x, y, z] if x.is_finite() && y.is_finite() && z.is_finite() => Ok(Vec3::new(x, y, z)),
        _ => Err(format!(
            "'{}' must be three finite numbers x,y,z (millimetres)",
            specula::excerpt(text)
        )),
    }
}

/// The volume `--input` names.
fn load(args: &Args) -> Result<Volume, String> {
    let side = args.size as usize;
    let built = match args.input.as_str() {
        "phantom" => phantom::shepp_logan(side),
        "marschner-lobb" => phantom::marschner_lobb(side),
        other => {
            return Err(format!(
                "unknown volume '{}'; built in: {}{}",
                specula::excerpt(other),
                BUILT_IN.join(", "),
                specula::did_you_mean(other, BUILT_IN)
            ))
        }
    };
    built.map_err(|e| e.to_string())
}

/// The transfer function `--transfer` names, in the volume's values.
fn transfer(args: &Args, volume: &Volume) -> Result<TransferFunction, String> {
    let function = match &args.transfer {
        None => TransferFunction::default_for(volume),
        Some(name) if name.ends_with(".toml") => {
            let bytes = specula_render::input::read_within(std::path::Path::new(name), 1 << 20)?;
            let text = String::from_utf8(bytes).map_err(|_| format!("{name}: not UTF-8 text"))?;
            TransferFunction::from_toml(&text).map_err(|e| format!("{name}: {e}"))?
        }
        Some(name) => TransferFunction::preset(name).map_err(|e| e.to_string())?,
    };
    Ok(function.for_volume(volume))
}

/// Renders and writes the image.
pub fn run(args: &Args) -> CommandResult {
    check_output_path(&args.output).map_err(|e| e.to_string())?;
    let started = Instant::now();
    let volume = load(args)?;
    let transfer = transfer(args, &volume)?;
    let shading = Shading {
        lobe: Lobe::new(args.lobe, args.n),
        geometry: args.geometry,
        normalisation: args.normalisation,
        ka: 0.25,
        kd: 0.7,
        ks: 0.5,
    };
    let view = args.eye.map_or(args.view, View::Eye);
    let settings = DvrSettings::new(args.width, args.height, view, Some(shading));
    let bar = ProgressBar::new(u64::from(args.height)).with_style(
        ProgressStyle::with_template("ray marching {bar:30} {percent}% {elapsed}")
            .unwrap_or_else(|_| ProgressStyle::default_bar()),
    );
    let image =
        render_dvr(&volume, &transfer, &settings, &|| bar.inc(1)).map_err(|e| e.to_string())?;
    bar.finish_and_clear();
    write_image(&args.output, &image, Display::default()).map_err(|e| e.to_string())?;
    let [nx, ny, nz] = volume.dims();
    eprintln!(
        "wrote {} ({}x{}, {} {nx}x{ny}x{nz}, {} n = {}, {:.2} s)",
        args.output.display(),
        args.width,
        args.height,
        args.input,
        args.lobe,
        args.n,
        started.elapsed().as_secs_f64()
    );
    Ok(())
}
