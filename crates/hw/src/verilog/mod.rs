//! Verilog from a datapath description: a pipelined module and a self-checking testbench.
//!
//! Every registered node becomes `r_<name>`, loaded each clock from its exact result passed
//! through `specula_resize` (the rounding and saturation of [`Format::resize`], written once
//! as a parameterised module). Exact results are computed in 64-bit signed intermediates, a
//! width the emitter checks each node's exact result fits; synthesis trims the bits that are
//! constant. Operands that arrive from earlier stages are read from delay registers
//! `r_<name>_d<k>`, so that one input set enters and one result leaves every clock, with a
//! latency of [`Resources::latency`](crate::Resources) cycles.
//!
//! The testbench holds input vectors and the outputs [`Datapath::eval`] gives for them,
//! drives one vector per clock, and prints `PASS <count> vectors` only if every output is
//! bit-identical.

use core::fmt::Write as _;

use crate::datapath::{Datapath, NodeId, Op};
use crate::fixed::Format;
use crate::lobes::HwLobe;
use crate::log2::Log2Unit;

mod testbench;

pub use testbench::{
    default_vectors, exhaustive_vectors, test_vectors, testbench, testbench_in, EXHAUSTIVE_BITS,
    SAMPLED_VECTORS,
};

/// Bits of the intermediates the Verilog computes exact results in (signed).
const EXACT_BITS: u32 = 64;

const RESIZE_MODULE: &str = r#"`ifndef SPECULA_RESIZE
`define SPECULA_RESIZE
// Rounds x (an exact value with SHIFT more fraction bits than the result) by dropping SHIFT
// bits, to nearest with ties to even or towards minus infinity, or appends -SHIFT zero bits;
// then saturates to [MIN, MAX] and keeps the low WIDTH bits (the result's format: every
// value in [MIN, MAX] fits). The Rust model's Format::resize, bit for bit.
module specula_resize #(
    parameter integer SHIFT = 0,
    parameter integer ROUND_HALF_EVEN = 1,
    parameter signed [63:0] MIN = 0,
    parameter signed [63:0] MAX = 0,
    parameter integer WIDTH = 64
) (
    input wire signed [63:0] x,
    output wire [WIDTH-1:0] y
);
    wire signed [63:0] rounded;
    generate
        if (SHIFT > 0) begin : drop
            wire signed [63:0] floor_x = x >>> SHIFT;
            wire signed [63:0] remainder = x - (floor_x <<< SHIFT);
            wire signed [63:0] half = 64'sd1 <<< (SHIFT - 1);
            wire up = (ROUND_HALF_EVEN != 0)
                && ((remainder > half) || ((remainder == half) && floor_x[0]));
            assign rounded = floor_x + (up ? 64'sd1 : 64'sd0);
        end else begin : widen
            assign rounded = x <<< (-SHIFT);
        end
    endgenerate
    // Above WIDTH the saturated value only repeats its sign: those bits are dropped.
    /* verilator lint_off UNUSEDSIGNAL */
    wire signed [63:0] saturated = (rounded < MIN) ? MIN : ((rounded > MAX) ? MAX : rounded);
    /* verilator lint_on UNUSEDSIGNAL */
    assign y = saturated[WIDTH-1:0];
endmodule
`endif
"#;

/// A signed 64-bit literal.
fn literal(value: i128) -> String {
    if value < 0 {
        format!("(-64'sd{})", -value)
    } else {
        format!("64'sd{value}")
    }
}

struct Emitter<'a> {
    datapath: &'a Datapath,
    stages: Vec<u32>,
}

