//! Mitsuba 3 takes specula's plugins: for every lobe, Mitsuba's own chi-square test
//! (`mitsuba.chi2`, in the JIT `llvm_ad_rgb` variant) passes at n in {8, 64, 512}, both
//! geometries and incidence angles 0, 35 and 70 degrees; the same file passes in
//! `scalar_rgb`; and a plugin whose density is wrong fails, so the test can.

mod common;

use common::{have_python_module, ok, run_python};
use specula::{Lobe, LobeKind};

const EXPONENTS: [f64; 3] = [8.0, 64.0, 512.0];

/// Runs the harness's chi-square test of `plugin` (in `dir`) and returns its output.
fn chi2(
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
        .current_dir(dir)
        .arg(common::renderer_script("mitsuba_check.py"))
        .args(&args)
        .output()
        .expect("python runs")
}

fn export(dir: &std::path::Path, lobe: &str, n: f64, file: &str) {
    ok(
        dir,
        &[
            "shader",
            "--lobe",
            lobe,
            "--n",
            &n.to_string(),
            "--lang",
            "mitsuba",
            "-o",
            file,
        ],
    );
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

#[test]
fn the_same_plugin_runs_in_the_scalar_variant() {
    if !have_python_module("mitsuba", "mitsuba") {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    export(dir.path(), "cosquad", 64.0, "cosquad.py");
    let output = run_python(
        dir.path(),
        "mitsuba_check.py",
        &[
            "chi2",
            "--plugin",
            "cosquad.py",
            "--bsdf",
            "specula_cosquad",
            "--variant",
            "scalar_rgb",
            "--n",
            "64",
            "--theta",
            "35",
        ]
        .map(str::to_owned),
    );
    assert!(String::from_utf8_lossy(&output.stdout).contains("2 passed, 0 failed"));
}

/// A plugin that draws `n = 64` but reports the density of `n = 80` fails the test.
#[test]
fn a_wrong_density_fails_the_test() {
    if !have_python_module("mitsuba", "mitsuba") {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    export(dir.path(), "pow", 64.0, "pow.py");
    let plugin = std::fs::read_to_string(dir.path().join("pow.py")).unwrap();
    let wrong = plugin.replace(
        "return dr.select(inside, self.cosine.eval_pdf_normalized",
        "return 1.25 * dr.select(inside, self.cosine.eval_pdf_normalized",
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
