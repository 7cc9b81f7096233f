//! The WGSL library covers the Rust registry, and exported shaders are valid in every
//! language (naga's validator for all; `glslangValidator` and `spirv-val` where installed,
//! required under CI, where `.ci/run` installs them).

mod common;

use std::process::Command;

use specula::{Exponent, Geometry, Lobe, LobeKind, Normalisation};
use specula_gpu::export::{
    export, export_wgsl_source, export_wgsl_source_of_n, GlslVersion, Language, Options, ShaderCode,
};
use specula_gpu::{wgsl, LobeEvaluator};

/// Every lobe of `LobeKind::ALL` has its function in the render module, which naga validates,
/// and no lobe function is typed by hand: none of the WGSL files defines one. (That
/// `lobe_eval` reaches each function with the right block is the compute tests' to show: they
/// evaluate every lobe through it against the `f64` formula.)
#[test]
fn every_rust_lobe_has_its_generated_function() {
    let (module, _) = wgsl::validate(&wgsl::render_module()).unwrap();
    let functions: Vec<&str> = module
        .functions
        .iter()
        .filter_map(|(_, f)| f.name.as_deref())
        .collect();
    for kind in LobeKind::ALL {
        let name = wgsl::lobe_function(kind);
        assert!(functions.contains(&name.as_str()), "{kind}: no `{name}`");
    }
    for (file, text) in [
        ("geometry", wgsl::GEOMETRY),
        ("brdf", wgsl::BRDF),
        ("render", wgsl::RENDER),
        ("volume", wgsl::VOLUME),
        ("evaluate", wgsl::EVALUATE),
    ] {
        assert!(
            !text.contains("fn lobe_"),
            "{file}.wgsl defines a lobe function by hand"
        );
    }
}

/// A scene's render module holds its lobes' functions and no other built-in lobe's, and
/// validates; the block of each of its lobes names a function it has.
#[test]
fn a_scenes_render_module_holds_its_lobes_only() {
    let lobes = [
        Lobe::new(LobeKind::SchlickMod, Exponent::new(100.0)),
        Lobe::new(LobeKind::CosQuad { v: 6 }, Exponent::new(40.0)),
    ];
    let keys: Vec<wgsl::FunctionKey> = lobes.iter().map(wgsl::FunctionKey::of).collect();
    let source = wgsl::render_module_for(&keys);
    wgsl::validate(&source).unwrap();
    for (lobe, key) in lobes.iter().zip(&keys) {
        let function = format!("fn {}_f{}(", wgsl::lobe_function(lobe.kind()), key.function);
        assert!(
            source.contains(&function),
            "{}: no `{function}`",
            lobe.kind()
        );
    }
    // schlick-mod's functions are its shapes: at n = 100 it squares four times (a = 16), the
    // fifth shape, from 64 to 128; cosquad's are its variants, v = 0 to 10.
    assert_eq!(keys[0].function, 4);
    assert_eq!(keys[1].function, 6);
    let others = LobeKind::ALL
        .into_iter()
        .filter(|kind| !lobes.iter().any(|lobe| lobe.kind().index() == kind.index()))
        .filter(|&kind| source.contains(&format!("fn {}(", wgsl::lobe_function(kind))));
    assert_eq!(others.count(), 0, "other lobes in the scene's module");
}

/// A parameter beyond its range, which the model clamps (`cosquad` with `v` = 12 prepares
/// `v` = 10), finds the function of the operations it records.
#[test]
fn a_clamped_parameter_finds_its_function() {
    let n = Exponent::new(64.0);
    let beyond = Lobe::new(LobeKind::CosQuad { v: 12 }, n);
    let clamped = Lobe::new(LobeKind::CosQuad { v: 10 }, n);
    assert_eq!(
        wgsl::FunctionKey::of(&beyond),
        wgsl::FunctionKey::of(&clamped)
    );
}

/// A lobe for each generated function: every variant of every built-in lobe at the least
/// exponent of each of its shapes, plus `inside`.
fn one_lobe_per_function(inside: f64) -> Vec<Lobe> {
    let lobes = LobeKind::ALL
        .into_iter()
        .flat_map(LobeKind::variants)
        .flat_map(|kind| {
            let starts = Lobe::new(kind, Exponent::new(1.0)).shape_exponents();
            starts
                .iter()
                .map(move |start| Lobe::new(kind, Exponent::new(start + inside)))
        });
    lobes.collect()
}

