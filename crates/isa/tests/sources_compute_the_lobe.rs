//! The sources the vendors' compilers are given compute the lobe: the same text run on the
//! CPU (the CUDA C through `g++`, the OpenCL C through `gcc`, each under a prelude that
//! defines what a GPU's runtime would; the SPIR-V module on Mesa's lavapipe), against the
//! core's `f64` lobe within the bound each model states for a GPU (`Lobe::gpu_ulp_bound`),
//! and the specular term against the core's geometry and normalisation.

use std::io::Write as _;
use std::process::{Command, Stdio};

use specula::{Exponent, Geometry, Lobe, LobeKind, Normalisation};
use specula_isa::Work;
use specula_targets::compute::{kernel, ComputeLanguage};

/// One ULP of 1.0.
const ULP: f64 = 1.0 / 8_388_608.0;

/// What CUDA's runtime and headers give a kernel, for g++.
const CUDA_PRELUDE: &str = r#"
#include <cmath>
#include <cstring>
#define __global__
#define __device__
#define __forceinline__ inline
#define __restrict__
struct Dim { unsigned int x; };
static Dim blockIdx, blockDim, threadIdx;
static inline float __uint_as_float(unsigned int u) {
    float f; std::memcpy(&f, &u, 4); return f;
}
static inline unsigned int __float_as_uint(float f) {
    unsigned int u; std::memcpy(&u, &f, 4); return u;
}
"#;

const CUDA_DRIVER: &str = r#"
#include <cstdio>
#include <cstdlib>
#include <vector>
int main(int argc, char** argv) {
    long per_thread = std::strtol(argv[1], nullptr, 10);
    std::vector<float> input;
    float value;
    while (std::fread(&value, sizeof value, 1, stdin) == 1) input.push_back(value);
    std::vector<float> output(input.size() / per_thread);
    blockDim.x = 64;
    for (unsigned int i = 0; i < output.size(); i++) {
        blockIdx.x = i / 64;
        threadIdx.x = i % 64;
        specula_evaluate(input.data(), output.data());
    }
    std::fwrite(output.data(), sizeof(float), output.size(), stdout);
}
"#;

/// What OpenCL's runtime gives a kernel, for gcc (C11 with type-generic maths).
const OPENCL_PRELUDE: &str = r#"
#include <tgmath.h>
#include <string.h>
#include <stddef.h>
#define __kernel
#define __global
static size_t specula_thread;
#define get_global_id(dimension) specula_thread
static inline float as_float(unsigned int u) { float f; memcpy(&f, &u, 4); return f; }
static inline unsigned int as_uint(float f) { unsigned int u; memcpy(&u, &f, 4); return u; }
#define native_powr(x, y) powf(x, y)
#define native_exp2(x) exp2f(x)
#define native_log2(x) log2f(x)
#define native_sqrt(x) sqrtf(x)
#define native_exp(x) expf(x)
#define native_log(x) logf(x)
#define native_sin(x) sinf(x)
#define native_cos(x) cosf(x)
#define native_divide(a, b) ((a) / (b))
#define max(a, b) fmaxf(a, b)
#define min(a, b) fminf(a, b)
"#;

const OPENCL_DRIVER: &str = r#"
#include <stdio.h>
#include <stdlib.h>
int main(int argc, char** argv) {
    long per_thread = strtol(argv[1], NULL, 10);
    static float input[1 << 20], output[1 << 20];
    size_t count = fread(input, sizeof(float), 1 << 20, stdin) / per_thread;
    for (specula_thread = 0; specula_thread < count; specula_thread++)
        specula_evaluate(input, output);
    fwrite(output, sizeof(float), count, stdout);
    return 0;
}
"#;

/// Compiles `source` between the prelude and the driver with `compiler` and runs it.
fn run_on_cpu(
    language: ComputeLanguage,
    source: &str,
    inputs: &[f32],
    per_thread: usize,
) -> Vec<f32> {
    let (compiler, prelude, driver, extension, flags): (_, _, _, _, &[&str]) = match language {
        ComputeLanguage::Cuda => ("g++", CUDA_PRELUDE, CUDA_DRIVER, "cpp", &["-std=c++17"]),
        ComputeLanguage::OpenCl => ("gcc", OPENCL_PRELUDE, OPENCL_DRIVER, "c", &["-std=c11"]),
    };
    let folder = tempfile::tempdir().unwrap();
    let file = folder.path().join(format!("kernel.{extension}"));
    std::fs::write(&file, format!("{prelude}\n{source}\n{driver}")).unwrap();
    let program = folder.path().join("kernel");
    let built = Command::new(compiler)
        .args(flags)
        .arg("-O1")
        .arg("-o")
        .arg(&program)
        .arg(&file)
        .arg("-lm")
        .output()
        .unwrap_or_else(|e| panic!("{compiler}: {e} (apt-get install {compiler})"));
    assert!(
        built.status.success(),
        "{compiler} refused the kernel: {}\n{source}",
        String::from_utf8_lossy(&built.stderr)
    );
    let mut child = Command::new(&program)
        .arg(per_thread.to_string())
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .spawn()
        .unwrap();
    let bytes: Vec<u8> = inputs.iter().flat_map(|v| v.to_le_bytes()).collect();
    child.stdin.take().unwrap().write_all(&bytes).unwrap();
    let output = child.wait_with_output().unwrap();
    assert!(output.status.success());
    output
        .stdout
        .chunks_exact(4)
        .map(|b| f32::from_le_bytes([b[0], b[1], b[2], b[3]]))
        .collect()
}

