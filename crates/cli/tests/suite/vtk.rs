//! `specula shader --lang vtk` in VTK itself (the pinned `vtk` wheel, offscreen through Mesa's
//! EGL): every built-in lobe, a formula lobe and a designed one, put in place of `pow` in
//! vtkOpenGLPolyDataMapper's and vtkOpenGLGPUVolumeRayCastMapper's specular
//! (`tests/renderers/vtk_lobe_render.py`: a unit sphere, specular only), and VTK's images held
//! against the lobe as specula evaluates it:
//!
//! - the surface under VTK's headlight shades each pixel `lobe(N.z)` (N the sphere's normal
//!   there, known in closed form): within 1/255 of specula's `f64` lobe;
//! - every other path (the ray caster's headlight, directional and positional lights on both
//!   mappers) forms its cosine from VTK's own gradients and reflection vectors, so the cosine is
//!   read off VTK's own `pow` render of the same scene (`t = pow_pixel^(1/n)`, where that pixel
//!   is neither black nor saturated) and the lobe's render must be `lobe(t)` there, within
//!   2/255;
//! - each lobe's render moves from `pow`'s by more than 2 tolerances wherever the lobe is more
//!   than 3 tolerances from `t^n`, and no specular `pow` is left in any shader VTK wrote (the
//!   module's watch, which reports what it finds left when the replacements are dropped).

use std::path::Path;

use specula::{Exponent, Lobe, LobeKind};

use crate::common::{have_python_module, ok, python, renderer_script};

const SIDE: usize = 96;
const N: f64 = 32.0;
/// The surface's headlight against specula's lobe: 8-bit rounding and `f32` arithmetic.
const SURFACE_TOLERANCE: f64 = 1.0 / 255.0;
/// A path whose cosine is read off VTK's `pow` render: that reading's rounding besides.
const READ_TOLERANCE: f64 = 2.0 / 255.0;

/// One render's job: the module (none for VTK's `pow`), the mapper and the lights.
struct Job {
    module: Option<String>,
    n: f64,
    kind: &'static str,
    lights: &'static str,
    /// The module without its replacements: its watch must report every `pow` left.
    control: bool,
}

/// Renders every job in one Python process; each image's red channel in [0, 1], bottom row
/// first, and what the module's watch found left (`None`: it saw no shader).
fn render(directory: &Path, jobs: &[Job]) -> Vec<(Vec<f64>, Option<Vec<String>>)> {
    let mut paths = Vec::new();
    for (k, job) in jobs.iter().enumerate() {
        let path = directory.join(format!("job-{k}.json"));
        let spec = serde_json::json!({
            "module": job.module.as_ref().map(|m| directory.join(m)),
            "n": job.n,
            "side": SIDE,
            "kind": job.kind,
            "lights": job.lights,
            "control": job.control,
            "output": directory.join(format!("image-{k}.rgb")),
        });
        std::fs::write(&path, spec.to_string()).unwrap();
        paths.push(path);
    }
    // Two processes, one per core of the machine CI has: each render is mostly the shader's
    // compile on llvmpipe, one thread's work.
    let half = paths.len().div_ceil(2);
    let children: Vec<_> = paths
        .chunks(half.max(1))
        .map(|part| {
            std::process::Command::new(python())
                .arg(renderer_script("vtk_lobe_render.py"))
                .args(part)
                .stdout(std::process::Stdio::piped())
                .stderr(std::process::Stdio::piped())
                .spawn()
                .expect("python runs")
        })
        .collect();
    let mut lines: Vec<serde_json::Value> = Vec::new();
    for child in children {
        let output = child.wait_with_output().unwrap();
        let stderr = String::from_utf8_lossy(&output.stderr);
        assert!(output.status.success(), "vtk_lobe_render.py: {stderr}");
        assert!(
            !stderr.contains("ERR|"),
            "VTK reported an error (a shader that did not compile?): {stderr}"
        );
        lines.extend(
            String::from_utf8_lossy(&output.stdout)
                .lines()
                .map(|line| serde_json::from_str::<serde_json::Value>(line).unwrap()),
        );
    }
    assert_eq!(lines.len(), jobs.len());
    lines
        .iter()
        .enumerate()
        .map(|(k, line)| {
            assert_eq!(line["vtk"], "9.7.2", "the pinned wheel");
            let bytes = std::fs::read(directory.join(format!("image-{k}.rgb"))).unwrap();
            assert_eq!(bytes.len(), SIDE * SIDE * 3);
            let red = bytes.chunks(3).map(|p| f64::from(p[0]) / 255.0).collect();
            let left = line["uncovered"].as_array().map(|left| {
                left.iter()
                    .map(|v| v.as_str().unwrap().to_owned())
                    .collect()
            });
            (red, left)
        })
        .collect()
}

