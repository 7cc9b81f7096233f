//! The medical section's real scans: a head CT and a head MRI from Debian's packages,
//! ray-marched with every lobe (FLIP and PSNR against `pow`), and VTK's CPU ray caster
//! (`vtkFixedPointVolumeRayCastMapper`) set up alike beside specula ([`vtk::alike_settings`],
//! [`vtk::job`]): both images, their agreement and both frame rates.

use std::path::Path;
use std::time::Instant;

use glam::Vec3;
use specula::{Exponent, LobeKind};
use specula_render::metrics::compare;
use specula_render::{Display, Image};
use specula_volume::dvr::{render_dvr_lobes, render_dvr_prepared, DvrSettings, View};
use specula_volume::march::PreparedVolume;
use specula_volume::transfer::TransferFunction;
use specula_volume::{self as volume, vtk, Units, Volume};

use super::comparison::{self, Compared};
use super::html::{paragraph, table_with_files};
use super::prose;
use super::{Context, RealScanSizes};
use crate::format::psnr;
use crate::medical::{cpu_threads, march_times, shading, EXPONENT};
use crate::vtk_peer;

/// A real scan a Debian package installs.
struct Scan {
    /// File names start `real-KEY-`.
    key: &'static str,
    /// "CT" or "MRI".
    name: &'static str,
    /// What it is.
    what: &'static str,
    path: &'static str,
    package: &'static str,
    /// Its default transfer function.
    transfer: &'static str,
    /// The NIfTI file VTK reads.
    vtk_reads: &'static str,
}

const SCANS: [Scan; 2] = [
    Scan {
        key: "ct",
        name: "CT",
        what: "InVesalius' example head CT Cranium.inv3",
        path: "/usr/share/doc/invesalius-examples/examples/Cranium.inv3",
        package: "invesalius-examples",
        transfer: "ct-bone",
        vtk_reads: "for the CT a 16-bit integer copy that specula writes (the scan's own type, as \
            a VTK user reads it)",
    },
    Scan {
        key: "mri",
        name: "MRI",
        what: "the Colin27 T1-weighted head MRI with skull ch2.nii.gz",
        path: "/usr/share/mricron/templates/ch2.nii.gz",
        package: "mricron-data",
        transfer: "mr",
        vtk_reads: "for the MRI ch2.nii.gz itself (8-bit)",
    },
];

/// Millimetres between samples in the VTK comparison (`specula bench volume`'s default).
const SAMPLE_DISTANCE: f32 = 0.5;

/// The lobes `--quick` renders the real scans with (and any of the user's): the reference,
/// the classic cheap approximation and the thesis's cosine-quadratic.
const QUICK_LOBES: [LobeKind; 3] = [
    LobeKind::Pow,
    LobeKind::Schlick,
    LobeKind::CosQuad {
        v: specula::lobe::CosQuad::DEFAULT_V,
    },
];

/// A scan read, with its transfer function.
struct Loaded<'a> {
    scan: &'a Scan,
    volume: Volume,
    transfer: TransferFunction,
    read_ms: f64,
}

fn milliseconds(since: Instant) -> f64 {
    since.elapsed().as_secs_f64() * 1e3
}

fn load(scan: &Scan) -> Result<Loaded<'_>, String> {
    let started = Instant::now();
    let volume = volume::read(Path::new(scan.path)).map_err(|e| e.to_string())?;
    let read_ms = milliseconds(started);
    let transfer = TransferFunction::preset(scan.transfer)
        .map_err(|e| e.to_string())?
        .for_volume(&volume);
    Ok(Loaded {
        scan,
        volume,
        transfer,
        read_ms,
    })
}

