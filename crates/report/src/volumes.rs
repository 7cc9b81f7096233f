//! The report's medical section: the head phantom ray-marched with every lobe (FLIP and PSNR
//! against `pow`, time per frame on the CPU and the GPU), its isosurface, and on the
//! Marschner-Lobb signal the shading error that central-difference gradients cause, set
//! beside each lobe's own error; then the real scans and VTK (`real_scans.rs`).

use std::time::Instant;

use glam::{DVec3, Vec3};
use specula::{Geometry, Lobe, LobeKind};
use specula_gpu::{Gpu, GpuVolumeRenderer};
use specula_render::metrics::compare;
use specula_render::{Display, Image};
use specula_volume::dvr::{render_dvr_lobes, render_dvr_prepared, DvrSettings, RayCamera, View};
use specula_volume::isosurface::{default_isovalue, render_isosurface, IsoSettings};
use specula_volume::march::PreparedVolume;
use specula_volume::phantom::{self, marschner_lobb_gradient};
use specula_volume::transfer::TransferFunction;
use specula_volume::Volume;

use super::comparison::{self, Compared};
use super::html::{paragraph, table, table_with_files};
use super::prose;
use super::Context;
use crate::format::{psnr, sig};
use crate::medical::{cpu_threads, march_times, shading, EXPONENT};

/// The best of `runs` wall-clock runs, in milliseconds, and what the last one made.
fn timed<T>(runs: usize, mut draw: impl FnMut() -> Result<T, String>) -> Result<(f64, T), String> {
    let mut best = f64::INFINITY;
    let mut made = None;
    for _ in 0..runs {
        let started = Instant::now();
        made = Some(draw()?);
        best = best.min(started.elapsed().as_secs_f64() * 1e3);
    }
    Ok((best, made.ok_or("no run")?))
}

/// The phantom and, beside it, the real scans.
pub fn volumes(context: &mut Context) -> Result<String, String> {
    let mut real = context.sibling();
    // The real scans wait on files and on VTK's process, and time specula beside VTK's
    // threads: on threads of their own (as many as the sections share) they hold none of the
    // sections' workers, and their parallel work does not queue behind the other sections'.
    let threads = rayon::current_num_threads();
    let (phantom, real_scans) = std::thread::scope(|scope| {
        let real_scans = scope.spawn(|| {
            rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .map_err(|e| e.to_string())?
                .install(|| super::real_scans::real_scans(&mut real))
        });
        let phantom = phantom(context);
        let real_scans = real_scans
            .join()
            .unwrap_or_else(|panic| std::panic::resume_unwind(panic));
        (phantom, real_scans)
    });
    context.absorb(real);
    Ok(phantom? + &real_scans?)
}

