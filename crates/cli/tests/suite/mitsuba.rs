//! Mitsuba 3 takes specula's plugins: for every lobe, Mitsuba's own chi-square test
//! (`mitsuba.chi2`, in the JIT `llvm_ad_rgb` variant) passes at n in {8, 64, 512}, both
//! geometries and incidence angles 0, 35 and 70 degrees; the same file passes in
//! `scalar_rgb`; and a plugin whose density is wrong fails, so the test can.

use crate::common;

use crate::common::{export_lobe, have_python_module, ok, run_python};
use specula::{Lobe, LobeKind};
use specula_render::metrics::{mean_radiance, rms_difference};

const EXPONENTS: [f64; 3] = [8.0, 64.0, 512.0];

/// Runs the harness's chi-square test of `plugin` (in `dir`) and returns its output.
pub(crate) fn chi2(
    dir: &std::path::Path,
    plugin: &str,
    name: &str,
    variant: &str,
    extra: &[&str],
) -> std::process::Output {
    let mut args: Vec<String> = [
        "chi2",
        "--plugin",
        plugin,
        "--bsdf",
        name,
        "--variant",
        variant,
    ]
    .map(str::to_owned)
    .to_vec();
    args.extend(extra.iter().map(|s| (*s).to_owned()));
    std::process::Command::new(common::python())
        .env("SPECULA_CACHE_DIR", crate::common::test_cache())
        .current_dir(dir)
        .arg(common::renderer_script("mitsuba_check.py"))
        .args(&args)
        .output()
        .expect("python runs")
}

pub(crate) fn export(dir: &std::path::Path, lobe: &str, n: f64, file: &str) {
    export_lobe(dir, lobe, n, "phong", "mitsuba", file);
}

