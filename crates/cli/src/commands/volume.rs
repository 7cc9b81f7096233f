//! `specula volume`: a volume (built in, NIfTI or a DICOM series) rendered with any lobe, by
//! ray marching or as an isosurface, on the CPU or the GPU; `specula volume-convert` writes
//! one as NIfTI or DICOM.

use std::path::PathBuf;
use std::time::Instant;

use glam::Vec3;
use indicatif::ProgressBar;
use specula::{Exponent, Geometry, Lobe, LobeKind, Normalisation};
use specula_gpu::{Gpu, GpuRenderer, GpuVolumeRenderer};
use specula_render::{check_output_path, render, write_image, Display, Image};
use specula_volume::dvr::{render_dvr, DvrSettings, Light, Shading, View};
use specula_volume::isosurface::{default_isovalue, iso_scene, marching_cubes, IsoSettings};
use specula_volume::phantom::BuiltIn;
use specula_volume::transfer::TransferFunction;
use specula_volume::{self as volume, Volume};

use super::CommandResult;
use crate::args::{choice, parse_exponent, InputLimit, LobeParser, RendererArg};

/// How the volume is drawn.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum Mode {
    /// Direct volume rendering: rays through a transfer function, shaded by the gradient.
    Dvr,
    /// The surface at `--iso` by marching cubes, drawn by the rasterizer.
    Iso,
}

/// Arguments of `specula volume`.
#[derive(Debug, clap::Args)]
pub struct Args {
    #[command(flatten)]
    source: Source,
    /// How to draw it.
    #[arg(long, value_enum, default_value = "dvr")]
    mode: Mode,
    /// The isovalue of --mode iso; by default 300 (bone) for CT, else the middle of the range.
    #[arg(long, allow_hyphen_values = true, value_parser = parse_finite)]
    iso: Option<f32>,
    /// How --mode iso interpolates its lighting.
    #[arg(
        long,
        value_parser = choice(&specula_render::Shading::ALL, specula_render::Shading::id),
        default_value = "phong",
    )]
    shading: specula_render::Shading,
    /// The transfer function: a preset (ct-bone, ct-soft-tissue, mr, surface) or a .toml file; by
    /// default surface for marschner-lobb, ct-bone for CT and mr otherwise.
    #[arg(long)]
    transfer: Option<String>,
    /// Place the transfer function's ramp as a radiologist's window (its first control point at
    /// level - window/2, its last at level + window/2), in the volume's values (HU for CT).
    #[arg(long, requires = "level", value_parser = parse_finite)]
    window: Option<f32>,
    /// The window's centre (see --window).
    #[arg(long, requires = "window", allow_hyphen_values = true, value_parser = parse_finite)]
    level: Option<f32>,
    /// Segment length along a ray in millimetres (VTK's sample distance); by default half the
    /// smallest voxel spacing. At most 4 voxels.
    #[arg(long, value_parser = parse_finite)]
    step: Option<f32>,
    /// The light: key (at the eye, up and to the left) or headlight (along the view).
    #[arg(long, value_parser = choice(&Light::ALL, Light::id), default_value = "key")]
    light: Light,
    /// Ambient, diffuse and specular weights of the volume's shading.
    #[arg(long, value_parser = parse_weight, default_value = "0.25")]
    ambient: f32,
    /// Diffuse weight (see --ambient).
    #[arg(long, value_parser = parse_weight, default_value = "0.7")]
    diffuse: f32,
    /// Specular weight (see --ambient).
    #[arg(long, value_parser = parse_weight, default_value = "0.5")]
    specular: f32,
    /// Shade every sample with a gradient fully, as VTK does (by default a sample fades to its
    /// unshaded colour where its gradient is weak, inside uniform tissue).
    #[arg(long)]
    full_shading: bool,
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
    #[arg(
        long,
        value_parser = choice(&Normalisation::ALL, Normalisation::id),
        default_value = "none",
    )]
    normalisation: Normalisation,
    /// The side the camera stands on: anterior (the face), posterior, left, right, superior or
    /// inferior (also coronal = anterior, sagittal = left, axial = inferior).
    #[arg(long, value_parser = View::parse, default_value = "anterior", conflicts_with = "eye")]
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
    /// Which renderer draws.
    #[arg(long, value_enum, default_value = "cpu")]
    backend: RendererArg,
    /// Output image: .png (8-bit sRGB) or .exr (linear f32).
    #[arg(short, long, default_value = "volume.png")]
    output: PathBuf,
}

