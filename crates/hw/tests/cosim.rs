//! Co-simulation: every datapath's Verilog, at two word lengths, run by Icarus Verilog against
//! vectors from the Rust model; every output must be bit-identical. Every built-in datapath
//! and two compiled from formulas (`K_4` by hand, and `specula design`'s quadratic family,
//! whose `min`, `max`, signed products and wide curvature the built-ins do not all have).
//!
//! Also: every module passes Verilator's `--lint-only -Wall` with no warning.
//!
//! Needs `iverilog` and `vvp` (Debian package `iverilog`) and `verilator` (Debian package
//! `verilator`), which `.ci/run` installs. Without them the tests fail when `CI=true` and are
//! skipped, with a message, otherwise.

use std::path::Path;
use std::process::Command;

use specula_hw::verilog::{self, Form};
use specula_hw::HwLobe;

const WIDTHS: [u32; 2] = [10, 20];

/// The built-in datapaths and two compiled from formulas.
fn datapaths() -> Vec<HwLobe> {
    let compiled = [
        "=let a = (n + 1) / 17; max(0, a * (t - 1) + 1) ^ 16",
        "=let s = 0.125 * n + 0.5 / n; let c = (0.5 * s - 0.5) * s; let disc = s * s - 4 * c; \
         let stop = select(disc < 0, s / (2 * c), 2 / (s + sqrt(max(disc, 0)))); \
         let v = min(1 - t, stop); (1 - v * (s - c * v)) ^ 8",
    ]
    .map(|formula| HwLobe::parse(formula).expect("compiles"));
    HwLobe::ALL.into_iter().chain(compiled).collect()
}

fn have(tool: &str, version_flag: &str) -> bool {
    let found = Command::new(tool)
        .arg(version_flag)
        .output()
        .is_ok_and(|o| o.status.success());
    if !found {
        assert!(
            std::env::var("CI").as_deref() != Ok("true"),
            "{tool} is not installed, and CI=true requires it: apt-get install {tool}"
        );
        eprintln!("skipped: {tool} is not installed (apt-get install {tool})");
    }
    found
}

fn have_iverilog() -> bool {
    have("iverilog", "-V")
}

#[test]
fn every_module_is_lint_clean_under_verilator() {
    if !have("verilator", "--version") {
        return;
    }
    let directory = tempfile::tempdir().expect("temporary directory");
    for lobe in datapaths() {
        for bits in [8, 10, 16, 20, 24] {
            let datapath = lobe.build(bits).expect("valid width");
            for form in [Form::Pipelined, Form::Combinational] {
                let module = directory
                    .path()
                    .join(format!("{}.v", form.module_name(&datapath)));
                let text = verilog::module_in(&datapath, lobe, bits, form);
                std::fs::write(&module, text).expect("write");
                let lint = Command::new("verilator")
                    .args(["--lint-only", "-Wall"])
                    .arg(&module)
                    .output()
                    .expect("run verilator");
                let text = String::from_utf8_lossy(&lint.stderr);
                assert!(
                    lint.status.success() && !text.contains("%Warning"),
                    "{} at {bits} bits, {form:?}:\n{text}",
                    lobe.id()
                );
            }
        }
    }
}

/// The testbenches too (delays and `$fatal` need `--timing`), exhaustive and sampled.
#[test]
fn every_testbench_is_lint_clean_under_verilator() {
    if !have("verilator", "--version") {
        return;
    }
    let directory = tempfile::tempdir().expect("temporary directory");
    for lobe in datapaths() {
        for bits in [8, 20] {
            let datapath = lobe.build(bits).expect("valid width");
            for form in [Form::Pipelined, Form::Combinational] {
                let name = form.module_name(&datapath);
                let module = directory.path().join(format!("{name}.v"));
                let bench = directory.path().join(format!("{name}_tb.v"));
                let vectors = verilog::default_vectors(lobe, &datapath, bits, 64);
                std::fs::write(&module, verilog::module_in(&datapath, lobe, bits, form))
                    .expect("write");
                std::fs::write(&bench, verilog::testbench_in(&datapath, &vectors, form))
                    .expect("write");
                let lint = Command::new("verilator")
                    .args(["--lint-only", "-Wall", "--timing", "--top-module"])
                    .arg(format!("{name}_tb"))
                    .args([&bench, &module])
                    .output()
                    .expect("run verilator");
                let text = String::from_utf8_lossy(&lint.stderr);
                assert!(
                    lint.status.success() && !text.contains("%Warning"),
                    "{} testbench at {bits} bits, {form:?}:\n{text}",
                    lobe.id()
                );
            }
        }
    }
}

