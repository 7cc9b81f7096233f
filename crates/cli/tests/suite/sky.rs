//! `specula sky`: the built-in sky written as a file is the sky `--env sky` lights with,
//! pixel for pixel, and a render lit by the file is the render lit by `--env sky`.

use crate::common::{ok, specula};

#[test]
fn the_written_sky_is_the_built_in_one() {
    let directory = tempfile::tempdir().expect("temporary directory");
    let d = directory.path();
    let written = ok(d, &["sky", "-o", "sky.exr"]);
    let said = String::from_utf8_lossy(&written.stderr);
    let sun = specula_render::ibl::sun_direction();
    assert!(
        said.contains(&format!("({:.4}, {:.4}, {:.4})", sun.x, sun.y, sun.z)),
        "{said}"
    );
    // Read back by the image reader (not the writer's code): the same pixels, exactly (EXR
    // keeps f32 losslessly), as the environment `--env sky` builds.
    let read = specula_render::read_image(&d.join("sky.exr")).expect("an EXR file");
    let built = specula_render::ibl::Environment::sky(specula_render::ibl::SKY_WIDTH);
    assert_eq!((read.width(), read.height()), (1024, 512));
    assert_eq!(read.pixels(), built.image().pixels());
    // The sun is the brightest pixel, in the direction the command names.
    let (brightest, _) = read
        .pixels()
        .iter()
        .enumerate()
        .max_by(|a, b| a.1.x.total_cmp(&b.1.x))
        .expect("pixels");
    let (x, y) = (
        (brightest % 1024) as f32 + 0.5,
        (brightest / 1024) as f32 + 0.5,
    );
    let theta = std::f32::consts::PI * y / 512.0;
    let phi = 1.5 * std::f32::consts::PI - std::f32::consts::TAU * x / 1024.0;
    let direction = glam::Vec3::new(
        theta.sin() * phi.cos(),
        theta.sin() * phi.sin(),
        theta.cos(),
    );
    assert!(
        direction.dot(sun) > (3.0_f32).to_radians().cos(),
        "{direction} vs {sun}"
    );
    // A render lit by the file is the render lit by the built-in sky.
    let render = |env: &str, out: &str| {
        ok(
            d,
            &[
                "render", "--env", env, "--spp", "4", "--width", "64", "--height", "36", "-o", out,
            ],
        )
    };
    render("sky", "built-in.exr");
    render("sky.exr", "from-file.exr");
    let built_in = specula_render::read_image(&d.join("built-in.exr")).expect("render");
    let from_file = specula_render::read_image(&d.join("from-file.exr")).expect("render");
    assert_eq!(built_in.pixels(), from_file.pixels());
}

#[test]
fn a_sky_that_would_clip_is_refused() {
    let directory = tempfile::tempdir().expect("temporary directory");
    let output = specula(directory.path(), &["sky", "-o", "sky.png"]);
    assert_eq!(output.status.code(), Some(2));
    let said = String::from_utf8_lossy(&output.stderr);
    assert!(said.contains("write it as .exr or .hdr"), "{said}");
    assert!(!directory.path().join("sky.png").exists());
}
