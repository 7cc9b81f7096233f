//! GPU and CPU renderers draw the same images: every lobe x shading method on the default
//! scene, compared by mean FLIP and PSNR (on display values, as `specula diff` does).
//!
//! Thresholds set on llvmpipe (LLVM 15.0.6, 256 bits), Mesa 22.3.6, where the worst case
//! measured is listed in docs/gpu.md: the two rasterizers agree on coverage except where a
//! pixel centre lies within rounding of an edge, and shading differs by `f32` rounding (more
//! for the angle lobes, through the driver's `acos`).

mod common;

use specula::LobeKind;
use specula_gpu::GpuRenderer;
use specula_render::metrics::compare;
use specula_render::{render, Overrides, Scene, Shading};

const MAX_MEAN_FLIP: f64 = 1e-3;
const MIN_PSNR_DB: f64 = 70.0;

#[test]
fn gpu_renders_match_the_cpu_for_every_lobe_and_shading_method() {
    let Some(gpu) = common::gpu() else { return };
    let renderer = GpuRenderer::new(&gpu).unwrap();
    let mut worst = (f64::INFINITY, 0.0_f64);
    for kind in LobeKind::ALL {
        for shading in Shading::ALL {
            let mut scene = Scene::default_scene();
            scene.apply(&Overrides {
                lobe: Some(kind),
                shading: Some(shading),
                width: Some(320),
                height: Some(180),
                samples: Some(2),
                ..Overrides::default()
            });
            let cpu = render(&scene, &|_, _| {}).unwrap();
            let gpu_image = renderer.render(&scene).unwrap();
            let difference = compare(&cpu, &gpu_image, scene.display).unwrap();
            eprintln!(
                "{kind:>12} {:>7}: PSNR {:.1} dB, mean FLIP {:.2e}",
                shading.id(),
                difference.psnr_db,
                difference.mean_flip
            );
            assert!(
                difference.mean_flip <= MAX_MEAN_FLIP && difference.psnr_db >= MIN_PSNR_DB,
                "{kind} {shading:?} on {}: PSNR {:.1} dB, mean FLIP {:.2e}",
                gpu.adapter_name(),
                difference.psnr_db,
                difference.mean_flip
            );
            worst = (
                worst.0.min(difference.psnr_db),
                worst.1.max(difference.mean_flip),
            );
        }
    }
    eprintln!("worst: PSNR {:.1} dB, mean FLIP {:.2e}", worst.0, worst.1);
}

/// The parity is not vacuous: a different lobe is further from the CPU image than the GPU is.
#[test]
fn a_different_lobe_fails_the_same_thresholds() {
    let Some(gpu) = common::gpu() else { return };
    let renderer = GpuRenderer::new(&gpu).unwrap();
    let mut scene = Scene::default_scene();
    scene.apply(&Overrides {
        width: Some(320),
        height: Some(180),
        ..Overrides::default()
    });
    let cpu = render(&scene, &|_, _| {}).unwrap();
    scene.apply(&Overrides {
        lobe: Some(LobeKind::Schlick),
        ..Overrides::default()
    });
    let other = renderer.render(&scene).unwrap();
    let difference = compare(&cpu, &other, scene.display).unwrap();
    assert!(difference.mean_flip > MAX_MEAN_FLIP || difference.psnr_db < MIN_PSNR_DB);
}
