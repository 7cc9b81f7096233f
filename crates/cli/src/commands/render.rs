//! `specula render`: the CPU renderer on a scene file or the embedded default scene.

use std::path::{Path, PathBuf};
use std::time::Instant;

use indicatif::{ProgressBar, ProgressStyle};
use specula::{Exponent, Geometry, LobeKind, Normalisation};
use specula_gpu::{Gpu, GpuRenderer};
use specula_render::ibl::{
    render_ibl, render_ibl_grid, Environment, IblSettings, Strategy, MAX_SPP,
};
use specula_render::microfacet_scene::render_ibl_microfacet;
use specula_render::{
    check_output_path, made_renders, render, render_grid_with, write_image, write_png_srgb8,
    GridOptions, IlluminationModel, Image, LoadedScene, Overrides, Scene, Shading, DEFAULT_SCENE,
};

use super::CommandResult;
use crate::args::{choice, parse_exponent, LobeParser, RendererArg};

/// Arguments of `specula render`.
#[derive(Debug, clap::Args)]
pub struct Args {
    #[command(flatten)]
    input_limit: crate::args::InputLimit,
    /// The most triangles a scene may have (procedural shapes are counted before they are
    /// built; about 100 bytes of memory each while rendering).
    #[arg(
        long,
        default_value_t = specula_render::MAX_TRIANGLES,
        value_parser = clap::value_parser!(u64).range(1..=1 << 28),
    )]
    max_triangles: u64,
    /// A scene file (TOML); the embedded default scene when omitted.
    scene: Option<PathBuf>,
    /// Output image: .png (8-bit sRGB), .exr (linear f32 radiance) or .hdr (linear RGBE).
    #[arg(short, long, default_value = "render.png")]
    output: PathBuf,
    /// Every material's lobe.
    #[arg(long, value_parser = LobeParser)]
    lobe: Option<LobeKind>,
    /// Every material's exponent, in [1, 1000].
    #[arg(long, value_parser = parse_exponent, allow_hyphen_values = true)]
    n: Option<Exponent>,
    /// Every material's geometry.
    #[arg(long, value_parser = choice(&Geometry::ALL, Geometry::id))]
    geometry: Option<Geometry>,
    /// Every material's normalisation.
    #[arg(long, value_parser = choice(&Normalisation::ALL, Normalisation::id))]
    normalisation: Option<Normalisation>,
    /// The shading method.
    #[arg(long, value_parser = choice(&Shading::ALL, Shading::id))]
    shading: Option<Shading>,
    /// The illumination model.
    #[arg(long, value_parser = choice(&IlluminationModel::ALL, IlluminationModel::id))]
    model: Option<IlluminationModel>,
    /// Image width in pixels (per tile, with --grid).
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=16384))]
    width: Option<u32>,
    /// Image height in pixels (per tile, with --grid).
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=16384))]
    height: Option<u32>,
    /// Supersampling: S x S samples per pixel.
    #[arg(
        long,
        value_parser = clap::value_parser!(u32).range(1..=specula_render::MAX_SAMPLES as i64),
    )]
    samples: Option<u32>,
    /// One tile per lobe with its FLIP against pow, e.g. `lobes=pow,schlick,cheb2` (PNG only).
    #[arg(long, value_parser = parse_grid, value_name = "lobes=ID,...")]
    grid: Option<LobeList>,
    /// The renderer: the CPU rasterizer, or wgpu (a GPU, or Mesa's lavapipe without one).
    #[arg(long, value_enum, default_value_t)]
    backend: RendererArg,
    /// Light the scene by an environment instead of its lights: `sky` (built in; a file named
    /// sky is `./sky`) or an equirectangular .hdr, .exr or .png file (at most 4096 x 4096),
    /// rendered by Monte Carlo with multiple importance sampling on the CPU, physical model
    /// (or, with --model microfacet, the microfacet model). Without a scene file, the
    /// embedded environment scene (a sphere and the teapot).
    #[arg(long, value_name = "sky|FILE", conflicts_with_all = ["shading"])]
    env: Option<PathBuf>,
    /// Samples per pixel with --env.
    #[arg(
        long,
        requires = "env",
        default_value_t = 64,
        value_parser = clap::value_parser!(u32).range(1..=i64::from(MAX_SPP)),
    )]
    spp: u32,
    /// The random stream with --env: renders with different seeds are independent.
    #[arg(long, requires = "env", default_value_t = 0)]
    seed: u64,
    /// Print the embedded default scene (a starting point for your own) and exit.
    #[arg(long, exclusive = true)]
    dump_default_scene: bool,
}

/// The lobes of `--grid` (a newtype: clap reads a bare `Vec` as repeated values).
#[derive(Clone, Debug)]
struct LobeList(Vec<LobeKind>);

fn parse_grid(text: &str) -> Result<LobeList, String> {
    let list = text.strip_prefix("lobes=").ok_or_else(|| {
        format!("'{text}' must have the form lobes=ID,ID,... (e.g. lobes=pow,schlick)")
    })?;
    specula_render::lobe_file::parse_lobe_list(list, None).map(LobeList)
}

fn progress_bar(label: &str) -> ProgressBar {
    ProgressBar::new(0).with_style(
        ProgressStyle::with_template(&format!("{label} {{bar:30}} {{percent}}% {{elapsed}}"))
            .unwrap_or_else(|_| ProgressStyle::default_bar()),
    )
}