fn phantom(context: &mut Context) -> Result<String, String> {
    let (side, pixels, runs) = context.sizes.volume;
    let volume = phantom::shepp_logan(side).map_err(|e| e.to_string())?;
    let transfer = TransferFunction::default_for(&volume).for_volume(&volume);
    let gpu = Gpu::new();
    let renderer = gpu.as_ref().ok().map(GpuVolumeRenderer::new);
    let mut html = paragraph(&prose::fill(
        prose::PHANTOM,
        &[
            ("side", &side),
            ("pixels", &pixels),
            ("exponent", &EXPONENT),
            ("runs", &runs),
        ],
    )?);
    // pow's frame alone, then every lobe's image from one march (each bit for bit the one
    // marched for its lobe alone), on the volume's gradients and bricks computed once.
    let prepared = PreparedVolume::new(&volume);
    let settings_for = |kind| -> Result<DvrSettings, String> {
        Ok(DvrSettings::new(
            pixels,
            pixels,
            View::Anterior,
            Some(shading(kind)?),
        ))
    };
    let (alone_ms, _) = timed(runs, || {
        render_dvr_prepared(
            &volume,
            &prepared,
            &transfer,
            &settings_for(LobeKind::Pow)?,
            &|| {},
        )
        .map_err(|e| e.to_string())
    })?;
    let lobes = context
        .lobes
        .iter()
        .map(|&kind| shading(kind).map(|s| s.lobe))
        .collect::<Result<Vec<_>, _>>()?;
    let (together_ms, marched) = timed(runs, || {
        render_dvr_lobes(
            &volume,
            &prepared,
            &transfer,
            &settings_for(LobeKind::Pow)?,
            &lobes,
            &|| {},
        )
        .map_err(|e| e.to_string())
    })?;
    html += &paragraph(&march_times(
        &cpu_threads(),
        alone_ms,
        together_ms,
        lobes.len(),
    ));
    // The same on the GPU: every lobe's image from one march (up to 16 a march). A software
    // rasterizer's frame is the CPU's work, slowed by the sections beside it, and no GPU's
    // time: there the images are drawn once for the parity column, and timed with --bench.
    let untimed = gpu.as_ref().is_ok_and(Gpu::is_software) && !context.bench;
    let gpu_images = match &renderer {
        Some(renderer) if untimed => renderer
            .render_lobes(&volume, &transfer, &settings_for(LobeKind::Pow)?, &lobes)
            .map_err(|e| e.to_string())?
            .into_iter()
            .map(Some)
            .collect(),
        Some(renderer) => {
            // Compiled beforehand, so that a frame's time is its upload, march and read-back.
            renderer
                .prepare(&[shading(LobeKind::Pow)?.lobe])
                .map_err(|e| e.to_string())?;
            renderer.prepare(&lobes).map_err(|e| e.to_string())?;
            let (alone_ms, _) = timed(runs, || {
                renderer
                    .render(&volume, &transfer, &settings_for(LobeKind::Pow)?)
                    .map_err(|e| e.to_string())
            })?;
            let (together_ms, images) = timed(runs, || {
                renderer
                    .render_lobes(&volume, &transfer, &settings_for(LobeKind::Pow)?, &lobes)
                    .map_err(|e| e.to_string())
            })?;
            html += &paragraph(&march_times(
                "the GPU (upload, march and read-back)",
                alone_ms,
                together_ms,
                lobes.len(),
            ));
            images.into_iter().map(Some).collect()
        }
        None => vec![None; lobes.len()],
    };
    let mut rows = Vec::new();
    let mut reference: Option<Image> = None;
    let mut differences = Vec::new();
    for ((&kind, image), gpu_image) in context.lobes.clone().iter().zip(marched).zip(gpu_images) {
        let name = format!("volume-{}.png", kind.id());
        let bytes = image.to_srgb8(Display::default());
        context.write_png_file(&name, pixels, pixels, &bytes)?;
        let written = Image::from_srgb8(pixels, pixels, &bytes).ok_or("inconsistent image size")?;
        let reference_image = reference.get_or_insert_with(|| written.clone());
        let against_pow =
            compare(reference_image, &written, Display::default()).map_err(|e| e.to_string())?;
        let parity = match &gpu_image {
            Some(gpu_image) => format!(
                "{:.1e}",
                compare(&image, gpu_image, Display::default())
                    .map_err(|e| e.to_string())?
                    .mean_flip
            ),
            None => "not run".into(),
        };
        rows.push(vec![
            kind.to_string(),
            name.clone(),
            psnr(against_pow.psnr_db),
            format!("{:.5}", against_pow.mean_flip),
            parity,
        ]);
        differences.push((kind, name, against_pow));
    }
    let compared: Vec<Compared> = differences
        .iter()
        .map(|(kind, name, d)| Compared::new(*kind, name, d, *kind == LobeKind::Pow))
        .collect();
    html += &comparison::grid(context, "volume", "pow", &compared)?;
    html += &table_with_files(
        &[
            "lobe",
            "image",
            "PSNR vs the pow image (dB)",
            "mean FLIP vs the pow image",
            "mean FLIP, CPU vs GPU",
        ],
        &rows,
        &[1],
    );
    match &gpu {
        Ok(gpu) if untimed => {
            html += &paragraph(&format!(
                "GPU: {}, a rasterizer in software: its images are drawn once for the parity \
                    column and its frames not timed, their time being the CPU's (`specula report \
                    --bench` times them).",
                gpu.adapter_name()
            ));
        }
        Ok(gpu) => html += &paragraph(&format!("GPU: {}.", gpu.adapter_name())),
        Err(error) => {
            html +=
                &paragraph("GPU: not run (no GPU adapter here; see the notes on this machine).");
            context.machine_note(format!(
                "No GPU adapter: the GPU renders and timings were not run ({error})."
            ));
        }
    }
    let iso = default_isovalue(&volume);
    let settings = IsoSettings {
        width: pixels,
        height: pixels,
        view: View::Eye(Vec3::new(300.0, -400.0, 200.0)),
        iso,
        shading: shading(LobeKind::Pow)?,
        method: specula_render::Shading::Phong,
        samples: 2,
    };
    let surface = render_isosurface(&volume, &settings, &|_, _| {}).map_err(|e| e.to_string())?;
    let bytes = surface.to_srgb8(Display::default());
    html += &context.png_srgb8(
        "volume-iso.png",
        pixels,
        pixels,
        &bytes,
        &format!(
            "the isosurface at {iso} (marching cubes, Phong shading, pow), seen from (300, \
            -400, 200) mm"
        ),
    )?;
    html += &marschner_lobb_errors(&context.lobes)?;
    Ok(html)
}

