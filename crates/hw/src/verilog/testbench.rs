//! Self-checking testbenches: vectors from the bit-accurate model, driven one per clock into
//! the module, every output compared bit for bit; a failure ends with `$fatal`.

use core::fmt::Write as _;

use super::Form;
use crate::datapath::Datapath;
use crate::lobes::HwLobe;

/// Word lengths up to this get exhaustive testbenches by default.
pub const EXHAUSTIVE_BITS: u32 = 16;
/// Vectors of a wider datapath's default testbench.
pub const SAMPLED_VECTORS: usize = 10_000;

/// The default testbench vectors: every input word at exponent `n` when `bits` is at most
/// [`EXHAUSTIVE_BITS`], else [`SAMPLED_VECTORS`] of [`test_vectors`].
#[must_use]
pub fn default_vectors(
    lobe: HwLobe,
    datapath: &Datapath,
    bits: u32,
    n: u32,
) -> Vec<(Vec<i64>, i64)> {
    if bits <= EXHAUSTIVE_BITS {
        exhaustive_vectors(lobe, datapath, bits, n)
    } else {
        test_vectors(lobe, datapath, bits, SAMPLED_VECTORS)
    }
}

/// Every value of the input word (`t`, or `g` for the angle datapaths) at exponent `n`.
#[must_use]
pub fn exhaustive_vectors(
    lobe: HwLobe,
    datapath: &Datapath,
    bits: u32,
    n: u32,
) -> Vec<(Vec<i64>, i64)> {
    let material = lobe.material_inputs(bits, n);
    (0..1_i64 << bits)
        .map(|raw| {
            let inputs: Vec<i64> = core::iter::once(raw)
                .chain(material.iter().copied())
                .collect();
            let expected = datapath.eval(&inputs);
            (inputs, expected)
        })
        .collect()
}

/// `count` test vectors `(inputs, expected output)` for `lobe` at `bits`, from the model.
///
/// Each vector draws its own integer `n` in `[1, 1000]` and a cosine where the lobe lives: `y =
/// n log2 t` over `[-1.8, 0]` for three vectors in four (the epicentre is `y >= -1`), over
/// `[-12, -1.8]` (the outer bloom, `y >= -8`, and the tail) for the fourth, so few vectors
/// expect the 0 that the lobes' cut-offs and the tail give. The first
/// vectors are the edge cases: `t = 0`, `t = 1`, the largest input word, and each zone's
/// boundary.
#[must_use]
pub fn test_vectors(
    lobe: HwLobe,
    datapath: &Datapath,
    bits: u32,
    count: usize,
) -> Vec<(Vec<i64>, i64)> {
    let to_input = |t: f64| {
        if lobe.takes_angle() {
            t.clamp(0.0, 1.0).acos()
        } else {
            t
        }
    };
    let vector = |x: f64, n: u32| {
        let inputs = lobe.inputs(bits, x, n);
        let expected = datapath.eval(&inputs);
        (inputs, expected)
    };
    let mut vectors = vec![
        vector(to_input(0.0), 64),
        vector(to_input(1.0), 64),
        // The largest input word: 2 saturates into the input's UQ1.(W-1) format.
        vector(2.0, 64),
        vector(to_input((-1.0_f64 / 64.0).exp2()), 64),
        vector(to_input((-8.0_f64 / 64.0).exp2()), 64),
    ];
    vectors.truncate(count);
    vectors.extend((vectors.len()..count).map(|i| {
        let n = 1 + (i as u32 * 7919) % 1000;
        // Weyl sequence: three vectors in four over y in [-1.8, 0] (the epicentre and the
        // inner bloom, where every lobe is alive), the fourth over [-12, -1.8].
        let u = (i as f64 * 0.618_033_988_749_895).fract();
        let y = if i % 4 == 3 {
            -1.8 - 10.2 * u
        } else {
            -1.8 * u
        };
        vector(to_input((y / f64::from(n)).exp2()), n)
    }));
    vectors
}

