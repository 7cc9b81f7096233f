//! The real flows, on small datapaths: Yosys's gate-level netlist simulates bit for bit like
//! the model (synthesis kept the function), and the resource and timing figures obey what
//! the datapath description and the parts imply.
//!
//! Needs `yosys`, `nextpnr-ice40` and `iverilog` (Debian packages `yosys`, `nextpnr-ice40`,
//! `fpga-icestorm`, `iverilog`), which `.ci/run` installs. Without them the tests fail when
//! `CI=true` and are skipped, with a message, otherwise.

use std::process::Command;

use specula_hw::verilog::{self, Form};
use specula_hw::HwLobe;
use specula_synth::cache::Cache;
use specula_synth::{synthesize, Ice40Device, Target};

fn have(tool: &str, version_flag: &str, package: &str) -> bool {
    let found = Command::new(tool)
        .arg(version_flag)
        .output()
        .is_ok_and(|o| o.status.success());
    if !found {
        assert!(
            std::env::var("CI").as_deref() != Ok("true"),
            "{tool} is not installed, and CI=true requires it: apt-get install {package}"
        );
        eprintln!("skipped: {tool} is not installed (apt-get install {package})");
    }
    found
}

/// Multipliers and squarers in the model: at 8 bits each fits one multiplier block.
fn multiplications(lobe: HwLobe, bits: u32) -> u64 {
    let r = lobe.build(bits).expect("valid width").resources();
    (r.multipliers.len() + r.squarers.len()) as u64
}

#[test]
fn the_generic_netlist_simulates_like_the_model() {
    if !have("yosys", "-V", "yosys") || !have("iverilog", "-V", "iverilog") {
        return;
    }
    let directory = tempfile::tempdir().expect("temporary directory");
    let bits = 8;
    for lobe in [HwLobe::CosQuad, HwLobe::Pow, HwLobe::Sg, HwLobe::Schlick] {
        let datapath = lobe.build(bits).expect("valid width");
        let netlist = specula_synth::generic_netlist(lobe, bits).expect("synthesis");
        let vectors = verilog::default_vectors(lobe, &datapath, bits, 64);
        let bench = verilog::testbench_in(&datapath, &vectors, Form::Pipelined);
        let (netlist_path, bench_path, program) = (
            directory.path().join(format!("{}_netlist.v", lobe.id())),
            directory.path().join(format!("{}_tb.v", lobe.id())),
            directory.path().join(format!("{}.vvp", lobe.id())),
        );
        std::fs::write(&netlist_path, netlist).expect("write");
        std::fs::write(&bench_path, bench).expect("write");
        let compiled = Command::new("iverilog")
            .args(["-g2012", "-o"])
            .arg(&program)
            .args([&netlist_path, &bench_path])
            .output()
            .expect("run iverilog");
        assert!(
            compiled.status.success(),
            "{}: {}",
            lobe.id(),
            String::from_utf8_lossy(&compiled.stderr)
        );
        let run = Command::new("vvp")
            .arg("-n")
            .arg(&program)
            .output()
            .expect("run vvp");
        let text = String::from_utf8_lossy(&run.stdout);
        assert!(
            run.status.success() && text.contains(&format!("PASS {} vectors", vectors.len())),
            "{} gate level: {text}",
            lobe.id()
        );
    }
}

#[test]
fn ice40_figures_agree_with_the_description_and_the_part() {
    if !have("yosys", "-V", "yosys") || !have("nextpnr-ice40", "--version", "nextpnr-ice40") {
        return;
    }
    let bits = 8;
    let lobe = HwLobe::CosQuad;
    let registers = lobe
        .build(bits)
        .expect("valid width")
        .resources()
        .register_bits;
    let hx8k = synthesize(lobe, bits, Target::Ice40(Ice40Device::Hx8k), None).expect("flow");
    let up5k = synthesize(lobe, bits, Target::Ice40(Ice40Device::Up5k), None).expect("flow");
    // The HX8K has no multiplier blocks; the UP5K's take at most one per multiplication.
    assert_eq!(hx8k.cells.dsp, 0);
    assert!(
        (1..=multiplications(lobe, bits)).contains(&up5k.cells.dsp),
        "{up5k:?}"
    );
    // Multipliers moved into blocks leave fewer LUTs.
    assert!(up5k.cells.logic < hx8k.cells.logic, "{up5k:?} {hx8k:?}");
    for result in [&hx8k, &up5k] {
        // Synthesis may merge or drop constant register bits, never add any.
        assert!(
            (1..=registers).contains(&result.cells.flip_flops),
            "{} of {registers} register bits",
            result.cells.flip_flops
        );
        // Each LUT and each flip-flop needs a logic cell of its own or shares one.
        let placed = result.logic_cells_placed.expect("placed");
        assert!(
            placed >= result.cells.logic.max(result.cells.flip_flops),
            "{result:?}"
        );
        // An iCE40's fabric runs at tens to a few hundred MHz.
        let fmax = result.fmax_mhz.expect("timed");
        assert!((10.0..=600.0).contains(&fmax), "{fmax} MHz");
        assert!(result.tools.yosys.starts_with("Yosys"));
        assert!(result
            .tools
            .nextpnr
            .as_deref()
            .is_some_and(|v| v.contains("nextpnr")));
    }
}

#[test]
fn xilinx_and_generic_counts_and_the_cache() {
    if !have("yosys", "-V", "yosys") {
        return;
    }
    let bits = 8;
    let lobe = HwLobe::Pow;
    let xilinx = synthesize(lobe, bits, Target::Xilinx, None).expect("flow");
    assert!(xilinx.cells.logic > 0 && xilinx.fmax_mhz.is_none() && xilinx.fmax_note.is_some());
    assert!(xilinx.cells.dsp <= multiplications(lobe, bits));
    let directory = tempfile::tempdir().expect("temporary directory");
    let cache = Cache::new(directory.path());
    let first = synthesize(lobe, bits, Target::Generic, Some(&cache)).expect("flow");
    // One result stored (beside it the design's lock file, `Cache::hold`).
    let results = std::fs::read_dir(directory.path())
        .expect("cache written")
        .filter(|entry| {
            entry
                .as_ref()
                .is_ok_and(|e| e.path().extension().is_some_and(|x| x == "json"))
        })
        .count();
    assert_eq!(results, 1);
    // Gates outnumber the LUTs that absorb several of them.
    assert!(
        first.cells.logic > xilinx.cells.logic,
        "{first:?} {xilinx:?}"
    );
    assert_eq!(
        synthesize(lobe, bits, Target::Generic, Some(&cache)).expect("cached"),
        first
    );
}