/// The unit sphere's `N.z` at each pixel (parallel projection, the sphere filling the
/// height), where the pixel lies well inside its silhouette.
fn sphere_cosines() -> Vec<Option<f64>> {
    (0..SIDE * SIDE)
        .map(|k| {
            let centre = |i: usize| (i as f64 + 0.5 - SIDE as f64 / 2.0) / (SIDE as f64 / 2.0);
            let (x, y) = (centre(k % SIDE), centre(k / SIDE));
            let rho2 = x * x + y * y;
            (rho2 < 0.9 * 0.9).then(|| (1.0 - rho2).sqrt())
        })
        .collect()
}

/// The cosine VTK formed at each pixel, read off its `pow` render where that pixel is
/// neither black nor saturated (inside the sphere's silhouette).
fn read_cosines(pow_image: &[f64], n: f64) -> Vec<Option<f64>> {
    let inside = sphere_cosines();
    pow_image
        .iter()
        .zip(inside)
        .map(|(&p, inside)| {
            (inside.is_some() && p > 8.0 / 255.0 && p < 247.0 / 255.0).then(|| p.powf(1.0 / n))
        })
        .collect()
}

/// The largest `|image - lobe(t)|` over the pixels with a cosine, and how many there were.
fn worst(image: &[f64], cosines: &[Option<f64>], lobe: &dyn Fn(f64) -> f64) -> (f64, usize) {
    let mut counted = 0;
    let worst = image
        .iter()
        .zip(cosines)
        .filter_map(|(&v, t)| t.map(|t| (v - lobe(t).clamp(0.0, 1.0)).abs()))
        .inspect(|_| counted += 1)
        .fold(0.0, f64::max);
    (worst, counted)
}

