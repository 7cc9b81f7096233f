//! `specula hw`: tables, Verilog and diagrams from the command line, and its refusals.

use crate::common::{have_tool, ok, specula};

/// A command line's words.
fn words(line: &str) -> Vec<&str> {
    line.split_whitespace().collect()
}

#[test]
fn table_json_has_a_row_per_width_and_resources() {
    let directory = tempfile::tempdir().expect("temporary directory");
    let output = ok(
        directory.path(),
        &words("hw table --lobe cosquad,schlick --bits 10..12 --n 64 --samples 500 --format json"),
    );
    let sweeps: serde_json::Value = serde_json::from_slice(&output.stdout).expect("JSON");
    let sweeps = sweeps.as_array().expect("array");
    assert_eq!(sweeps.len(), 2);
    for sweep in sweeps {
        let rows = sweep["rows"].as_array().expect("rows");
        let bits: Vec<u64> = rows
            .iter()
            .map(|row| row["bits"].as_u64().expect("bits"))
            .collect();
        assert_eq!(bits, [10, 11, 12]);
        for row in rows {
            assert!(row["errors"]["epicentre_max_rel"].as_f64().expect("figure") > 0.0);
            assert!(row["resources"]["latency"].as_u64().expect("latency") >= 2);
        }
        assert!(sweep["float"]["epicentre_max_rel"].as_f64().is_some());
    }
}

#[test]
fn table_text_names_the_minimum_width() {
    let directory = tempfile::tempdir().expect("temporary directory");
    let output = ok(
        directory.path(),
        &words("hw table --lobe schlick --bits 8..24 --samples 500"),
    );
    let text = String::from_utf8_lossy(&output.stdout);
    assert!(
        text.contains("schlick") && text.contains("meets it from"),
        "{text}"
    );
}

#[test]
fn verilog_and_diagram_are_written_whole() {
    let directory = tempfile::tempdir().expect("temporary directory");
    ok(
        directory.path(),
        &words(
            "hw verilog --lobe logexp --bits 14 -o logexp.v --testbench logexp_tb.v --vectors 64",
        ),
    );
    let module = std::fs::read_to_string(directory.path().join("logexp.v")).expect("module");
    assert!(
        module.contains("module specula_logexp_w14 (") && module.trim_end().ends_with("endmodule")
    );
    let bench = std::fs::read_to_string(directory.path().join("logexp_tb.v")).expect("testbench");
    assert!(bench.contains("localparam integer COUNT = 64;"));
    ok(
        directory.path(),
        &words("hw diagram --lobe cheb2 -o cheb2.svg"),
    );
    let svg = std::fs::read_to_string(directory.path().join("cheb2.svg")).expect("diagram");
    let document = roxmltree::Document::parse(&svg).expect("well-formed SVG");
    let labels: Vec<&str> = document
        .descendants()
        .filter_map(|n| n.text())
        .map(str::trim)
        .collect();
    for node in ["rom_a", "inner_g", "value"] {
        assert!(labels.contains(&node), "{node} missing from {labels:?}");
    }
}

#[test]
fn bad_requests_name_the_problem_and_write_nothing() {
    let directory = tempfile::tempdir().expect("temporary directory");
    let cases: [(&[&str], &str); 5] = [
        (
            &[
                "hw", "verilog", "--lobe", "sg-karis", "--bits", "16", "-o", "x.v",
            ],
            "valid: schlick, schlick-mod, cheb2, logexp, logexp-mitchell, cosquad, pow, sg",
        ),
        (
            &[
                "hw", "verilog", "--lobe", "cosquad", "--bits", "40", "-o", "x.v",
            ],
            "valid: 8 to 24",
        ),
        (&["hw", "table", "--n", "64.5"], "integer in [1, 1000]"),
        (&["hw", "table", "--bits", "20..10"], "LOW <= HIGH"),
        (
            &[
                "hw", "diagram", "--lobe", "cosquad", "--bits", "nine", "-o", "x.svg",
            ],
            "not a word length",
        ),
    ];
    for (args, message) in cases {
        let output = specula(directory.path(), args);
        let stderr = String::from_utf8_lossy(&output.stderr);
        assert_eq!(output.status.code(), Some(2), "{args:?}");
        assert!(stderr.contains(message), "{args:?}: {stderr}");
    }
    assert_eq!(
        std::fs::read_dir(directory.path()).expect("list").count(),
        0,
        "no file written"
    );
}

