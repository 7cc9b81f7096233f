//! The WGSL library covers the Rust registry, and exported shaders are valid in every
//! language (naga's validator for all; `glslangValidator` and `spirv-val` where installed,
//! required under CI, where `.ci/run` installs them).

mod common;

use std::process::Command;

use specula::{Exponent, Geometry, Lobe, LobeKind, Normalisation};
use specula_gpu::export::{export, export_wgsl_source, GlslVersion, Language, Options, ShaderCode};
use specula_gpu::{wgsl, LobeEvaluator};

/// Every lobe of `LobeKind::ALL` has its WGSL function, and `lobe_eval` dispatches its index
/// to it: adding a lobe in Rust without its WGSL fails here.
#[test]
fn every_rust_lobe_has_its_wgsl_function_and_switch_case() {
    let (module, _) = wgsl::validate(&wgsl::render_module()).unwrap();
    let functions: Vec<&str> = module
        .functions
        .iter()
        .filter_map(|(_, f)| f.name.as_deref())
        .collect();
    for kind in LobeKind::ALL {
        let name = wgsl::lobe_function(kind);
        assert!(
            functions.contains(&name.as_str()),
            "{kind}: no `{name}` in lobes.wgsl"
        );
        let case = format!("case {}u: {{ return {name}(lobe, c); }}", kind.index());
        assert!(
            wgsl::LOBES.contains(&case),
            "{kind}: `lobe_eval` lacks `{case}`"
        );
    }
    let cases = wgsl::LOBES.matches("case ").count();
    assert_eq!(
        cases,
        LobeKind::ALL.len(),
        "a WGSL case without a Rust lobe"
    );
}

/// The ray marcher's module validates for any list of lobes: none (unshaded), every
/// built-in lobe, the most one march holds, and a user's lobe.
#[test]
fn the_ray_marcher_validates_for_any_lobes() {
    let formula = LobeKind::parse("=t^n").unwrap();
    for kinds in [
        Vec::new(),
        LobeKind::ALL.to_vec(),
        LobeKind::ALL.iter().copied().cycle().take(16).collect(),
        vec![LobeKind::Pow, formula],
    ] {
        wgsl::validate(&wgsl::volume_module(&kinds)).unwrap_or_else(|e| panic!("{kinds:?}: {e}"));
    }
}

fn tool(name: &str) -> Option<&str> {
    let found = Command::new(name).arg("--version").output().is_ok();
    if !found && std::env::var("CI").as_deref() == Ok("true") {
        panic!("CI=true but {name} is not installed (.ci/run installs it)");
    }
    found.then_some(name)
}

#[test]
fn every_lobe_exports_to_every_language_and_validates() {
    let directory = tempfile::tempdir().unwrap();
    let glslang = tool("glslangValidator");
    let spirv_val = tool("spirv-val");
    let kinds = LobeKind::ALL
        .into_iter()
        .chain([LobeKind::CosQuad { v: 6 }]);
    for kind in kinds {
        let lobe = Lobe::new(kind, Exponent::new(48.0));
        for (geometry, normalisation) in [
            (Geometry::Phong, Normalisation::Lobe),
            (Geometry::Blinn, Normalisation::BlinnApprox),
        ] {
            for language in Language::ALL {
                let options = Options {
                    example: true,
                    glsl: GlslVersion::Desktop450,
                };
                let code = export(&lobe, geometry, normalisation, language, options)
                    .unwrap_or_else(|e| panic!("{kind} {language:?}: {e}"));
                let label = format!("{kind} {geometry:?} {language:?}");
                match (&code, language) {
                    (ShaderCode::Text(text), Language::Wgsl) => {
                        wgsl::validate(text).unwrap_or_else(|e| panic!("{label}: {e}"));
                    }
                    (ShaderCode::Text(text), Language::Glsl) => {
                        assert!(text.starts_with("#version 450"), "{label}");
                        if let Some(glslang) = glslang {
                            let path = directory.path().join("lobe.frag");
                            std::fs::write(&path, text).unwrap();
                            let out = Command::new(glslang).arg(&path).output().unwrap();
                            assert!(
                                out.status.success(),
                                "{label}: {}",
                                String::from_utf8_lossy(&out.stdout)
                            );
                        }
                    }
                    (ShaderCode::SpirV(words), Language::Spirv) => {
                        assert_eq!(words[0], 0x0723_0203, "{label}: SPIR-V magic");
                        if let Some(spirv_val) = spirv_val {
                            let path = directory.path().join("lobe.spv");
                            std::fs::write(&path, code.to_bytes()).unwrap();
                            let out = Command::new(spirv_val).arg(&path).output().unwrap();
                            assert!(
                                out.status.success(),
                                "{label}: {}",
                                String::from_utf8_lossy(&out.stderr)
                            );
                        }
                    }
                    (ShaderCode::Text(text), _) => {
                        assert!(text.contains("specula_lobe"), "{label}");
                    }
                    (ShaderCode::SpirV(_), _) => panic!("{label}: binary for a text language"),
                }
                if let ShaderCode::Text(text) = &code {
                    // Unused lobes are compacted away: only this lobe's function remains.
                    let others = LobeKind::ALL
                        .into_iter()
                        .filter(|k| k.index() != kind.index())
                        .map(wgsl::lobe_function)
                        .filter(|f| text.contains(&format!("{f}(")));
                    assert_eq!(others.count(), 0, "{label}: other lobes left in");
                }
            }
        }
    }
}

/// The exported function computes what the library computes: its baked constants are the
/// prepared lobe's. Run on the GPU through a compute entry point appended to the export.
#[test]
fn the_exported_function_evaluates_like_the_library() {
    let Some(gpu) = common::gpu() else { return };
    let evaluator = LobeEvaluator::new(&gpu).unwrap();
    let ts: Vec<f32> = (0..=2000)
        .map(|i| 1.0 - (i as f32 / 2000.0).powi(2))
        .collect();
    for kind in LobeKind::ALL {
        let lobe = Lobe::new(kind, Exponent::new(77.0));
        let source = export_wgsl_source(&lobe, Geometry::Blinn, Normalisation::None);
        let exported =
            specula_gpu::evaluate_wgsl_function(&gpu, &source, "specula_lobe", &ts).unwrap();
        let library = evaluator.eval(&lobe, &ts).unwrap();
        assert_eq!(exported, library, "{kind}");
    }
}