impl Emitter<'_> {
    fn reg(&self, id: NodeId) -> String {
        format!("r_{}", self.datapath.node(id).name)
    }

    /// The register (or delayed copy) holding `operand` when the registered node `reader`
    /// reads it.
    fn operand_reg(&self, reader: NodeId, operand: NodeId) -> String {
        let source = self.datapath.wired_source(operand);
        let delay = self.stages[reader.0] - 1 - self.stages[source.0];
        if delay == 0 {
            self.reg(source)
        } else {
            format!("{}_d{delay}", self.reg(source))
        }
    }

    /// Operand `operand` of the registered node `reader`: its 64-bit signed value (raw in
    /// the operand's own format) and that format.
    fn operand(&self, reader: NodeId, operand: NodeId) -> (String, Format) {
        let format = self.datapath.node(operand).format;
        let source = self.datapath.wired_source(operand);
        if let Op::Const(raw) = self.datapath.node(source).op {
            return (literal(i128::from(raw)), format);
        }
        let name = self.operand_reg(reader, operand);
        let width = format.width();
        let fill = if format.signed {
            format!("{{{}{{{name}[{}]}}}}", EXACT_BITS - width, width - 1)
        } else {
            format!("{}'d0", EXACT_BITS - width)
        };
        (format!("$signed({{{fill}, {name}}})"), format)
    }

    /// The exact result of `id` as a Verilog expression (or the name of a wire the caller
    /// declares in `prelude`), its fraction bits, and its magnitude bound in bits.
    fn exact(&self, id: NodeId, prelude: &mut String) -> (String, u32, u32) {
        let node = self.datapath.node(id);
        let out = node.format;
        let aligned = |(expr, format): (String, Format), frac: u32| {
            let shift = frac - format.frac_bits;
            (format!("({expr} <<< {shift})"), format.width() + shift)
        };
        match &node.op {
            Op::Add(a, b) | Op::Sub(a, b) | Op::Min(a, b) => {
                let (a, b) = (self.operand(id, *a), self.operand(id, *b));
                let frac = a.1.frac_bits.max(b.1.frac_bits);
                let ((ea, wa), (eb, wb)) = (aligned(a, frac), aligned(b, frac));
                let bits = wa.max(wb) + 1;
                let expr = match node.op {
                    Op::Add(..) => format!("{ea} + {eb}"),
                    Op::Sub(..) => format!("{ea} - {eb}"),
                    _ => format!("(({ea} < {eb}) ? {ea} : {eb})"),
                };
                (expr, frac, bits)
            }
            Op::Mul(a, b) => {
                let (a, b) = (self.operand(id, *a), self.operand(id, *b));
                let bits = a.1.width() + b.1.width();
                (
                    format!("{} * {}", a.0, b.0),
                    a.1.frac_bits + b.1.frac_bits,
                    bits,
                )
            }
            Op::Square(a) => {
                let a = self.operand(id, *a);
                (
                    format!("{} * {}", a.0, a.0),
                    2 * a.1.frac_bits,
                    2 * a.1.width(),
                )
            }
            Op::Div(a, b) => {
                let (a, b) = (self.operand(id, *a), self.operand(id, *b));
                let shift =
                    i64::from(out.frac_bits) + i64::from(b.1.frac_bits) - i64::from(a.1.frac_bits);
                let (numerator, denominator, bits) = if shift >= 0 {
                    (
                        format!("({} <<< {shift})", a.0),
                        b.0.clone(),
                        a.1.width() + shift as u32,
                    )
                } else {
                    (
                        a.0.clone(),
                        format!("({} <<< {})", b.0, -shift),
                        b.1.width() - shift as u32,
                    )
                };
                let expr = format!(
                    "(({} == 64'sd0) ? 64'sd0 : {numerator} / {denominator})",
                    b.0
                );
                (expr, out.frac_bits, bits)
            }
            Op::NonZero(a) => {
                let (a, _) = self.operand(id, *a);
                (format!("(({a} != 64'sd0) ? 64'sd1 : 64'sd0)"), 0, 2)
            }
            Op::Log2(a, unit) => {
                let input = self.datapath.node(*a).format;
                let frac = unit.frac_bits(input, out.frac_bits);
                let operand = self.operand_reg(id, *a);
                let wire = format!("{}_log2", self.reg(id));
                let _ = writeln!(
                    prelude,
                    "    wire signed [63:0] {wire};\n    {}_{}_log2 {wire}_unit (.x({operand}), .y({wire}));",
                    self.datapath.name, node.name
                );
                (wire, frac, EXACT_BITS - 1)
            }
            Op::Rom { index, table } => {
                let index = self.operand_reg(id, *index);
                let wire = format!("{}_rom", self.reg(id));
                let _ = writeln!(
                    prelude,
                    "    reg signed [63:0] {wire};\n    always @* begin\n        case ({index})"
                );
                for (address, value) in table.iter().enumerate() {
                    let _ = writeln!(
                        prelude,
                        "            {address}: {wire} = {};",
                        literal(i128::from(*value))
                    );
                }
                let last = literal(i128::from(table[table.len() - 1]));
                let _ = writeln!(
                    prelude,
                    "            default: {wire} = {last};\n        endcase\n    end"
                );
                (wire, out.frac_bits, out.width())
            }
            Op::Select { index, options } => {
                let index = self.operand_reg(id, *index);
                let values: Vec<(String, Format)> = options
                    .iter()
                    .map(|option| self.operand(id, *option))
                    .collect();
                let frac = values.iter().map(|v| v.1.frac_bits).max().unwrap_or(0);
                let wire = format!("{}_select", self.reg(id));
                let _ = writeln!(
                    prelude,
                    "    reg signed [63:0] {wire};\n    always @* begin\n        case ({index})"
                );
                let mut bits = 0;
                let count = values.len();
                for (k, value) in values.into_iter().enumerate() {
                    let (expr, width) = aligned(value, frac);
                    bits = bits.max(width);
                    let label = if k + 1 == count {
                        "default".to_owned()
                    } else {
                        k.to_string()
                    };
                    let _ = writeln!(prelude, "            {label}: {wire} = {expr};");
                }
                let _ = writeln!(prelude, "        endcase\n    end");
                (wire, frac, bits)
            }
            Op::Input | Op::Const(_) | Op::Shift(..) => unreachable!("not a registered operation"),
        }
    }
}