fn simulate(directory: &Path, lobe: HwLobe, bits: u32, form: Form) -> String {
    let datapath = lobe.build(bits).expect("valid width");
    let vectors = verilog::default_vectors(lobe, &datapath, bits, 64);
    let name = form.module_name(&datapath);
    let module = directory.join(format!("{name}.v"));
    let bench = directory.join(format!("{name}_tb.v"));
    std::fs::write(&module, verilog::module_in(&datapath, lobe, bits, form)).expect("write");
    std::fs::write(&bench, verilog::testbench_in(&datapath, &vectors, form)).expect("write");
    let program = directory.join(format!("{name}.vvp"));
    // Verilog-2005 and SystemVerilog-2012 both: an identifier that is a keyword in one fails.
    for generation in ["-g2012", "-g2005"] {
        let compiled = Command::new("iverilog")
            .args([generation, "-Wall", "-o"])
            .arg(&program)
            .arg(&module)
            .arg(&bench)
            .output()
            .expect("run iverilog");
        let compiler_text = String::from_utf8_lossy(&compiled.stderr).into_owned();
        assert!(
            compiled.status.success(),
            "{} ({generation}): iverilog failed:\n{compiler_text}",
            datapath.name
        );
    }
    let run = Command::new("vvp")
        .arg("-n")
        .arg(&program)
        .output()
        .expect("run vvp");
    format!(
        "{}{}",
        String::from_utf8_lossy(&run.stdout),
        String::from_utf8_lossy(&run.stderr)
    )
}

#[test]
fn every_datapath_simulates_bit_exactly_at_two_widths() {
    if !have_iverilog() {
        return;
    }
    let directory = tempfile::tempdir().expect("temporary directory");
    for lobe in datapaths() {
        for bits in WIDTHS {
            for form in [Form::Pipelined, Form::Combinational] {
                let output = simulate(directory.path(), lobe, bits, form);
                // Exhaustive at 10 bits (every input word), sampled at 20.
                let count = if bits <= verilog::EXHAUSTIVE_BITS {
                    1 << bits
                } else {
                    verilog::SAMPLED_VECTORS
                };
                assert!(
                    output.contains(&format!("PASS {count} vectors")),
                    "{} at {bits} bits, {form:?}:\n{output}",
                    lobe.id()
                );
            }
        }
    }
}

/// The check can fail: a testbench whose expected values are off by one bit reports it.
#[test]
fn a_wrong_expected_value_is_caught() {
    if !have_iverilog() {
        return;
    }
    let directory = tempfile::tempdir().expect("temporary directory");
    let (lobe, bits) = (HwLobe::CosQuad, 12);
    let datapath = lobe.build(bits).expect("valid width");
    let mut vectors = verilog::test_vectors(lobe, &datapath, bits, 50);
    vectors[7].1 ^= 1;
    let module = directory.path().join("m.v");
    let bench = directory.path().join("tb.v");
    std::fs::write(&module, verilog::module(&datapath, lobe, bits)).expect("write");
    std::fs::write(&bench, verilog::testbench(&datapath, &vectors)).expect("write");
    let program = directory.path().join("sim.vvp");
    let compiled = Command::new("iverilog")
        .arg("-o")
        .arg(&program)
        .arg(&module)
        .arg(&bench)
        .status()
        .expect("iverilog");
    assert!(compiled.success());
    let run = Command::new("vvp")
        .arg("-n")
        .arg(&program)
        .output()
        .expect("vvp");
    let text = format!(
        "{}{}",
        String::from_utf8_lossy(&run.stdout),
        String::from_utf8_lossy(&run.stderr)
    );
    assert!(
        text.contains("FAIL 1 of 50 vectors") && text.contains("MISMATCH vector 7"),
        "{text}"
    );
    // `$fatal`: the simulator's exit status says so too, for scripts and make.
    assert!(!run.status.success(), "a failing testbench exited 0");
}
