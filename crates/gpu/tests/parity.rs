//! GPU and CPU renderers draw the same images: every lobe x shading method on the default
//! scene, compared by mean FLIP and PSNR (on display values, as `specula diff` does).
//!
//! Thresholds set on llvmpipe (LLVM 15.0.6, 256 bits), Mesa 22.3.6, where the worst case
//! measured is listed in docs/gpu.md: the two rasterizers agree on coverage except where a
//! pixel centre lies within rounding of an edge, and shading differs by `f32` rounding (more
//! for the angle lobes, through the driver's `acos`).

mod common;

use common::Parity;
use specula::LobeKind;
use specula_gpu::GpuRenderer;
use specula_render::{render, IlluminationModel, Overrides, Scene, Shading};

const MAX_MEAN_FLIP: f64 = 1e-3;
const MIN_PSNR_DB: f64 = 70.0;

/// The default scene at 320x180 with 2x2 samples under `overrides`, drawn by both renderers
/// and checked.
fn check_default_scene(
    parity: &mut Parity,
    gpu: &specula_gpu::Gpu,
    renderer: &GpuRenderer,
    overrides: Overrides,
    what: &str,
) {
    let mut scene = Scene::default_scene();
    scene.apply(&Overrides {
        width: Some(320),
        height: Some(180),
        samples: Some(2),
        ..overrides
    });
    let cpu = render(&scene, &|_, _| {}).unwrap();
    let gpu_image = renderer.render(&scene).unwrap();
    parity.check(what, gpu, &cpu, &gpu_image, scene.display);
}

#[test]
fn gpu_renders_match_the_cpu_for_every_lobe_and_shading_method() {
    let Some(gpu) = common::gpu() else { return };
    let renderer = GpuRenderer::new(&gpu);
    let mut parity = Parity::new(MAX_MEAN_FLIP, MIN_PSNR_DB);
    for kind in LobeKind::ALL {
        for shading in Shading::ALL {
            let overrides = Overrides {
                lobe: Some(kind),
                shading: Some(shading),
                ..Overrides::default()
            };
            let what = format!("{kind} {}", shading.id());
            check_default_scene(&mut parity, &gpu, &renderer, overrides, &what);
        }
    }
    parity.report();
}

/// The microfacet model (every lobe as a distribution, its masking table and Fresnel in the
/// material's uniform block) draws as the CPU does, Phong shading, the same thresholds.
#[test]
fn gpu_microfacet_renders_match_the_cpu_for_every_lobe() {
    let Some(gpu) = common::gpu() else { return };
    let renderer = GpuRenderer::new(&gpu);
    let mut parity = Parity::new(MAX_MEAN_FLIP, MIN_PSNR_DB);
    for kind in LobeKind::ALL {
        let overrides = Overrides {
            lobe: Some(kind),
            model: Some(IlluminationModel::Microfacet),
            ..Overrides::default()
        };
        let what = format!("{kind} microfacet");
        check_default_scene(&mut parity, &gpu, &renderer, overrides, &what);
    }
    parity.report();
}

/// The parity is not vacuous: a different lobe is further from the CPU image than the GPU is.
#[test]
fn a_different_lobe_fails_the_same_thresholds() {
    let Some(gpu) = common::gpu() else { return };
    let renderer = GpuRenderer::new(&gpu);
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
    let parity = Parity::new(MAX_MEAN_FLIP, MIN_PSNR_DB);
    assert!(parity.exceeded(&cpu, &other, scene.display));
}
