//! The GPU ray marcher draws what the CPU's does: every lobe on the head phantom, and the
//! isosurface through the GPU rasterizer, compared by mean FLIP and PSNR on display values.
//! Rays, steps and jitter are the same by construction; what differs is `f32` rounding in
//! the driver's `exp`, `sqrt` and the lobes, which moves a ray's stopping sample now and then.

mod common;

use common::Parity;
use specula::{Exponent, Geometry, Lobe, LobeKind, Normalisation};
use specula_gpu::{GpuRenderer, GpuVolumeRenderer};
use specula_render::metrics::compare;
use specula_render::{render, Display};
use specula_volume::dvr::{render_dvr, DvrSettings, Shading, View};
use specula_volume::isosurface::{iso_scene, marching_cubes, IsoSettings};
use specula_volume::phantom;
use specula_volume::transfer::TransferFunction;

const MAX_MEAN_FLIP: f64 = 1e-3;
const MIN_PSNR_DB: f64 = 65.0;

fn shading(kind: LobeKind) -> Shading {
    Shading::new(
        Lobe::new(kind, Exponent::try_new(32.0).unwrap()),
        Geometry::Blinn,
        Normalisation::ThesisPhong,
    )
}

#[test]
fn gpu_ray_marching_matches_the_cpu_for_every_lobe() {
    let Some(gpu) = common::gpu() else { return };
    let renderer = GpuVolumeRenderer::new(&gpu);
    let volume = phantom::shepp_logan(48).unwrap();
    let transfer = TransferFunction::default_for(&volume).for_volume(&volume);
    let mut parity = Parity::new(MAX_MEAN_FLIP, MIN_PSNR_DB);
    for (kind, view) in LobeKind::ALL.into_iter().zip(
        [
            View::Anterior,
            View::Inferior,
            View::Left,
            View::Eye(glam::Vec3::new(300.0, -200.0, 150.0)),
        ]
        .into_iter()
        .cycle(),
    ) {
        let settings = DvrSettings::new(96, 80, view, Some(shading(kind)));
        let cpu = render_dvr(&volume, &transfer, &settings, &|| {}).unwrap();
        let gpu_image = renderer.render(&volume, &transfer, &settings).unwrap();
        let what = format!("{kind} {}", view.id());
        parity.check(&what, &gpu, &cpu, &gpu_image, Display::default());
    }
    parity.report();
    // Not vacuous: the unshaded image is further from the CPU's pow image than the GPU's is.
    let settings = DvrSettings::new(96, 80, View::Anterior, Some(shading(LobeKind::Pow)));
    let cpu = render_dvr(&volume, &transfer, &settings, &|| {}).unwrap();
    let unshaded = DvrSettings::new(96, 80, View::Anterior, None);
    let other = render_dvr(&volume, &transfer, &unshaded, &|| {}).unwrap();
    let gpu_image = renderer.render(&volume, &transfer, &settings).unwrap();
    let apart = compare(&cpu, &other, Display::default()).unwrap().mean_flip;
    let agreement = compare(&cpu, &gpu_image, Display::default())
        .unwrap()
        .mean_flip;
    assert!(apart > 10.0 * agreement.max(1e-5), "{apart} vs {agreement}");
}

/// A sample with no gradient keeps its ambient term alone on the GPU as on the CPU
/// (`Shading::ambient_where_flat`, VTK's GPU caster's rule), and the rule changes the image.
#[test]
fn gpu_flat_samples_keep_their_ambient_term_as_the_cpu_does() {
    let Some(gpu) = common::gpu() else { return };
    let renderer = GpuVolumeRenderer::new(&gpu);
    let volume = phantom::shepp_logan(48).unwrap();
    let transfer = TransferFunction::default_for(&volume).for_volume(&volume);
    let shading = |flat: bool| Shading {
        fade_weak_gradients: false,
        ambient_where_flat: flat,
        ..shading(LobeKind::Pow)
    };
    let settings = DvrSettings::new(96, 80, View::Anterior, Some(shading(true)));
    let cpu = render_dvr(&volume, &transfer, &settings, &|| {}).unwrap();
    let gpu_image = renderer.render(&volume, &transfer, &settings).unwrap();
    let mut parity = Parity::new(MAX_MEAN_FLIP, MIN_PSNR_DB);
    parity.check(
        "pow, ambient where flat",
        &gpu,
        &cpu,
        &gpu_image,
        Display::default(),
    );
    parity.report();
    let unlit = DvrSettings::new(96, 80, View::Anterior, Some(shading(false)));
    let other = render_dvr(&volume, &transfer, &unlit, &|| {}).unwrap();
    let apart = compare(&cpu, &other, Display::default()).unwrap().mean_flip;
    let agreement = compare(&cpu, &gpu_image, Display::default())
        .unwrap()
        .mean_flip;
    assert!(apart > 10.0 * agreement.max(1e-5), "{apart} vs {agreement}");
}

/// Every lobe's image from one march is the one its lobe alone draws, bit for bit, past
/// the 16 images one march holds (20 lobes: two marches); an unshaded march has no lobe to
/// vary and is refused.
#[test]
fn gpu_lobes_marched_together_are_each_marched_alone() {
    let Some(gpu) = common::gpu() else { return };
    let renderer = GpuVolumeRenderer::new(&gpu);
    let volume = phantom::shepp_logan(40).unwrap();
    let transfer = TransferFunction::default_for(&volume).for_volume(&volume);
    let kinds: Vec<LobeKind> = LobeKind::ALL.into_iter().cycle().take(20).collect();
    let lobes: Vec<Lobe> = kinds.iter().map(|&kind| shading(kind).lobe).collect();
    let settings = DvrSettings::new(64, 48, View::Anterior, Some(shading(LobeKind::Pow)));
    let together = renderer
        .render_lobes(&volume, &transfer, &settings, &lobes)
        .unwrap();
    assert_eq!(together.len(), lobes.len());
    for (kind, image) in kinds.iter().zip(&together) {
        let alone = renderer
            .render(
                &volume,
                &transfer,
                &DvrSettings::new(64, 48, View::Anterior, Some(shading(*kind))),
            )
            .unwrap();
        assert!(alone.pixels() == image.pixels(), "{kind}");
    }
    assert!(
        together[0].pixels() != together[1].pixels(),
        "pow's and schlick's images differ"
    );
    let unshaded = DvrSettings::new(64, 48, View::Anterior, None);
    assert!(renderer
        .render_lobes(&volume, &transfer, &unshaded, &lobes)
        .is_err());
}

#[test]
fn gpu_isosurfaces_match_the_cpu() {
    let Some(gpu) = common::gpu() else { return };
    let renderer = GpuRenderer::new(&gpu);
    let volume = phantom::shepp_logan(48).unwrap();
    for kind in [LobeKind::Pow, LobeKind::parse("cosquad").unwrap()] {
        let settings = IsoSettings {
            width: 96,
            height: 80,
            view: View::Anterior,
            iso: 0.5,
            shading: shading(kind),
            method: specula_render::Shading::Phong,
            samples: 2,
        };
        let scene = iso_scene(&volume, marching_cubes(&volume, 0.5).unwrap(), &settings).unwrap();
        let cpu = render(&scene, &|_, _| {}).unwrap();
        let gpu_image = renderer.render(&scene).unwrap();
        let difference = compare(&cpu, &gpu_image, scene.display).unwrap();
        assert!(
            difference.mean_flip <= MAX_MEAN_FLIP,
            "{kind}: mean FLIP {:.2e}",
            difference.mean_flip
        );
    }
}