#[test]
fn vtk_shades_with_each_lobe_in_place_of_pow() {
    if !have_python_module("vtk", "vtk==9.7.2") {
        return;
    }
    let directory = tempfile::tempdir().unwrap();
    let d = directory.path();
    // Every built-in lobe, a formula lobe, a lobe `specula design` wrote, and n = 90 through
    // the uniform of a lobe whose constants follow n; each evaluated as specula resolves it.
    ok(
        d,
        &[
            "design",
            "--target",
            "gpu-nvidia",
            "--n",
            "8..512",
            "--max-error",
            "0.1%",
        ]
        .into_iter()
        .chain(["-o", "designed.toml"])
        .collect::<Vec<_>>(),
    );
    let named = LobeKind::ALL
        .iter()
        .map(|kind| (kind.id().to_owned(), N))
        .chain([
            ("=exp2(n * (t - 1) * 1.4427)".to_owned(), N),
            ("@designed.toml".to_owned(), N),
            ("cosquad".to_owned(), 90.0),
        ]);
    let lobes: Vec<(String, f64, Lobe)> = named
        .map(|(text, n)| {
            let kind = specula_render::lobe_file::parse_lobe(&text, Some(d)).unwrap();
            let lobe = Lobe::checked(kind, Exponent::new(n)).unwrap();
            (text, n, lobe)
        })
        .collect();
    for (k, (lobe, _, _)) in lobes.iter().enumerate() {
        ok(
            d,
            &[
                "shader",
                "--lobe",
                lobe,
                "--n",
                "32",
                "--lang",
                "vtk",
                "-o",
                &format!("lobe{k}.py"),
            ],
        );
    }
    let paths = [
        ("surface", "headlight"),
        ("surface", "directional"),
        ("surface", "positional"),
        ("volume", "headlight"),
        ("volume", "directional"),
        ("volume", "positional"),
    ];
    let mut jobs = Vec::new();
    for &(kind, lights) in &paths {
        for n in [N, 90.0] {
            jobs.push(Job {
                module: None,
                n,
                kind,
                lights,
                control: false,
            });
        }
        for (k, (_, n, _)) in lobes.iter().enumerate() {
            jobs.push(Job {
                module: Some(format!("lobe{k}.py")),
                n: *n,
                kind,
                lights,
                control: false,
            });
        }
    }
    // VTK's light kit (a key, fill, back and head light): every shader it writes is
    // replaced, and a lobe unlike t^n moves the image.
    let kit_from = jobs.len();
    for kind in ["surface", "volume"] {
        jobs.push(Job {
            module: None,
            n: N,
            kind,
            lights: "kit",
            control: false,
        });
        jobs.push(Job {
            module: Some("lobe1.py".to_owned()),
            n: N,
            kind,
            lights: "kit",
            control: false,
        });
    }
    // The watch can fail: each path's module without its replacements reports what it left.
    let controls_from = jobs.len();
    for &(kind, lights) in &paths {
        jobs.push(Job {
            module: Some("lobe1.py".to_owned()),
            n: N,
            kind,
            lights,
            control: true,
        });
    }
    let images = render(d, &jobs);
    let per_path = lobes.len() + 2;
    let mut failures = Vec::new();
    let mut check = |holds: bool, message: String| {
        eprintln!("{message}");
        if !holds {
            failures.push(message);
        }
    };
    for (p, &(kind, lights)) in paths.iter().enumerate() {
        let base = p * per_path;
        let pow_image = |n: f64| &images[base + usize::from(n != N)].0;
        for (k, (lobe, n, specula_lobe)) in lobes.iter().enumerate() {
            let eval = |t: f64| specula_lobe.eval(t);
            let (image, left) = &images[base + 2 + k];
            let label = format!("{lobe} at n = {n}, {kind} under the {lights}");
            check(
                left.as_deref() == Some(&[]),
                format!("{label}: VTK's shader kept {left:?}"),
            );
            let (cosines, tolerance) = if (kind, lights) == ("surface", "headlight") {
                (sphere_cosines(), SURFACE_TOLERANCE)
            } else {
                (read_cosines(pow_image(*n), *n), READ_TOLERANCE)
            };
            let (error, counted) = worst(image, &cosines, &eval);
            check(
                counted > 50,
                format!("{label}: {counted} pixels to compare"),
            );
            check(
                error <= tolerance,
                format!("{label}: {:.2}/255 from specula's lobe", error * 255.0),
            );
            // Where the lobe is not t^n, VTK's image is not pow's.
            let (apart, _) = worst(pow_image(*n), &cosines, &eval);
            if apart > 3.0 * tolerance {
                let (moved, _) = worst(image, &cosines, &|t| t.powf(*n));
                check(
                    moved > 2.0 * tolerance,
                    format!("{label}: {:.1}/255 from pow's image", moved * 255.0),
                );
            }
        }
    }
    for (&(kind, lights), (_, left)) in paths.iter().zip(&images[controls_from..]) {
        check(
            left.as_ref().is_some_and(|left| !left.is_empty()),
            format!("{kind} under the {lights}, replacements dropped: the watch saw {left:?}"),
        );
    }
    for pair in images[kit_from..controls_from].chunks(2) {
        let ((pow_image, _), (image, left)) = (&pair[0], &pair[1]);
        check(
            left.as_deref() == Some(&[]),
            format!("{}: the light kit kept {left:?}", lobes[1].0),
        );
        let moved = image
            .iter()
            .zip(pow_image)
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f64::max);
        check(
            moved > 10.0 / 255.0,
            format!(
                "{} under the light kit: {:.1}/255 from pow's",
                lobes[1].0,
                moved * 255.0
            ),
        );
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

/// What the module and the export refuse, each in one line naming the valid choices.
#[test]
fn the_vtk_module_refuses_in_one_line() {
    let directory = tempfile::tempdir().unwrap();
    let d = directory.path();
    let blinn = crate::common::specula(
        d,
        &[
            "shader",
            "--lobe",
            "cosquad",
            "--n",
            "32",
            "--geometry",
            "blinn",
            "--lang",
            "vtk",
        ],
    );
    let message = String::from_utf8_lossy(&blinn.stderr);
    assert!(
        !blinn.status.success() && message.contains("leave --geometry at phong"),
        "{message}"
    );
    if !have_python_module("vtk", "vtk==9.7.2") {
        return;
    }
    ok(
        d,
        &[
            "shader", "--lobe", "minimax2", "--n", "32", "--lang", "vtk", "-o", "baked.py",
        ],
    );
    ok(
        d,
        &[
            "shader",
            "--lobe",
            "cosquad",
            "--n",
            "32",
            "--lang",
            "vtk",
            "-o",
            "taking_n.py",
        ],
    );
    let script = r#"
import vtk, baked, taking_n
def refused(call, *words):
    try:
        call()
    except baked.SpeculaVtkError as e:
        text = str(e)
        assert "\n" not in text and all(w in text for w in words), text
        print(text)
        return
    raise AssertionError("accepted")
volume = vtk.vtkVolume()
volume.SetMapper(vtk.vtkFixedPointVolumeRayCastMapper())
refused(lambda: baked.apply_to_volume(volume), "shades on the CPU", "vtkGPUVolumeRayCastMapper")
refused(lambda: baked.apply_to_volume(vtk.vtkVolume(), n=40), "n must be 32")
refused(lambda: baked.apply_to_volume(vtk.vtkActor()), "takes a vtkVolume")
actor = vtk.vtkActor()
actor.GetProperty().SetInterpolationToPBR()
refused(lambda: baked.apply_to_actor(actor), "PBR", "SetInterpolationToPhong")
try:
    taking_n.apply_to_actor(vtk.vtkActor(), n=2000)
except taking_n.SpeculaVtkError as e:
    assert "in [1.0, 1000.0]" in str(e), e
    print(e)
else:
    raise AssertionError("n = 2000 accepted")
"#;
    let output = std::process::Command::new(python())
        .current_dir(d)
        .args(["-c", script])
        .output()
        .unwrap();
    assert!(
        output.status.success(),
        "{}{}",
        String::from_utf8_lossy(&output.stdout),
        String::from_utf8_lossy(&output.stderr)
    );
}

/// The README's VTK example runs as printed, after the export above it, against the wheel.
#[test]
fn the_readme_vtk_example_runs_as_written() {
    let readme =
        std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("../../README.md"))
            .unwrap();
    let section = readme
        .split("### Use a lobe in VTK, 3D Slicer and ParaView")
        .nth(1)
        .expect("the README's VTK section");
    let block = |fence: &str| {
        section
            .split(fence)
            .nth(1)
            .and_then(|rest| rest.split("```").next())
            .expect("a code block")
            .trim()
            .to_owned()
    };
    let (export, example) = (block("```sh\n"), block("```python\n"));
    let directory = tempfile::tempdir().unwrap();
    let d = directory.path();
    let args: Vec<&str> = export.split_whitespace().skip(1).collect();
    ok(d, &args);
    if !have_python_module("vtk", "vtk==9.7.2") {
        return;
    }
    std::fs::write(
        d.join("example.py"),
        format!(
            "{example}\n# A second frame: the ray caster announces the shader it reuses.\n\
             volume.Modified(); window.Render()\nassert lobe.uncovered(volume) == []\n"
        ),
    )
    .unwrap();
    let output = std::process::Command::new(python())
        .current_dir(d)
        .env("VTK_DEFAULT_OPENGL_WINDOW", "vtkEGLRenderWindow")
        .arg("example.py")
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(
        output.status.success() && !stderr.contains("ERR|"),
        "{stderr}"
    );
}

