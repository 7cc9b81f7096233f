use specula_gpu::{Gpu, GpuRenderer};
use specula_render::{metrics::compare, render, Scene};

#[test]
fn smoke() {
    let gpu = Gpu::new().unwrap();
    eprintln!("{}", gpu.adapter_name());
    let renderer = GpuRenderer::new(&gpu).unwrap();
    let scene = Scene::default_scene();
    let image = renderer.render(&scene).unwrap();
    let cpu = render(&scene, &|_, _| {}).unwrap();
    let d = compare(&cpu, &image, scene.display).unwrap();
    eprintln!("psnr {} flip {} max {}", d.psnr_db, d.mean_flip, d.max_abs_error);
    specula_render::write_image(std::path::Path::new("/tmp/gpu.png"), &image, scene.display).unwrap();
}
