//! `specula bench`: throughput measured in one run, printed as figures and ratios (never a
//! pass/fail timing: these machines are noisy).

use std::time::Instant;

use specula::LobeKind;
use specula_gpu::{throughput, Gpu, GpuRenderer};
use specula_render::{render, Overrides, Scene, Shading};

use super::CommandResult;
use crate::output::{number, Table};

pub mod environment;
mod first_run;
pub mod lobes;
mod mitsuba_peer;
pub mod volume;
mod vtk_lobes;

/// What to measure.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum Target {
    /// Every lobe's SIMD kernel against its bound, its plain loop, powf and the fast pow.
    Lobes,
    /// A whole frame: the CPU rasterizer against the GPU pipeline, per shading method.
    Frame,
    /// The CPU renderer: ms per frame of the default scene for each shading method.
    Render,
    /// The GPU renderer: ms per frame of the default scene (Phong shading) for each lobe.
    Gpu,
    /// Every lobe in a GPU compute shader: G evaluations/s and the ratio to pow.
    GpuLobes,
    /// The environment-lit renderer (`render --env sky`): shaded samples per second on the
    /// embedded scene and a full-frame sphere, for pow and cosquad on 1 and all threads,
    /// beside Mitsuba 3 (llvm_ad_rgb) rendering the same views when the `mitsuba` wheel is
    /// present.
    Environment,
    /// What a newcomer meets first: `report --quick`, `report` and `fit` (both models) on a
    /// bundled material, each this binary on an empty cache folder, with each section's time.
    FirstRun,
    /// The volume renderer on the CPU: frames per second of `--input` (512 x 512 unless
    /// `--width`/`--height` say otherwise), beside VTK's CPU ray caster when the `vtk` wheel
    /// is present.
    Volume,
    /// Every lobe inside VTK's GPU ray caster (`specula shader --lang vtk`) on `--input`
    /// (256 x 256 unless `--width`/`--height` say otherwise): frame time against VTK's own pow
    /// in the same process, and the image against specula's marcher set up alike.
    VtkLobes,
}

/// Arguments of `specula bench`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// What to measure.
    #[arg(value_enum)]
    target: Target,
    /// Frame width (1920, or 512 for `bench volume`).
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=16384))]
    width: Option<u32>,
    /// Frame height (1080, or 512 for `bench volume`).
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=16384))]
    height: Option<u32>,
    /// Samples per pixel (`bench environment`; by default 16, then 64).
    #[arg(
        long,
        value_parser = clap::value_parser!(u32).range(1..=i64::from(specula_render::ibl::MAX_SPP)),
    )]
    spp: Option<u32>,
    /// Timed frames per method (after one untimed warm-up frame).
    #[arg(long, default_value_t = 5, value_parser = clap::value_parser!(u32).range(1..=1000))]
    frames: u32,
    /// The exponent the lobes are prepared for (`bench lobes`; VTK's specular power in
    /// `bench volume`).
    #[arg(
        long,
        allow_hyphen_values = true,
        default_value = "64",
        value_parser = crate::args::parse_exponent,
    )]
    n: specula::Exponent,
    /// Output format (`bench lobes`, `bench gpu-lobes`).
    #[arg(long, value_enum, default_value_t = crate::args::OutputFormat::Table)]
    format: crate::args::OutputFormat,
    /// The volume `bench volume` renders: built-in (phantom, marschner-lobb), NIfTI or DICOM.
    #[arg(long, default_value = "phantom")]
    input: String,
    /// The transfer function of `bench volume` (a preset); by default the volume's own.
    #[arg(long)]
    transfer: Option<String>,
    /// The view of `bench volume` (anterior, posterior, left, right, superior, inferior).
    #[arg(
        long,
        value_parser = specula_volume::dvr::View::parse,
        default_value = "anterior",
    )]
    view: specula_volume::dvr::View,
    /// Millimetres between samples along a ray (`bench volume`; VTK's sample distance).
    #[arg(long, default_value_t = 0.5, value_parser = parse_distance)]
    sample_distance: f32,
    /// Also write the last frame of each renderer into this folder (`bench volume`).
    #[arg(long)]
    images: Option<std::path::PathBuf>,
}

