//! The datapath description: one per lobe, and the single source of its bit-accurate model
//! ([`Datapath::eval`]), its resources ([`Datapath::resources`]), its Verilog and its block
//! diagram.
//!
//! A datapath is a list of named nodes in topological order. Each node is one hardware stage
//! (an adder, a multiplier, a squarer, a divider, a log2 unit, a ROM, a multiplexer, or a
//! wiring-only shift) with its own output [`FixedPoint`] and [`Rounding`]; its exact result is
//! resized into that format (rounded, then saturated). In the pipeline every non-wiring node
//! ends in a register, and operands from earlier stages are delayed to arrive together.

use serde::{Deserialize, Serialize};

use crate::exp2::Exp2Unit;
use crate::fixed::{exact_add, exact_mul, FixedPoint, Rounding, MAX_WIDTH};
use crate::log2::Log2Unit;

/// A node's position in its datapath.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize)]
pub struct NodeId(pub usize);

/// What a node computes.
#[derive(Clone, Debug, PartialEq, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum Op {
    /// A module input.
    Input,
    /// A constant, as a raw value of the node's format.
    Const(i64),
    /// `a + b`.
    Add(NodeId, NodeId),
    /// `a - b`.
    Sub(NodeId, NodeId),
    /// `a * b`.
    Mul(NodeId, NodeId),
    /// `a * a`, on a squarer (about half a multiplier).
    Square(NodeId),
    /// `a / b` for unsigned operands, the quotient truncated (a restoring divider); a zero
    /// divisor gives 0 (in the lobes it only meets `t = 0`, whose lobe value is 0).
    Div(NodeId, NodeId),
    /// `a * 2^shift`: wiring only, no register.
    Shift(NodeId, i32),
    /// `log2 a` for an unsigned `a`.
    Log2(NodeId, Log2Unit),
    /// `2^-a` for an unsigned `a`.
    Exp2Neg(NodeId, Exp2Unit),
    /// `min(a, b)`: a comparator and a multiplexer.
    Min(NodeId, NodeId),
    /// `max(a, b)`: a comparator and a multiplexer.
    Max(NodeId, NodeId),
    /// 1 if `a` is not zero, else 0: an OR of its bits.
    NonZero(NodeId),
    /// `table[index]`, the index clamped to the table.
    Rom {
        /// The address.
        index: NodeId,
        /// The contents, raw values of the node's format.
        table: Vec<i64>,
    },
    /// `options[index]`, the index clamped to the options.
    Select {
        /// Which option.
        index: NodeId,
        /// The candidates.
        options: Vec<NodeId>,
    },
}

/// One stage.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Node {
    /// A short name (`u`, `a_u`, `square_3`): the Verilog register and the diagram's label.
    pub name: String,
    /// The computation.
    pub op: Op,
    /// The output format.
    pub format: FixedPoint,
    /// How fraction bits are dropped into it.
    pub rounding: Rounding,
}

/// A datapath: its nodes in topological order, its inputs and its output.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Datapath {
    /// The module name.
    pub name: String,
    nodes: Vec<Node>,
    inputs: Vec<NodeId>,
    output: NodeId,
    /// Each node's log2 or exp2 table (empty for other nodes), built once here rather than
    /// per evaluation: the sweeps evaluate a datapath millions of times.
    #[serde(skip)]
    tables: Vec<Vec<i64>>,
}

/// The datapath builder: nodes are added in order, each naming its operands.
#[derive(Debug, Default)]
pub struct Builder {
    nodes: Vec<Node>,
    inputs: Vec<NodeId>,
    rounding: Rounding,
}

impl Builder {
    /// An empty datapath whose nodes round with `rounding`.
    #[must_use]
    pub fn new(rounding: Rounding) -> Self {
        Self {
            rounding,
            ..Self::default()
        }
    }

    /// Adds a node.
    ///
    /// # Panics
    /// If the format is wider than [`MAX_WIDTH`] or an operand does not exist yet: both are
    /// mistakes in a datapath's construction, not in its inputs.
    pub fn node(&mut self, name: &str, op: Op, format: FixedPoint) -> NodeId {
        assert!(
            format.width() <= MAX_WIDTH,
            "{name}: {} is too wide",
            format.name()
        );
        let id = NodeId(self.nodes.len());
        for operand in operands(&op) {
            assert!(
                operand < id,
                "{name}: operand {operand:?} is not defined before it"
            );
        }
        if op == Op::Input {
            self.inputs.push(id);
        }
        self.nodes.push(Node {
            name: name.to_owned(),
            op,
            format,
            rounding: self.rounding,
        });
        id
    }