/// Shading errors on the Marschner-Lobb signal at 41³ (the test's usual size): normals from
/// the volume's central differences against the analytic gradient, and what each lobe's
/// specular term makes of the difference.
fn marschner_lobb_errors(lobes: &[LobeKind]) -> Result<String, String> {
    const SIDE: usize = 41;
    let volume: Volume = phantom::marschner_lobb(SIDE).map_err(|e| e.to_string())?;
    let camera = RayCamera::new(View::Anterior, &volume).map_err(|e| e.to_string())?;
    let (wo, wi) = (-camera.forward, camera.light());
    // Cell centres away from the boundary, where the gradient is not negligible.
    let mut normals = Vec::new();
    let mut angles = Vec::new();
    for k in 2..SIDE - 3 {
        for j in 2..SIDE - 3 {
            for i in 2..SIDE - 3 {
                let index = Vec3::new(i as f32 + 0.5, j as f32 + 0.5, k as f32 + 0.5);
                let exact = marschner_lobb_gradient(volume.world(index).as_dvec3());
                if exact.length() < 0.05 {
                    continue;
                }
                let numeric = volume.gradient(index).as_dvec3();
                let (exact, numeric) = (-exact.normalize(), -numeric.normalize_or_zero());
                angles.push(exact.dot(numeric).clamp(-1.0, 1.0).acos().to_degrees());
                let facing = |n: DVec3| if n.dot(wo.as_dvec3()) < 0.0 { -n } else { n };
                normals.push((facing(exact).as_vec3(), facing(numeric).as_vec3()));
            }
        }
    }
    let count = angles.len().max(1) as f64;
    let mean_angle = angles.iter().sum::<f64>() / count;
    let max_angle = angles.iter().copied().fold(0.0, f64::max);
    let pow = shading(LobeKind::Pow)?;
    let mut rows = Vec::new();
    for &kind in lobes {
        let lobe = shading(kind)?.lobe;
        let specular =
            |n: Vec3, lobe: &Lobe| f64::from(lobe.eval(Geometry::Blinn.cos_lobe_f32(n, wo, wi)));
        let rms = |f: &dyn Fn(Vec3, Vec3) -> f64| {
            (normals.iter().map(|&(e, m)| f(e, m).powi(2)).sum::<f64>() / count).sqrt()
        };
        let gradient_error = rms(&|e, m| specular(m, &lobe) - specular(e, &lobe));
        let lobe_error = rms(&|e, _| specular(e, &lobe) - specular(e, &pow.lobe));
        rows.push(vec![kind.to_string(), sig(gradient_error), sig(lobe_error)]);
    }
    let mut html = paragraph(&prose::fill(
        prose::GRADIENT_ERROR,
        &[
            ("side", &SIDE),
            ("cells", &angles.len()),
            ("mean_angle", &format!("{mean_angle:.2}")),
            ("max_angle", &format!("{max_angle:.1}")),
            ("exponent", &EXPONENT),
        ],
    )?);
    html += &table(
        &[
            "lobe",
            "RMS error from the gradient",
            "RMS error of the lobe vs pow",
        ],
        &rows,
    );
    Ok(html)
}
