//! `specula bench environment`: the environment-lit renderer's shaded samples per second on
//! two views lit by the built-in sky, beside Mitsuba 3 rendering the same views when the
//! `mitsuba` wheel is present.
//!
//! The work is made equal: the same triangles (each mesh written as OBJ), camera, map (the
//! sky written as EXR, which both read), resolution and samples per pixel; Mitsuba's
//! `llvm_ad_rgb` variant with the `direct` integrator (one emitter and one BSDF sample per
//! camera sample, MIS by the power heuristic, as specula's) and specula's own Mitsuba
//! plugin of the same lobe (`specula shader --lang mitsuba`). What differs, and is said in
//! the output: Mitsuba traces rays (the camera's, and a shadow ray per emitter sample) where
//! specula rasterizes and leaves the environment unoccluded, and it interpolates the map
//! bilinearly where specula takes the nearest texel.

use std::path::Path;
use std::time::Instant;

use specula::LobeKind;
use specula_gpu::export::{Format, Options};
use specula_render::ibl::{render_ibl, Environment, IblSettings, SKY_WIDTH};
use specula_render::metrics::{mean_radiance, rms_difference};
use specula_render::{read_image, write_image, write_mitsuba_scene, Display, Image, Overrides};
use specula_render::{Scene, IBL_SCENE};
use specula_report::vtk_peer;

use super::Args;
use crate::commands::CommandResult;
use crate::output::Table;

/// The Mitsuba harness (`mitsuba_check.py render --frames`), compiled in.
const MITSUBA_SCRIPT: &str = include_str!("../../../tests/renderers/mitsuba_check.py");

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

/// A view: its name and scene.
struct View {
    name: &'static str,
    scene: Scene,
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
            name: "embedded scene (960 x 540)",
            scene: embedded,
        },
        View {
            name: "close-up, sphere fills the frame (512 x 512)",
            scene: close_up,
        },
    ])
}

