//! The Mitsuba 3 plugins' microfacet model (`"model": "microfacet"`): every lobe as a normal
//! distribution passes Mitsuba's own chi-square test (`mitsuba.chi2`, `llvm_ad_rgb`) at n in
//! {8, 512} and incidence 0 and 70 degrees; and the plugin's `eval` and `pdf` are specula's
//! microfacet BRDF, checked against the core's `f64` `MicrofacetBrdf` (its own `Lambda`
//! table, computed apart from the plugin's set-up), a check the chi-square test cannot make:
//! it compares the draws with the plugin's density, not the density with `D cos theta_h`.

use glam::DVec3;
use serde_json::Value;
use specula::microfacet::{Distribution, MicrofacetBrdf};
use specula::{Exponent, Lobe, LobeKind};

use crate::common::{self, have_python_module};
use crate::mitsuba::{chi2, export};

#[test]
fn every_lobe_as_a_distribution_passes_mitsubas_chi_square_test() {
    if !have_python_module("mitsuba", "mitsuba") {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    for kind in LobeKind::ALL {
        let name = format!("specula_{}", kind.id().replace('-', "_"));
        // A plugin serves the n of its structural range: one file where that holds 8 and
        // 512, one per n where it does not.
        let [low, high] = Lobe::try_new(kind, 64.0).unwrap().structural_range();
        let groups: Vec<(f64, Vec<f64>)> = if low <= 8.0 && high >= 512.0 {
            vec![(64.0, vec![8.0, 512.0])]
        } else {
            vec![(8.0, vec![8.0]), (512.0, vec![512.0])]
        };
        for (exported, members) in groups {
            let file = format!("{}-{exported}.py", kind.id());
            export(dir.path(), kind.id(), exported, &file);
            let mut extra: Vec<String> = ["--model", "microfacet", "--geometry", "blinn"]
                .map(str::to_owned)
                .to_vec();
            extra.extend(["--theta", "0", "70", "--n"].map(str::to_owned));
            extra.extend(members.iter().map(f64::to_string));
            let extra: Vec<&str> = extra.iter().map(String::as_str).collect();
            let output = chi2(dir.path(), &file, &name, "llvm_ad_rgb", &extra);
            let stdout = String::from_utf8_lossy(&output.stdout);
            assert!(
                output.status.success()
                    && stdout.contains(&format!("{} passed, 0 failed", 2 * members.len())),
                "{kind} as a distribution, exported at n = {exported}:\n{stdout}\n{}",
                String::from_utf8_lossy(&output.stderr)
            );
        }
    }
}

/// Direction pairs over the hemisphere (`wo`, `wi` in the local frame), from near the normal
/// to 75 degrees, in and out of the plane of incidence, some near the mirror direction.
fn pairs() -> Vec<(DVec3, DVec3)> {
    let direction = |theta: f64, phi: f64| {
        let (t, p) = (theta.to_radians(), phi.to_radians());
        DVec3::new(t.sin() * p.cos(), t.sin() * p.sin(), t.cos())
    };
    let mut pairs = Vec::new();
    for theta_o in [0.0, 20.0, 45.0, 70.0] {
        for (theta_i, phi) in [(5.0, 180.0), (22.0, 175.0), (45.0, 170.0), (60.0, 120.0)] {
            pairs.push((
                direction(theta_o, 0.0),
                direction(theta_i + 0.1 * theta_o, phi),
            ));
        }
        pairs.push((direction(theta_o, 0.0), direction(theta_o, 180.0)));
    }
    pairs
}

/// The plugin's `[r, g, b, pdf]` at `pairs` (`mitsuba_check.py eval`).
fn plugin_values(
    dir: &std::path::Path,
    file: &str,
    name: &str,
    n: f64,
    material: &[&str],
    pairs: &[(DVec3, DVec3)],
) -> Vec<[f64; 4]> {
    use std::io::Write as _;
    let json: Vec<[[f64; 3]; 2]> = pairs
        .iter()
        .map(|(wo, wi)| [wo.to_array(), wi.to_array()])
        .collect();
    let n = n.to_string();
    let mut args = vec!["eval", "--plugin", file, "--bsdf", name, "--variant"];
    args.extend(["llvm_ad_rgb", "--model", "microfacet", "--n", &n]);
    args.extend_from_slice(material);
    let mut child = std::process::Command::new(common::python())
        .env("SPECULA_CACHE_DIR", crate::common::test_cache())
        .current_dir(dir)
        .arg(common::renderer_script("mitsuba_check.py"))
        .args(&args)
        .stdin(std::process::Stdio::piped())
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .expect("python runs");
    let input = serde_json::to_vec(&json).unwrap();
    child.stdin.take().unwrap().write_all(&input).unwrap();
    let output = child.wait_with_output().unwrap();
    assert!(
        output.status.success(),
        "{}",
        String::from_utf8_lossy(&output.stderr)
    );
    let values: Value = serde_json::from_slice(&output.stdout).expect("JSON");
    values
        .as_array()
        .unwrap()
        .iter()
        .map(|v| core::array::from_fn(|k| v[k].as_f64().unwrap()))
        .collect()
}

#[test]
fn the_microfacet_plugin_evaluates_speculas_microfacet_brdf() {
    if !have_python_module("mitsuba", "mitsuba") {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let (kd, ks, f0) = ([0.2, 0.1, 0.05], 0.7, [0.04, 0.5, 1.0]);
    let pairs = pairs();
    for (kind, n) in [
        (LobeKind::Pow, 8.0),
        (LobeKind::CosQuad { v: 6 }, 64.0),
        (LobeKind::SchlickMod, 300.0),
        (LobeKind::Sg, 40.0),
    ] {
        // The plugin's name, as `specula shader` makes it from the lobe's full id.
        let name = format!(
            "specula_{}",
            kind.to_string()
                .replace(|c: char| !c.is_ascii_alphanumeric(), "_")
        );
        let file = format!("{}.py", kind.id());
        export(dir.path(), &kind.to_string(), n, &file);
        let material = ["--kd", "0.2", "0.1", "0.05", "--ks", "0.7"];
        let mut with_f0 = material.to_vec();
        with_f0.extend(["--f0", "0.04", "0.5", "1"]);
        let values = plugin_values(dir.path(), &file, &name, n, &with_f0, &pairs);
        // The density alone: no diffuse draws.
        let specular_only = plugin_values(
            dir.path(),
            &file,
            &name,
            n,
            &["--kd", "0", "--ks", "1"],
            &pairs,
        );
        let brdfs = f0.map(|f0| MicrofacetBrdf {
            distribution: Distribution::lobe(kind, Exponent::new(n)),
            f0,
        });
        for (k, &(wo, wi)) in pairs.iter().enumerate() {
            for c in 0..3 {
                let expected = (kd[c] / core::f64::consts::PI + ks * brdfs[c].f(wo, wi)) * wi.z;
                let got = values[k][c];
                assert!(
                    (got - expected).abs() <= 1e-2 * expected + 1e-6,
                    "{kind} n = {n}, {wo} {wi}, channel {c}: {got} vs {expected}"
                );
            }
            let (got, expected) = (specular_only[k][3], brdfs[0].pdf(wo, wi));
            assert!(
                (got - expected).abs() <= 1e-2 * expected + 1e-6,
                "{kind} n = {n}, {wo} {wi}: pdf {got} vs {expected}"
            );
        }
    }
}
