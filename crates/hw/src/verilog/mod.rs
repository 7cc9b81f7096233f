//! Verilog from a datapath description: a pipelined module and a self-checking testbench.
//!
//! Every registered node becomes `r_<name>`, loaded each clock from its exact result passed
//! through `specula_resize` (the rounding and saturation of [`FixedPoint::resize`], written once
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
use crate::exp2::Exp2Unit;
use crate::fixed::FixedPoint;
use crate::lobes::HwLobe;
use crate::log2::Log2Unit;

mod testbench;
mod units;

pub use testbench::{
    default_vectors, exhaustive_vectors, test_vectors, testbench, testbench_in, EXHAUSTIVE_BITS,
    SAMPLED_VECTORS,
};

/// Bits of the intermediates the Verilog computes exact results in (signed).
const EXACT_BITS: u32 = 64;

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
    fn operand(&self, reader: NodeId, operand: NodeId) -> (String, FixedPoint) {
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
        let width_of = |operand: NodeId| self.datapath.node(operand).format.width();
        let fb_of = |operand: NodeId| self.datapath.node(operand).format.frac_bits;
        let aligned = |(expr, format): (String, FixedPoint), frac: u32| {
            let shift = frac - format.frac_bits;
            (format!("({expr} <<< {shift})"), format.width() + shift)
        };
        match &node.op {
            Op::Add(a, b) | Op::Sub(a, b) | Op::Min(a, b) | Op::Max(a, b) => {
                let (a, b) = (self.operand(id, *a), self.operand(id, *b));
                let frac = a.1.frac_bits.max(b.1.frac_bits);
                let ((ea, wa), (eb, wb)) = (aligned(a, frac), aligned(b, frac));
                let bits = wa.max(wb) + 1;
                let expr = match node.op {
                    Op::Add(..) => format!("{ea} + {eb}"),
                    Op::Sub(..) => format!("{ea} - {eb}"),
                    Op::Min(..) => format!("(({ea} < {eb}) ? {ea} : {eb})"),
                    _ => format!("(({ea} > {eb}) ? {ea} : {eb})"),
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
                let shift = i64::from(out.frac_bits) + i64::from(fb_of(*b)) - i64::from(fb_of(*a));
                let (dividend, divisor) = (self.operand_reg(id, *a), self.operand_reg(id, *b));
                let (wa, wb) = (width_of(*a), width_of(*b));
                // Unsigned and as wide as the operands: the divider synthesis builds is the
                // one the model describes, not a 64-bit one.
                let (low_a, low_b) = (shift.max(0) as u32, (-shift).max(0) as u32);
                let bits = (wa + low_a).max(wb + low_b);
                let widen = |name: &str, width: u32, low: u32| {
                    let mut parts = Vec::new();
                    if bits > width + low {
                        parts.push(format!("{}'d0", bits - width - low));
                    }
                    parts.push(name.to_owned());
                    if low > 0 {
                        parts.push(format!("{low}'d0"));
                    }
                    format!("{{{}}}", parts.join(", "))
                };
                let wire = self.reg(id);
                let _ = writeln!(
                    prelude,
                    "    wire [{top}:0] {wire}_dividend = {};\n    wire [{top}:0] {wire}_divisor = \
                        {};\n    wire [{top}:0] {wire}_quotient = ({wire}_divisor == {bits}'d0) ? \
                        {bits}'d0 : {wire}_dividend / {wire}_divisor;",
                    widen(&dividend, wa, low_a),
                    widen(&divisor, wb, low_b),
                    top = bits - 1
                );
                (
                    format!("$signed({{{}'d0, {wire}_quotient}})", EXACT_BITS - bits),
                    out.frac_bits,
                    bits,
                )
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
                    "    wire signed [63:0] {wire};\n    {}_{}_log2 {wire}_unit (.x({operand}), \
                        .y({wire}));",
                    self.datapath.name, node.name
                );
                (wire, frac, log2_bound(*unit, input, out))
            }
            Op::Exp2Neg(a, _) => {
                let operand = self.operand_reg(id, *a);
                let wire = format!("{}_exp2", self.reg(id));
                let _ = writeln!(
                    prelude,
                    "    wire signed [63:0] {wire};\n    {}_{}_exp2 {wire}_unit (.x({operand}), \
                        .y({wire}));",
                    self.datapath.name, node.name
                );
                // 2^-f <= 1, shifted right: below 2^(frac + 1).
                let frac = Exp2Unit::frac_bits(out.frac_bits);
                (wire, frac, frac + 1)
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
                let values: Vec<(String, FixedPoint)> = options
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

/// Bits that bound the magnitude of a log2 unit's exact result: `(e + f) 2^frac` with the
/// leading-one position `|e| <=` the input's larger part, or the saturated minimum for 0.
fn log2_bound(unit: Log2Unit, input: FixedPoint, out: FixedPoint) -> u32 {
    let frac = unit.frac_bits(input, out.frac_bits);
    let largest_exponent = input.frac_bits.max(input.int_bits) + 1;
    let normal = frac + (u32::BITS - largest_exponent.leading_zeros());
    let zero = out.width() + frac.saturating_sub(out.frac_bits);
    normal.max(zero)
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
        "// Generated by specula-hw from the `{}` datapath description, W = {bits}.\n// Bit-exact \
            with specula_hw::Datapath::eval; {}.\n`timescale 1ns/1ps\n`default_nettype none\n// \
            The file holds several modules and its name is the user's choice.\n/* verilator \
            lint_off DECLFILENAME */\n",
        lobe.id(),
        match form {
            Form::Pipelined =>
                format!("latency {} cycles, one result per cycle", resources.latency),
            Form::Combinational => "combinational, no register".to_owned(),
        }
    );
    v.push_str(units::RESIZE_MODULE);
    v.push('\n');
    for (k, node) in datapath.nodes().iter().enumerate() {
        match node.op {
            Op::Log2(a, unit) => v.push_str(&units::log2_module(
                datapath,
                NodeId(k),
                unit,
                datapath.node(a).format,
            )),
            Op::Exp2Neg(a, unit) => v.push_str(&units::exp2_module(
                datapath,
                NodeId(k),
                unit,
                datapath.node(a).format,
            )),
            _ => {}
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
            // The magnitude and a sign bit; resize rounds in 64 bits, so no carry bit is needed.
            let exact_width = exact_bits + 1;
            assert!(
                exact_width < EXACT_BITS,
                "{}: exact result needs {exact_bits} bits",
                node.name
            );
            v.push_str(&prelude);
            let shift = i64::from(frac) - i64::from(node.format.frac_bits);
            let _ = writeln!(v, "    wire [{}:0] {reg}_next;", width - 1);
            let _ = writeln!(
                v,
                "    specula_resize #(.XW({exact_width}), .SHIFT({shift}), .ROUND_HALF_EVEN({}), \
                    .MIN({}), .MAX({}), .WIDTH({width})) {reg}_resize (\n        \
                    .x({expr}),\n        .y({reg}_next)\n    );",
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
        Op::Exp2Neg(a, unit) => format!("2^-{} ({})", name(a), unit.name()),
        Op::Min(a, b) => format!("min({}, {})", name(a), name(b)),
        Op::Max(a, b) => format!("max({}, {})", name(a), name(b)),
        Op::NonZero(a) => format!("{} != 0", name(a)),
        Op::Rom { index, table } => format!("ROM[{}] ({} words)", name(index), table.len()),
        Op::Select { index, options } => format!(
            "select by {} of {}",
            name(index),
            options.iter().map(name).collect::<Vec<_>>().join(", ")
        ),
    }
}
