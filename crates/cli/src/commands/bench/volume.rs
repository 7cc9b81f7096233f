//! `specula bench volume`: the CPU ray marcher's frames per second on one volume, beside
//! VTK's CPU ray caster set up alike ([`specula_render::volume::vtk`]) when Python has the
//! `vtk` and `nibabel` packages.

use std::path::Path;
use std::time::Instant;

use specula_render::volume::march::PreparedVolume;
use specula_render::volume::transfer::TransferFunction;
use specula_render::volume::vtk;
use specula_render::{write_image, Display};
use specula_report::vtk_peer;

use super::Args;
use crate::commands::volume::{load, Source};
use crate::commands::CommandResult;
use crate::output::Table;

/// Measures and prints.
pub fn run(args: &Args) -> CommandResult {
    let source = Source::new(&args.input);
    let volume = load(&source)?;
    let transfer = match &args.transfer {
        Some(name) => TransferFunction::preset(name).map_err(|e| e.to_string())?,
        None => TransferFunction::default_for(&volume),
    }
    .for_volume(&volume);
    let (width, height) = args.size();
    let view = args.view;
    let settings = vtk::alike_settings(&volume, width, height, view, args.n, args.sample_distance)
        .map_err(|e| e.to_string())?;
    let started = Instant::now();
    let prepared = PreparedVolume::new(&volume);
    let preparation = started.elapsed().as_secs_f64();
    let (image, specula) = vtk_peer::time_specula(
        &volume,
        &prepared,
        &transfer,
        &settings,
        args.frames as usize,
    )?;
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
        "{} ({nx} x {ny} x {nz}), {} view, {width} x {height}, {} mm between samples, {threads} threads; \
         median of {} frames after one warm-up; specula's gradients and bricks took {:.0} ms once",
        args.input,
        view.id(),
        args.sample_distance,
        args.frames,
        preparation * 1e3
    );
    let mut table = Table::new(&["renderer", "median ms/frame", "frames/s", "specula vs VTK"]);
    let row = |name: String, seconds: f64, ratio: String| {
        vec![
            name,
            format!("{:.1}", seconds * 1e3),
            format!("{:.2}", 1.0 / seconds),
            ratio,
        ]
    };
    match &vtk {
        Ok(times) => {
            table.push(row(
                "specula (CPU)".into(),
                specula,
                format!("{:.2}x", times.median_draw / specula),
            ));
            table.push(row(
                format!("VTK {} vtkFixedPointVolumeRayCastMapper", times.version),
                times.median_draw,
                "1.00x".into(),
            ));
        }
        Err(why) => {
            table.push(row("specula (CPU)".into(), specula, "-".into()));
            println!(
                "VTK not measured: {why} (install the vtk and nibabel wheels for {})",
                vtk_peer::python().display()
            );
        }
    }
    table.print(crate::args::Format::Table);
    if let Some(dir) = &args.images {
        std::fs::create_dir_all(dir).map_err(|e| format!("{}: {e}", dir.display()))?;
        write_image(&dir.join("specula.exr"), &image, Display::default())
            .map_err(|e| e.to_string())?;
        if vtk.is_ok() {
            std::fs::copy(&vtk_output, dir.join("vtk.png"))
                .map_err(|e| format!("{}: {e}", dir.display()))?;
        }
        println!(
            "wrote {} (linear) and, from VTK, vtk.png (8-bit linear values, as VTK composites them)",
            dir.join("specula.exr").display()
        );
    }
    Ok(())
}
