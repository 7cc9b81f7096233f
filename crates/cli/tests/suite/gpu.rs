//! The GPU commands: `render --backend gpu`, `analyze --backend gpu`, `shader`, `bench gpu`.
//! Tests that need an adapter are skipped without one, except under CI (`CI=true`), where
//! `.ci/run` installs Mesa's lavapipe and a missing adapter is a failure.

use crate::common::{have_gpu, have_tool, ok, specula};
use assert_cmd::Command;
use serde_json::Value;

#[test]
fn gpu_render_writes_the_image_the_cpu_writes() {
    if !have_gpu() {
        return;
    }
    let directory = tempfile::tempdir().unwrap();
    let d = directory.path();
    let size = ["--width", "160", "--height", "90"];
    ok(
        d,
        &[&["render", "--backend", "gpu", "-o", "gpu.png"][..], &size].concat(),
    );
    ok(d, &[&["render", "-o", "cpu.png"][..], &size].concat());
    let output = ok(d, &["diff", "cpu.png", "gpu.png", "--format", "json"]);
    let report: Value = serde_json::from_slice(&output.stdout).unwrap();
    assert!(report["mean_flip"].as_f64().unwrap() < 1e-3, "{report}");
    ok(
        d,
        &[
            "render",
            "--backend",
            "gpu",
            "--grid",
            "lobes=pow,logexp",
            "--width",
            "64",
            "--height",
            "40",
            "-o",
            "grid.png",
        ],
    );
}

#[test]
fn no_adapter_is_a_clear_error_and_no_file() {
    let directory = tempfile::tempdir().unwrap();
    let output = Command::cargo_bin("specula")
        .unwrap()
        .env("SPECULA_CACHE_DIR", crate::common::test_cache())
        .current_dir(directory.path())
        .env("WGPU_BACKEND", "metal")
        .args(["render", "--backend", "gpu", "-o", "x.png"])
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert_eq!(output.status.code(), Some(2), "{stderr}");
    assert!(
        stderr.contains("no GPU adapter") && stderr.contains("mesa-vulkan-drivers"),
        "{stderr}"
    );
    assert!(!stderr.contains("panicked"));
    assert_eq!(std::fs::read_dir(directory.path()).unwrap().count(), 0);
}

#[test]
fn analyze_on_the_gpu_reports_figures_close_to_the_cpu_f32_path() {
    if !have_gpu() {
        return;
    }
    let directory = tempfile::tempdir().unwrap();
    let d = directory.path();
    let figures = |backend: &str| -> Value {
        let output = ok(
            d,
            &[
                "analyze",
                "--lobe",
                "schlick-mod,cosquad",
                "--n",
                "64",
                "--format",
                "json",
                "--backend",
                backend,
            ],
        );
        serde_json::from_slice(&output.stdout).unwrap()
    };
    let (gpu, f32) = (figures("gpu"), figures("f32"));
    for (g, c) in gpu.as_array().unwrap().iter().zip(f32.as_array().unwrap()) {
        assert_eq!(g["precision"], "gpu");
        let (a, b) = (
            g["epicentre_max_rel"].as_f64().unwrap(),
            c["epicentre_max_rel"].as_f64().unwrap(),
        );
        assert!((a - b).abs() <= 1e-3 * b, "{a} {b}");
    }
}

#[test]
fn shader_exports_text_and_binary() {
    let directory = tempfile::tempdir().unwrap();
    let d = directory.path();
    let output = ok(
        d,
        &[
            "shader",
            "--lobe",
            "cosquad:v=5",
            "--n",
            "100",
            "--lang",
            "glsl",
        ],
    );
    let text = String::from_utf8_lossy(&output.stdout);
    assert!(
        text.starts_with("#version 450") && text.contains("float specula_lobe(float"),
        "{text}"
    );
    assert!(text.contains("cosquad:v=5, n = 100"), "{text}");
    ok(
        d,
        &[
            "shader", "--lobe", "cheb2", "--n", "32", "--lang", "spirv", "-o", "lobe.spv",
        ],
    );
    assert_eq!(
        &std::fs::read(d.join("lobe.spv")).unwrap()[..4],
        &[0x03, 0x02, 0x23, 0x07]
    );
    for (args, needle) in [
        (
            &["shader", "--lobe", "pow", "--n", "8", "--lang", "spirv"][..],
            "-o",
        ),
        (
            &["shader", "--lobe", "pow", "--n", "8", "--lang", "cg"][..],
            "glsl",
        ),
        (
            &["shader", "--lobe", "pow", "--n", "0", "--lang", "glsl"][..],
            "[1, 1000]",
        ),
    ] {
        let output = specula(d, args);
        let stderr = String::from_utf8_lossy(&output.stderr);
        assert_eq!(output.status.code(), Some(2), "{args:?}");
        assert!(stderr.contains(needle), "{args:?}: {stderr}");
    }
}

