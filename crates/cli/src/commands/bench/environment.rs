//! `specula bench environment`: the environment-lit renderer's shaded samples per second on
//! two views lit by the built-in sky, beside Mitsuba 3 rendering the same views when the
//! `mitsuba` wheel is present ([`super::mitsuba_peer`]).
//!
//! The work is made equal: the same shapes (spheres exact in both, the teapot's triangles
//! written as OBJ), camera, map (the sky written as EXR, which both read), resolution and
//! samples per pixel; Mitsuba's `llvm_ad_rgb` variant with the `direct` integrator (one
//! emitter and one BSDF sample per camera sample, MIS by the power heuristic, as specula's)
//! and specula's own Mitsuba plugin of the same lobe. Each is timed three ways: a warm
//! render (specula's in this process; Mitsuba's after its first frame, the scene loaded and
//! the kernels compiled), specula's whole process (`specula render`: the sky, the raster,
//! the render, the file) against Mitsuba's warm render, and both from a cold start to the
//! first image written. What differs, and is said in the output: Mitsuba traces rays (the
//! camera's, and a shadow ray per emitter sample) where specula rasterizes and leaves the
//! environment unoccluded, and it interpolates the map bilinearly where specula takes the
//! nearest texel.

use std::path::Path;
use std::process::Command;
use std::time::Instant;

use specula::LobeKind;
use specula_render::ibl::{render_ibl, Environment, IblSettings, SKY_WIDTH};
use specula_render::metrics::{mean_radiance, rms_difference};
use specula_render::{write_image, Display, Image, Overrides};
use specula_render::{Scene, IBL_SCENE};
use specula_report::vtk_peer::{self, median};

use super::mitsuba_peer::{time_mitsuba, MitsubaRun};
use super::Args;
use crate::commands::CommandResult;
use crate::output::Table;

/// The lobes measured: `pow` and the cheapest of the thesis's approximations.
const LOBES: [LobeKind; 2] = [LobeKind::Pow, LobeKind::CosQuad { v: 4 }];

/// The close-up: one sphere filling every pixel, so shading is all the work.
const CLOSE_UP: &str = r#"
[camera]
eye = [0.0, -2.0, 0.0]
target = [0.0, 0.0, 0.0]
up = [0.0, 0.0, 1.0]
fov = 30.0

[render]
width = 512
height = 512
samples = 1
model = "physical"

[[objects]]
shape = "sphere"
radius = 0.9
[objects.material]
kd = 0.35
ks = 0.65
colour = [0.7, 0.1, 0.08]
n = 64
normalisation = "lobe"
"#;

/// A view: its name, its scene and the scene's text (for `specula render`).
struct View {
    name: &'static str,
    scene: Scene,
    text: &'static str,
}

fn views() -> Result<[View; 2], String> {
    let load = |text: &str, name: &str| {
        Scene::from_toml(text, name, None)
            .map(|loaded| loaded.scene)
            .map_err(|e| e.to_string())
    };
    let mut embedded = load(IBL_SCENE, "<environment scene>")?;
    let mut close_up = load(CLOSE_UP, "<close-up>")?;
    for scene in [&mut embedded, &mut close_up] {
        scene.apply(&Overrides {
            samples: Some(1),
            ..Overrides::default()
        });
    }
    Ok([
        View {
            name: "embedded scene 960 x 540",
            scene: embedded,
            text: IBL_SCENE,
        },
        View {
            name: "close-up 512 x 512",
            scene: close_up,
            text: CLOSE_UP,
        },
    ])
}

