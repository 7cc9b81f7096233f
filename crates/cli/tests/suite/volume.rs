//! `specula volume` and `volume-convert` from the command line: the phantom, and the same
//! head as NIfTI and as a DICOM series, drawn on the CPU and the GPU, by ray marching and as
//! an isosurface; bad input refused in one line.

use std::path::Path;

use crate::common::{have_gpu, ok, specula};
use specula_render::metrics::compare;
use specula_render::{read_image, Display};

fn mean_flip(d: &Path, a: &str, b: &str) -> f64 {
    let (a, b) = (
        read_image(&d.join(a)).unwrap(),
        read_image(&d.join(b)).unwrap(),
    );
    compare(&a, &b, Display::default()).unwrap().mean_flip
}

#[test]
fn the_head_as_phantom_nifti_and_dicom_renders_alike_on_cpu_and_gpu() {
    let directory = tempfile::tempdir().unwrap();
    let d = directory.path();
    let size = ["--size", "48", "--width", "96", "--height", "96"];
    for output in ["head.nii.gz", "head-dicom"] {
        let convert = [
            "volume-convert",
            "--input",
            "phantom",
            "--size",
            "48",
            "-o",
            output,
        ];
        ok(d, &convert);
    }
    assert_eq!(std::fs::read_dir(d.join("head-dicom")).unwrap().count(), 48);
    let gpu = have_gpu();
    for (input, name) in [
        ("phantom", "phantom"),
        ("head.nii.gz", "nifti"),
        ("head-dicom", "dicom"),
    ] {
        for mode in ["dvr", "iso"] {
            let cpu = format!("{name}-{mode}-cpu.png");
            let base = [
                "volume", "--input", input, "--mode", mode, "--lobe", "cosquad",
            ];
            ok(d, &[&base[..], &size, &["-o", &cpu]].concat());
            let reference = format!("phantom-{mode}-cpu.png");
            // NIfTI keeps f32 exactly and the phantom's tissues survive 16-bit DICOM.
            assert!(mean_flip(d, &reference, &cpu) < 1e-3, "{name} {mode}");
            if gpu {
                let on_gpu = format!("{name}-{mode}-gpu.png");
                ok(
                    d,
                    &[&base[..], &size, &["--backend", "gpu", "-o", &on_gpu]].concat(),
                );
                let flip = mean_flip(d, &cpu, &on_gpu);
                assert!(
                    flip < 1e-3,
                    "{name} {mode}: CPU and GPU differ by mean FLIP {flip}"
                );
            }
        }
    }
    // Not vacuous: the isosurface and the ray-marched head are different images.
    assert!(mean_flip(d, "phantom-dvr-cpu.png", "phantom-iso-cpu.png") > 0.05);
}

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

/// Marschner-Lobb's value falls from 0.8 at its bottom face to 0.2 at its top, so its 0.5
/// isosurface spans the whole cube: seen from above, every ray through the middle of the frame
/// must meet it. By default the signal is drawn as that surface (lit, at least the ambient
/// term everywhere); the `mr` preset shows the same cube as a faint fog.
#[test]
fn marschner_lobb_is_drawn_as_its_mid_range_surface_by_default() {
    let directory = tempfile::tempdir().unwrap();
    let d = directory.path();
    let base = [
        "volume",
        "--input",
        "marschner-lobb",
        "--size",
        "41",
        "--view",
        "axial",
        "--width",
        "64",
        "--height",
        "64",
    ];
    ok(d, &[&base[..], &["-o", "surface.png"]].concat());
    ok(
        d,
        &[&base[..], &["--transfer", "mr", "-o", "fog.png"]].concat(),
    );
    let middle = |name: &str| {
        let image = read_image(&d.join(name)).unwrap();
        (16..48)
            .flat_map(|y| (16..48).map(move |x| (x, y)))
            .map(|(x, y)| image.get(x, y).min_element())
            .fold(f32::INFINITY, f32::min)
    };
    // The ambient weight (0.25) times the surface's darkest colour (0.8), nearly opaque.
    assert!(middle("surface.png") > 0.15, "{}", middle("surface.png"));
    assert!(middle("fog.png") < 0.05, "{}", middle("fog.png"));
}

#[test]
fn bad_volume_requests_are_refused_in_one_line() {
    let directory = tempfile::tempdir().unwrap();
    let d = directory.path();
    std::fs::write(d.join("notes.txt"), "not a volume").unwrap();
    std::fs::write(d.join("bad.nii"), [0_u8; 400]).unwrap();
    for (args, expected) in [
        (
            vec!["volume", "--input", "phantm"],
            "nor an existing file or folder; did you mean 'phantom'?",
        ),
        (vec!["volume", "--input", "."], "no DICOM files"),
        (
            vec!["volume", "--input", "notes.txt"],
            "give a .nii or .nii.gz file",
        ),
        (vec!["volume", "--input", "bad.nii"], "not a NIfTI-1 header"),
        (
            vec!["volume", "--mode", "iso", "--iso", "7", "--size", "16"],
            "outside the volume's values",
        ),
        (
            vec!["volume", "--mode", "iso", "--iso", "nan"],
            "finite number",
        ),
        (
            vec![
                "volume-convert",
                "--input",
                "phantom",
                "--size",
                "16",
                "-o",
                ".",
            ],
            "not an empty folder",
        ),
        (
            vec!["volume", "--transfer", "ct-boen"],
            "presets: ct-bone, ct-soft-tissue, mr, surface, or a .toml file; did you mean \
                'ct-bone'?",
        ),
        (
            vec!["volume", "--eye", "0,0,0"],
            "outside the volume's bounding sphere",
        ),
        (vec!["volume", "--eye", "1,2"], "three finite numbers"),
        (vec!["volume", "--size", "100000"], "8..=512"),
        (
            vec!["volume-convert", "--resample", "512x5", "-o", "r.nii"],
            "write three whole numbers as NXxNYxNZ",
        ),
        (
            vec!["volume-convert", "--resample", "1x64x64", "-o", "r.nii"],
            "every side must be 2 to",
        ),
    ] {
        let output = specula(d, &args);
        let stderr = String::from_utf8_lossy(&output.stderr);
        assert_eq!(output.status.code(), Some(2), "{args:?}: {stderr}");
        assert!(stderr.contains(expected), "{args:?}: {stderr}");
        assert_eq!(stderr.trim_end().lines().count(), 1, "{args:?}: {stderr}");
    }
    assert!(!d.join("volume.png").exists());
}

/// `--resample` writes the volume on the grid asked for, over the same corners.
#[test]
fn volume_convert_resamples_onto_the_grid_asked_for() {
    let directory = tempfile::tempdir().unwrap();
    let d = directory.path();
    let base = ["volume-convert", "--input", "phantom", "--size", "16"];
    ok(d, &[&base[..], &["-o", "small.nii"]].concat());
    ok(
        d,
        &[&base[..], &["--resample", "24x20x18", "-o", "large.nii"]].concat(),
    );
    let small = specula_volume::read(&d.join("small.nii")).unwrap();
    let large = specula_volume::read(&d.join("large.nii")).unwrap();
    assert_eq!(large.dims(), [24, 20, 18]);
    for (a, b) in large.corners().iter().zip(small.corners()) {
        assert!((*a - b).length() < 1e-3, "{a} {b}");
    }
}