/// VTK's GPU ray caster with each lobe's module against specula's marcher set up alike
/// (`specula bench vtk-lobes --images`: the built-in phantom, 96 x 96). Measured: `pow`'s
/// images differ by 0.0120 on average and at 0.44 % of the pixels by more than 0.1 (the
/// casters' own differences: VTK's gradients and sample lattice); every lobe's images agree
/// within 0.0006 and 0.4 points of that, and the change a lobe makes from `pow` in VTK's image
/// is 0.34-1.3x the change it makes in specula's (`fasterpow` is the 0.34, not yet explained).
#[test]
fn the_gpu_caster_with_each_lobe_agrees_with_specula() {
    if have_python_module("vtk", "vtk==9.7.2") {
        lobes_agree_in_the_gpu_caster(&["--input", "phantom"], (0.015, 0.008));
    }
}

/// `specula bench vtk-lobes ARGS` at 96 x 96: `pow`'s images within `pow_bounds` (the mean
/// absolute difference, the fraction of pixels off by more than 0.1), every lobe's within
/// 0.001 and 1 point of `pow`'s, and each lobe's change from `pow` alike in both renderers:
/// VTK's 0.5-2x specula's (measured 0.8-1.3x), but `fasterpow`'s 0.15-2x (measured 0.22x on
/// the CT and 0.34x on the phantom, not yet explained), and under 2e-4 where specula's is
/// under 1e-4.
pub(crate) fn lobes_agree_in_the_gpu_caster(args: &[&str], pow_bounds: (f64, f64)) {
    use specula_render::read_image;
    let directory = tempfile::tempdir().unwrap();
    let d = directory.path();
    let output = crate::common::command(d)
        .env("SPECULA_PYTHON", python())
        .args(["bench", "vtk-lobes", "--frames", "1"])
        .args(args)
        .args(["--width", "96", "--height", "96", "--images", "images"])
        .output()
        .unwrap();
    assert!(
        output.status.success(),
        "{}",
        String::from_utf8_lossy(&output.stderr)
    );
    let specula = |name: &str| -> Vec<[f32; 3]> {
        let image = read_image(&d.join(format!("images/specula-{name}.exr"))).unwrap();
        image
            .pixels()
            .iter()
            .map(|p| p.to_array().map(|c| c.clamp(0.0, 1.0)))
            .collect()
    };
    // VTK's bytes as written (the real-scan tests check the reading for every byte).
    let vtk = |name: &str| {
        specula_report::vtk_peer::read_png(&d.join(format!("images/vtk-{name}.png"))).unwrap()
    };
    let mean = |a: &[[f32; 3]], b: &[[f32; 3]]| {
        let sum: f64 = a
            .iter()
            .zip(b)
            .flat_map(|(p, q)| (0..3).map(move |c| f64::from((p[c] - q[c]).abs())))
            .sum();
        sum / (3 * a.len()) as f64
    };
    let far = |a: &[[f32; 3]], b: &[[f32; 3]]| {
        let off = a
            .iter()
            .zip(b)
            .filter(|(p, q)| (0..3).any(|c| (p[c] - q[c]).abs() > 0.1))
            .count();
        off as f64 / a.len() as f64
    };
    let (vtk_pow, specula_pow) = (vtk("vtk-pow"), specula("vtk-pow"));
    let (pow_agree, pow_off) = (mean(&specula_pow, &vtk_pow), far(&specula_pow, &vtk_pow));
    assert!(
        pow_agree < pow_bounds.0 && pow_off < pow_bounds.1,
        "pow: {pow_agree} mean, {pow_off} off"
    );
    let mut failures = Vec::new();
    for kind in LobeKind::ALL {
        let name = kind.id();
        let (ours, theirs) = (specula(name), vtk(name));
        let (agree, off) = (mean(&ours, &theirs), far(&ours, &theirs));
        let (moved_vtk, moved_specula) = (mean(&theirs, &vtk_pow), mean(&ours, &specula_pow));
        let line = format!(
            "{name}: {agree:.4} mean, {:.2} % of pixels > 0.1; from pow: VTK {moved_vtk:.5}, \
             specula {moved_specula:.5}",
            off * 100.0
        );
        eprintln!("{line}");
        // The lobe changes VTK's image as it changes specula's: within 0.5-2x (fasterpow's,
        // unexplained, within 0.15-2x), and hardly where specula's hardly changes.
        let low = if kind.id() == "fasterpow" { 0.15 } else { 0.5 };
        let alike = if moved_specula < 1e-4 {
            moved_vtk < 2e-4
        } else {
            (low..=2.0).contains(&(moved_vtk / moved_specula))
        };
        if agree > pow_agree + 0.001 || off > pow_off + 0.01 || !alike {
            failures.push(line);
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}