/// Where a volume comes from (shared by `volume` and `volume-convert`).
#[derive(Debug, clap::Args)]
pub struct Source {
    /// The volume: `phantom` (the 3D Shepp-Logan head), `marschner-lobb` (the test signal), a
    /// NIfTI-1 file (.nii, .nii.gz), a folder holding one DICOM series, a multi-frame
    /// (enhanced) DICOM file, or an InVesalius project (.inv3).
    #[arg(long, default_value = "phantom")]
    input: String,
    /// Voxels along each side of a built-in volume.
    #[arg(
        long,
        default_value_t = 128,
        value_parser = clap::value_parser!(u32)
            .range(*BuiltIn::SIDES.start() as i64..=*BuiltIn::SIDES.end() as i64),
    )]
    size: u32,
    #[command(flatten)]
    input_limit: InputLimit,
}

impl Source {
    /// The volume at `input`, with the default size and input limit.
    pub(crate) fn new(input: &str) -> Self {
        Self {
            input: input.to_owned(),
            size: 128,
            input_limit: InputLimit::default(),
        }
    }
}

/// Arguments of `specula volume-convert`.
#[derive(Debug, clap::Args)]
pub struct ConvertArgs {
    #[command(flatten)]
    source: Source,
    /// Resample onto a grid of this many voxels (`NXxNYxNZ`, e.g. `512x512x432`) over the same
    /// extent, trilinearly; a scan of whole numbers (a CT) stays whole.
    #[arg(long, value_parser = parse_grid)]
    resample: Option<[usize; 3]>,
    /// Where to write: a .nii or .nii.gz file, or else a new folder for a DICOM series.
    #[arg(short, long)]
    output: PathBuf,
}

/// A grid size written `NXxNYxNZ`, checked as a volume's grid is.
fn parse_grid(text: &str) -> Result<[usize; 3], String> {
    let sides: Vec<Option<usize>> = text
        .split('x')
        .map(|side| side.trim().parse().ok())
        .collect();
    match sides.as_slice() {
        [Some(x), Some(y), Some(z)] => {
            let dims = [*x, *y, *z];
            Volume::check_dims(dims).map_err(|e| e.to_string())?;
            Ok(dims)
        }
        _ => Err(format!(
            "'{}' is not a grid size; write three whole numbers as NXxNYxNZ, e.g. 512x512x432",
            specula::excerpt(text)
        )),
    }
}

fn parse_finite(text: &str) -> Result<f32, String> {
    match text.trim().parse::<f32>() {
        Ok(value) if value.is_finite() => Ok(value),
        _ => Err(format!(
            "'{}' must be a finite number",
            specula::excerpt(text)
        )),
    }
}

