//! The emitted Verilog uses no SystemVerilog keyword as an identifier, so it compiles as
//! Verilog-2005 and as SystemVerilog alike (a tool-free check; `cosim.rs` compiles both).

use specula_hw::{verilog, HwLobe};

/// IEEE 1800-2017's reserved words that Verilog-2005 (IEEE 1364) does not reserve.
const SYSTEMVERILOG_ONLY: &[&str] = &[
    "accept_on",
    "alias",
    "always_comb",
    "always_ff",
    "always_latch",
    "assert",
    "assume",
    "before",
    "bind",
    "bins",
    "binsof",
    "bit",
    "break",
    "byte",
    "chandle",
    "checker",
    "class",
    "clocking",
    "const",
    "constraint",
    "context",
    "continue",
    "cover",
    "covergroup",
    "coverpoint",
    "cross",
    "dist",
    "do",
    "endchecker",
    "endclass",
    "endclocking",
    "endgroup",
    "endinterface",
    "endpackage",
    "endprogram",
    "endproperty",
    "endsequence",
    "enum",
    "eventually",
    "expect",
    "export",
    "extends",
    "extern",
    "final",
    "first_match",
    "foreach",
    "forkjoin",
    "global",
    "iff",
    "ignore_bins",
    "illegal_bins",
    "implements",
    "implies",
    "import",
    "inside",
    "int",
    "interconnect",
    "interface",
    "intersect",
    "join_any",
    "join_none",
    "let",
    "local",
    "logic",
    "longint",
    "matches",
    "modport",
    "nettype",
    "new",
    "nexttime",
    "null",
    "package",
    "packed",
    "priority",
    "program",
    "property",
    "protected",
    "pure",
    "rand",
    "randc",
    "randcase",
    "randsequence",
    "ref",
    "reject_on",
    "restrict",
    "return",
    "s_always",
    "s_eventually",
    "s_nexttime",
    "s_until",
    "s_until_with",
    "sequence",
    "shortint",
    "shortreal",
    "soft",
    "solve",
    "static",
    "string",
    "strong",
    "struct",
    "super",
    "sync_accept_on",
    "sync_reject_on",
    "tagged",
    "this",
    "throughout",
    "timeprecision",
    "timeunit",
    "type",
    "typedef",
    "union",
    "unique",
    "unique0",
    "until",
    "until_with",
    "untyped",
    "var",
    "virtual",
    "void",
    "wait_order",
    "weak",
    "wildcard",
    "with",
    "within",
];

/// Identifier-like tokens outside comments and strings.
fn identifiers(text: &str) -> Vec<String> {
    let mut tokens = Vec::new();
    for line in text.lines() {
        let code = line.split("//").next().unwrap_or_default();
        let mut in_string = false;
        let mut current = String::new();
        for c in code.chars() {
            if c == '"' {
                in_string = !in_string;
            }
            if !in_string && (c.is_ascii_alphanumeric() || c == '_' || c == '$') {
                current.push(c);
            } else if !current.is_empty() {
                tokens.push(std::mem::take(&mut current));
            }
        }
        if !current.is_empty() {
            tokens.push(current);
        }
    }
    tokens
}

#[test]
fn no_systemverilog_keyword_is_an_identifier() {
    // The check itself can fail: the old log2 unit's interpolation variable.
    assert!(identifiers("    reg signed [63:0] low, high, within;")
        .iter()
        .any(|t| SYSTEMVERILOG_ONLY.contains(&t.as_str())));
    for lobe in HwLobe::ALL {
        for bits in [8, 12, 16, 24] {
            let datapath = lobe.build(bits).expect("valid width");
            let vectors = verilog::test_vectors(lobe, &datapath, bits, 20);
            for text in [
                verilog::module(&datapath, lobe, bits),
                verilog::testbench(&datapath, &vectors),
            ] {
                for token in identifiers(&text) {
                    assert!(
                        !SYSTEMVERILOG_ONLY.contains(&token.as_str()),
                        "{} at {bits} bits uses the SystemVerilog keyword '{token}'",
                        lobe.id()
                    );
                }
            }
        }
    }
}

/// The testbench's vectors cover the lobe, not its tail: at most 30 % expect 0, and the edge
/// cases (t = 0, the peak, the largest input word) come first.
#[test]
fn test_vectors_cover_the_lobe() {
    for lobe in HwLobe::ALL {
        for bits in [12, 16, 20] {
            let datapath = lobe.build(bits).expect("valid width");
            let vectors = verilog::test_vectors(lobe, &datapath, bits, 2000);
            assert_eq!(vectors.len(), 2000);
            let zeros = vectors.iter().filter(|(_, out)| *out == 0).count();
            assert!(
                zeros * 10 <= vectors.len() * 3,
                "{} at {bits} bits: {zeros} of {} vectors expect 0",
                lobe.id(),
                vectors.len()
            );
            let first_inputs: Vec<i64> = vectors[..3].iter().map(|(i, _)| i[0]).collect();
            let top = (1_i64 << bits) - 1;
            assert!(
                first_inputs.contains(&top),
                "{}: no largest input",
                lobe.id()
            );
        }
    }
}

/// Up to 16 bits the default testbench visits every input word once; above, 10,000 vectors.
#[test]
fn default_testbenches_are_exhaustive_up_to_sixteen_bits() {
    for lobe in HwLobe::ALL {
        let datapath = lobe.build(12).expect("valid width");
        let vectors = verilog::default_vectors(lobe, &datapath, 12, 64);
        let mut words: Vec<i64> = vectors.iter().map(|(inputs, _)| inputs[0]).collect();
        words.sort_unstable();
        assert_eq!(words, (0..1 << 12).collect::<Vec<i64>>(), "{}", lobe.id());
        let wide = lobe.build(20).expect("valid width");
        assert_eq!(
            verilog::default_vectors(lobe, &wide, 20, 64).len(),
            verilog::SAMPLED_VECTORS
        );
    }
}
