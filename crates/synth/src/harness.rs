//! The timing harness: the datapath between a serial input and a one-bit output, so that
//! placement needs three pins whatever the datapath's width (a 16-bit `cosquad` has 54 I/O
//! bits; the UP5K's SG48 package has 39 pins).
//!
//! Every input bit comes from a shift register fed by `din`, and `dout` registers the XOR of
//! every output bit, so no logic is constant or unobserved and synthesis keeps all of it. The
//! harness adds only register-to-register paths of one LUT level, never the critical one, so
//! nextpnr's Fmax is the datapath's. The datapath is synthesized once, alone: its resource
//! figures come from that netlist, and the harness is synthesized around it as a black box,
//! so nextpnr places exactly the netlist the figures count.

use core::fmt::Write as _;

use specula_hw::Datapath;

/// The harness's module name.
pub const HARNESS: &str = "specula_harness";

/// The harness around the pipelined module of `datapath`.
#[must_use]
pub fn harness(datapath: &Datapath) -> String {
    let inputs = datapath.input_ports();
    let total: u32 = inputs.iter().map(|(_, width)| width).sum::<u32>().max(2);
    let output = datapath.node(datapath.output()).format.width();
    let mut v = String::new();
    let _ = writeln!(
        v,
        "module {HARNESS} (\n    input wire clk,\n    input wire din,\n    output reg \
            dout\n);\n    reg [{}:0] chain;\n    always @(posedge clk) chain <= {{chain[{}:0], \
            din}};\n    wire [{}:0] value;",
        total - 1,
        total - 2,
        output - 1
    );
    let mut low = 0;
    let mut ports = Vec::new();
    for (name, width) in inputs {
        ports.push(format!(".{name}(chain[{}:{low}])", low + width - 1));
        low += width;
    }
    let _ = writeln!(
        v,
        "    {} dut (.clk(clk), {}, .value(value));\n    always @(posedge clk) dout <= \
            ^value;\nendmodule",
        datapath.name,
        ports.join(", ")
    );
    v
}