/// specula's median seconds per frame on `threads` threads, and its first frame.
fn time_specula(
    scene: &Scene,
    sky: &Environment,
    spp: u32,
    frames: u32,
    threads: usize,
) -> Result<(f64, Image), String> {
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .map_err(|e| e.to_string())?;
    pool.install(|| {
        let settings = IblSettings {
            spp,
            seed: 1,
            ..IblSettings::default()
        };
        let image = render_ibl(scene, sky, &settings, &|_, _| {}).map_err(|e| e.to_string())?;
        let seconds = (0..frames)
            .map(|frame| {
                let settings = IblSettings {
                    seed: 2 + u64::from(frame),
                    ..settings
                };
                let start = Instant::now();
                render_ibl(scene, sky, &settings, &|_, _| {}).map_err(|e| e.to_string())?;
                Ok(start.elapsed().as_secs_f64())
            })
            .collect::<Result<Vec<_>, String>>()?;
        Ok((median(seconds), image))
    })
}

/// specula's whole process, `specula render` of `scene_file` with `kind` on `threads`
/// threads: the median wall time of `frames` runs, seconds.
fn time_process(
    scene_file: &Path,
    kind: LobeKind,
    spp: u32,
    frames: u32,
    threads: usize,
) -> Result<f64, String> {
    let executable = std::env::current_exe().map_err(|e| e.to_string())?;
    let output = scene_file.with_file_name("specula.exr");
    let seconds = (0..frames)
        .map(|_| {
            let started = Instant::now();
            let result = Command::new(&executable)
                .arg("render")
                .arg(scene_file)
                .args(["--env", "sky", "--samples", "1", "--lobe", kind.id()])
                .args(["--spp", &spp.to_string(), "--seed", "1", "-o"])
                .arg(&output)
                .env("RAYON_NUM_THREADS", threads.to_string())
                .output()
                .map_err(|e| format!("{}: {e}", executable.display()))?;
            let seconds = started.elapsed().as_secs_f64();
            if !result.status.success() {
                return Err(format!(
                    "specula render failed: {}",
                    String::from_utf8_lossy(&result.stderr).trim()
                ));
            }
            Ok(seconds)
        })
        .collect::<Result<Vec<_>, String>>()?;
    Ok(median(seconds))
}

/// The columns comparing one configuration's measures with Mitsuba's, or dashes without it.
fn compared(
    measured: &Measured,
    mitsuba: Option<&MitsubaRun>,
    samples: f64,
    (image, second): (&Image, &Image),
) -> Vec<String> {
    let Some(run) = mitsuba else {
        return vec!["-".to_owned(); 7];
    };
    vec![
        format!("{:.2}", samples / run.warm / 1e6),
        format!("{:.2}x", run.warm / measured.render),
        format!("{:.3}", run.warm),
        format!("{:.2}x", run.warm / measured.process),
        format!("{:.2}", run.cold),
        format!("{:.2}x", run.cold / measured.process),
        format!(
            "{:.2} / {:+.2} %",
            rms_difference(image, &run.image) / rms_difference(image, second),
            100.0 * (mean_radiance(&run.image) / mean_radiance(image) - 1.0)
        ),
    ]
}

/// specula's times for one configuration, seconds.
struct Measured {
    /// The median warm render, in this process.
    render: f64,
    /// The median whole process.
    process: f64,
}

