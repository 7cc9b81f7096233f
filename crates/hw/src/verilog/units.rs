//! The shared pieces of every emitted file: the rounding-and-saturation module and the table
//! units (log2, exp2), each its own module so that a datapath's body stays one line per node.

use core::fmt::Write as _;

use super::{literal, EXACT_BITS};
use crate::datapath::{Datapath, NodeId};
use crate::exp2::Exp2Unit;
use crate::fixed::FixedPoint;
use crate::log2::Log2Unit;

/// `specula_resize`: [`FixedPoint::resize`] in Verilog, written once and parameterised.
pub(super) const RESIZE_MODULE: &str = r#"`ifndef SPECULA_RESIZE
`define SPECULA_RESIZE
// Rounds x (an exact value with SHIFT more fraction bits than the result, whose low XW bits
// hold it as a signed number) by dropping SHIFT bits, to nearest with ties to even or towards
// minus infinity, or appends -SHIFT zero bits; then saturates to [MIN, MAX] and keeps the low
// WIDTH bits (the result's format: every value in [MIN, MAX] fits). The Rust model's
// FixedPoint::resize, bit for bit. XW tells synthesis how wide the arithmetic really is.
module specula_resize #(
    parameter integer XW = 63,
    parameter integer SHIFT = 0,
    parameter integer ROUND_HALF_EVEN = 1,
    parameter signed [63:0] MIN = 0,
    parameter signed [63:0] MAX = 0,
    parameter integer WIDTH = 64
) (
    // Only the low XW bits carry the value; above them the intermediate repeats its sign.
    /* verilator lint_off UNUSEDSIGNAL */
    input wire signed [63:0] x,
    /* verilator lint_on UNUSEDSIGNAL */
    output wire [WIDTH-1:0] y
);
    wire signed [63:0] exact = {{(64-XW){x[XW-1]}}, x[XW-1:0]};
    wire signed [63:0] rounded;
    generate
        if (SHIFT > 0) begin : drop
            localparam [63:0] HALF = 64'd1 << (SHIFT - 1);
            wire signed [63:0] floor_x = exact >>> SHIFT;
            wire [63:0] dropped = {{(64-SHIFT){1'b0}}, exact[SHIFT-1:0]};
            wire up = (ROUND_HALF_EVEN != 0)
                && ((dropped > HALF) || ((dropped == HALF) && floor_x[0]));
            assign rounded = floor_x + {63'd0, up};
        end else begin : widen
            assign rounded = exact <<< (-SHIFT);
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

/// A table unit's interpolation, as wires of their true widths (so synthesis builds the
/// multiplier the model counts): `entry(i)` holds the table, `first` and `second` are the
/// entries around the `source` fraction (`bits` wide, its top `k` bits the index), and the
/// returned expression is `|second - first|` times the rest of the fraction, shifted back:
/// the step from `first` towards `second`, `table_width` bits wide.
fn interpolation(
    v: &mut String,
    table: &[i64],
    k: u32,
    source: &str,
    bits: u32,
    rising: bool,
) -> String {
    let width = table_width(table);
    let rest = bits - k;
    assert!(rest > 0, "the fraction needs bits below the table index");
    let _ = writeln!(
        v,
        "    function [{}:0] entry(input [{k}:0] at);\n        case (at)",
        width - 1
    );
    for (i, value) in table.iter().enumerate() {
        let _ = writeln!(v, "            {i}: entry = {width}'d{value};");
    }
    let _ = writeln!(
        v,
        "            default: entry = {width}'d{};\n        endcase\n    endfunction",
        table[table.len() - 1]
    );
    let (top, product) = (bits - 1, width + rest);
    let difference = if rising {
        "second - first"
    } else {
        "first - second"
    };
    let _ = writeln!(
        v,
        "    wire [{k}:0] index = {{1'b0, {source}[{top}:{rest}]}};\n    wire [{w}:0] first = \
            entry(index);\n    wire [{w}:0] second = entry(index + 1'b1);\n    // The product's \
            low bits are the part of a step the interpolation drops.\n    /* verilator lint_off \
            UNUSEDSIGNAL */\n    wire [{p}:0] step = {{{{{rest}{{1'b0}}}}, {difference}}} * \
            {{{{{width}{{1'b0}}}}, {source}[{}:0]}};\n    /* verilator lint_on UNUSEDSIGNAL */",
        rest - 1,
        w = width - 1,
        p = product - 1,
    );
    format!("step[{}:{rest}]", product - 1)
}

/// Bits of the widest (non-negative) table entry.
fn table_width(table: &[i64]) -> u32 {
    let largest = table.iter().copied().max().unwrap_or(0).max(1);
    u64::BITS - (largest as u64).leading_zeros()
}

/// `value` (`width` unsigned bits) zero-extended to a 64-bit signed operand.
fn widened(value: &str, width: u32) -> String {
    format!("$signed({{{}'d0, {value}}})", EXACT_BITS - width)
}

/// The log2 unit of node `id` as its own module.
pub(super) fn log2_module(
    datapath: &Datapath,
    id: NodeId,
    unit: Log2Unit,
    input: FixedPoint,
) -> String {
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
        "    integer i;\n    reg [6:0] p;\n    reg [{}:0] f;\n    reg signed [63:0] e;\n    // x \
            shifted so its leading one is the top bit, which f then drops.\n    /* verilator \
            lint_off UNUSEDSIGNAL */\n    reg [{}:0] normalised;\n    /* verilator lint_on \
            UNUSEDSIGNAL */",
        mantissa - 1,
        width - 1
    );
    let _ = writeln!(
        v,
        "    always @* begin\n        p = 7'd0;\n        for (i = 0; i < {width}; i = i + \
            1)\n            if (x[i]) p = i[6:0];\n        normalised = x << ({mantissa} - \
            p);\n        f = normalised[{}:0];\n        e = $signed({{57'd0, p}}) - {};\n    end",
        mantissa - 1,
        input.frac_bits
    );
    let mantissa_value = match unit {
        Log2Unit::Mitchell => widened("f", mantissa),
        Log2Unit::Table { segments_log2: k } => {
            assert!(mantissa >= k, "the table index needs {k} mantissa bits");
            let table = unit.table(frac);
            let step = interpolation(&mut v, &table, k, "f", mantissa, true);
            let width = table_width(&table);
            format!("{} + {}", widened("first", width), widened(&step, width))
        }
    };
    let _ = writeln!(
        v,
        "    always @*\n        if (x == 0)\n            y = {};\n        else\n            y = (e \
            <<< {frac}) + {mantissa_value};\nendmodule\n",
        literal(zero)
    );
    v
}

/// The exp2 unit of node `id` (`2^-x`) as its own module.
///
/// # Panics
/// If the input has fewer fraction bits than the table has address bits (a construction
/// mistake in the datapath).
pub(super) fn exp2_module(
    datapath: &Datapath,
    id: NodeId,
    unit: Exp2Unit,
    input: FixedPoint,
) -> String {
    let node = datapath.node(id);
    let frac = Exp2Unit::frac_bits(node.format.frac_bits);
    let k = unit.segments_log2;
    let (int_bits, in_frac) = (input.int_bits, input.frac_bits);
    assert!(
        in_frac > k && int_bits > 0,
        "the exp2 unit needs {k} fraction bits and an integer part"
    );
    let table = unit.table(frac);
    let width = table_width(&table);
    let mut v = String::new();
    let _ = writeln!(
        v,
        "// 2^-x of a {} input, {} unit: exact result with {frac} fraction bits.",
        input.name(),
        unit.name()
    );
    let _ = writeln!(
        v,
        "module {}_{}_exp2 (\n    input wire [{}:0] x,\n    output wire signed [63:0] y\n);",
        datapath.name,
        node.name,
        input.width() - 1
    );
    let _ = writeln!(
        v,
        "    wire [{}:0] shift = x[{}:{in_frac}];",
        int_bits - 1,
        input.width() - 1,
    );
    // 2^-f falls across the segment: the first entry minus the step towards the second.
    let step = interpolation(&mut v, &table, k, "x", in_frac, false);
    let _ = writeln!(v, "    wire [{}:0] m = first - {step};", width - 1);
    let last = Exp2Unit::last_shift(node.format.frac_bits);
    let shifted = widened("m >> shift", width);
    if last < (1 << int_bits) - 1 {
        let _ = writeln!(
            v,
            "    // Past a shift of {last} every bit is gone.\n    assign y = (shift > \
                {int_bits}'d{last}) ? 64'sd0 : {shifted};"
        );
    } else {
        let _ = writeln!(v, "    assign y = {shifted};");
    }
    let _ = writeln!(v, "endmodule\n");
    v
}