#[test]
fn bench_gpu_lists_every_lobe_with_its_ratio_to_pow() {
    if !have_gpu() {
        return;
    }
    let directory = tempfile::tempdir().unwrap();
    let output = ok(
        directory.path(),
        &[
            "bench", "gpu", "--width", "64", "--height", "36", "--frames", "1",
        ],
    );
    let text = String::from_utf8_lossy(&output.stdout);
    for id in [
        "pow ",
        "schlick-mod",
        "cheb2-thesis",
        "logexp-rr",
        "cosquad",
    ] {
        assert!(text.contains(id), "{text}");
    }
    assert!(text.contains("1.00x"), "{text}");
}

/// The recipe in docs/gpu.md: the exported text, as it is, at the top of a shader of one's own that
/// calls `specula_specular`; glslang accepts it.
#[test]
fn the_documented_glsl_paste_recipe_compiles() {
    if !have_tool("glslangValidator", "--version", "glslang-tools") {
        return;
    }
    let directory = tempfile::tempdir().unwrap();
    let d = directory.path();
    let output = ok(
        d,
        &[
            "shader",
            "--lobe",
            "schlick-mod",
            "--n",
            "64",
            "--geometry",
            "blinn",
            "--normalisation",
            "blinn-approx",
            "--lang",
            "glsl",
        ],
    );
    let exported = String::from_utf8(output.stdout).unwrap();
    let shader = format!(
        "{exported}\n{}",
        "layout(location = 0) in vec3 v_position;
layout(location = 1) in vec3 v_normal;
layout(location = 0) out vec4 colour;
uniform vec3 u_eye, u_light, u_light_colour, u_kd, u_ks;

void main() {
    vec3 n = normalize(v_normal);
    vec3 wo = normalize(u_eye - v_position);
    vec3 wi = normalize(u_light - v_position);
    float cos_in = max(dot(n, wi), 0.0);
    vec3 brdf = u_kd / 3.14159265 + u_ks * specula_specular(n, wo, wi);
    colour = vec4(u_light_colour * brdf * cos_in, 1.0);
}
"
    );
    std::fs::write(d.join("mine.frag"), shader).unwrap();
    let check = std::process::Command::new("glslangValidator")
        .arg(d.join("mine.frag"))
        .output()
        .unwrap();
    assert!(
        check.status.success(),
        "{}",
        String::from_utf8_lossy(&check.stdout)
    );
}

#[test]
fn bench_frame_compares_cpu_and_gpu_per_shading_method() {
    if !have_gpu() {
        return;
    }
    let directory = tempfile::tempdir().unwrap();
    let output = ok(
        directory.path(),
        &[
            "bench", "frame", "--width", "64", "--height", "36", "--frames", "1",
        ],
    );
    let text = String::from_utf8_lossy(&output.stdout);
    for method in ["flat", "gouraud", "phong"] {
        assert!(text.lines().any(|l| l.starts_with(method)), "{text}");
    }
    assert!(text.contains("CPU / GPU"), "{text}");
}

#[test]
fn bench_gpu_lobes_lists_every_lobe_against_pow() {
    if !have_gpu() {
        return;
    }
    let directory = tempfile::tempdir().unwrap();
    let output = ok(directory.path(), &["bench", "gpu-lobes", "--format", "csv"]);
    // CSV is data alone: the header, then a row a lobe whose throughput over pow's is a number
    // (pow's own exactly 1), the adapter's name on stderr.
    let text = String::from_utf8_lossy(&output.stdout);
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().unwrap_or_default().split(',').collect();
    let column = header
        .iter()
        .position(|&h| h == "x pow's throughput")
        .unwrap_or_else(|| panic!("no throughput column: {text}"));
    let rows: Vec<Vec<&str>> = lines.map(|l| l.split(',').collect()).collect();
    assert_eq!(rows.len(), specula::LobeKind::ALL.len(), "{text}");
    for row in &rows {
        let ratio: f64 = row[column].parse().unwrap_or_else(|_| panic!("{text}"));
        assert!(ratio > 0.0, "{text}");
    }
    assert!(rows[0][0] == "pow" && rows[0][column] == "1.0", "{text}");
}

