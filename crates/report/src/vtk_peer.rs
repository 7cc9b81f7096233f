//! VTK's CPU ray caster (`vtkFixedPointVolumeRayCastMapper`) as a peer: the embedded
//! `vtk_volume.py` run by the Python that has the `vtk` and `nibabel` wheels, on jobs made by
//! [`specula_volume::vtk::job`]. Used by `specula bench volume` and the report's
//! medical section.

use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::Instant;

use specula_render::Image;
use specula_volume::dvr::{render_dvr_prepared, DvrSettings};
use specula_volume::march::PreparedVolume;
use specula_volume::transfer::TransferFunction;
use specula_volume::{self as volume, nifti, vtk, Volume};

/// The VTK side of a comparison: `vtk_volume.py`, run by the Python that has VTK. The script
/// lives beside this module (`crates/cli/tests/volumes/vtk_facts.py` runs it directly) and is
/// compiled in, so it is found from any working directory.
const VTK_SCRIPT: &str = include_str!("vtk_volume.py");

/// Renders several jobs in one Python process started ahead of them (VTK imported while the
/// caller prepares the jobs): the script's own `read_job` and `render` on each job file whose
/// path arrives on standard input, one JSON line per job (`{"error": ...}` for a job it
/// refused). VTK is imported as the script does, after the same environment defaults (argv:
/// the script, the threads).
const DRIVER: &str = "\
import importlib.util, json, os, sys
os.environ.setdefault('VTK_DEFAULT_OPENGL_WINDOW', 'vtkEGLRenderWindow')
os.environ.setdefault('LP_NUM_THREADS', sys.argv[2])
spec = importlib.util.spec_from_file_location('vtk_volume', sys.argv[1])
peer = importlib.util.module_from_spec(spec)
spec.loader.exec_module(peer)
try:
    import vtk, nibabel
except ImportError:
    pass
for line in sys.stdin:
    path = line.strip()
    if not path:
        continue
    try:
        print(json.dumps(peer.render(peer.read_job(path))), flush=True)
    except peer.Failure as e:
        print(json.dumps({'error': str(e)}), flush=True)
";

/// The Python that runs VTK: `$SPECULA_PYTHON`, else `python3`.
pub fn python() -> PathBuf {
    std::env::var_os("SPECULA_PYTHON").map_or_else(|| PathBuf::from("python3"), PathBuf::from)
}

/// What VTK measured.
pub struct VtkTimes {
    /// The median of the timed frames' ray casts (the mapper's own time to draw), seconds.
    pub median_draw: f64,
    /// Each timed frame's, seconds (on the GPU caster, `Render()` and `glFinish`).
    pub draw_seconds: Vec<f64>,
    /// VTK's version.
    pub version: String,
    /// Seconds from starting its process to its first frame drawn (Python, the imports, the
    /// file read, the mapper's gradients and tables, the ray cast).
    pub first_image: Option<f64>,
    /// The process's peak resident memory, bytes.
    pub peak_bytes: Option<u64>,
}

/// The times in `report`; the first image's counted from `spawned_unix` when the process was
/// started for this one job (a process that renders several has no such start).
fn times(report: &serde_json::Value, spawned_unix: Option<f64>) -> Result<VtkTimes, String> {
    if let Some(error) = report["error"].as_str() {
        return Err(error.to_owned());
    }
    Ok(VtkTimes {
        median_draw: report["median_draw"]
            .as_f64()
            .ok_or("vtk_volume.py reported no median_draw")?,
        draw_seconds: report["draw_seconds"]
            .as_array()
            .map(|frames| {
                frames
                    .iter()
                    .filter_map(serde_json::Value::as_f64)
                    .collect()
            })
            .unwrap_or_default(),
        version: report["vtk"].as_str().unwrap_or("?").to_owned(),
        first_image: report["first_image_unix"]
            .as_f64()
            .zip(spawned_unix)
            .map(|(at, spawned)| at - spawned),
        peak_bytes: report["peak_bytes"].as_u64(),
    })
}

/// The wall clock now, seconds since the Unix epoch.
fn unix_now() -> f64 {
    std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map_or(0.0, |elapsed| elapsed.as_secs_f64())
}