/// The real scans' part of the medical section.
pub fn real_scans(context: &mut Context) -> Result<String, String> {
    let RealScanSizes {
        side,
        frames,
        every_lobe,
        every_scan_against_vtk,
    } = context.sizes.real_scans;
    let mut html = String::from("<h3>Real scans</h3>\n");
    let present: Vec<&Scan> = SCANS
        .iter()
        .filter(|scan| Path::new(scan.path).is_file())
        .collect();
    for scan in SCANS.iter().filter(|scan| !Path::new(scan.path).is_file()) {
        context.machine_note(format!(
            "The real {} is not here: it is {} at {}, which the Debian package {} installs \
                (apt-get install {}).",
            scan.name, scan.what, scan.path, scan.package, scan.package
        ));
    }
    if present.is_empty() {
        html += &paragraph("No real scan is on this machine (see the notes on this machine).");
        return Ok(html);
    }
    // VTK's Python starts first and imports VTK while specula reads the scans; it then
    // renders while specula does.
    let scratch = specula_temporaries::dir("scans-").map_err(|e| e.to_string())?;
    let running = vtk_peer::start(rayon::current_num_threads(), scratch.path());
    // Each file is read (and decompressed) on a thread of its own.
    let loaded: Vec<Result<Loaded, String>> = std::thread::scope(|scope| {
        let reading: Vec<_> = present
            .iter()
            .map(|scan| scope.spawn(|| load(scan)))
            .collect();
        reading
            .into_iter()
            .map(|read| {
                read.join()
                    .unwrap_or_else(|panic| std::panic::resume_unwind(panic))
            })
            .collect()
    });
    let mut scans = Vec::new();
    for (scan, loaded) in present.iter().zip(loaded) {
        match loaded {
            Ok(loaded) => scans.push(loaded),
            Err(error) => {
                html += &paragraph(&format!(
                    "The real {} ({}) is here but could not be read: {error}",
                    scan.name, scan.path
                ));
            }
        }
    }
    if scans.is_empty() {
        return Ok(html);
    }
    let lobes: Vec<LobeKind> = context
        .lobes
        .iter()
        .copied()
        .filter(|kind| every_lobe || QUICK_LOBES.contains(kind) || !LobeKind::ALL.contains(kind))
        .collect();
    let which = if every_lobe {
        "every lobe".to_owned()
    } else {
        format!(
            "{} (--quick; the full report renders every lobe)",
            lobes
                .iter()
                .map(ToString::to_string)
                .collect::<Vec<_>>()
                .join(", ")
        )
    };
    html += &paragraph(&prose::fill(
        prose::REAL_SCANS,
        &[("side", &side), ("exponent", &EXPONENT), ("which", &which)],
    )?);
    let compared = if every_scan_against_vtk {
        &scans[..]
    } else {
        &scans[..1]
    };
    let setups = compared
        .iter()
        .map(|loaded| alike_setup(loaded, side, frames, scratch.path()))
        .collect::<Result<Vec<_>, _>>()?;
    let jobs: Vec<vtk::VtkJob> = setups.iter().map(|(_, job)| job.clone()).collect();
    // The first scan also on VTK's GPU ray caster, with the lobe's module.
    let gpu = crate::vtk_gpu::setup(
        &compared[0].volume,
        &jobs[0].volume,
        &compared[0].transfer,
        side,
        SAMPLE_DISTANCE,
        &scratch.path().join(compared[0].scan.key),
    )?;
    let running = running.and_then(|mut running| {
        running.submit(&[&jobs[..], std::slice::from_ref(&gpu.1)].concat())?;
        Ok(running)
    });
    let prepared: Vec<PreparedVolume> = scans
        .iter()
        .map(|loaded| PreparedVolume::new(&loaded.volume))
        .collect();
    for (loaded, prepared) in scans.iter().zip(&prepared) {
        html += &lobe_table(context, loaded, prepared, &lobes, side)?;
    }
    // specula's frames are timed once VTK is done, so that neither times the other's work.
    let (theirs, gpu_run) = match running.and_then(vtk_peer::Running::finish) {
        Ok(mut runs) => {
            let gpu_run = runs.pop().unwrap_or_else(|| Err("no answer".to_owned()));
            (Ok(runs), gpu_run)
        }
        Err(why) => (Err(why.clone()), Err(why)),
    };
    let ours = compared
        .iter()
        .zip(&prepared)
        .zip(&setups)
        .map(|((loaded, prepared), (settings, _))| {
            specula_alike(loaded, prepared, settings, frames)
        })
        .collect::<Result<Vec<_>, _>>()?;
    let quick = if compared.len() < scans.len() {
        " (--quick compares the first scan alone; the full report every scan)"
    } else {
        ""
    };
    html += &against_vtk(
        context,
        compared,
        &ours,
        &jobs,
        theirs,
        (side, frames, quick),
    )?;
    let first = &compared[0];
    html += &crate::vtk_gpu::section(
        context,
        (first.scan.name, first.scan.key),
        (&first.volume, &prepared[0], &first.transfer),
        &gpu,
        gpu_run,
    )?;
    Ok(html)
}

