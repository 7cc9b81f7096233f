//! MaterialX takes specula's documents: for every lobe, the document validates against
//! MaterialX's standard libraries, MaterialX's own generators write GLSL, ESSL, MSL, OSL and
//! MDL from it (the material, and a probe of the exact lobe node), glslangValidator accepts
//! the GLSL and ESSL stages, and Blender's OSL compiler the OSL.

mod common;

use common::{have_python_module, have_tool, ok, run_python};
use specula::LobeKind;

const TARGETS: [&str; 5] = ["glsl", "essl", "msl", "osl", "mdl"];

fn check(lobe: &str, geometry: &str) {
    let dir = tempfile::tempdir().unwrap();
    let file = format!("{lobe}-{geometry}.mtlx");
    ok(
        dir.path(),
        &[
            "shader",
            "--lobe",
            lobe,
            "--n",
            "100",
            "--geometry",
            geometry,
            "--lang",
            "mtlx",
            "-o",
            &file,
        ],
    );
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
}
