//! A scene uploaded once (`GpuRenderer::prepare`) draws the same image every time it is drawn,
//! the image `render` draws from scratch, and its frame times bracket the GPU's pass.

mod common;

use specula::LobeKind;
use specula_gpu::GpuRenderer;
use specula_render::{Overrides, Scene, Shading};

fn scene() -> Scene {
    let mut scene = Scene::default_scene();
    scene.apply(&Overrides {
        lobe: Some(LobeKind::CosQuad { v: 4 }),
        shading: Some(Shading::Phong),
        width: Some(160),
        height: Some(90),
        samples: Some(2),
        ..Overrides::default()
    });
    scene
}

#[test]
fn a_prepared_frame_redraws_the_image_render_draws() {
    let Some(gpu) = common::gpu() else { return };
    let renderer = GpuRenderer::new(&gpu);
    let scene = scene();
    let frame = renderer.prepare(&scene).unwrap();
    let first = frame.image().unwrap();
    // Drawing without read-back in between must not disturb the targets' next frame.
    frame.draw(false).unwrap();
    let second = frame.image().unwrap();
    let fresh = renderer.render(&scene).unwrap();
    assert_eq!(first.pixels(), second.pixels());
    assert_eq!(first.pixels(), fresh.pixels());
    // And the image is a render, not a cleared target.
    let background = first.pixels()[0];
    assert!(first.pixels().iter().any(|&p| p != background));
}

#[test]
fn frame_times_bracket_the_gpu_pass() {
    let Some(gpu) = common::gpu() else { return };
    let renderer = GpuRenderer::new(&gpu);
    let frame = renderer.prepare(&scene()).unwrap();
    for read_back in [false, true] {
        let time = frame.draw(read_back).unwrap();
        assert!(time.wall.as_nanos() > 0);
        if let Some(pass) = time.pass {
            // The pass runs between submission and the wait's end, both inside `wall`.
            assert!(pass <= time.wall, "pass {pass:?} > frame {:?}", time.wall);
            assert!(pass.as_nanos() > 0, "a drawn pass takes time");
        }
    }
}