/// One scan with every lobe: a table and the images.
fn lobe_table(
    context: &mut Context,
    loaded: &Loaded,
    prepared: &PreparedVolume,
    lobes: &[LobeKind],
    side: u32,
) -> Result<String, String> {
    let Loaded {
        scan,
        volume,
        transfer,
        read_ms,
    } = loaded;
    let [nx, ny, nz] = volume.dims();
    let spacing = volume.spacing();
    let (low, high) = volume.range();
    let units = match volume.units() {
        Units::Hounsfield => "Hounsfield units",
        Units::Arbitrary => "arbitrary units",
    };
    let mut html = paragraph(&format!(
        "The real {}: {} ({}, Debian {}), {nx} x {ny} x {nz} voxels of {:.3} x {:.3} x {:.3} mm, \
            values {low} to {high} read as {units}, read in {read_ms:.0} ms; the {} transfer \
            function.",
        scan.name,
        scan.what,
        scan.path,
        scan.package,
        spacing.x,
        spacing.y,
        spacing.z,
        scan.transfer
    ));
    // pow's frame alone, then every lobe's from one march (the samples, their colours and
    // opacities are the lobe's no more than the light is; only the highlights differ).
    let settings = DvrSettings::new(side, side, View::Anterior, Some(shading(LobeKind::Pow)?));
    let started = Instant::now();
    render_dvr_prepared(volume, prepared, transfer, &settings, &|| {})
        .map_err(|e| e.to_string())?;
    let alone_ms = milliseconds(started);
    let shaded = lobes
        .iter()
        .map(|&kind| shading(kind).map(|s| s.lobe))
        .collect::<Result<Vec<_>, _>>()?;
    let started = Instant::now();
    let images = render_dvr_lobes(volume, prepared, transfer, &settings, &shaded, &|| {})
        .map_err(|e| e.to_string())?;
    let together_ms = milliseconds(started);
    html += &paragraph(&march_times(
        &cpu_threads(),
        alone_ms,
        together_ms,
        lobes.len(),
    ));
    let mut rows = Vec::new();
    let mut differences = Vec::new();
    let mut reference: Option<Image> = None;
    for (&kind, image) in lobes.iter().zip(images) {
        let name = format!("real-{}-{}.png", scan.key, kind.id());
        let bytes = image.to_srgb8(Display::default());
        context.write_png_file(&name, side, side, &bytes)?;
        // Compared as written (8-bit sRGB), so `specula diff` on the files prints the same.
        let written = Image::from_srgb8(side, side, &bytes).ok_or("inconsistent image size")?;
        let reference_image = reference.get_or_insert_with(|| written.clone());
        let against_pow =
            compare(reference_image, &written, Display::default()).map_err(|e| e.to_string())?;
        rows.push(vec![
            kind.to_string(),
            name.clone(),
            psnr(against_pow.psnr_db),
            format!("{:.5}", against_pow.mean_flip),
        ]);
        differences.push((kind, name, against_pow));
    }
    let compared: Vec<Compared> = differences
        .iter()
        .map(|(kind, name, d)| Compared::new(*kind, name, d, *kind == LobeKind::Pow))
        .collect();
    html += &comparison::grid(context, &format!("real-{}", scan.key), "pow", &compared)?;
    html += &table_with_files(
        &[
            "lobe",
            "image",
            &format!("PSNR vs pow on the real {} (dB)", scan.name),
            "mean FLIP vs the pow image",
        ],
        &rows,
        &[1],
    );
    Ok(html)
}

/// specula's settings for a render VTK can match, and VTK's job for it.
fn alike_setup(
    loaded: &Loaded,
    side: u32,
    frames: usize,
    scratch: &Path,
) -> Result<(DvrSettings, vtk::VtkJob), String> {
    let Loaded {
        scan,
        volume,
        transfer,
        ..
    } = loaded;
    let settings = vtk::alike_settings(
        volume,
        side,
        side,
        View::Anterior,
        Exponent::new(EXPONENT),
        SAMPLE_DISTANCE,
    )
    .map_err(|e| e.to_string())?;
    let folder = scratch.join(scan.key);
    // Not `create_dir_all`: after an interrupt has removed the scratch folder, this must fail
    // rather than make it again outside the temporaries' registry.
    std::fs::create_dir(&folder).map_err(|e| format!("{}: {e}", folder.display()))?;
    let file = vtk_peer::nifti_file(Path::new(scan.path), volume, &folder)?;
    let job = vtk::job(
        volume,
        &file,
        transfer,
        &settings,
        &folder.join("vtk.png"),
        rayon::current_num_threads(),
        frames as u32,
    )
    .map_err(|e| e.to_string())?;
    Ok((settings, job))
}

/// specula's image set up as VTK, and the median seconds of `frames` frames.
fn specula_alike(
    loaded: &Loaded,
    prepared: &PreparedVolume,
    settings: &DvrSettings,
    frames: usize,
) -> Result<(Image, f64), String> {
    vtk_peer::time_specula(&loaded.volume, prepared, &loaded.transfer, settings, frames)
}