/// Loads the scene (or the default) and applies the command line's overrides.
fn load(args: &Args) -> Result<Scene, String> {
    let LoadedScene {
        mut scene,
        warnings,
    } = Scene::from_file_or_default(args.scene.as_deref(), args.env.is_some())
        .map_err(|e| e.to_string())?;
    for warning in warnings {
        eprintln!("warning: {warning}");
    }
    scene.apply(&Overrides {
        lobe: args.lobe,
        n: args.n,
        geometry: args.geometry,
        normalisation: args.normalisation,
        shading: args.shading,
        model: args.model,
        width: args.width,
        height: args.height,
        samples: args.samples,
    });
    scene.check_lobes()?;
    if let Some(LobeList(lobes)) = &args.grid {
        let exponents: Vec<Exponent> = scene
            .objects
            .iter()
            .map(|o| o.material.lobe.exponent())
            .collect();
        crate::args::check_lobes(lobes, &exponents)?;
    }
    Ok(scene)
}

/// Renders and writes the image.
pub fn run(args: &Args) -> CommandResult {
    args.input_limit.apply();
    specula_render::set_max_triangles(args.max_triangles);
    if args.dump_default_scene {
        print!("{DEFAULT_SCENE}");
        return Ok(());
    }
    check_output_path(&args.output).map_err(|e| e.to_string())?;
    let scene = load(args)?;
    let started = Instant::now();
    let bar = progress_bar("rendering");
    let microfacet = args.model == Some(IlluminationModel::Microfacet);
    let environment = match &args.env {
        Some(_) if args.backend == RendererArg::Gpu => {
            return Err("--env renders on the CPU only; drop --backend gpu".into())
        }
        Some(_) if args.model == Some(IlluminationModel::Classic) => {
            return Err(
                "--env renders the physical or the microfacet model, not the classic \
                one; valid --model values with --env: physical, microfacet"
                    .into(),
            )
        }
        Some(_) if microfacet && args.grid.is_some() => {
            return Err("--env --model microfacet renders one image; drop --grid".into())
        }
        Some(name) => Some(Environment::named(name).map_err(|e| e.to_string())?),
        None => None,
    };
    let gpu = match args.backend {
        RendererArg::Cpu => None,
        RendererArg::Gpu => Some(Gpu::new().map_err(|e| e.to_string())?),
    };
    let gpu_renderer = gpu.as_ref().map(GpuRenderer::new);
    let ibl = IblSettings {
        spp: args.spp,
        seed: args.seed,
        strategy: Strategy::Mis,
    };
    let renders = 1 + args.grid.as_ref().map_or(0, |LobeList(lobes)| lobes.len());
    // Renders the `index`-th image of `renders`, on the chosen backend, with progress.
    let mut draw = |scene: &Scene, index: usize| -> Result<Image, String> {
        let progress = |done: usize, total: usize| {
            bar.set_length((renders * total) as u64);
            bar.set_position((index * total + done) as u64);
        };
        match (&gpu_renderer, &environment) {
            (Some(renderer), _) => {
                let image = renderer.render(scene).map_err(|e| e.to_string());
                progress(1, 1);
                image
            }
            (None, Some(environment)) if microfacet => {
                render_ibl_microfacet(scene, environment, &ibl, &progress)
                    .map_err(|e| e.to_string())
            }
            (None, Some(environment)) => {
                render_ibl(scene, environment, &ibl, &progress).map_err(|e| e.to_string())
            }
            (None, None) => render(scene, &progress).map_err(|e| e.to_string()),
        }
    };
    let (width, height) = match &args.grid {
        Some(LobeList(lobes)) => {
            if !is_png(&args.output) {
                return Err(format!(
                    "{}: a grid is written as PNG; give an output ending in .png",
                    args.output.display()
                ));
            }
            let options = GridOptions {
                lobes: lobes.clone(),
                reference: LobeKind::Pow,
            };
            // Lit by an environment on the CPU, every lobe is drawn in one pass from the same
            // draws, then handed to the grid.
            let grid = match (&gpu_renderer, &environment) {
                (None, Some(environment)) => {
                    let progress = |done: usize, total: usize| {
                        bar.set_length(total as u64);
                        bar.set_position(done as u64);
                    };
                    let mut images =
                        render_ibl_grid(&scene, &options, environment, &ibl, &progress)
                            .map_err(|e| e.to_string())?;
                    let mut renders = made_renders(&mut images);
                    render_grid_with(&scene, &options, &mut renders)
                }
                _ => render_grid_with(&scene, &options, &mut draw),
            }
            .map_err(|e| e.to_string())?;
            bar.finish_and_clear();
            write_png_srgb8(&args.output, grid.width, grid.height, &grid.bytes)
                .map_err(|e| e.to_string())?;
            (grid.width, grid.height)
        }
        None => {
            let image = draw(&scene, 0)?;
            bar.finish_and_clear();
            write_image(&args.output, &image, scene.display).map_err(|e| e.to_string())?;
            (image.width(), image.height())
        }
    };
    let device = gpu.map_or_else(|| "CPU".to_owned(), |gpu| gpu.adapter_name());
    let method = match &args.env {
        Some(env) => format!(
            "{} spp, lit by {}, {} model",
            args.spp,
            env.display(),
            if microfacet { "microfacet" } else { "physical" }
        ),
        None => format!(
            "{} shading, {} model",
            scene.settings.shading.id(),
            scene.settings.model.id()
        ),
    };
    eprintln!(
        "wrote {} ({width}x{height}, {method}, {device}, {:.2} s)",
        args.output.display(),
        started.elapsed().as_secs_f64()
    );
    Ok(())
}

fn is_png(path: &Path) -> bool {
    path.extension()
        .and_then(|e| e.to_str())
        .is_some_and(|e| e.eq_ignore_ascii_case("png"))
}