/// The ray marcher's module validates for any list of lobes: none (unshaded), every shape
/// of every built-in lobe (in marches of at most sixteen), and a user's lobe.
#[test]
fn the_ray_marcher_validates_for_any_lobes() {
    let formula = Lobe::new(LobeKind::parse("=t^n").unwrap(), Exponent::new(8.0));
    let every_shape = one_lobe_per_function(0.0);
    let marches = every_shape
        .chunks(wgsl::MAX_HIGHLIGHTS)
        .map(<[Lobe]>::to_vec)
        .chain([Vec::new(), vec![every_shape[0], formula]]);
    for lobes in marches {
        let keys: Vec<wgsl::FunctionKey> = lobes.iter().map(wgsl::FunctionKey::of).collect();
        wgsl::validate(&wgsl::volume_module(&keys)).unwrap_or_else(|e| panic!("{keys:?}: {e}"));
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
                    n_input: false,
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

/// The exported function computes what the library computes, bit for bit: its baked
/// constants are the prepared lobe's, and the library's block picks the function of the same
/// operations and uploads the same parameters. Every variant just inside each of its shapes
/// and at n = 77, on the GPU through a compute entry point appended to the export (not at an
/// exponent such as 1, where a compiler may fold `pow(t, 1.0)` to `t` when the exponent is a
/// literal, as the export's is, but not when it is a uniform, as the library's is).
#[test]
fn the_exported_function_evaluates_like_the_library() {
    let Some(gpu) = common::gpu() else { return };
    let evaluator = LobeEvaluator::new(&gpu).unwrap();
    let ts: Vec<f32> = (0..=2000)
        .map(|i| 1.0 - (i as f32 / 2000.0).powi(2))
        .collect();
    let at_77 = LobeKind::ALL.map(|kind| Lobe::new(kind, Exponent::new(77.0)));
    for lobe in one_lobe_per_function(0.37).into_iter().chain(at_77) {
        let kind = lobe.kind();
        let source = export_wgsl_source(&lobe, Geometry::Blinn, Normalisation::None);
        let exported =
            specula_gpu::evaluate_wgsl_function(&gpu, &source, "specula_lobe", &ts).unwrap();
        let library = evaluator.eval(&lobe, &ts).unwrap();
        assert_eq!(exported, library, "{kind} n = {}", lobe.exponent());
    }
}

/// The export that takes `n` (`--n-input`) computes, at an `n` other than the exported one
/// inside the range it serves, the lobe prepared for that `n` and its normalisation: on the
/// GPU through wrappers appended to the export, against the library's lobe (whose constants
/// are prepared in `f64`, so within `f32` rounding of the constants rather than bit for bit)
/// and the normalisation's `f64` constant. Every lobe whose constants follow `n`, every shape,
/// every normalisation; a fitted lobe is refused with the reason.
#[test]
fn the_export_taking_n_computes_the_lobe_prepared_for_that_n() {
    let Some(gpu) = common::gpu() else { return };
    let evaluator = LobeEvaluator::new(&gpu).unwrap();
    let directory = tempfile::tempdir().unwrap();
    let glslang = tool("glslangValidator");
    let ts: Vec<f32> = (0..=500)
        .map(|i| 1.0 - (i as f32 / 500.0).powi(2))
        .collect();
    let mut taking = 0;
    for exported in one_lobe_per_function(0.37) {
        let kind = exported.kind();
        let [low, high] = exported.structural_range();
        let other = (low + 0.61 * (high.min(1000.0) - low)).max(exported.exponent().get());
        let at = Lobe::new(kind, Exponent::new(other));
        for normalisation in Normalisation::ALL {
            let source = match export_wgsl_source_of_n(&exported, Geometry::Phong, normalisation) {
                Ok(source) => source,
                Err(reason) => {
                    let fitted = at.parameters().iter().any(|p| p.preparation.is_none());
                    let numerical = normalisation == Normalisation::Lobe
                        && at.sampling_expressions().is_none()
                        && at.newton_expressions().is_none();
                    assert!(fitted || numerical, "{kind} {normalisation:?}: {reason}");
                    assert!(reason.contains("fitted") || reason.contains("numerically"));
                    continue;
                }
            };
            taking += 1;
            let options = Options {
                example: true,
                glsl: GlslVersion::Es300,
                n_input: true,
            };
            let label = format!("{kind} {normalisation:?} GLSL ES 3.00 taking n");
            let Ok(ShaderCode::Text(glsl)) = export(
                &exported,
                Geometry::Phong,
                normalisation,
                Language::Glsl,
                options,
            ) else {
                panic!("{label}: no GLSL");
            };
            assert!(glsl.contains("float specula_specular(float n"), "{label}");
            if let Some(glslang) = glslang {
                let path = directory.path().join("lobe.frag");
                std::fs::write(&path, &glsl).unwrap();
                let out = Command::new(glslang).arg(&path).output().unwrap();
                let log = String::from_utf8_lossy(&out.stdout);
                assert!(out.status.success(), "{label}: {log}");
            }
            let n = format!("{:?}", other as f32);
            let source = format!(
                "{source}\nfn lobe_at(t: f32) -> f32 {{ return specula_lobe({n}, t); }}\n\
                    fn normalisation_at(t: f32) -> f32 {{ return specula_normalisation({n}); }}\n"
            );
            let label = format!(
                "{kind} exported at n = {}, run at {other}",
                exported.exponent()
            );
            let shader = specula_gpu::evaluate_wgsl_function(&gpu, &source, "lobe_at", &ts)
                .unwrap_or_else(|e| panic!("{label}: {e}"));
            let library = evaluator.eval(&at, &ts).unwrap();
            let worst = shader
                .iter()
                .zip(&library)
                .map(|(a, b)| (a - b).abs())
                .fold(0.0f32, f32::max);
            assert!(worst <= 2e-5, "{label}: lobe differs by {worst}");
            let constant =
                specula_gpu::evaluate_wgsl_function(&gpu, &source, "normalisation_at", &[0.5])
                    .unwrap()[0];
            let expected = normalisation.constant_for(&at);
            let relative = (f64::from(constant) - expected).abs() / expected;
            assert!(
                relative <= 1e-5,
                "{label} {normalisation:?}: N = {constant}, expected {expected}"
            );
        }
    }
    assert!(taking > 20, "only {taking} exports took n");
}
