//! Mitsuba 3 rendering a view of `specula bench environment`, as a Mitsuba user would: the
//! `llvm_ad_rgb` variant, the `direct` integrator, spheres as Mitsuba's own `sphere` shape
//! (the teapot as OBJ), specula's plugin of the lobe (`specula shader --lang mitsuba`), run
//! by the compiled-in harness `mitsuba_check.py render --frames`.

use std::io::{BufRead, BufReader, Read};
use std::path::Path;
use std::process::{Command, Stdio};
use std::time::Instant;

use specula_gpu::export::{ExportFormat, Options};
use specula_render::{read_image, write_mitsuba_scene, Image, Scene};
use specula_report::vtk_peer::{self, median};

/// The Mitsuba harness (`mitsuba_check.py render --frames`), compiled in.
const MITSUBA_SCRIPT: &str = include_str!("../../../tests/renderers/mitsuba_check.py");

/// What Mitsuba measured.
pub(super) struct MitsubaRun {
    /// The median of the timed frames (scene loaded, kernels compiled), seconds.
    pub(super) warm: f64,
    /// From the process's start to its first image written (Python, the import, the scene's
    /// loading, the kernels' compilation, the render), seconds.
    pub(super) cold: f64,
    /// The first frame.
    pub(super) image: Image,
    pub(super) version: String,
}

/// Renders `scene` in Mitsuba (`llvm_ad_rgb`) with specula's plugin of its first object's
/// lobe: a first frame from a cold start, then `frames` timed frames, on `threads` threads.
pub(super) fn time_mitsuba(
    scene: &Scene,
    directory: &Path,
    spp: u32,
    frames: u32,
    threads: usize,
) -> Result<MitsubaRun, String> {
    let material = &scene.objects[0].material;
    let plugin = ExportFormat::parse("mitsuba")?
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
        let mut command = Command::new("taskset");
        command.args(["-c", "0"]).arg(vtk_peer::python());
        command
    } else {
        Command::new(vtk_peer::python())
    };
    let workers = threads.max(2);
    command
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
        .args(["--frames", &frames.to_string()])
        .args(["--threads", &workers.to_string()])
        .stdout(Stdio::piped())
        .stderr(Stdio::piped());
    let started = Instant::now();
    let mut child = command
        .spawn()
        .map_err(|e| format!("{}: {e}", vtk_peer::python().display()))?;
    // Stderr drained beside stdout, so that neither pipe fills and stalls the harness.
    let stderr = child.stderr.take().map(|mut err| {
        std::thread::spawn(move || {
            let mut text = String::new();
            err.read_to_string(&mut text).map(|_| text)
        })
    });
    // The cold start ends when the harness says it wrote the first frame.
    let mut cold = None;
    let mut stdout = String::new();
    if let Some(out) = child.stdout.take() {
        for line in BufReader::new(out).lines() {
            let line = line.map_err(|e| e.to_string())?;
            if cold.is_none() && line.starts_with("wrote ") {
                cold = Some(started.elapsed().as_secs_f64());
            }
            stdout.push_str(&line);
            stdout.push('\n');
        }
    }
    let stderr = match stderr.map(std::thread::JoinHandle::join) {
        Some(Ok(Ok(text))) => text,
        _ => String::new(),
    };
    let status = child.wait().map_err(|e| e.to_string())?;
    if !status.success() {
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
        warm: median(seconds),
        cold: cold.ok_or("mitsuba_check.py did not say it wrote its first frame")?,
        image: read_image(&directory.join("mitsuba.exr")).map_err(|e| e.to_string())?,
        version: report["mitsuba"].as_str().unwrap_or("?").to_owned(),
    })
}