fn parse_distance(text: &str) -> Result<f32, String> {
    match text.trim().parse::<f32>() {
        Ok(value) if value > 0.0 && value.is_finite() => Ok(value),
        _ => Err(format!(
            "'{}' must be a positive distance in millimetres",
            specula::excerpt(text)
        )),
    }
}

/// Measures and prints.
pub fn run(args: &Args) -> CommandResult {
    match args.target {
        Target::Lobes => lobes::run(args.n, args.format),
        Target::Frame => bench_frame(args),
        Target::Render => bench_render(args),
        Target::Gpu => bench_gpu(args),
        Target::GpuLobes => bench_gpu_lobes(args),
        Target::Volume => volume::run(args),
        Target::VtkLobes => vtk_lobes::run(args),
        Target::Environment => environment::run(args),
        Target::FirstRun => first_run::run(),
    }
}

impl Args {
    /// The frame's size: the target's default unless given.
    fn size(&self) -> (u32, u32) {
        let (width, height) = match self.target {
            Target::Volume => (512, 512),
            Target::VtkLobes => (256, 256),
            _ => (1920, 1080),
        };
        (self.width.unwrap_or(width), self.height.unwrap_or(height))
    }
}

/// The default scene at the requested size, one sample per pixel, with these overrides.
fn bench_scene(args: &Args, overrides: Overrides) -> Scene {
    let mut scene = Scene::default_scene();
    let (width, height) = args.size();
    scene.apply(&Overrides {
        width: Some(width),
        height: Some(height),
        samples: Some(1),
        ..overrides
    });
    scene
}

/// Best and mean of `frames` timed calls after one warm-up, in ms.
fn time(frames: u32, mut frame: impl FnMut() -> Result<f64, String>) -> Result<(f64, f64), String> {
    frame()?;
    let times = (0..frames)
        .map(|_| frame())
        .collect::<Result<Vec<_>, _>>()?;
    let best = times.iter().copied().fold(f64::INFINITY, f64::min);
    Ok((best, times.iter().sum::<f64>() / times.len() as f64))
}

/// A GPU frame's figures: best and mean wall time without read-back, best with it, and the
/// best pass time by the GPU's timestamps, in ms; set-up (pipelines, uploads, targets) is
/// done once, before any timing.
struct GpuTimes {
    best: f64,
    mean: f64,
    read_back: f64,
    pass: Option<f64>,
}

impl GpuTimes {
    fn measure(renderer: &GpuRenderer, scene: &Scene, frames: u32) -> Result<Self, String> {
        let frame = renderer.prepare(scene).map_err(|e| e.to_string())?;
        let mut passes = Vec::new();
        let mut draw = |read_back: bool| {
            let time = frame.draw(read_back).map_err(|e| e.to_string())?;
            passes.extend(time.pass);
            Ok(time.wall.as_secs_f64() * 1e3)
        };
        let (best, mean) = time(frames, || draw(false))?;
        let (read_back, _) = time(frames, || draw(true))?;
        let pass = passes
            .iter()
            .map(|d| d.as_secs_f64() * 1e3)
            .reduce(f64::min);
        Ok(Self {
            best,
            mean,
            read_back,
            pass,
        })
    }

    fn pass_cell(&self) -> String {
        self.pass
            .map_or_else(|| "no timestamps".to_owned(), |ms| format!("{ms:.2}"))
    }
}

