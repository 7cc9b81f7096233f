//! MaterialX takes specula's documents: for every lobe, the document validates against
//! MaterialX's standard libraries, MaterialX's own generators write GLSL, ESSL, MSL, OSL and
//! MDL from it (the material, and a probe of the exact lobe node), glslangValidator accepts
//! the GLSL and ESSL stages, and Blender's OSL compiler the OSL.

use crate::common;

use crate::common::{export_lobe, have_python_module, have_tool, run_python};
use specula::{Lobe, LobeKind};

const TARGETS: [&str; 5] = ["glsl", "essl", "msl", "osl", "mdl"];

fn check(lobe: &str, geometry: &str) {
    let dir = tempfile::tempdir().unwrap();
    let stem = lobe.replace(|c: char| !c.is_ascii_alphanumeric() && c != '-', "_");
    let file = format!("{stem}-{geometry}.mtlx");
    export_lobe(dir.path(), lobe, 100.0, geometry, "mtlx", &file);
    let args = [
        file.as_str(),
        "--out",
        "generated",
        "--glslang",
        "--osl-compile",
        "--require-tools",
    ]
    .map(str::to_owned);
    let output = run_python(dir.path(), "materialx_check.py", &args);
    let stdout = String::from_utf8_lossy(&output.stdout);
    assert!(stdout.contains("ok validate"), "{file}:\n{stdout}");
    for target in TARGETS {
        let generated = stdout
            .lines()
            .filter(|line| line.starts_with(&format!("ok {target} ")))
            .count();
        assert_eq!(
            generated, 2,
            "{file}: {target} for the material and the lobe's probe:\n{stdout}"
        );
    }
    assert_eq!(
        stdout
            .lines()
            .filter(|l| l.starts_with("ok glslang"))
            .count(),
        8,
        "{file}:\n{stdout}"
    );
    assert_eq!(
        stdout.lines().filter(|l| l.starts_with("ok oslc")).count(),
        2,
        "{file}:\n{stdout}"
    );
    assert!(!stdout.contains("failed"), "{file}:\n{stdout}");
}

#[test]
fn every_lobes_document_validates_and_generates_every_language() {
    if !have_python_module("MaterialX", "materialx")
        || !have_python_module("bpy", "bpy")
        || !have_tool("glslangValidator", "--version", "glslang-tools")
    {
        return;
    }
    for kind in LobeKind::ALL {
        check(kind.id(), "phong");
    }
    for lobe in ["pow", "fastpow"] {
        check(lobe, "blinn");
    }
    // A lobe of the user's (docs/lobes/quartic.toml) is generated from the same description.
    check(
        &format!("@{}", common::docs_lobe("quartic.toml").display()),
        "phong",
    );
}

/// The lobe's node graph, evaluated as MaterialX defines its nodes (an independent reader,
/// in float32), is the lobe: within 1e-4 relative (plus 1e-7) of specula's `f64` value at
/// 400 cosines, with `n` set through the node's input to another value than the exported one
/// where the lobe takes `n` as an input.
#[test]
fn every_lobes_node_graph_evaluates_to_the_lobe() {
    if !have_python_module("MaterialX", "materialx") {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let cosines: Vec<f64> = (0..400)
        .map(|k| -0.05 + 1.1 * f64::from(k) / 399.0)
        .collect();
    // The built-in lobes, and a lobe of the user's (its file's formula, n an input).
    let quartic = format!("@{}", common::docs_lobe("quartic.toml").display());
    let user = specula_render::lobe_file::parse_lobe(&quartic, None).unwrap();
    let cases = LobeKind::ALL
        .map(|kind| (kind.id().to_owned(), kind))
        .into_iter()
        .chain([(quartic, user)]);
    for (argument, kind) in cases {
        let file = format!("{}.mtlx", kind.id());
        export_lobe(dir.path(), &argument, 100.0, "phong", "mtlx", &file);
        let exported = Lobe::try_new(kind, 100.0).unwrap();
        let takes_n = exported.structural_range() != [100.0, 100.0];
        let n = if takes_n { 80.0 } else { 100.0 };
        let lobe = Lobe::try_new(kind, n).unwrap();
        let node = format!("ND_specula_{}_float", kind.id().replace('-', "_"));
        let mut args = vec![file.clone(), node, "--t".to_owned()];
        args.extend(cosines.iter().map(f64::to_string));
        if takes_n {
            args.extend(["--input".to_owned(), format!("n={n}")]);
        }
        let output = run_python(dir.path(), "materialx_eval.py", &args);
        let values: Vec<f64> = String::from_utf8_lossy(&output.stdout)
            .lines()
            .map(|line| line.parse().unwrap())
            .collect();
        assert_eq!(values.len(), cosines.len(), "{kind}");
        for (t, value) in cosines.iter().zip(values) {
            let expected = lobe.eval(*t);
            assert!(
                (value - expected).abs() <= 1e-4 * expected + 1e-7,
                "{kind} n = {n} at t = {t}: graph {value}, lobe {expected}"
            );
        }
    }
}