/// A self-checking testbench for the module of `datapath` over `vectors`.
#[must_use]
pub fn testbench(datapath: &Datapath, vectors: &[(Vec<i64>, i64)]) -> String {
    testbench_in(datapath, vectors, Form::Pipelined)
}

/// The self-checking testbench for the module of `datapath` in `form`. A combinational
/// module's output is read in the same step its inputs are set (a latency of one step).
#[must_use]
pub fn testbench_in(datapath: &Datapath, vectors: &[(Vec<i64>, i64)], form: Form) -> String {
    let latency = match form {
        Form::Pipelined => datapath.resources().latency,
        Form::Combinational => 1,
    };
    let output = datapath.node(datapath.output()).format;
    let inputs = datapath.input_ports();
    let name = &form.module_name(datapath);
    let count = vectors.len();
    let mut v = String::new();
    let _ = writeln!(
        v,
        "// Self-checking testbench for {name}: vectors and expected outputs from \
        specula_hw::Datapath::eval.\n`timescale 1ns/1ps\n`default_nettype none\n/* verilator \
        lint_off DECLFILENAME */\nmodule {name}_tb;\n    localparam integer COUNT = {count};\n    \
        localparam integer LATENCY = {latency};"
    );
    // The combinational form has no clock: the same 10 ns steps pace its vectors.
    let (rise, fall) = match form {
        Form::Pipelined => {
            let _ = writeln!(v, "    reg clk = 1'b0;");
            ("#5 clk = 1'b1;", "#4 clk = 1'b0;")
        }
        Form::Combinational => ("#5;", "#4;"),
    };
    for (input, width) in &inputs {
        let _ = writeln!(
            v,
            "    reg [{}:0] {input};  // x until the first vector: its assignment is an event\n    \
                reg [{}:0] vector_{input} [0:COUNT-1];",
            width - 1,
            width - 1
        );
    }
    let _ = writeln!(
        v,
        "    reg [{}:0] expected [0:COUNT-1];\n    wire [{}:0] value;",
        output.width() - 1,
        output.width() - 1
    );
    let ports: Vec<String> = inputs
        .iter()
        .map(|(input, _)| format!(".{input}({input})"))
        .collect();
    let clock = if form == Form::Pipelined {
        ".clk(clk), "
    } else {
        ""
    };
    let _ = writeln!(
        v,
        "    {name} dut ({clock}{}, .value(value));",
        ports.join(", ")
    );
    let _ = writeln!(v, "    integer i, j, errors;\n    initial begin");
    for (k, (values, expected)) in vectors.iter().enumerate() {
        for ((input, width), &value) in inputs.iter().zip(values) {
            let _ = write!(v, "        vector_{input}[{k}] = {};", sized(value, *width));
        }
        let _ = writeln!(v, " expected[{k}] = {};", sized(*expected, output.width()));
    }
    let assign: Vec<String> = inputs
        .iter()
        .map(|(input, _)| format!("{input} = vector_{input}[i];"))
        .collect();
    let _ = writeln!(
        v,
        "        errors = 0;\n        for (i = 0; i < COUNT + LATENCY - 1; i = i + 1) \
            begin\n            if (i < COUNT) begin {} end\n            {rise}\n            \
            #1;\n            j = i + 1 - LATENCY;\n            if (j >= 0 && value !== \
            expected[j]) begin\n                errors = errors + 1;\n                if (errors \
            <= 10) $display(\"MISMATCH vector %0d: got %0d, expected %0d\", j, value, \
            expected[j]);\n            end\n            {fall}\n        end\n        if (errors != \
            0) $fatal(1, \"FAIL %0d of %0d vectors\", errors, COUNT);\n        $display(\"PASS %0d \
            vectors\", COUNT);\n        $finish;\n    end\nendmodule",
        assign.join(" ")
    );
    v
}

/// `raw` as a `width`-bit literal: its two's complement bits, so that a negative value or one
/// beyond 32 bits (an unsized decimal's width) fills its port exactly.
fn sized(raw: i64, width: u32) -> String {
    format!("{width}'d{}", i128::from(raw).rem_euclid(1_i128 << width))
}