fn bench_frame(args: &Args) -> CommandResult {
    let gpu = Gpu::new().map_err(|e| e.to_string())?;
    let renderer = GpuRenderer::new(&gpu);
    println!(
        "default scene, {}x{}, 1 sample per pixel, {} frames per method; CPU: {} threads; GPU: {}\n\
         GPU frames are drawn from buffers uploaded once; 'GPU pass' is the scene pass by the \
         GPU's own timestamps",
        args.size().0,
        args.size().1,
        args.frames,
        rayon::current_num_threads(),
        gpu.adapter_name()
    );
    let mut table = Table::new(&[
        "shading",
        "CPU ms/frame",
        "GPU ms/frame",
        "GPU with read-back",
        "GPU pass ms",
        "CPU / GPU",
    ]);
    for shading in Shading::ALL {
        let scene = bench_scene(
            args,
            Overrides {
                shading: Some(shading),
                ..Overrides::default()
            },
        );
        let (cpu, _) = time(args.frames, || cpu_frame_ms(&scene))?;
        let gpu = GpuTimes::measure(&renderer, &scene, args.frames)?;
        table.push(vec![
            shading.id().to_owned(),
            format!("{cpu:.1}"),
            format!("{:.2}", gpu.best),
            format!("{:.2}", gpu.read_back),
            gpu.pass_cell(),
            format!("{:.2}", cpu / gpu.best),
        ]);
    }
    table.print(crate::args::OutputFormat::Table);
    Ok(())
}

fn bench_gpu(args: &Args) -> CommandResult {
    let gpu = Gpu::new().map_err(|e| e.to_string())?;
    let renderer = GpuRenderer::new(&gpu);
    println!(
        "{}\ndefault scene, {}x{}, Phong shading, 1 sample per pixel, {} frames per lobe, \
         drawn from buffers uploaded once (draw and wait; then with the image copied back); \
         'pass' is the scene pass by the GPU's own timestamps",
        gpu.adapter_name(),
        args.size().0,
        args.size().1,
        args.frames
    );
    let mut table = Table::new(&[
        "lobe",
        "best ms/frame",
        "mean ms/frame",
        "with read-back",
        "pass ms",
        "vs pow",
    ]);
    let mut pow = None;
    for kind in LobeKind::ALL {
        let scene = bench_scene(
            args,
            Overrides {
                lobe: Some(kind),
                shading: Some(Shading::Phong),
                ..Overrides::default()
            },
        );
        let times = GpuTimes::measure(&renderer, &scene, args.frames)?;
        // Against pow by the GPU's pass time where there is one: it excludes the host.
        let figure = times.pass.unwrap_or(times.best);
        let pow = *pow.get_or_insert(figure);
        table.push(vec![
            kind.to_string(),
            format!("{:.2}", times.best),
            format!("{:.2}", times.mean),
            format!("{:.2}", times.read_back),
            times.pass_cell(),
            format!("{:.2}x", figure / pow),
        ]);
    }
    table.print(crate::args::OutputFormat::Table);
    Ok(())
}

