//! `specula bench vtk-lobes`: every built-in lobe inside VTK's GPU ray caster (the module of
//! `specula shader --lang vtk`), its frame time against VTK's own `pow` in the same VTK
//! process, and its image against specula's marcher set up alike for that caster
//! ([`specula_volume::vtk::alike_gpu_settings`]).

use std::path::Path;

use specula::{Geometry, Lobe, LobeKind, Normalisation};
use specula_gpu::export::Engine;
use specula_render::{write_image, Display};
use specula_report::vtk_peer;
use specula_volume::dvr::render_dvr_prepared;
use specula_volume::march::PreparedVolume;
use specula_volume::vtk;

use super::Args;
use crate::commands::CommandResult;
use crate::output::Table;

/// Measures and prints.
pub fn run(args: &Args) -> CommandResult {
    let (volume, transfer) = super::volume::volume_and_transfer(args)?;
    let (width, height) = args.size();
    let threads = rayon::current_num_threads();
    let scratch = specula_temporaries::dir("bench-vtk-").map_err(|e| e.to_string())?;
    let file = vtk_peer::nifti_file(Path::new(&args.input), &volume, scratch.path())?;
    // VTK imports while specula renders.
    let mut running = vtk_peer::start(threads, scratch.path())?;
    let prepared = PreparedVolume::new(&volume);
    // VTK's own pow first, then each lobe through its module (pow's included, which must
    // cost what VTK's own does).
    let lobes: Vec<Option<LobeKind>> = std::iter::once(None)
        .chain(LobeKind::ALL.map(Some))
        .collect();
    let mut jobs = Vec::new();
    let mut images = Vec::new();
    for (k, lobe) in lobes.iter().enumerate() {
        let kind = lobe.unwrap_or(LobeKind::Pow);
        let settings = vtk::alike_gpu_settings(
            &volume,
            width,
            height,
            args.view,
            Lobe::new(kind, args.n),
            args.sample_distance,
        )
        .map_err(|e| e.to_string())?;
        images.push(
            render_dvr_prepared(&volume, &prepared, &transfer, &settings, &|| {})
                .map_err(|e| e.to_string())?,
        );
        let module = match lobe {
            Some(kind) => {
                let text = Engine::Vtk
                    .write(
                        &Lobe::new(*kind, args.n),
                        Geometry::Phong,
                        Normalisation::None,
                    )
                    .map_err(|e| e.to_string())?;
                let path = scratch.path().join(format!("lobe{k}_vtk.py"));
                std::fs::write(&path, text).map_err(|e| format!("{}: {e}", path.display()))?;
                Some(path)
            }
            None => None,
        };
        let output = scratch.path().join(format!("vtk-{k}.png"));
        jobs.push(
            vtk::job(&volume, &file, &transfer, &settings, &output, threads, 1)
                .map_err(|e| e.to_string())?
                .on_gpu(module),
        );
    }
    // Round after round of every lobe, one timed frame each (after the job's warm-up, which
    // compiles its shader): a drift of the machine's speed falls on every lobe alike.
    let rounds: Vec<_> = (0..args.frames)
        .flat_map(|_| jobs.iter().cloned())
        .collect();
    running.submit(&rounds)?;
    let answers = running
        .finish()?
        .into_iter()
        .collect::<Result<Vec<_>, String>>()
        .map_err(|why| format!("VTK refused a job: {why}"))?;
    let vtk_images = (0..jobs.len())
        .map(|k| vtk_peer::read_png(&scratch.path().join(format!("vtk-{k}.png"))))
        .collect::<Result<Vec<_>, String>>()?;
    let frames: Vec<Vec<f64>> = (0..jobs.len())
        .map(|k| {
            answers
                .iter()
                .skip(k)
                .step_by(jobs.len())
                .flat_map(|times| times.draw_seconds.iter().copied())
                .collect()
        })
        .collect();
    let version = answers.first().map_or("?", |times| times.version.as_str());
    let [nx, ny, nz] = volume.dims();
    println!(
        "{} ({nx} x {ny} x {nz}), {} view, {width} x {height}, {} mm between samples, n = {}; VTK \
         {} vtkGPUVolumeRayCastMapper in one process, each lobe the module of `specula shader \
         --lang vtk`; {} rounds of every lobe, one timed frame each after a warm-up (the \
         shader's compile), each window.Render() and glFinish; x pow: the lobe's median frame \
         time over VTK's own pow's, the range from their fastest and slowest frames (a range \
         holding 1 is a tie)",
        args.input,
        args.view.id(),
        args.sample_distance,
        args.n,
        version,
        args.frames,
    );
    println!(
        "against specula: its marcher set up for this caster (Phong's R.V, rays stopped at \
         1 - 1/255, a sample with no gradient lit by its ambient term alone), mean absolute \
         difference over pixels and channels (of 1) and the \
         pixels whose largest channel differs by more than 0.1; against pow: VTK's image with \
         the lobe against its own pow's"
    );
    let mut table = Table::new(&[
        "lobe",
        "VTK ms/frame",
        "range",
        "x pow",
        "x pow range",
        "vs specula: mean",
        "pixels > 0.1",
        "vs VTK's pow: mean",
    ]);
    let pow = &frames[0];
    let median = |values: &[f64]| vtk_peer::median(values.to_vec());
    let bounds = |values: &[f64]| {
        let low = values.iter().copied().fold(f64::INFINITY, f64::min);
        (low, values.iter().copied().fold(0.0, f64::max))
    };
    let (pow_low, pow_high) = bounds(pow);
    for (k, lobe) in lobes.iter().enumerate() {
        let frames = &frames[k];
        let (low, high) = bounds(frames);
        let name = lobe.map_or("pow (VTK's own)".to_owned(), |kind| kind.id().to_owned());
        let (mean, far) = vtk_peer::agreement(&images[k], &vtk_images[k]);
        let (against_pow, _) = vtk_peer::agreement_of_pixels(&vtk_images[k], &vtk_images[0]);
        let (ratio_low, ratio_high) = (low / pow_high, high / pow_low);
        let tie = if ratio_low <= 1.0 && ratio_high >= 1.0 {
            " (tie)"
        } else {
            ""
        };
        table.push(vec![
            name,
            format!("{:.1}", median(frames) * 1e3),
            format!("{:.1}-{:.1}", low * 1e3, high * 1e3),
            format!("{:.2}x", median(frames) / median(pow)),
            format!("{ratio_low:.2}-{ratio_high:.2}x{tie}"),
            format!("{mean:.4}"),
            format!("{:.2} %", far * 100.0),
            format!("{against_pow:.4}"),
        ]);
    }
    table.print(crate::args::OutputFormat::Table);
    if let Some(dir) = &args.images {
        std::fs::create_dir_all(dir).map_err(|e| format!("{}: {e}", dir.display()))?;
        for (k, lobe) in lobes.iter().enumerate() {
            let name = lobe.map_or("vtk-pow".to_owned(), |kind| kind.id().to_owned());
            write_image(
                &dir.join(format!("specula-{name}.exr")),
                &images[k],
                Display::default(),
            )
            .map_err(|e| e.to_string())?;
            std::fs::copy(
                scratch.path().join(format!("vtk-{k}.png")),
                dir.join(format!("vtk-{name}.png")),
            )
            .map_err(|e| format!("{}: {e}", dir.display()))?;
        }
        println!(
            "wrote specula-LOBE.exr (linear) and vtk-LOBE.png (VTK's 8-bit framebuffer, linear \
             values) per lobe into {} (vtk-pow: VTK's own pow)",
            dir.display()
        );
    }
    Ok(())
}