/// Cosines from below 0 to above 1, dense near 1 where the lobes live.
fn cosines() -> Vec<f32> {
    let mut ts: Vec<f32> = (0..=400).map(|k| k as f32 / 400.0).collect();
    ts.extend((1..=200).map(|k| 1.0 - (k as f32 / 200.0).powi(3) * 0.05));
    ts.extend([-0.5, -0.0, 1.0e-30, 1.25, f32::NAN]);
    ts
}

/// The lobes checked: every built-in at a few exponents, and a formula.
fn lobes() -> Vec<Lobe> {
    let formula = LobeKind::parse("=max(0, 1 - n * (1 - t) / 4)^4").unwrap();
    let mut lobes = Vec::new();
    for kind in LobeKind::ALL.into_iter().chain([formula]) {
        for n in [3.0, 64.0, 700.0] {
            lobes.push(Lobe::new(kind, Exponent::new(n)));
        }
    }
    lobes
}

fn check(lobe: &Lobe, what: &str, ts: &[f32], values: &[f32]) {
    assert_eq!(
        values.len(),
        ts.len(),
        "{what}: {} outputs for {} inputs",
        values.len(),
        ts.len()
    );
    let bound = lobe.gpu_ulp_bound() * ULP;
    for (&t, &value) in ts.iter().zip(values) {
        let reference = lobe.eval(f64::from(t));
        let error = (f64::from(value) - reference).abs();
        assert!(
            error <= bound,
            "{what}: {} n = {} t = {t:e}: {value:e} against f64 {reference:e} ({:.0} ULP > {:.0})",
            lobe.kind(),
            lobe.exponent(),
            error / ULP,
            bound / ULP
        );
    }
}

#[test]
fn the_cuda_and_opencl_kernels_compute_the_lobe_on_the_cpu() {
    let ts = cosines();
    for lobe in lobes() {
        for language in ComputeLanguage::ALL {
            let values = run_on_cpu(language, &kernel(&lobe, language, Work::Lobe), &ts, 1);
            check(&lobe, &format!("{language:?}"), &ts, &values);
        }
    }
}

#[test]
fn the_spirv_kernel_computes_the_lobe_on_lavapipe() {
    let ts = cosines();
    for lobe in lobes() {
        match specula_isa::run_spirv_on_lavapipe(&lobe, Work::Lobe, &ts) {
            Ok(values) => check(&lobe, "SPIR-V on lavapipe", &ts, &values),
            Err(error) if std::env::var("CI").as_deref() != Ok("true") => {
                eprintln!("skipped: {error}");
                return;
            }
            Err(error) => panic!("CI=true requires lavapipe and the Vulkan helper: {error}"),
        }
    }
}

/// Unit directions about the normal +z: `wi` and `wo` around the mirror, so `t` spans the
/// lobe.
fn directions() -> Vec<f32> {
    let mut inputs = Vec::new();
    for k in 0..64 {
        let a = k as f32 * 0.37;
        let wi = [0.6 * a.cos() * 0.9, 0.6 * a.sin() * 0.9, 0.0];
        let wi_z = (1.0 - wi[0] * wi[0] - wi[1] * wi[1]).sqrt();
        let spread = 0.002 * k as f32;
        let wo = [-wi[0] + spread, -wi[1] - 0.5 * spread, 0.0];
        let wo_z = (1.0 - wo[0] * wo[0] - wo[1] * wo[1]).sqrt();
        inputs.extend([0.0, 0.0, 1.0, wo[0], wo[1], wo_z, wi[0], wi[1], wi_z]);
    }
    inputs
}

#[test]
fn the_shading_kernels_compute_the_specular_term() {
    let inputs = directions();
    for geometry in Geometry::ALL {
        for kind in [LobeKind::Pow, LobeKind::Schlick, LobeKind::Sg] {
            let lobe = Lobe::new(kind, Exponent::new(48.0));
            let normalisation = Normalisation::Lobe;
            let work = Work::Shading(geometry, normalisation);
            let scale = normalisation.constant_for(&lobe);
            let expected: Vec<f64> = inputs
                .chunks_exact(9)
                .map(|v| {
                    let vector = |k: usize| {
                        glam::DVec3::new(f64::from(v[k]), f64::from(v[k + 1]), f64::from(v[k + 2]))
                    };
                    scale * lobe.eval(geometry.cos_lobe(vector(0), vector(3), vector(6)))
                })
                .collect();
            let mut results = Vec::new();
            for language in ComputeLanguage::ALL {
                results.push((
                    format!("{language:?}"),
                    run_on_cpu(language, &kernel(&lobe, language, work), &inputs, 9),
                ));
            }
            match specula_isa::run_spirv_on_lavapipe(&lobe, work, &inputs) {
                Ok(values) => results.push(("SPIR-V on lavapipe".to_owned(), values)),
                Err(error) => assert!(
                    std::env::var("CI").as_deref() != Ok("true"),
                    "CI=true requires lavapipe: {error}"
                ),
            }
            for (what, values) in results {
                for (value, reference) in values.iter().zip(&expected) {
                    // The directions arrive in f32: t carries a few ULP, which the lobe's
                    // slope near its peak (n) multiplies.
                    let bound =
                        scale * (lobe.gpu_ulp_bound() + 64.0 * 48.0) * ULP + 1e-6 * reference;
                    assert!(
                        (f64::from(*value) - reference).abs() <= bound,
                        "{what} {kind} {geometry:?}: {value} against {reference}"
                    );
                }
            }
        }
    }
}