/// The log2 unit of node `id` as its own module.
fn log2_module(datapath: &Datapath, id: NodeId, unit: Log2Unit, input: Format) -> String {
    let node = datapath.node(id);
    let out = node.format;
    let width = input.width();
    let mantissa = width - 1;
    let frac = unit.frac_bits(input, out.frac_bits);
    let (zero, _) = unit.eval(0, input, out.frac_bits, out);
    let mut v = String::new();
    let _ = writeln!(
        v,
        "// log2 of a {} input, {} unit: exact result with {frac} fraction bits.",
        input.name(),
        unit.name()
    );
    let _ = writeln!(
        v,
        "module {}_{}_log2 (\n    input wire [{}:0] x,\n    output reg signed [63:0] y\n);",
        datapath.name,
        node.name,
        width - 1
    );
    let _ = writeln!(
        v,
        "    integer i;\n    reg [6:0] p;\n    reg [{}:0] f;\n    reg signed [63:0] e;\n    // x shifted so its leading one is the top bit, which f then drops.\n    /* verilator lint_off UNUSEDSIGNAL */\n    reg [{}:0] normalised;\n    /* verilator lint_on UNUSEDSIGNAL */",
        mantissa - 1,
        width - 1
    );
    if let Log2Unit::Table { segments_log2: k } = unit {
        assert!(mantissa >= k, "the table index needs {k} mantissa bits");
        let table = unit.table(frac);
        let _ = writeln!(
            v,
            "    reg [{k}:0] index;\n    reg signed [63:0] low, high, fraction;"
        );
        let _ = writeln!(
            v,
            "    function signed [63:0] entry(input [{k}:0] at);\n        case (at)"
        );
        for (i, value) in table.iter().enumerate() {
            let _ = writeln!(
                v,
                "            {i}: entry = {};",
                literal(i128::from(*value))
            );
        }
        let _ = writeln!(
            v,
            "            default: entry = {};\n        endcase\n    endfunction",
            literal(i128::from(table[table.len() - 1]))
        );
    }
    let _ = writeln!(v, "    always @* begin\n        p = 7'd0;");
    if matches!(unit, Log2Unit::Table { .. }) {
        // Assigned on every path, so the block stays combinational (no latch for x = 0).
        let _ = writeln!(
            v,
            "        index = 0;\n        low = 64'sd0;\n        high = 64'sd0;\n        fraction = 64'sd0;"
        );
    }
    let _ = writeln!(
        v,
        "        for (i = 0; i < {width}; i = i + 1)\n            if (x[i]) p = i[6:0];"
    );
    let _ = writeln!(
        v,
        "        normalised = x << ({mantissa} - p);\n        f = normalised[{}:0];\n        e = $signed({{57'd0, p}}) - {};",
        mantissa - 1,
        input.frac_bits
    );
    let _ = writeln!(
        v,
        "        if (x == 0) begin\n            y = {};\n        end else begin",
        literal(zero)
    );
    match unit {
        Log2Unit::Mitchell => {
            let _ = writeln!(
                v,
                "            y = (e <<< {mantissa}) + $signed({{{}'d0, f}});",
                EXACT_BITS - mantissa
            );
        }
        Log2Unit::Table { segments_log2: k } => {
            let rest = mantissa - k;
            let _ = writeln!(
                v,
                "            index = {{1'b0, f[{}:{rest}]}};",
                mantissa - 1
            );
            let _ = writeln!(
                v,
                "            low = entry(index);\n            high = entry(index + 1);"
            );
            if rest > 0 {
                let _ = writeln!(
                    v,
                    "            fraction = $signed({{{}'d0, f[{}:0]}});",
                    EXACT_BITS - rest,
                    rest - 1
                );
            } else {
                let _ = writeln!(v, "            fraction = 64'sd0;");
            }
            let _ = writeln!(
                v,
                "            y = (e <<< {frac}) + low + (((high - low) * fraction) >>> {rest});"
            );
        }
    }
    let _ = writeln!(v, "        end\n    end\nendmodule\n");
    v
}