/// The comparison with VTK: what is alike, what differs, the images, their agreement and
/// both frame rates.
fn against_vtk(
    context: &mut Context,
    scans: &[Loaded],
    ours: &[(Image, f64)],
    jobs: &[vtk::VtkJob],
    theirs: Result<Vec<Result<vtk_peer::VtkTimes, String>>, String>,
    (side, frames, quick): (u32, usize, &str),
) -> Result<String, String> {
    let mut html = String::from("<h3>Against VTK's CPU ray caster</h3>\n");
    let files = scans
        .iter()
        .map(|loaded| loaded.scan.vtk_reads)
        .collect::<Vec<_>>()
        .join("; ");
    html += &paragraph(&prose::fill(
        prose::VTK_SETUP,
        &[
            ("quick", &quick),
            ("files", &files),
            ("side", &side),
            ("sample_distance", &SAMPLE_DISTANCE),
            ("exponent", &EXPONENT),
        ],
    )?);
    let vtk_runs = match theirs {
        Ok(runs) => runs,
        Err(why) => {
            html += &paragraph("VTK was not run here (see the notes on this machine).");
            context.machine_note(format!(
                "VTK was not run ({why}): the comparison needs the vtk wheel, with nibabel, in {} \
                    (pip install vtk nibabel; SPECULA_PYTHON names another Python).",
                vtk_peer::python().display()
            ));
            return Ok(html);
        }
    };
    let mut rows = Vec::new();
    let mut figures = String::new();
    let mut version = String::new();
    for (((loaded, (ours, seconds)), job), run) in scans.iter().zip(ours).zip(jobs).zip(vtk_runs) {
        let scan = loaded.scan;
        let times = match run {
            Ok(times) => times,
            Err(why) => {
                html += &paragraph(&format!("VTK refused the real {}: {why}", scan.name));
                continue;
            }
        };
        version = times.version.clone();
        let theirs = vtk_peer::read_png_image(&job.output)?;
        if (theirs.width(), theirs.height()) != (ours.width(), ours.height()) {
            return Err(format!(
                "VTK drew {}x{} pixels, specula {side}x{side}",
                theirs.width(),
                theirs.height()
            ));
        }
        let (mut total, mut off) = (0.0_f64, 0_usize);
        for (a, b) in ours.pixels().iter().zip(theirs.pixels()) {
            let d = (a.clamp(Vec3::ZERO, Vec3::ONE) - *b).abs();
            total += f64::from(d.x + d.y + d.z);
            off += usize::from(d.max_element() > 0.1);
        }
        let count = ours.pixels().len().max(1);
        let difference = compare(ours, &theirs, Display::default()).map_err(|e| e.to_string())?;
        let names = ["specula", "vtk", "flip"].map(|k| format!("real-{}-{k}.png", scan.key));
        figures += &context.png_srgb8(
            &names[0],
            side,
            side,
            &ours.to_srgb8(Display::default()),
            &format!("real {}, specula set up as VTK", scan.name),
        )?;
        figures += &context.png_srgb8(
            &names[1],
            side,
            side,
            &theirs.to_srgb8(Display::default()),
            &format!(
                "real {}, VTK {} (its linear values shown in sRGB)",
                scan.name, times.version
            ),
        )?;
        figures += &context.png_srgb8(
            &names[2],
            side,
            side,
            &difference.heatmap_srgb8(),
            &format!(
                "real {}, FLIP between the two (magma: black 0, white 1)",
                scan.name
            ),
        )?;
        let (ours_fps, theirs_fps) = (1.0 / seconds, 1.0 / times.median_draw);
        rows.push(vec![
            format!("real {}", scan.name),
            names[0].clone(),
            names[1].clone(),
            format!("{:.4}", total / (3 * count) as f64),
            format!("{:.2} %", 100.0 * off as f64 / count as f64),
            format!("{:.5}", difference.mean_flip),
            format!("{ours_fps:.1}"),
            format!("{theirs_fps:.1}"),
            format!("{:.2}x", ours_fps / theirs_fps),
        ]);
    }
    if rows.is_empty() {
        return Ok(html);
    }
    html += &table_with_files(
        &[
            "scan",
            "specula image",
            "VTK image",
            "mean |specula - VTK| (linear)",
            "pixels off by more than 0.1",
            "mean FLIP, specula vs VTK",
            "specula frames/s",
            "VTK frames/s",
            "specula frames/s over VTK's (higher is better)",
        ],
        &rows,
        &[1, 2],
    );
    html += &paragraph(&prose::fill(
        prose::VTK_FIGURES,
        &[
            ("version", &version),
            ("frames", &frames),
            ("threads", &rayon::current_num_threads()),
        ],
    )?);
    html += &figures;
    Ok(html)
}
