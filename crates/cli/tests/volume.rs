//! `specula volume` from the command line: a shaded image of a built-in volume, bad input
//! refused in one line.

mod common;

use common::{ok, specula};

#[test]
fn the_phantom_renders_with_every_view_and_a_lobe() {
    let directory = tempfile::tempdir().unwrap();
    let d = directory.path();
    for view in ["--view=axial", "--view=sagittal", "--eye=400,-300,200"] {
        ok(
            d,
            &[
                "volume", "--size", "48", "--width", "64", "--height", "64", "--lobe", "cosquad",
                view, "-o", "head.png",
            ],
        );
        let image = specula_render::read_image(&d.join("head.png")).unwrap();
        assert_eq!((image.width(), image.height()), (64, 64));
        // The head fills the middle of the frame; the corners see the black background.
        assert!(
            image.get(32, 32).max_element() > 0.02,
            "{view}: an empty centre"
        );
        assert_eq!(image.get(0, 0), glam::Vec3::ZERO, "{view}: a lit corner");
    }
}

#[test]
fn bad_volume_requests_are_refused_in_one_line() {
    let directory = tempfile::tempdir().unwrap();
    let d = directory.path();
    for (args, expected) in [
        (
            vec!["volume", "--input", "phantm"],
            "built in: phantom, marschner-lobb; did you mean 'phantom'?",
        ),
        (
            vec!["volume", "--transfer", "ct-boen"],
            "presets: ct-bone, ct-soft-tissue, mr, or a .toml file; did you mean 'ct-bone'?",
        ),
        (
            vec!["volume", "--eye", "0,0,0"],
            "outside the volume's bounding sphere",
        ),
        (vec!["volume", "--eye", "1,2"], "three finite numbers"),
        (vec!["volume", "--size", "100000"], "8..=512"),
    ] {
        let output = specula(d, &args);
        let stderr = String::from_utf8_lossy(&output.stderr);
        assert_eq!(output.status.code(), Some(2), "{args:?}: {stderr}");
        assert!(stderr.contains(expected), "{args:?}: {stderr}");
        assert_eq!(stderr.trim_end().lines().count(), 1, "{args:?}: {stderr}");
    }
    assert!(!d.join("volume.png").exists());
}