/// How a datapath is laid out in Verilog.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Form {
    /// Every stage registered: one result per clock, after the datapath's latency.
    Pipelined,
    /// No register at all: the output follows the inputs within one clock period (module
    /// `<name>_comb`, no clock port), for a design that registers around it.
    Combinational,
}

impl Form {
    /// The module's name for `datapath`.
    #[must_use]
    pub fn module_name(self, datapath: &Datapath) -> String {
        match self {
            Form::Pipelined => datapath.name.clone(),
            Form::Combinational => format!("{}_comb", datapath.name),
        }
    }

    /// `target` becoming `source`: a register loaded on the clock, or a wire.
    fn stage(self, v: &mut String, width: u32, target: &str, source: &str) {
        let _ = match self {
            Form::Pipelined => writeln!(
                v,
                "    reg [{}:0] {target};\n    always @(posedge clk) {target} <= {source};",
                width - 1
            ),
            Form::Combinational => {
                writeln!(v, "    wire [{}:0] {target} = {source};", width - 1)
            }
        };
    }
}

/// The pipelined module for `datapath`.
#[must_use]
pub fn module(datapath: &Datapath, lobe: HwLobe, bits: u32) -> String {
    module_in(datapath, lobe, bits, Form::Pipelined)
}

/// The module for `datapath` in `form`.
///
/// # Panics
/// If a node's exact result could exceed the 64-bit intermediates (a construction mistake in
/// the datapath, caught by the tests over every lobe and width).
#[must_use]
pub fn module_in(datapath: &Datapath, lobe: HwLobe, bits: u32, form: Form) -> String {
    let emitter = Emitter {
        datapath,
        stages: datapath.stages(),
    };
    let delays = datapath.delays();
    let resources = datapath.resources();
    let mut v = String::new();
    let _ = writeln!(
        v,
        "// Generated by specula-hw from the `{}` datapath description, W = {bits}.\n// Bit-exact with specula_hw::Datapath::eval; {}.\n`timescale 1ns/1ps\n`default_nettype none\n// The file holds several modules and its name is the user's choice.\n/* verilator lint_off DECLFILENAME */\n",
        lobe.id(),
        match form {
            Form::Pipelined => format!(
                "latency {} cycles, one result per cycle",
                resources.latency
            ),
            Form::Combinational => "combinational, no register".to_owned(),
        }
    );
    v.push_str(RESIZE_MODULE);
    v.push('\n');
    for (k, node) in datapath.nodes().iter().enumerate() {
        if let Op::Log2(a, unit) = node.op {
            v.push_str(&log2_module(
                datapath,
                NodeId(k),
                unit,
                datapath.node(a).format,
            ));
        }
    }
    let output = datapath.node(datapath.output()).format;
    let _ = writeln!(v, "module {} (", form.module_name(datapath));
    if form == Form::Pipelined {
        let _ = writeln!(v, "    input wire clk,");
    }
    for &input in datapath.inputs() {
        let node = datapath.node(input);
        let _ = writeln!(
            v,
            "    input wire [{}:0] {},  // {}",
            node.format.width() - 1,
            node.name,
            node.format.name()
        );
    }
    let _ = writeln!(
        v,
        "    output wire [{}:0] value  // {}\n);",
        output.width() - 1,
        output.name()
    );
    for (k, node) in datapath.nodes().iter().enumerate() {
        let id = NodeId(k);
        if !datapath.is_registered(id) {
            continue;
        }
        let width = node.format.width();
        let reg = emitter.reg(id);
        let _ = writeln!(
            v,
            "\n    // {} = {}: {}, stage {}",
            node.name,
            describe(datapath, &node.op),
            node.format.name(),
            emitter.stages[k]
        );
        if node.op == Op::Input {
            form.stage(&mut v, width, &reg, &node.name);
        } else {
            let mut prelude = String::new();
            let (expr, frac, exact_bits) = emitter.exact(id, &mut prelude);
            assert!(
                exact_bits < EXACT_BITS,
                "{}: exact result needs {exact_bits} bits",
                node.name
            );
            v.push_str(&prelude);
            let shift = i64::from(frac) - i64::from(node.format.frac_bits);
            let _ = writeln!(v, "    wire [{}:0] {reg}_next;", width - 1);
            let _ = writeln!(
                v,
                "    specula_resize #(.SHIFT({shift}), .ROUND_HALF_EVEN({}), .MIN({}), .MAX({}), .WIDTH({width})) {reg}_resize (\n        .x({expr}),\n        .y({reg}_next)\n    );",
                i32::from(node.rounding == crate::fixed::Rounding::HalfEven),
                literal(i128::from(node.format.min_raw())),
                literal(i128::from(node.format.max_raw()))
            );
            form.stage(&mut v, width, &reg, &format!("{reg}_next"));
        }
        let mut previous = reg.clone();
        for d in 1..=delays[k] {
            let delayed = format!("{reg}_d{d}");
            form.stage(&mut v, width, &delayed, &previous);
            previous = delayed;
        }
    }
    let source = datapath.wired_source(datapath.output());
    let _ = writeln!(
        v,
        "\n    assign value = {};\nendmodule",
        emitter.reg(source)
    );
    v
}