    /// An input.
    pub fn input(&mut self, name: &str, format: FixedPoint) -> NodeId {
        self.node(name, Op::Input, format)
    }

    /// The output node of a lobe's datapath: `value`, or 0 where `t = 0`, since every lobe is
    /// 0 there (SPEC section 1) and some formulas are not.
    pub fn zero_at_t_zero(&mut self, t: NodeId, value: NodeId, unit: FixedPoint) -> NodeId {
        let lit = self.node("t_nonzero", Op::NonZero(t), FixedPoint::unsigned(1, 0));
        let zero = self.node("zero", Op::Const(0), unit);
        self.node(
            "value",
            Op::Select {
                index: lit,
                options: vec![zero, value],
            },
            unit,
        )
    }

    /// The finished datapath, with `output` as its result.
    #[must_use]
    pub fn finish(self, name: &str, output: NodeId) -> Datapath {
        let tables = self
            .nodes
            .iter()
            .map(|node| match node.op {
                Op::Log2(_, unit) => unit.table(Log2Unit::table_frac_bits(node.format.frac_bits)),
                Op::Exp2Neg(_, unit) => unit.table(Exp2Unit::frac_bits(node.format.frac_bits)),
                _ => Vec::new(),
            })
            .collect();
        Datapath {
            name: name.to_owned(),
            nodes: self.nodes,
            inputs: self.inputs,
            output,
            tables,
        }
    }
}

/// The nodes an operation reads.
#[must_use]
pub fn operands(op: &Op) -> Vec<NodeId> {
    match op {
        Op::Input | Op::Const(_) => Vec::new(),
        Op::Add(a, b)
        | Op::Sub(a, b)
        | Op::Mul(a, b)
        | Op::Div(a, b)
        | Op::Min(a, b)
        | Op::Max(a, b) => {
            vec![*a, *b]
        }
        Op::Square(a) | Op::Shift(a, _) | Op::Log2(a, _) | Op::Exp2Neg(a, _) | Op::NonZero(a) => {
            vec![*a]
        }
        Op::Rom { index, .. } => vec![*index],
        Op::Select { index, options } => core::iter::once(*index)
            .chain(options.iter().copied())
            .collect(),
    }
}

/// What a datapath costs, counted from its nodes.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Resources {
    /// Multipliers as `(a bits, b bits)`, the log2 units' interpolation multipliers included.
    pub multipliers: Vec<(u32, u32)>,
    /// Squarers by operand bits.
    pub squarers: Vec<u32>,
    /// Adders and subtractors by result bits (comparators of `min` included).
    pub adders: Vec<u32>,
    /// Dividers as `(dividend bits, divisor bits)`.
    pub dividers: Vec<(u32, u32)>,
    /// Leading-one detectors (one per log2 unit) by input bits.
    pub leading_one_detectors: Vec<u32>,
    /// Barrel shifters (a log2 unit's normalisation, an exp2 unit's scaling) by data bits.
    pub shifters: Vec<u32>,
    /// ROM bits: coefficient tables and log2 tables.
    pub rom_bits: u64,
    /// Pipeline registers' bits, delay registers included.
    pub register_bits: u64,
    /// Register stages from inputs to output, the input registers included: the latency in
    /// clock cycles.
    pub latency: u32,
}

impl Datapath {
    /// The nodes, in order.
    #[must_use]
    pub fn nodes(&self) -> &[Node] {
        &self.nodes
    }

    /// The inputs, in the order [`Datapath::eval`] takes them.
    #[must_use]
    pub fn inputs(&self) -> &[NodeId] {
        &self.inputs
    }

    /// Each input's name and width in bits, in order: the module's input ports.
    #[must_use]
    pub fn input_ports(&self) -> Vec<(&str, u32)> {
        self.inputs
            .iter()
            .map(|&id| {
                let node = self.node(id);
                (node.name.as_str(), node.format.width())
            })
            .collect()
    }

    /// The output node.
    #[must_use]
    pub fn output(&self) -> NodeId {
        self.output
    }

    /// The node `id`.
    #[must_use]
    pub fn node(&self, id: NodeId) -> &Node {
        &self.nodes[id.0]
    }

    /// The output for raw `inputs` (one per input, in order; each saturated into its format),
    /// bit for bit what the Verilog computes.
    ///
    /// # Panics
    /// If `inputs` does not have one value per input.
    #[must_use]
    pub fn eval(&self, inputs: &[i64]) -> i64 {
        self.eval_in(inputs, &mut Vec::new())
    }

