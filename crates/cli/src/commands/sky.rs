//! `specula sky`: the built-in sky of `--env sky` written as an image file, so that Blender,
//! Mitsuba or any renderer can be lit by the same light.

use std::path::PathBuf;

use specula_render::ibl::{sun_direction, Environment, SKY_WIDTH, SUN_RADIANCE, SUN_RADIUS};
use specula_render::{is_linear_output, write_image, Display};

use super::CommandResult;

/// Arguments of `specula sky`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// The file: `.exr` (linear f32) or `.hdr` (Radiance RGBE), an equirectangular map of
    /// linear radiance (a PNG would clip the sun at 1, so it is refused).
    #[arg(short, long, default_value = "sky.exr")]
    output: PathBuf,
    /// Width in pixels (the height is half of it); `--env sky` uses 1024.
    #[arg(
        long,
        default_value_t = SKY_WIDTH,
        value_parser = clap::value_parser!(u32).range(2..=8192),
    )]
    width: u32,
}

/// Writes the sky and says what it holds.
pub fn run(args: &Args) -> CommandResult {
    if !is_linear_output(&args.output).map_err(|e| e.to_string())? {
        return Err(format!(
            "{}: the sky is linear radiance up to {} (the sun); write it as .exr or .hdr",
            args.output.display(),
            SUN_RADIANCE.x
        ));
    }
    let sky = Environment::sky(args.width);
    write_image(&args.output, sky.image(), Display::default()).map_err(|e| e.to_string())?;
    let sun = sun_direction();
    eprintln!(
        "wrote {} ({}x{} equirectangular, linear radiance, world z up; sun towards ({:.4}, {:.4}, \
            {:.4}), {:.1} degrees across)",
        args.output.display(),
        sky.image().width(),
        sky.image().height(),
        sun.x,
        sun.y,
        sun.z,
        2.0 * SUN_RADIUS.to_degrees()
    );
    Ok(())
}