/// The node's operation in words, for comments and diagrams.
#[must_use]
pub fn describe(datapath: &Datapath, op: &Op) -> String {
    let name = |id: &NodeId| datapath.node(*id).name.clone();
    match op {
        Op::Input => "input".to_owned(),
        Op::Const(raw) => format!("constant {raw}"),
        Op::Add(a, b) => format!("{} + {}", name(a), name(b)),
        Op::Sub(a, b) => format!("{} - {}", name(a), name(b)),
        Op::Mul(a, b) => format!("{} * {}", name(a), name(b)),
        Op::Square(a) => format!("{}^2", name(a)),
        Op::Div(a, b) => format!("{} / {}", name(a), name(b)),
        Op::Shift(a, s) => format!("{} * 2^{s}", name(a)),
        Op::Log2(a, unit) => format!("log2 {} ({})", name(a), unit.name()),
        Op::Min(a, b) => format!("min({}, {})", name(a), name(b)),
        Op::NonZero(a) => format!("{} != 0", name(a)),
        Op::Rom { index, table } => format!("ROM[{}] ({} words)", name(index), table.len()),
        Op::Select { index, options } => format!(
            "select by {} of {}",
            name(index),
            options.iter().map(name).collect::<Vec<_>>().join(", ")
        ),
    }
}