#[test]
fn every_lobe_passes_mitsubas_chi_square_test() {
    if !have_python_module("mitsuba", "mitsuba") {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    for kind in LobeKind::ALL {
        let name = format!("specula_{}", kind.id().replace('-', "_"));
        // One plugin serves every n within its structural range; the others are exported
        // for each n.
        let mut groups: Vec<(f64, Vec<f64>)> = Vec::new();
        for n in EXPONENTS {
            let [low, high] = Lobe::try_new(kind, 64.0).unwrap().structural_range();
            match groups.first_mut() {
                Some((_, members)) if low <= n && n <= high && low <= 8.0 && high >= 512.0 => {
                    members.push(n)
                }
                _ => groups.push((n, vec![n])),
            }
        }
        for (exported, members) in groups {
            let file = format!("{}-{exported}.py", kind.id());
            export(dir.path(), kind.id(), exported, &file);
            let mut extra = vec!["--n".to_owned()];
            extra.extend(members.iter().map(f64::to_string));
            let extra: Vec<&str> = extra.iter().map(String::as_str).collect();
            let output = chi2(dir.path(), &file, &name, "llvm_ad_rgb", &extra);
            let stdout = String::from_utf8_lossy(&output.stdout);
            eprint!("{stdout}");
            assert!(
                output.status.success()
                    && stdout.contains(&format!("{} passed, 0 failed", 6 * members.len())),
                "{kind} exported at n = {exported}:\n{stdout}\n{}",
                String::from_utf8_lossy(&output.stderr)
            );
        }
    }
}

/// Lobes of the user's pass too: one sampled by Newton on its own tail
/// (`docs/lobes/quartic.toml`) and one from specula's table (a formula without a tail).
#[test]
fn user_lobes_pass_mitsubas_chi_square_test() {
    if !have_python_module("mitsuba", "mitsuba") {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let quartic = format!("@{}", common::docs_lobe("quartic.toml").display());
    for (lobe, name) in [
        (quartic.as_str(), "specula_quartic"),
        ("=exp2(n * (t - 1) * 1.4427)", "specula_formula"),
    ] {
        let file = format!("{name}.py");
        export(dir.path(), lobe, 64.0, &file);
        let output = chi2(
            dir.path(),
            &file,
            name,
            "llvm_ad_rgb",
            &["--n", "8", "64", "512"],
        );
        let stdout = String::from_utf8_lossy(&output.stdout);
        assert!(
            output.status.success() && stdout.contains("18 passed, 0 failed"),
            "{lobe}:\n{stdout}\n{}",
            String::from_utf8_lossy(&output.stderr)
        );
    }
}

/// The same files in `scalar_rgb`: a closed-form lobe (`cosquad`), a Newton one (`schlick`)
/// and a tabulated one (`schlick-mod`, Mitsuba's distribution given Python lists there).
#[test]
fn the_same_plugins_run_in_the_scalar_variant() {
    if !have_python_module("mitsuba", "mitsuba") {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    for lobe in ["cosquad", "schlick", "schlick-mod"] {
        let file = format!("{lobe}.py");
        export(dir.path(), lobe, 64.0, &file);
        let name = format!("specula_{}", lobe.replace('-', "_"));
        let output = chi2(
            dir.path(),
            &file,
            &name,
            "scalar_rgb",
            &["--n", "64", "--theta", "35"],
        );
        let stdout = String::from_utf8_lossy(&output.stdout);
        assert!(
            output.status.success() && stdout.contains("2 passed, 0 failed"),
            "{lobe}:\n{stdout}"
        );
    }
}

/// Draws split between the lobe and a diffuse term (`kd` and `ks` both 0.5): the mixture's
/// density is what the draws follow.
#[test]
fn the_diffuse_and_specular_mixture_passes() {
    if !have_python_module("mitsuba", "mitsuba") {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    export(dir.path(), "schlick", 64.0, "schlick.py");
    let output = chi2(
        dir.path(),
        "schlick.py",
        "specula_schlick",
        "llvm_ad_rgb",
        &["--n", "64", "--kd", "0.5", "--ks", "0.5"],
    );
    let stdout = String::from_utf8_lossy(&output.stdout);
    assert!(
        output.status.success() && stdout.contains("6 passed, 0 failed"),
        "{stdout}"
    );
}

/// A plugin whose density is 25 % too high everywhere (the draws unchanged) fails the test.
#[test]
fn a_wrong_density_fails_the_test() {
    if !have_python_module("mitsuba", "mitsuba") {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    export(dir.path(), "pow", 64.0, "pow.py");
    let plugin = std::fs::read_to_string(dir.path().join("pow.py")).unwrap();
    let wrong = plugin.replace(
        "return dr.select(inside, density, 0.0)",
        "return 1.25 * dr.select(inside, density, 0.0)",
    );
    assert_ne!(wrong, plugin, "the density's line moved");
    std::fs::write(dir.path().join("wrong.py"), wrong).unwrap();
    let output = chi2(
        dir.path(),
        "wrong.py",
        "specula_pow",
        "llvm_ad_rgb",
        &["--n", "64"],
    );
    let stdout = String::from_utf8_lossy(&output.stdout);
    assert!(
        !output.status.success() && stdout.contains("0 passed, 6 failed"),
        "{stdout}"
    );
}

/// A smooth environment (a sky gradient and a broad warm glow) sampled at the row centres a
/// renderer reads: specula's at `(y + 0.5) / H`, Mitsuba's at `y / (H - 1)`, so that both
/// see the same function of direction (their lookups differ, nearest against bilinear,
/// which a smooth map at this resolution makes immaterial).
fn environment(rows_on_poles: bool) -> specula_render::Image {
    use glam::Vec3;
    let (width, height) = (1024u32, 512u32);
    let glow = Vec3::new(0.5, -0.6, 0.62).normalize();
    let mut image = specula_render::Image::new(width, height, Vec3::ZERO);
    for y in 0..height {
        let v = if rows_on_poles {
            f64::from(y) / f64::from(height - 1)
        } else {
            (f64::from(y) + 0.5) / f64::from(height)
        };
        let theta = core::f64::consts::PI * v;
        for x in 0..width {
            // specula's layout: z up, the middle column along +y.
            let phi = core::f64::consts::TAU * ((f64::from(x) + 0.5) / f64::from(width) - 0.5);
            let direction = Vec3::new(
                (theta.sin() * phi.sin()) as f32,
                (theta.sin() * phi.cos()) as f32,
                theta.cos() as f32,
            );
            let sky = Vec3::new(0.35, 0.45, 0.6) * (0.6 + 0.4 * direction.z.max(0.0));
            let ground = Vec3::splat(0.15) * (1.0 + direction.z.min(0.0));
            let base = if direction.z >= 0.0 { sky } else { ground };
            let warm = Vec3::new(6.0, 5.0, 3.5) * (12.0 * (direction.dot(glow) - 1.0)).exp();
            image.set(x, y, base + warm);
        }
    }
    image
}

/// The environment scene's sphere alone, as `sphere.toml` for `specula render`.
/// What `specula render` is lit by and renders: the scene file (the embedded scene if none),
/// the environment, the lobe (the scene's if none), and `[width, height, spp]`.
struct Lit<'a> {
    scene: Option<&'a str>,
    env: &'a str,
    lobe: Option<&'a str>,
    size: [u32; 3],
}

/// `specula render` of `lit` with `seed` into `output` (in `dir`), read back.
fn render_lit(dir: &std::path::Path, lit: &Lit, seed: &str, output: &str) -> specula_render::Image {
    let [width, height, spp] = lit.size.map(|v| v.to_string());
    let mut args = vec!["render"];
    args.extend(lit.scene);
    args.extend(["--env", lit.env]);
    if let Some(lobe) = lit.lobe {
        args.extend(["--lobe", lobe]);
    }
    args.extend([
        "--width", &width, "--height", &height, "--spp", &spp, "--seed", seed, "-o", output,
    ]);
    ok(dir, &args);
    specula_render::read_image(&dir.join(output)).unwrap()
}

fn write_sphere_scene(dir: &std::path::Path) {
    let sphere_only = specula_render::IBL_SCENE
        .split("\n[[objects]]")
        .take(2)
        .collect::<Vec<_>>()
        .join("\n[[objects]]");
    std::fs::write(dir.join("sphere.toml"), sphere_only).unwrap();
}

/// The environment scene's first `objects` objects at `size` (width, height, spp) for the
/// harness, lit by `mitsuba-map.exr`, as `<name>.json`.
fn mitsuba_scene(dir: &std::path::Path, name: &str, objects: usize, size: [u32; 3]) {
    let mut scene = specula_render::Scene::ibl_scene();
    scene.objects.truncate(objects);
    scene.apply(&specula_render::Overrides {
        width: Some(size[0]),
        height: Some(size[1]),
        ..specula_render::Overrides::default()
    });
    specula_render::write_mitsuba_scene(&scene, dir, name, "mitsuba-map.exr", size[2], 7).unwrap();
}

/// Mitsuba's `direct` integrator (one emitter and one BSDF sample, MIS) with specula's
/// plugin renders the environment scene's sphere with every lobe as `specula render --env`
/// does (one
/// environment and one BSDF sample, MIS): the two images differ by no more than two renders
/// of specula's with different seeds do (the RMS over all pixels of the difference, within
/// 30 %), and their means agree within 1 %. Only the sphere: Mitsuba traces shadow rays,
/// which specula's environment lighting leaves out by design (distant, unoccluded light),
/// and a convex object alone is the scene where that makes no difference; what it costs in
/// the whole scene, sphere and teapot, is measured and printed (and breaks the bound).
#[test]
fn mitsuba_renders_the_environment_scene_as_specula_does() {
    if !have_python_module("mitsuba", "mitsuba") {
        return;
    }
    let size = [240u32, 135, 64];
    let dir = tempfile::tempdir().unwrap();
    let display = specula_render::Display::default();
    specula_render::write_image(
        &dir.path().join("specula-map.exr"),
        &environment(false),
        display,
    )
    .unwrap();
    specula_render::write_image(
        &dir.path().join("mitsuba-map.exr"),
        &environment(true),
        display,
    )
    .unwrap();
    write_sphere_scene(dir.path());
    mitsuba_scene(dir.path(), "sphere", 1, size);
    mitsuba_scene(dir.path(), "scene", 2, size);
    for kind in LobeKind::ALL {
        let (lobe, name) = (
            kind.id(),
            format!("specula_{}", kind.id().replace('-', "_")),
        );
        let render = |scene: Option<&str>, seed: &str, output: &str| {
            let lit = Lit {
                scene,
                env: "specula-map.exr",
                lobe: Some(lobe),
                size,
            };
            render_lit(dir.path(), &lit, seed, output)
        };
        let mitsuba = |scene: &str, output: &str| {
            run_python(
                dir.path(),
                "mitsuba_check.py",
                &[
                    "render",
                    "--plugin",
                    &format!("{lobe}.py"),
                    "--bsdf",
                    &name,
                    "--scene",
                    scene,
                    "--output",
                    output,
                    "--variant",
                    "llvm_ad_rgb",
                ]
                .map(str::to_owned),
            );
            specula_render::read_image(&dir.path().join(output)).unwrap()
        };
        export(dir.path(), lobe, 64.0, &format!("{lobe}.py"));
        let first = render(Some("sphere.toml"), "1", "specula-1.exr");
        let second = render(Some("sphere.toml"), "2", "specula-2.exr");
        let theirs = mitsuba("sphere.json", "mitsuba.exr");
        let (noise, against) = (
            rms_difference(&first, &second),
            rms_difference(&first, &theirs),
        );
        let bias = mean_radiance(&theirs) / mean_radiance(&first) - 1.0;
        eprintln!(
            "{lobe}, the sphere: RMS difference from Mitsuba {against:.5}, between specula's \
            seeds {noise:.5}; means differ by {:.2} %",
            100.0 * bias
        );
        assert!(
            against < 1.3 * noise && bias.abs() < 0.01,
            "{lobe}: Mitsuba {against} against noise {noise}, bias {bias}"
        );
        // The whole scene's teapot has n = 256, which not every lobe's plugin exported for
        // n = 64 takes (schlick-mod's and the fitted lobes' do not); pow shows the cost.
        if kind != LobeKind::Pow {
            continue;
        }
        let whole = render(None, "1", "specula-scene.exr");
        let shadowed = mitsuba("scene.json", "mitsuba-scene.exr");
        let shadows = mean_radiance(&shadowed) / mean_radiance(&whole) - 1.0;
        eprintln!(
            "{lobe}, sphere and teapot: Mitsuba's shadows change the mean by {:.2} %",
            100.0 * shadows
        );
        // The bound can fail: shadows alone (measured 1.9 % darker) break it.
        assert!(
            shadows < -0.01,
            "{lobe}: occlusion should darken Mitsuba's whole scene"
        );
    }
}

/// The per-pixel mean of `images`.
fn mean_image(images: &[specula_render::Image]) -> specula_render::Image {
    let first = &images[0];
    let mut pixels = vec![glam::Vec3::ZERO; first.pixels().len()];
    for image in images {
        for (sum, &p) in pixels.iter_mut().zip(image.pixels()) {
            *sum += p / images.len() as f32;
        }
    }
    specula_render::Image::from_pixels(first.width(), first.height(), pixels)
        .expect("as many pixels as the first image")
}

/// One image's noise, from several renders of it: the mean over pairs of their RMS
/// difference, over sqrt(2).
fn noise_of(images: &[specula_render::Image]) -> f64 {
    let mut pairs = Vec::new();
    for (k, a) in images.iter().enumerate() {
        for b in &images[k + 1..] {
            pairs.push(rms_difference(a, b));
        }
    }
    pairs.iter().sum::<f64>() / pairs.len() as f64 / core::f64::consts::SQRT_2
}

/// The built-in sky leaves specula: Mitsuba lit by the file `specula sky -o sky.exr` writes
/// renders the environment scene's sphere (Mitsuba's own `sphere`) as `specula render --env
/// sky` does. The sky is not smooth (a sun disc 5 degrees across, 800 times the sky's
/// radiance), so most of either image's variance lies in a few pixels of the sun's
/// highlight, and the RMS difference of one pair of renders varies by a third from seed to
/// seed: here each renderer's noise is measured from several renders of its own, and the
/// difference of their means must be within 30 % of what those noises explain,
/// `sqrt(noise_m^2 / M + noise_s^2 / S)`, their means within 1 %. This also holds Mitsuba's
/// bilinear lookup and its rows centred half a row away from specula's on a real map.
#[test]
fn mitsuba_lit_by_the_written_sky_renders_as_env_sky() {
    if !have_python_module("mitsuba", "mitsuba") {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    ok(dir.path(), &["sky", "-o", "sky.exr"]);
    let size = [160u32, 90, 256];
    let mut scene = specula_render::Scene::ibl_scene();
    scene.objects.truncate(1);
    scene.apply(&specula_render::Overrides {
        width: Some(size[0]),
        height: Some(size[1]),
        ..specula_render::Overrides::default()
    });
    write_sphere_scene(dir.path());
    export(dir.path(), "pow", 64.0, "pow.py");
    let lit = Lit {
        scene: Some("sphere.toml"),
        env: "sky",
        lobe: None,
        size,
    };
    let ours: Vec<_> = (1..=4)
        .map(|seed| render_lit(dir.path(), &lit, &seed.to_string(), &format!("{seed}.exr")))
        .collect();
    let theirs: Vec<_> = [7u64, 8]
        .into_iter()
        .map(|seed| {
            let name = format!("sphere-{seed}");
            specula_render::write_mitsuba_scene(
                &scene,
                dir.path(),
                &name,
                "sky.exr",
                size[2],
                seed,
            )
            .unwrap();
            run_python(
                dir.path(),
                "mitsuba_check.py",
                &[
                    "render",
                    "--plugin",
                    "pow.py",
                    "--bsdf",
                    "specula_pow",
                    "--scene",
                    &format!("{name}.json"),
                    "--output",
                    &format!("{name}.exr"),
                    "--variant",
                    "llvm_ad_rgb",
                ]
                .map(str::to_owned),
            );
            specula_render::read_image(&dir.path().join(format!("{name}.exr"))).unwrap()
        })
        .collect();
    let (ours_mean, theirs_mean) = (mean_image(&ours), mean_image(&theirs));
    let against = rms_difference(&ours_mean, &theirs_mean);
    let (noise_s, noise_m) = (noise_of(&ours), noise_of(&theirs));
    let expected =
        (noise_m.powi(2) / theirs.len() as f64 + noise_s.powi(2) / ours.len() as f64).sqrt();
    let bias = mean_radiance(&theirs_mean) / mean_radiance(&ours_mean) - 1.0;
    eprintln!(
        "the sphere lit by sky.exr: RMS difference of the means {against:.5}, noise explains \
         {expected:.5} (one render's: specula {noise_s:.5}, Mitsuba {noise_m:.5}); means \
         differ by {:.2} %",
        100.0 * bias
    );
    assert!(
        against < 1.3 * expected && bias.abs() < 0.01,
        "Mitsuba {against} against noise {expected}, bias {bias}"
    );
}