/// The median of `values`.
fn median(mut values: Vec<f64>) -> f64 {
    values.sort_by(f64::total_cmp);
    values[values.len() / 2]
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

/// What Mitsuba measured: median seconds per frame, its first image, its version.
struct MitsubaRun {
    seconds: f64,
    image: Image,
    version: String,
}

/// Renders `scene` in Mitsuba (`llvm_ad_rgb`) with specula's plugin of its first object's
/// lobe, `frames` timed frames on `threads` threads after a first one.
fn time_mitsuba(
    scene: &Scene,
    directory: &Path,
    spp: u32,
    frames: u32,
    threads: usize,
) -> Result<MitsubaRun, String> {
    let material = &scene.objects[0].material;
    let plugin = Format::parse("mitsuba")?
        .write(
            &material.lobe,
            material.geometry,
            material.normalisation,
            Options::default(),
        )?
        .to_bytes();
    let script = directory.join("mitsuba_check.py");
    std::fs::write(&script, MITSUBA_SCRIPT).map_err(|e| e.to_string())?;
    std::fs::write(directory.join("plugin.py"), plugin).map_err(|e| e.to_string())?;
    let scene_file = write_mitsuba_scene(scene, directory, "scene", "sky.exr", spp, 1)?;
    let name = format!("specula_{}", material.lobe.kind().id().replace('-', "_"));
    // Dr.Jit 1.5 deadlocks in its first render with a single worker thread (as
    // `set_thread_count(1)` or on one allowed core), so Mitsuba's one core is two workers
    // pinned to one core with `taskset`.
    let mut command = if threads == 1 {
        let mut command = std::process::Command::new("taskset");
        command.args(["-c", "0"]).arg(vtk_peer::python());
        command
    } else {
        std::process::Command::new(vtk_peer::python())
    };
    let workers = threads.max(2);
    let output = command
        .current_dir(directory)
        .arg(&script)
        .args([
            "render",
            "--plugin",
            "plugin.py",
            "--bsdf",
            &name,
            "--scene",
        ])
        .arg(&scene_file)
        .args(["--output", "mitsuba.exr", "--variant", "llvm_ad_rgb"])
        .args([
            "--frames",
            &frames.to_string(),
            "--threads",
            &workers.to_string(),
        ])
        .output()
        .map_err(|e| format!("{}: {e}", vtk_peer::python().display()))?;
    let stdout = String::from_utf8_lossy(&output.stdout);
    if !output.status.success() {
        let stderr = String::from_utf8_lossy(&output.stderr);
        let last = |text: &str| {
            text.lines()
                .rev()
                .find(|l| !l.trim().is_empty())
                .map(str::to_owned)
        };
        let why = last(&stderr).or_else(|| last(&stdout));
        return Err(why.map_or_else(
            || "mitsuba_check.py failed".to_owned(),
            |w| w.trim().to_owned(),
        ));
    }
    let report: serde_json::Value = stdout
        .lines()
        .rev()
        .find_map(|line| serde_json::from_str(line).ok())
        .ok_or("mitsuba_check.py printed no timings")?;
    let seconds = report["seconds"]
        .as_array()
        .map(|s| {
            s.iter()
                .filter_map(serde_json::Value::as_f64)
                .collect::<Vec<_>>()
        })
        .filter(|s| !s.is_empty())
        .ok_or("mitsuba_check.py printed no timings")?;
    Ok(MitsubaRun {
        seconds: median(seconds),
        image: read_image(&directory.join("mitsuba.exr")).map_err(|e| e.to_string())?,
        version: report["mitsuba"].as_str().unwrap_or("?").to_owned(),
    })
}

/// Measures and prints.
pub fn run(args: &Args) -> CommandResult {
    let spp = args.spp;
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
        "lit by the built-in sky ({SKY_WIDTH} x {}), {spp} samples per pixel, each view's own exponents; median of {} frames \
         after one; samples/s = pixels x spp / seconds per frame",
        SKY_WIDTH / 2,
        args.frames
    );
    println!(
        "Mitsuba: llvm_ad_rgb, direct integrator (1 emitter + 1 BSDF sample, MIS), specula's plugin of the lobe, \
         the same OBJ meshes, camera and sky.exr; it also traces camera and shadow rays and interpolates the map bilinearly; \
         on 1 thread it runs two Dr.Jit workers pinned to one core (taskset; one worker deadlocks)"
    );
    let mut table = Table::new(&[
        "view",
        "lobe",
        "threads",
        "specula Msamples/s",
        "Mitsuba Msamples/s",
        "specula / Mitsuba",
        "images: RMS diff / noise",
        "means differ",
    ]);
    let mut missing = None;
    for view in views()? {
        let settings = &view.scene.settings;
        let samples = f64::from(settings.width * settings.height * spp);
        for kind in LOBES {
            let mut scene = view.scene.clone();
            scene.apply(&Overrides {
                lobe: Some(kind),
                ..Overrides::default()
            });
            // A second seed of specula's: the noise the images' difference is held to.
            let settings = IblSettings {
                spp,
                seed: 99,
                ..IblSettings::default()
            };
            let second =
                render_ibl(&scene, &sky, &settings, &|_, _| {}).map_err(|e| e.to_string())?;
            for &count in &threads {
                let (seconds, image) = time_specula(&scene, &sky, spp, args.frames, count)?;
                let mitsuba = match missing {
                    Some(_) => None,
                    None => time_mitsuba(&scene, scratch.path(), spp, args.frames, count)
                        .map_err(|why| missing = Some(why))
                        .ok(),
                };
                let compared = mitsuba.map_or_else(
                    || vec!["-".to_owned(); 4],
                    |run| {
                        vec![
                            format!(
                                "{:.2} (Mitsuba {})",
                                samples / run.seconds / 1e6,
                                run.version
                            ),
                            format!("{:.2}x", run.seconds / seconds),
                            format!(
                                "{:.2}",
                                rms_difference(&image, &run.image)
                                    / rms_difference(&image, &second)
                            ),
                            format!(
                                "{:+.2} %",
                                100.0 * (mean_radiance(&run.image) / mean_radiance(&image) - 1.0)
                            ),
                        ]
                    },
                );
                let mut row = vec![
                    view.name.to_owned(),
                    kind.id().to_owned(),
                    count.to_string(),
                    format!("{:.2}", samples / seconds / 1e6),
                ];
                row.extend(compared);
                table.push(row);
            }
        }
    }
    table.print(crate::args::Format::Table);
    println!(
        "images: the RMS difference between specula's and Mitsuba's first frames over that between two of specula's \
         (seeds 1 and 99): about 1 where they differ by noise alone, above where they differ"
    );
    if let Some(why) = missing {
        println!(
            "Mitsuba not measured: {why} (install the mitsuba and drjit wheels and Debian's libllvm19 for {})",
            vtk_peer::python().display()
        );
    }
    Ok(())
}