/// Measures and prints.
pub fn run(args: &Args) -> CommandResult {
    let spps: Vec<u32> = args.spp.map_or_else(|| vec![16, 64], |spp| vec![spp]);
    let sky = Environment::sky(SKY_WIDTH);
    let scratch = specula_temporaries::dir("bench-").map_err(|e| e.to_string())?;
    write_image(
        &scratch.path().join("sky.exr"),
        sky.image(),
        Display::default(),
    )
    .map_err(|e| e.to_string())?;
    let all = rayon::current_num_threads();
    let threads: Vec<usize> = if all > 1 { vec![1, all] } else { vec![1] };
    println!(
        "lit by the built-in sky ({SKY_WIDTH} x {}), each view's own exponents; warm renders: the \
            median of {} \
         frames after one; samples/s = pixels x spp / seconds per frame; x: how many times faster \
         specula is",
        SKY_WIDTH / 2,
        args.frames
    );
    println!(
        "Mitsuba: llvm_ad_rgb, direct integrator (1 emitter + 1 BSDF sample, MIS), specula's \
            plugin of the lobe, \
         spheres as Mitsuba's own sphere shape and the teapot as the same OBJ triangles, the same \
         camera and sky.exr; \
         on 1 thread it runs two Dr.Jit workers pinned to one core (taskset; one worker deadlocks)"
    );
    println!(
        "specula process: `specula render` from start to the image written (the sky, the raster, \
            the render, the EXR), \
         the median of {} runs; Mitsuba cold: from starting Python to its first image written (the \
         import, the \
         scene's loading, the kernels' compilation, the render)",
        args.frames
    );
    let mut table = Table::new(&[
        "view",
        "lobe",
        "spp",
        "threads",
        "specula Msamples/s",
        "Mitsuba Msamples/s",
        "warm render x",
        "specula process s",
        "Mitsuba warm s",
        "process vs warm x",
        "Mitsuba cold s",
        "cold start x",
        "images: RMS / noise, means",
    ]);
    let mut missing = None;
    let mut version = None;
    for view in views()? {
        let scene_file = scratch.path().join("view.toml");
        std::fs::write(&scene_file, view.text).map_err(|e| e.to_string())?;
        let pixels = f64::from(view.scene.settings.width * view.scene.settings.height);
        for kind in LOBES {
            let mut scene = view.scene.clone();
            scene.apply(&Overrides {
                lobe: Some(kind),
                ..Overrides::default()
            });
            for &spp in &spps {
                // A second seed of specula's: the noise the images' difference is held to.
                let settings = IblSettings {
                    spp,
                    seed: 99,
                    ..IblSettings::default()
                };
                let second =
                    render_ibl(&scene, &sky, &settings, &|_, _| {}).map_err(|e| e.to_string())?;
                let samples = pixels * f64::from(spp);
                for &count in &threads {
                    let (render, image) = time_specula(&scene, &sky, spp, args.frames, count)?;
                    let process = time_process(&scene_file, kind, spp, args.frames, count)?;
                    let mitsuba = match missing {
                        Some(_) => None,
                        None => time_mitsuba(&scene, scratch.path(), spp, args.frames, count)
                            .map_err(|why| missing = Some(why))
                            .ok(),
                    };
                    if let Some(run) = &mitsuba {
                        version = Some(run.version.clone());
                    }
                    let measured = Measured { render, process };
                    let mut row = vec![
                        view.name.to_owned(),
                        kind.id().to_owned(),
                        spp.to_string(),
                        count.to_string(),
                        format!("{:.2}", samples / render / 1e6),
                    ];
                    let mut rest =
                        compared(&measured, mitsuba.as_ref(), samples, (&image, &second));
                    rest.insert(2, format!("{process:.3}"));
                    row.extend(rest);
                    table.push(row);
                }
            }
        }
    }
    table.print(crate::args::OutputFormat::Table);
    println!(
        "images: the RMS difference between specula's and Mitsuba's first frames over that between \
            two of specula's \
         (seeds 1 and 99), about 1 where they differ by noise alone; and how far Mitsuba's mean is \
         from specula's"
    );
    println!(
        "what still differs: Mitsuba traces a camera ray and a shadow ray per sample (the scenes \
            have nothing to \
         occlude the sky, so the shadow rays change no pixel) and interpolates the map bilinearly \
         where specula takes \
         the nearest texel (a smooth sky: within noise)"
    );
    match (missing, version) {
        (Some(why), _) => println!(
            "Mitsuba not measured: {why} (install the mitsuba and drjit wheels and Debian's \
                libllvm19 for {})",
            vtk_peer::python().display()
        ),
        (None, Some(version)) => println!("Mitsuba {version}"),
        (None, None) => {}
    }
    Ok(())
}