fn parse_weight(text: &str) -> Result<f32, String> {
    match text.trim().parse::<f32>() {
        Ok(value) if (0.0..=10.0).contains(&value) => Ok(value),
        _ => Err(format!(
            "'{}' must be a weight from 0 to 10",
            specula::excerpt(text)
        )),
    }
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
pub(crate) fn load(source: &Source) -> Result<Volume, String> {
    source.input_limit.apply();
    let side = source.size as usize;
    let input = source.input.as_str();
    let built = match BuiltIn::parse(input) {
        Some(built_in) => built_in.make(side),
        None if std::path::Path::new(input).exists() => volume::read(std::path::Path::new(input)),
        None => {
            let names = BuiltIn::ALL.map(BuiltIn::id);
            return Err(format!(
                "'{}' is neither a built-in volume ({}) nor an existing file or folder{}",
                specula::excerpt(input),
                names.join(", "),
                specula::did_you_mean(input, names)
            ));
        }
    };
    built.map_err(|e| e.to_string())
}

/// The transfer function `--transfer` names, in the volume's values.
fn transfer(args: &Args, volume: &Volume) -> Result<TransferFunction, String> {
    let function = match &args.transfer {
        None => BuiltIn::parse(&args.source.input)
            .map_or_else(|| TransferFunction::default_for(volume), BuiltIn::transfer),
        Some(name) if name.ends_with(".toml") => {
            let bytes = specula_render::input::read_within(std::path::Path::new(name), 1 << 20)?;
            let text = String::from_utf8(bytes).map_err(|_| format!("{name}: not UTF-8 text"))?;
            TransferFunction::from_toml(&text).map_err(|e| format!("{name}: {e}"))?
        }
        Some(name) => TransferFunction::preset(name).map_err(|e| e.to_string())?,
    };
    let function = function.for_volume(volume);
    match (args.window, args.level) {
        (Some(window), Some(level)) => function.windowed(window, level).map_err(|e| e.to_string()),
        _ => Ok(function),
    }
}

/// Renders and writes the image.
pub fn run(args: &Args) -> CommandResult {
    check_output_path(&args.output).map_err(|e| e.to_string())?;
    let started = Instant::now();
    let volume = load(&args.source)?;
    let shading = Shading {
        ka: args.ambient,
        kd: args.diffuse,
        ks: args.specular,
        light: args.light,
        fade_weak_gradients: !args.full_shading,
        ..Shading::new(
            Lobe::checked(args.lobe, args.n).map_err(|e| e.to_string())?,
            args.geometry,
            args.normalisation,
        )
    };
    let view = args.eye.map_or(args.view, View::Eye);
    let gpu = match args.backend {
        RendererArg::Cpu => None,
        RendererArg::Gpu => Some(Gpu::new().map_err(|e| e.to_string())?),
    };
    let bar = crate::progress::bar("volume", 1, "{msg} {bar:30} {percent}% {elapsed}");
    let (image, drawn) = match args.mode {
        Mode::Dvr => {
            let transfer = transfer(args, &volume)?;
            let mut settings = DvrSettings::new(args.width, args.height, view, Some(shading));
            if let Some(step) = args.step {
                let voxel = volume.spacing().min_element();
                if !(step > 0.0 && step <= 4.0 * voxel) {
                    return Err(format!(
                        "--step {step} mm: the step must be more than 0 and at most 4 voxels ({} \
                            mm here)",
                        4.0 * voxel
                    ));
                }
                settings.step_fraction = step / voxel;
            }
            let image = match &gpu {
                Some(gpu) => GpuVolumeRenderer::new(gpu)
                    .render(&volume, &transfer, &settings)
                    .map_err(|e| e.to_string())?,
                None => {
                    bar.set_message("ray marching");
                    bar.set_length(u64::from(args.height));
                    render_dvr(&volume, &transfer, &settings, &|| bar.inc(1))
                        .map_err(|e| e.to_string())?
                }
            };
            (image, "ray marched".to_owned())
        }
        Mode::Iso => {
            let value = args.iso.unwrap_or_else(|| default_isovalue(&volume));
            let image = iso(args, &volume, value, view, shading, gpu.as_ref(), &bar)?;
            (image, format!("isosurface at {value}"))
        }
    };
    bar.finish_and_clear();
    write_image(&args.output, &image, Display::default()).map_err(|e| e.to_string())?;
    let [nx, ny, nz] = volume.dims();
    let device = gpu.map_or_else(|| "CPU".to_owned(), |gpu| gpu.adapter_name());
    eprintln!(
        "wrote {} ({}x{}, {} {nx}x{ny}x{nz}, {}, {} n = {}, {device}, {:.2} s)",
        args.output.display(),
        args.width,
        args.height,
        args.source.input,
        drawn,
        args.lobe,
        args.n,
        started.elapsed().as_secs_f64()
    );
    Ok(())
}

/// Extracts and draws the isosurface at `iso`.
fn iso(
    args: &Args,
    volume: &Volume,
    iso: f32,
    view: View,
    shading: Shading,
    gpu: Option<&Gpu>,
    bar: &ProgressBar,
) -> Result<Image, String> {
    let (lo, hi) = volume.range();
    if !(lo..=hi).contains(&iso) {
        return Err(format!(
            "--iso {iso} is outside the volume's values [{lo}, {hi}]; no surface would be drawn"
        ));
    }
    bar.set_message("marching cubes");
    let mesh = marching_cubes(volume, iso).map_err(|e| e.to_string())?;
    let settings = IsoSettings {
        width: args.width,
        height: args.height,
        view,
        iso,
        shading,
        method: args.shading,
        samples: 2,
    };
    let scene = iso_scene(volume, mesh, &settings).map_err(|e| e.to_string())?;
    match gpu {
        Some(gpu) => GpuRenderer::new(gpu)
            .render(&scene)
            .map_err(|e| e.to_string()),
        None => {
            bar.set_message("rasterizing");
            render(&scene, &|done, total| {
                bar.set_length(total as u64);
                bar.set_position(done as u64);
            })
            .map_err(|e| e.to_string())
        }
    }
}

/// Writes the volume as NIfTI or a DICOM series.
pub fn convert(args: &ConvertArgs) -> CommandResult {
    let mut volume = load(&args.source)?;
    if let Some(dims) = args.resample {
        volume = volume.resampled(dims).map_err(|e| e.to_string())?;
    }
    volume::write(&volume, &args.output).map_err(|e| e.to_string())?;
    let [nx, ny, nz] = volume.dims();
    eprintln!(
        "wrote {} ({} {nx}x{ny}x{nz})",
        args.output.display(),
        args.source.input
    );
    Ok(())
}