    /// The output for raw `inputs`, with every node's value left in `values`: a caller that
    /// evaluates many inputs passes the same buffer and allocates once (sweeps evaluate
    /// millions).
    ///
    /// # Panics
    /// If `inputs` does not have one value per input.
    pub fn eval_in(&self, inputs: &[i64], values: &mut Vec<i64>) -> i64 {
        assert_eq!(inputs.len(), self.inputs.len(), "one value per input");
        values.clear();
        values.resize(self.nodes.len(), 0);
        let mut next_input = inputs.iter();
        for (k, node) in self.nodes.iter().enumerate() {
            let out = node.format;
            let at = |id: NodeId| (values[id.0], self.nodes[id.0].format);
            let resize = |(raw, frac): (i128, u32)| out.resize(raw, frac, node.rounding);
            values[k] = match &node.op {
                Op::Input => {
                    let raw = *next_input.next().unwrap_or(&0);
                    raw.clamp(out.min_raw(), out.max_raw())
                }
                Op::Const(raw) => *raw,
                Op::Add(a, b) => {
                    let ((a, fa), (b, fb)) = (at(*a), at(*b));
                    resize(exact_add(a, fa, b, fb))
                }
                Op::Sub(a, b) => {
                    let ((a, fa), (b, fb)) = (at(*a), at(*b));
                    resize(exact_add(a, fa, -b, fb))
                }
                Op::Mul(a, b) => {
                    let ((a, fa), (b, fb)) = (at(*a), at(*b));
                    resize(exact_mul(a, fa, b, fb))
                }
                Op::Square(a) => {
                    let (a, fa) = at(*a);
                    resize(exact_mul(a, fa, a, fa))
                }
                Op::Div(a, b) => {
                    let ((a, fa), (b, fb)) = (at(*a), at(*b));
                    divide(a, fa, b, fb, out)
                }
                Op::Shift(a, shift) => {
                    let (a, fa) = at(*a);
                    // value * 2^shift = raw / 2^(frac - shift).
                    let frac = i64::from(fa.frac_bits) - i64::from(*shift);
                    if frac >= 0 {
                        resize((i128::from(a), frac as u32))
                    } else {
                        resize((i128::from(a) << -frac, 0))
                    }
                }
                Op::Log2(a, unit) => {
                    let (a, fa) = at(*a);
                    let table = &self.tables[k];
                    resize(unit.eval_with_table(table, a, fa, out.frac_bits, out))
                }
                Op::Exp2Neg(a, unit) => {
                    let (a, fa) = at(*a);
                    resize(unit.eval_with_table(&self.tables[k], a, fa, out.frac_bits))
                }
                Op::Min(a, b) | Op::Max(a, b) => {
                    let ((a, fa), (b, fb)) = (at(*a), at(*b));
                    let (a_exact, _) = exact_add(a, fa, 0, fb);
                    let (b_exact, frac) = exact_add(b, fb, 0, fa);
                    let chosen = if matches!(node.op, Op::Min(..)) {
                        a_exact.min(b_exact)
                    } else {
                        a_exact.max(b_exact)
                    };
                    resize((chosen, frac))
                }
                Op::NonZero(a) => resize((i128::from(at(*a).0 != 0), 0)),
                Op::Rom { index, table } => {
                    let (index, _) = at(*index);
                    table[(index.max(0) as usize).min(table.len() - 1)]
                }
                Op::Select { index, options } => {
                    let (index, _) = at(*index);
                    let chosen = options[(index.max(0) as usize).min(options.len() - 1)];
                    let (value, format) = at(chosen);
                    resize((i128::from(value), format.frac_bits))
                }
            };
        }
        values[self.output.0]
    }

    /// Each node's pipeline stage: inputs and constants at 0, wiring-only shifts at their
    /// operand's stage, every other node one after its latest operand.
    #[must_use]
    pub fn stages(&self) -> Vec<u32> {
        let mut stage = vec![0_u32; self.nodes.len()];
        for (k, node) in self.nodes.iter().enumerate() {
            let latest = operands(&node.op)
                .iter()
                .map(|id| stage[id.0])
                .max()
                .unwrap_or(0);
            stage[k] = match node.op {
                Op::Input | Op::Const(_) => 0,
                Op::Shift(..) => latest,
                _ => latest + 1,
            };
        }
        stage
    }

