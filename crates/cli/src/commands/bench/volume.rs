//! `specula bench volume`: the CPU ray marcher's frames per second on one volume, beside
//! VTK's CPU ray caster set up alike ([`specula_volume::vtk`]) when Python has the
//! `vtk` and `nibabel` packages.

use std::path::Path;
use std::time::Instant;

use specula_render::{write_image, Display};
use specula_report::vtk_peer;
use specula_volume::dvr::render_dvr_prepared;
use specula_volume::march::PreparedVolume;
use specula_volume::transfer::TransferFunction;
use specula_volume::{vtk, Volume};

use super::Args;
use crate::commands::volume::{load, Source};
use crate::commands::CommandResult;
use crate::output::Table;

/// `--input` and its transfer function (`--transfer`, else the volume's own), as both volume
/// benchmarks read them.
pub(super) fn volume_and_transfer(args: &Args) -> Result<(Volume, TransferFunction), String> {
    let volume = load(&Source::new(&args.input))?;
    let transfer = match &args.transfer {
        Some(name) => TransferFunction::preset(name).map_err(|e| e.to_string())?,
        None => TransferFunction::default_for(&volume),
    }
    .for_volume(&volume);
    Ok((volume, transfer))
}

/// Measures and prints.
pub fn run(args: &Args) -> CommandResult {
    let loading = Instant::now();
    let (volume, transfer) = volume_and_transfer(args)?;
    let (width, height) = args.size();
    let view = args.view;
    let settings = vtk::alike_settings(&volume, width, height, view, args.n, args.sample_distance)
        .map_err(|e| e.to_string())?;
    let started = Instant::now();
    let prepared = PreparedVolume::new(&volume);
    let preparation = started.elapsed().as_secs_f64();
    let first_frame = Instant::now();
    render_dvr_prepared(&volume, &prepared, &transfer, &settings, &|| {})
        .map_err(|e| e.to_string())?;
    let first_image = loading.elapsed().as_secs_f64();
    let first_frame = first_frame.elapsed().as_secs_f64();
    let (image, specula) = vtk_peer::time_specula(
        &volume,
        &prepared,
        &transfer,
        &settings,
        args.frames as usize,
    )?;
    // This process's peak so far: the volume, its preparation and the frames (VTK runs in
    // its own process, measured by itself).
    let specula_peak = peak_resident_bytes();
    let threads = rayon::current_num_threads();
    let scratch = specula_temporaries::dir("bench-").map_err(|e| e.to_string())?;
    let vtk_output = scratch.path().join("vtk.png");
    let vtk =
        vtk_peer::nifti_file(Path::new(&args.input), &volume, scratch.path()).and_then(|file| {
            let job = vtk::job(
                &volume,
                &file,
                &transfer,
                &settings,
                &vtk_output,
                threads,
                args.frames,
            )
            .map_err(|e| e.to_string())?;
            vtk_peer::run(&job, scratch.path())
        });
    let [nx, ny, nz] = volume.dims();
    println!(
        "{} ({nx} x {ny} x {nz}), {} view, {width} x {height}, {} mm between samples, {threads} \
            threads; \
         median of {} frames after one warm-up; specula's gradients and bricks took {:.0} ms once, \
         its first frame {:.0} ms",
        args.input,
        view.id(),
        args.sample_distance,
        args.frames,
        preparation * 1e3,
        first_frame * 1e3
    );
    println!(
        "first image: specula from reading the file to its first frame (in this process, started a \
            few ms before); \
         VTK from starting Python to its first frame (the imports, nibabel's read, VTK's copy, the \
         mapper's gradients, \
         the ray cast); peak: each process's peak resident memory (VTK's: Python, nibabel, VTK \
         together)"
    );
    let voxels = (nx * ny * nz) as f64;
    let mut table = Table::new(&[
        "renderer",
        "median ms/frame",
        "frames/s",
        "frame: specula x",
        "first image s",
        "first image: specula x",
        "peak MB",
        "peak bytes/voxel",
    ]);
    let peak = |bytes: Option<u64>| {
        bytes.map_or_else(
            || ("-".to_owned(), "-".to_owned()),
            |b| {
                (
                    format!("{:.0}", b as f64 / 1e6),
                    format!("{:.1}", b as f64 / voxels),
                )
            },
        )
    };
    let seconds = |value: Option<f64>| value.map_or_else(|| "-".to_owned(), |s| format!("{s:.2}"));
    let ratio = |ours: f64, theirs: Option<f64>| {
        theirs.map_or_else(|| "-".to_owned(), |theirs| format!("{:.2}x", theirs / ours))
    };
    let against = vtk.as_ref().ok();
    let (megabytes, per_voxel) = peak(specula_peak);
    table.push(vec![
        "specula (CPU)".into(),
        format!("{:.1}", specula * 1e3),
        format!("{:.2}", 1.0 / specula),
        ratio(specula, against.map(|t| t.median_draw)),
        seconds(Some(first_image)),
        ratio(first_image, against.and_then(|t| t.first_image)),
        megabytes,
        per_voxel,
    ]);
    match &vtk {
        Ok(times) => {
            let (megabytes, per_voxel) = peak(times.peak_bytes);
            table.push(vec![
                format!("VTK {} vtkFixedPointVolumeRayCastMapper", times.version),
                format!("{:.1}", times.median_draw * 1e3),
                format!("{:.2}", 1.0 / times.median_draw),
                "1.00x".into(),
                seconds(times.first_image),
                "1.00x".into(),
                megabytes,
                per_voxel,
            ]);
        }
        Err(why) => {
            println!(
                "VTK not measured: {why} (install the vtk and nibabel wheels for {})",
                vtk_peer::python().display()
            );
        }
    }
    table.print(crate::args::OutputFormat::Table);
    if let Some(dir) = &args.images {
        std::fs::create_dir_all(dir).map_err(|e| format!("{}: {e}", dir.display()))?;
        write_image(&dir.join("specula.exr"), &image, Display::default())
            .map_err(|e| e.to_string())?;
        if vtk.is_ok() {
            std::fs::copy(&vtk_output, dir.join("vtk.png"))
                .map_err(|e| format!("{}: {e}", dir.display()))?;
        }
        println!(
            "wrote {} (linear) and, from VTK, vtk.png (8-bit linear values, as VTK composites \
                them)",
            dir.join("specula.exr").display()
        );
    }
    Ok(())
}

/// This process's peak resident memory (Linux's `VmHWM`), bytes; `None` elsewhere.
fn peak_resident_bytes() -> Option<u64> {
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = status.lines().find(|line| line.starts_with("VmHWM:"))?;
    let kib: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kib * 1024)
}