/// `hw synth` reports Yosys's own cell counts with its version; a cached rerun agrees.
#[test]
fn synth_json_carries_the_tools_figures_and_versions() {
    if !have_tool("yosys", "-V", "yosys") {
        return;
    }
    let directory = tempfile::tempdir().expect("temporary directory");
    let cache = directory.path().join("cache");
    let run = || {
        let output = assert_cmd::Command::cargo_bin("specula")
            .expect("binary built")
            .env("SPECULA_CACHE_DIR", crate::common::test_cache())
            .env("SPECULA_CACHE_DIR", &cache)
            .args(words(
                "hw synth --target generic --bits 8 --lobe cosquad,sg --format json",
            ))
            .output()
            .expect("runs");
        assert!(
            output.status.success(),
            "{}",
            String::from_utf8_lossy(&output.stderr)
        );
        serde_json::from_slice::<serde_json::Value>(&output.stdout).expect("JSON")
    };
    let results = run();
    let results = results.as_array().expect("array");
    assert_eq!(results.len(), 2);
    for result in results {
        assert!(result["cells"]["logic"].as_u64().expect("gates") > 0);
        assert!(result["cells"]["flip_flops"].as_u64().expect("FFs") > 0);
        assert!(result["tools"]["yosys"]
            .as_str()
            .expect("version")
            .starts_with("Yosys"));
        assert!(result["fmax_mhz"].is_null(), "generic gates have no timing");
    }
    assert_eq!(run().as_array().expect("array"), results);
}

/// Without Yosys on the path: one line naming the package, exit 2, nothing printed.
#[test]
fn synth_without_yosys_names_the_package() {
    let directory = tempfile::tempdir().expect("temporary directory");
    let output = assert_cmd::Command::cargo_bin("specula")
        .expect("binary built")
        .env("SPECULA_CACHE_DIR", crate::common::test_cache())
        .env("PATH", directory.path())
        .args(words("hw synth --lobe cosquad --bits 8"))
        .output()
        .expect("runs");
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert_eq!(output.status.code(), Some(2), "{stderr}");
    assert!(
        stderr.contains("install the Debian package `yosys`"),
        "{stderr}"
    );
    assert_eq!(stderr.trim().lines().count(), 1, "{stderr}");
    assert!(output.stdout.is_empty());
}

#[test]
fn synth_refuses_an_unknown_target_with_the_valid_ones() {
    let directory = tempfile::tempdir().expect("temporary directory");
    let output = specula(directory.path(), &words("hw synth --target asic"));
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert_eq!(output.status.code(), Some(2));
    assert!(
        stderr.contains("generic") && stderr.contains("ice40") && stderr.contains("xilinx"),
        "{stderr}"
    );
}

/// `hw --help` names every datapath id (from the registry, so it cannot drift) and the widths.
#[test]
fn help_lists_the_datapaths_and_widths() {
    let directory = tempfile::tempdir().expect("temporary directory");
    let help = ok(directory.path(), &["hw", "--help"]);
    let help = String::from_utf8_lossy(&help.stdout);
    let listed = help
        .lines()
        .find_map(|line| line.strip_prefix("Datapaths (--lobe): "))
        .expect("a datapaths line");
    assert_eq!(listed, specula_hw::HwLobe::valid_ids());
    assert!(help.contains("8 to 24 bits"));
}
