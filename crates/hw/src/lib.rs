//! # specula-hw: the thesis's hardware "structural schemes", bit for bit
//!
//! SPEC section 8 asks for each approximation as a fixed-point datapath with configurable word
//! lengths. This crate holds one description per lobe ([`HwLobe::build`]) and derives
//! everything from it:
//! - the bit-accurate model, [`Datapath::eval`], over the fixed-point arithmetic of
//!   [`fixed`] (explicit rounding and saturation at every stage);
//! - the resources, [`Datapath::resources`]: multipliers and squarers by width, adders,
//!   dividers, ROM bits, registers and pipeline latency;
//! - the error against `t^n` per zone and word length, [`analysis::sweep`], measured with the
//!   core's zone scan (the datapath is an [`Evaluator`](specula::analysis::Evaluator));
//! - synthesizable, pipelined Verilog and a self-checking testbench ([`verilog`]), whose
//!   co-simulation with Icarus Verilog the tests require to be bit-exact;
//! - a block diagram, [`diagram::svg`].
//!
//! A lobe of yours whose formula is transcendental-free has a datapath too, compiled from its
//! recorded expression a stage per operation ([`HwLobe::Formula`]).
//!
//! No I/O: the CLI writes the files.

pub mod analysis;
mod compiled;
mod datapath;
pub mod diagram;
mod exp2;
pub mod fixed;
mod lobes;
mod log2;
pub mod verilog;

pub use datapath::{operands, Builder, Datapath, Node, NodeId, Op, Resources};
pub use exp2::{Exp2Unit, EXP2_GUARD_BITS};
pub use lobes::{
    integer_exponent, HwError, HwLobe, BITS, COSQUAD_V, LOGEXP_TABLE, POW_EXP2_TABLE,
    POW_LOG2_TABLE,
};
pub use log2::{Log2Unit, TABLE_GUARD_BITS};