/// Without a session's `XDG_RUNTIME_DIR` (CI, SSH), the GPU path prints nothing but its
/// result: no driver noise on stderr.
#[test]
fn the_gpu_path_keeps_stderr_clean() {
    if !have_gpu() {
        return;
    }
    let directory = tempfile::tempdir().unwrap();
    let output = Command::cargo_bin("specula")
        .unwrap()
        .env("SPECULA_CACHE_DIR", crate::common::test_cache())
        .current_dir(directory.path())
        .env_remove("XDG_RUNTIME_DIR")
        .args([
            "render",
            "--backend",
            "gpu",
            "--width",
            "16",
            "--height",
            "16",
        ])
        .args(["-o", "gpu.png"])
        .output()
        .unwrap();
    assert!(output.status.success());
    let stderr = String::from_utf8_lossy(&output.stderr);
    let lines: Vec<&str> = stderr.lines().collect();
    assert!(
        lines.len() == 1 && lines[0].starts_with("wrote gpu.png"),
        "stderr: {stderr}"
    );
}

/// Every lobe exports to GLSL 4.50, ES 3.00 and ES 1.00 as functions a shader of one's own
/// calls as they are (no edit, no example to cut out, no `while (true)`), and glslang accepts
/// each such shader. ES 1.00 has no bit operations: exactly the lobes whose operation count
/// includes a power-of-two scaling or bit read (the cost model's `shift`) are refused, with
/// the construct named.
#[test]
fn exported_glsl_compiles_unedited_for_each_version() {
    if !have_tool("glslangValidator", "--version", "glslang-tools") {
        return;
    }
    let directory = tempfile::tempdir().unwrap();
    let d = directory.path();
    for kind in specula::LobeKind::ALL {
        for (version, output, write) in [
            ("450", "layout(location = 0) out vec4 colour;", "colour"),
            ("300es", "out vec4 colour;", "colour"),
            ("100", "", "gl_FragColor"),
        ] {
            let args = [
                "shader",
                "--lobe",
                kind.id(),
                "--n",
                "64",
                "--lang",
                "glsl",
                "--glsl-version",
                version,
            ];
            let bit_operations = specula::Lobe::new(kind, specula::Exponent::new(64.0))
                .ops()
                .shift
                > 0;
            if version == "100" && bit_operations {
                let refused = specula(d, &args);
                let stderr = String::from_utf8_lossy(&refused.stderr);
                assert_eq!(refused.status.code(), Some(2), "{kind}: {stderr}");
                assert!(
                    stderr.contains(kind.id()) && stderr.contains("use --glsl-version 300es"),
                    "{kind}: {stderr}"
                );
                continue;
            }
            let exported = ok(d, &args);
            let exported = String::from_utf8(exported.stdout).unwrap();
            assert!(
                !exported.contains("while(true)"),
                "{kind} {version}: a loop"
            );
            assert!(
                !exported.contains("void main"),
                "{kind} {version}: an example"
            );
            let shader = format!(
                "{exported}\n{output}\nvoid main() {{\n    float s = specula_specular(vec3(0.0, \
                    0.0, 1.0), normalize(vec3(0.2, 0.1, 1.0)), normalize(vec3(-0.2, 0.0, \
                    1.0)));\n    {write} = vec4(s, s, s, 1.0);\n}}\n"
            );
            let file = d.join(format!("{}-{version}.frag", kind.id()));
            std::fs::write(&file, shader).unwrap();
            let check = std::process::Command::new("glslangValidator")
                .arg(&file)
                .output()
                .unwrap();
            assert!(
                check.status.success(),
                "{kind} {version}: {}",
                String::from_utf8_lossy(&check.stdout)
            );
        }
    }
}