    /// Whether node `id` ends in a register (inputs are registered on entry; constants and
    /// shifts are wiring). Inputs sit at stage 0, so the output of a node at stage `s` is
    /// valid `s + 1` clock edges after its inputs were presented.
    #[must_use]
    pub fn is_registered(&self, id: NodeId) -> bool {
        !matches!(self.nodes[id.0].op, Op::Const(_) | Op::Shift(..))
    }

    /// For each node, the delay registers its value needs: a node at stage `s` reads its
    /// operands as they stood at stage `s - 1`, so an operand from stage `s_o` is delayed by
    /// `s - 1 - s_o` cycles (constants need none).
    #[must_use]
    pub fn delays(&self) -> Vec<u32> {
        let stage = self.stages();
        let mut delay = vec![0_u32; self.nodes.len()];
        for (k, node) in self.nodes.iter().enumerate() {
            if !self.is_registered(NodeId(k)) {
                continue;
            }
            for operand in operands(&node.op) {
                let source = self.wired_source(operand);
                if self.is_registered(source) {
                    delay[source.0] = delay[source.0].max(stage[k] - 1 - stage[source.0]);
                }
            }
        }
        delay
    }

    /// The registered node a wiring-only node reads through (itself if registered).
    #[must_use]
    pub fn wired_source(&self, mut id: NodeId) -> NodeId {
        while let Op::Shift(a, _) = self.nodes[id.0].op {
            id = a;
        }
        id
    }

    /// The resources, counted from the nodes.
    #[must_use]
    pub fn resources(&self) -> Resources {
        let mut r = Resources::default();
        let width = |id: &NodeId| self.nodes[id.0].format.width();
        let delays = self.delays();
        for (k, node) in self.nodes.iter().enumerate() {
            let bits = node.format.width();
            match &node.op {
                Op::Input | Op::Const(_) | Op::Shift(..) | Op::NonZero(_) => {}
                Op::Add(..) | Op::Sub(..) => r.adders.push(bits),
                Op::Min(a, b) | Op::Max(a, b) => r.adders.push(width(a).max(width(b))),
                Op::Mul(a, b) => r.multipliers.push((width(a), width(b))),
                Op::Square(a) => r.squarers.push(width(a)),
                Op::Div(a, b) => r.dividers.push((width(a), width(b))),
                Op::Log2(a, unit) => {
                    r.leading_one_detectors.push(width(a));
                    r.shifters.push(width(a));
                    if let Log2Unit::Table { segments_log2 } = unit {
                        let frac = Log2Unit::table_frac_bits(node.format.frac_bits);
                        r.rom_bits += ((1_u64 << segments_log2) + 1) * u64::from(frac + 1);
                        let within = width(a).saturating_sub(1 + segments_log2);
                        r.multipliers.push((frac + 1, within));
                        r.adders.push(frac + 1);
                    }
                }
                Op::Exp2Neg(a, unit) => {
                    let frac = Exp2Unit::frac_bits(node.format.frac_bits);
                    r.rom_bits += ((1_u64 << unit.segments_log2) + 1) * u64::from(frac + 1);
                    let fraction = self.nodes[a.0].format.frac_bits;
                    r.multipliers
                        .push((frac + 1, fraction.saturating_sub(unit.segments_log2)));
                    r.adders.push(frac + 1);
                    r.shifters.push(frac + 1);
                }
                Op::Rom { table, .. } => r.rom_bits += table.len() as u64 * u64::from(bits),
                Op::Select { .. } => {}
            }
            let own = u64::from(self.is_registered(NodeId(k)));
            r.register_bits += (own + u64::from(delays[k])) * u64::from(bits);
        }
        r.latency = self.stages()[self.output.0] + 1;
        r
    }
}

/// `a / b` for unsigned operands, truncated, into `out` (saturated; `b = 0` gives 0).
fn divide(a: i64, fa: FixedPoint, b: i64, fb: FixedPoint, out: FixedPoint) -> i64 {
    if b <= 0 {
        return 0;
    }
    // a / b = (a_raw / b_raw) 2^(fb - fa); with `out.frac` bits: (a_raw 2^s) / b_raw.
    let shift = i64::from(out.frac_bits) + i64::from(fb.frac_bits) - i64::from(fa.frac_bits);
    let (numerator, denominator) = if shift >= 0 {
        (i128::from(a) << shift, i128::from(b))
    } else {
        (i128::from(a), i128::from(b) << -shift)
    };
    (numerator / denominator).clamp(i128::from(out.min_raw()), i128::from(out.max_raw())) as i64
}