fn bench_gpu_lobes(args: &Args) -> CommandResult {
    let gpu = Gpu::new().map_err(|e| e.to_string())?;
    // CSV is data alone: the notes go to stderr, every figure a number with all its digits.
    let csv = args.format == crate::args::OutputFormat::Csv;
    let note = |text: String| {
        if csv {
            eprintln!("{text}");
        } else {
            println!("{text}");
        }
    };
    let ratio = |x: f64| {
        if csv {
            number(x)
        } else {
            format!("{x:.2}x")
        }
    };
    note(format!(
        "{}\nevery lobe at n = {}, its constants baked into a compute shader; each invocation \
         sums the lobe at {} cosines (bound by arithmetic, not memory); dispatches grow until \
         one takes 20 ms, then {} are timed: the rate is the fastest, the spread (in brackets) \
         runs from the median; a lobe whose spread overlaps pow's is a tie",
        gpu.adapter_name(),
        args.n,
        throughput::CHAIN,
        throughput::TIMED
    ));
    // Each vendor's current generation as `recommend` costs it (the compiled machine code, or
    // the model where the compiler is missing), beside what this adapter measures.
    let targets = specula_decide::Target::GPUS;
    let mut headers = vec![
        "lobe".to_owned(),
        "G evals/s".to_owned(),
        "x pow's throughput".to_owned(),
        "vs pow".to_owned(),
        "evaluations timed".to_owned(),
        "ms".to_owned(),
        "shader ops".to_owned(),
    ];
    headers.extend(targets.iter().map(|&target| {
        format!(
            "x pow's throughput, {} ({})",
            target.gpu(None).ok().flatten().map_or("", |gpu| gpu.id),
            specula_decide::rate_unit(target)
        )
    }));
    let headers: Vec<&str> = headers.iter().map(String::as_str).collect();
    let mut table = Table::new(&headers);
    let mut pow: Option<(throughput::LobeThroughput, Vec<f64>)> = None;
    for kind in LobeKind::ALL {
        let lobe = specula::Lobe::new(kind, args.n);
        let (rate, _) = throughput::measure(&gpu, &lobe).map_err(|e| e.to_string())?;
        let ops = specula_gpu::shader_ops::lobe_shader_ops(&lobe)?;
        let modelled = targets
            .iter()
            .map(|&target| specula_decide::lobe_rate(target, &lobe))
            .collect::<Result<Vec<f64>, String>>()?;
        let (pow_rate, pow_modelled) = pow.get_or_insert_with(|| (rate, modelled.clone())).clone();
        let spread =
            |r: &throughput::LobeThroughput| [r.median_evals_per_second(), r.evals_per_second];
        let ([low, high], [pow_low, pow_high]) = (spread(&rate), spread(&pow_rate));
        let standing = if kind == LobeKind::Pow {
            "the reference"
        } else if low <= pow_high && pow_low <= high {
            "tie"
        } else if low > pow_high {
            "faster"
        } else {
            "slower"
        };
        let mut row = vec![
            kind.to_string(),
            if csv {
                number(rate.evals_per_second / 1e9)
            } else {
                format!("{:.1}", rate.evals_per_second / 1e9)
            },
            if csv {
                number(high / pow_rate.evals_per_second)
            } else {
                format!(
                    "{:.2}x ({:.2}-{:.2})",
                    high / pow_rate.evals_per_second,
                    low / pow_rate.evals_per_second,
                    high / pow_rate.evals_per_second
                )
            },
            standing.to_owned(),
            rate.evaluations.to_string(),
            if csv {
                number(rate.time.as_secs_f64() * 1e3)
            } else {
                format!("{:.2}", rate.time.as_secs_f64() * 1e3)
            },
            ops.expanded().total().to_string(),
        ];
        row.extend(
            modelled
                .iter()
                .zip(&pow_modelled)
                .map(|(m, p)| ratio(m / p)),
        );
        table.push(row);
    }
    note(
        "each vendor's column: the machine code its compiler writes for the lobe (specula isa), \
         at the generation's published per-clock rates (crates/specula/src/gpus.rs names the \
         sources); the naga-IR model where the compiler is missing, as the unit says"
            .to_owned(),
    );
    table.print(args.format);
    Ok(())
}

/// One CPU frame of `scene`, in ms.
fn cpu_frame_ms(scene: &Scene) -> Result<f64, String> {
    let started = Instant::now();
    render(scene, &|_, _| {}).map_err(|e| e.to_string())?;
    Ok(started.elapsed().as_secs_f64() * 1e3)
}

fn bench_render(args: &Args) -> CommandResult {
    let cores = rayon::current_num_threads();
    println!(
        "default scene, {}x{}, 1 sample per pixel, {} frames per method, {cores} threads",
        args.size().0,
        args.size().1,
        args.frames
    );
    let mut table = Table::new(&["shading", "best ms/frame", "mean ms/frame", "vs flat"]);
    let mut flat_best = None;
    for shading in Shading::ALL {
        let overrides = Overrides {
            shading: Some(shading),
            ..Overrides::default()
        };
        let scene = bench_scene(args, overrides);
        let (best, mean) = time(args.frames, || cpu_frame_ms(&scene))?;
        let flat = *flat_best.get_or_insert(best);
        table.push(vec![
            shading.id().to_owned(),
            format!("{best:.1}"),
            format!("{mean:.1}"),
            format!("{:.2}x", best / flat),
        ]);
    }
    table.print(crate::args::OutputFormat::Table);
    Ok(())
}