/// The last line a failed run printed (on stderr, else on stdout: the script says there that
/// it skipped because VTK is missing).
fn last_line(output: &std::process::Output) -> String {
    [&output.stderr, &output.stdout]
        .into_iter()
        .find_map(|bytes| {
            String::from_utf8_lossy(bytes)
                .lines()
                .rev()
                .find(|line| !line.trim().is_empty())
                .map(str::to_owned)
        })
        .unwrap_or_else(|| "no message".to_owned())
}

fn write(path: &Path, bytes: &[u8]) -> Result<(), String> {
    std::fs::write(path, bytes).map_err(|e| format!("{}: {e}", path.display()))
}

/// Renders `job` with VTK; `Err` says why VTK could not run (reported, not fatal).
pub fn run(job: &vtk::VtkJob, scratch: &Path) -> Result<VtkTimes, String> {
    let script = scratch.join("vtk_volume.py");
    write(&script, VTK_SCRIPT.as_bytes())?;
    let job_file = scratch.join("job.json");
    write(
        &job_file,
        &serde_json::to_vec(job).map_err(|e| e.to_string())?,
    )?;
    let spawned = unix_now();
    let output = Command::new(python())
        .arg(&script)
        .arg(&job_file)
        .output()
        .map_err(|e| format!("{}: {e}", python().display()))?;
    if !output.status.success() {
        return Err(last_line(&output));
    }
    let report: serde_json::Value = serde_json::from_slice(&output.stdout)
        .map_err(|e| format!("vtk_volume.py printed no JSON ({e})"))?;
    times(&report, Some(spawned))
}

/// VTK started ahead of its jobs ([`start`]).
pub struct Running {
    /// `None` once waited for.
    child: Option<std::process::Child>,
    scratch: PathBuf,
    jobs: usize,
}

impl Drop for Running {
    /// A run given up on (an error elsewhere) is stopped, not left behind.
    fn drop(&mut self) {
        if let Some(mut child) = self.child.take() {
            let _ = child.kill();
            let _ = child.wait();
        }
    }
}

/// Starts the Python that will render jobs with VTK on `threads` threads, and returns at once
/// (VTK is imported meanwhile). `scratch` holds the script and the jobs. `Err` says why
/// Python could not start.
pub fn start(threads: usize, scratch: &Path) -> Result<Running, String> {
    let script = scratch.join("vtk_volume.py");
    write(&script, VTK_SCRIPT.as_bytes())?;
    let child = Command::new(python())
        .arg("-c")
        .arg(DRIVER)
        .arg(&script)
        .arg(threads.to_string())
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .map_err(|e| format!("{}: {e}", python().display()))?;
    Ok(Running {
        child: Some(child),
        scratch: scratch.to_owned(),
        jobs: 0,
    })
}

impl Running {
    /// Hands VTK every job (rendered one after another, in order); no more can follow.
    pub fn submit(&mut self, jobs: &[vtk::VtkJob]) -> Result<(), String> {
        let mut paths = String::new();
        for job in jobs {
            let file = self.scratch.join(format!("job-{}.json", self.jobs));
            write(&file, &serde_json::to_vec(job).map_err(|e| e.to_string())?)?;
            paths += &format!("{}\n", file.display());
            self.jobs += 1;
        }
        let child = self.child.as_mut().ok_or("VTK was already waited for")?;
        // Closing standard input ends the driver's loop. A Python that stopped early (VTK
        // missing) has closed its end: what it said is read in `finish`.
        if let Some(mut stdin) = child.stdin.take() {
            let _ = std::io::Write::write_all(&mut stdin, paths.as_bytes());
        }
        Ok(())
    }

    /// Waits for VTK. The outer `Err` says why VTK could not run at all; an inner one why it
    /// refused that job.
    pub fn finish(mut self) -> Result<Vec<Result<VtkTimes, String>>, String> {
        let mut child = self.child.take().ok_or("VTK was already waited for")?;
        drop(child.stdin.take());
        let output = child.wait_with_output().map_err(|e| e.to_string())?;
        if !output.status.success() {
            return Err(last_line(&output));
        }
        let lines: Vec<&[u8]> = output
            .stdout
            .split(|&b| b == b'\n')
            .filter(|line| !line.is_empty())
            .collect();
        if lines.len() != self.jobs {
            return Err(format!(
                "vtk_volume.py answered {} of {} jobs",
                lines.len(),
                self.jobs
            ));
        }
        Ok(lines
            .into_iter()
            .map(|line| {
                serde_json::from_slice(line)
                    .map_err(|e| format!("vtk_volume.py printed no JSON ({e})"))
                    .and_then(|report| times(&report, None))
            })
            .collect())
    }
}

/// VTK's PNG as it wrote it (8-bit linear values, no gamma: its framebuffer): `read_image`
/// decodes sRGB, which encoding again undoes exactly for every byte (the real-scan tests
/// check every byte).
pub fn read_png(path: &Path) -> Result<Vec<[f32; 3]>, String> {
    Ok(read_png_image(path)?
        .pixels()
        .iter()
        .map(|p| p.to_array())
        .collect())
}

/// [`read_png`] as an image.
pub fn read_png_image(path: &Path) -> Result<Image, String> {
    let decoded = specula_render::read_image(path).map_err(|e| e.to_string())?;
    let pixels = decoded
        .pixels()
        .iter()
        .map(|p| {
            p.to_array()
                .map(|c| (specula_render::srgb_encode(c) * 255.0).round() / 255.0)
        })
        .map(glam::Vec3::from_array)
        .collect();
    Image::from_pixels(decoded.width(), decoded.height(), pixels)
        .ok_or_else(|| "VTK's image has an inconsistent size".to_owned())
}

/// specula's linear image (clamped to [0, 1], as a framebuffer holds it) against VTK's
/// pixels: the mean absolute difference over pixels and channels, and the fraction of pixels
/// whose largest channel difference exceeds 0.1.
#[must_use]
pub fn agreement(specula: &Image, vtk: &[[f32; 3]]) -> (f64, f64) {
    let ours: Vec<[f32; 3]> = specula
        .pixels()
        .iter()
        .map(|p| p.to_array().map(|c| c.clamp(0.0, 1.0)))
        .collect();
    agreement_of_pixels(&ours, vtk)
}

/// [`agreement`] between two sets of pixels already in [0, 1].
#[must_use]
pub fn agreement_of_pixels(a: &[[f32; 3]], b: &[[f32; 3]]) -> (f64, f64) {
    let mut sum = 0.0;
    let mut far = 0usize;
    for (p, q) in a.iter().zip(b) {
        let largest = (0..3).map(|c| (p[c] - q[c]).abs()).fold(0.0, f32::max);
        sum += (0..3).map(|c| f64::from((p[c] - q[c]).abs())).sum::<f64>();
        far += usize::from(largest > 0.1);
    }
    let pixels = a.len().max(1) as f64;
    (sum / (3.0 * pixels), far as f64 / pixels)
}

/// The volume as a NIfTI file VTK can read: `input` itself, or a copy in `scratch`.
pub fn nifti_file(input: &Path, volume: &Volume, scratch: &Path) -> Result<PathBuf, String> {
    if nifti::is_nifti_path(input) && input.is_file() {
        return Ok(input.to_owned());
    }
    let copy = scratch.join("volume.nii");
    volume::write(volume, &copy).map_err(|e| e.to_string())?;
    Ok(copy)
}

/// specula's side of a comparison: the last of `frames` frames of `volume` (whose gradients
/// and bricks, which VTK computes in its untimed first frame, are `prepared`) after one untimed
/// warm-up, and the median seconds a frame took.
pub fn time_specula(
    volume: &Volume,
    prepared: &PreparedVolume,
    transfer: &TransferFunction,
    settings: &DvrSettings,
    frames: usize,
) -> Result<(Image, f64), String> {
    let draw = || {
        render_dvr_prepared(volume, prepared, transfer, settings, &|| {}).map_err(|e| e.to_string())
    };
    let mut image = draw()?;
    let mut times = Vec::new();
    for _ in 0..frames.max(1) {
        let started = Instant::now();
        image = draw()?;
        times.push(started.elapsed().as_secs_f64());
    }
    Ok((image, median(times)))
}

/// The median of `values` (at least one): of an even count, the mean of the middle two.
#[must_use]
pub fn median(mut values: Vec<f64>) -> f64 {
    values.sort_by(f64::total_cmp);
    let middle = values.len() / 2;
    if values.len() % 2 == 1 {
        values[middle]
    } else {
        0.5 * (values[middle - 1] + values[middle])
    }
}
