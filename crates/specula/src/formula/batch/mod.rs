//! A formula over a batch of cosines: its tape compiled to *chains* and *columns*.
//!
//! An interpreter that dispatches on every operation for every vector spends more time
//! choosing than computing, and one that keeps values in memory between operations spends
//! the rest on loads and stores. So the plan ([`Plan`]) finds *chains*, runs of operations
//! each taking the previous one's value and otherwise only per-material constants, and runs
//! each over a group of vectors held in registers (`chain.rs`, with superinstructions for the
//! lobes' common shapes); what chains cannot carry (two varying values meeting) runs as
//! *columns*, one operation over a block of vectors in L1 before the next is chosen
//! (`columns.rs`). A formula that is one chain runs over the whole batch in one pass, its
//! shared rules chosen once by a range analysis ([`Rules`]). Per-material constants are
//! splatted once per batch; a multiply whose only use is an add becomes one fused
//! multiply-add, as the built-in kernels compute it; registers are reused once their last
//! reader has run.

mod chain;
mod columns;
mod links;
mod ranges;

use super::op::Op;
use crate::simd::tally::{Class, Instructions};
use crate::simd::Lanes;
use chain::{Chain, End};
use columns::{binary, run_step, Binary, Inside, Map, ACOS_DOMAIN, LOG2_DOMAIN};
use links::{link, push_fused, save_values, Link};

/// Which of the shared rules a batch's output needs: the clamp of the value to `[0, 1]`
/// (NaN to 0), and the zero where `t <= 0` or NaN. Both are needed unless the formula is a
/// chain from `t` whose range over `[0, 1]` is within `[0, 1]` and whose value at 0 is +0
/// (then the clamp of `t` on the way in already sends `t <= 0` and NaN to that 0), as
/// `cosquad`'s kernel skips its mask when its slope is at least 1. And whether the chain's
/// polynomials (`exp2`, `log2`, `acos`) need their inputs checked lane by lane: not where the
/// range analysis puts every input inside the polynomial's domain, as `sg`'s kernel calls
/// `exp2` on `r (t - 1) <= 0` unchecked.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct Rules {
    pub clamp: bool,
    pub mask: bool,
    pub checked: bool,
}

impl Rules {
    /// Every rule.
    pub(crate) const ALL: Rules = Rules {
        clamp: true,
        mask: true,
        checked: true,
    };
}

/// Vectors per block: 16 vectors of 8 lanes keep a register in 512 bytes, so a formula's
/// live registers stay in L1.
pub const BLOCK_VECTORS: usize = 16;

/// Where an operand comes from.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Source {
    /// A column register.
    Register(usize),
    /// A per-material constant (slot) or a folded constant, splatted.
    Scalar(usize),
}

/// A scalar the batch splats: a slot's value or a constant.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Scalar {
    Slot(usize),
    Constant(f64),
}

/// One step: a chain, or a column operation.
#[derive(Clone, Debug, PartialEq)]
enum Step {
    Chain(Chain, End, End),
    Binary(Binary, Source, Source, usize),
    Fma(Source, Source, Source, usize),
    SelectLess([Source; 4], usize),
}

/// A tape compiled to chains and column operations.
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct Plan {
    scalars: Vec<Scalar>,
    steps: Vec<Step>,
    registers: usize,
    /// Whether a column step reads `t` (register 0 then holds the clamped cosines).
    needs_t: bool,
    /// The result's register when no chain writes the output itself.
    result: Option<Source>,
}

/// What a tape operation becomes.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Role {
    Scalar(usize),
    T,
    /// A link of a chain: its one varying operand and the link.
    Link(usize, Link),
    Column,
}

impl Plan {
    /// Compiles `tape` (the formula's varying part).
    pub(crate) fn new(tape: &[Op]) -> Self {
        let mut uses = vec![0usize; tape.len()];
        let mut last_use = vec![0usize; tape.len()];
        for (index, op) in tape.iter().enumerate() {
            for operand in op.operands() {
                uses[operand] += 1;
                last_use[operand] = index;
            }
        }
        let mut scalars = Vec::new();
        let mut roles: Vec<Role> = Vec::with_capacity(tape.len());
        for &op in tape {
            let role = match op {
                Op::Slot(s) => {
                    scalars.push(Scalar::Slot(s));
                    Role::Scalar(scalars.len() - 1)
                }
                Op::Const(c) => {
                    scalars.push(Scalar::Constant(c));
                    Role::Scalar(scalars.len() - 1)
                }
                Op::T => Role::T,
                op => link(op, &roles).map_or(Role::Column, |(x, l)| Role::Link(x, l)),
            };
            roles.push(role);
        }
        let saved_refs = save_values(tape, &mut roles, &uses);
        // The link reading each value as its chain's value, where exactly one does.
        let mut chain_reader: Vec<Option<usize>> = vec![None; tape.len()];
        let mut link_readers = vec![0usize; tape.len()];
        for (index, role) in roles.iter().enumerate() {
            if let Role::Link(x, _) = *role {
                link_readers[x] += 1;
                chain_reader[x] = Some(index);
            }
        }
        // A link continues into its one reader when that reader is a link taking it (and
        // its other readers are the chain's later links that read it saved).
        let continues =
            |index: usize| link_readers[index] == 1 && uses[index] == 1 + saved_refs[index];
        // A multiply read only by an add is fused into it: the add's first such operand.
        let fusible = |index: usize| {
            matches!(roles[index], Role::Column)
                && matches!(tape[index], Op::Mul(..))
                && uses[index] == 1
                && matches!(roles[last_use[index]], Role::Column)
        };
        let fused_into_add = |index: usize| {
            fusible(index)
                && match tape[last_use[index]] {
                    Op::Add(a, _) if a == index => true,
                    Op::Add(a, b) if b == index => !fusible(a),
                    _ => false,
                }
        };
        // Where each operation's step runs: a link with its chain's last link, a fused
        // multiply with its add, the others in place; a value's register is free once the
        // last step reading it has run (not its last reader's own index, which for a chain's
        // head or a fused multiply's operands comes earlier).
        let emitted = |index: usize| {
            let mut at = index;
            if matches!(roles[at], Role::Link(..)) {
                while continues(at) {
                    at = chain_reader[at].unwrap_or(at);
                }
            } else if fused_into_add(at) {
                at = last_use[at];
            }
            at
        };
        let mut freed_after = vec![0usize; tape.len()];
        for (index, op) in tape.iter().enumerate() {
            for operand in op.operands() {
                freed_after[operand] = freed_after[operand].max(emitted(index));
            }
        }
        let last = tape.len() - 1;
        let mut source: Vec<Option<Source>> = vec![None; tape.len()];
        let mut free: Vec<usize> = Vec::new();
        let mut registers = 1;
        let mut steps = Vec::new();
        let mut needs_t = false;
        let mut chains: Vec<Option<(usize, Vec<Link>)>> = vec![None; tape.len()];
        for index in 0..tape.len() {
            let at = |i: usize| match roles[i] {
                Role::Scalar(s) => Source::Scalar(s),
                Role::T => Source::Register(0),
                _ => source[i].unwrap_or(Source::Register(0)),
            };
            let mut take = |free: &mut Vec<usize>| {
                free.pop().unwrap_or_else(|| {
                    registers += 1;
                    registers - 1
                })
            };
            let release = |i: usize, step: usize, free: &mut Vec<usize>| {
                if freed_after[i] == step && matches!(roles[i], Role::Link(..) | Role::Column) {
                    if let Some(Source::Register(r)) = source[i] {
                        if r != 0 && !free.contains(&r) {
                            free.push(r);
                        }
                    }
                }
            };
            match roles[index] {
                Role::Scalar(_) | Role::T => {}
                Role::Link(x, l) => {
                    // Extend the chain ending at `x`, or start one from `x`.
                    let (head, mut links) = chains[x].take().unwrap_or((x, Vec::new()));
                    if saved_refs[x] > 0 {
                        links.push(Link::Save);
                    }
                    push_fused(&mut links, l);
                    if continues(index) {
                        chains[index] = Some((head, links));
                        continue;
                    }
                    let input = match (roles[head], source[head]) {
                        (Role::T, _) => End::Batch,
                        (_, Some(Source::Register(r))) => End::Register(r),
                        _ => unreachable!("a chain starts from t or from a step's register"),
                    };
                    release(head, index, &mut free);
                    let output = if index == last {
                        End::Batch
                    } else {
                        let out = take(&mut free);
                        source[index] = Some(Source::Register(out));
                        End::Register(out)
                    };
                    steps.push(Step::Chain(Chain::new(links), input, output));
                }
                Role::Column => {
                    if fused_into_add(index) {
                        continue;
                    }
                    let op = tape[index];
                    let operands = op.operands();
                    needs_t |= operands.iter().any(|&i| roles[i] == Role::T);
                    let out = take(&mut free);
                    let step = match op {
                        Op::Add(a, b) if fused_into_add(a) || fused_into_add(b) => {
                            let (product, addend) = if fused_into_add(a) { (a, b) } else { (b, a) };
                            let Op::Mul(x, y) = tape[product] else {
                                unreachable!("fused_into_add holds multiplies")
                            };
                            needs_t |= [x, y].iter().any(|&i| roles[i] == Role::T);
                            for i in [x, y, addend] {
                                release(i, index, &mut free);
                            }
                            Step::Fma(at(x), at(y), at(addend), out)
                        }
                        Op::SelectLess {
                            a,
                            b,
                            then,
                            otherwise,
                        } => Step::SelectLess([at(a), at(b), at(then), at(otherwise)], out),
                        // Every operation of one varying operand is a link; of two, a binary.
                        op => match binary(op) {
                            Some(b) => Step::Binary(b, at(operands[0]), at(operands[1]), out),
                            None => unreachable!("every operation of a tape is a step: {op:?}"),
                        },
                    };
                    for &i in &operands {
                        release(i, index, &mut free);
                    }
                    steps.push(step);
                    source[index] = Some(Source::Register(out));
                }
            }
        }
        let result = match roles[last] {
            Role::Link(..) => None,
            Role::T => {
                needs_t = true;
                Some(Source::Register(0))
            }
            _ => source[last],
        };
        Self {
            scalars,
            steps,
            registers,
            needs_t,
            result,
        }
    }

    /// Whether the whole tape is one chain from `t` to the output.
    #[cfg(test)]
    pub(crate) fn is_one_chain(&self) -> bool {
        matches!(
            self.steps.as_slice(),
            [Step::Chain(_, End::Batch, End::Batch)]
        )
    }

    /// The links of the whole tape's one chain, if it is one.
    #[cfg(test)]
    pub(crate) fn one_chain_links(&self) -> Option<usize> {
        match self.steps.as_slice() {
            [Step::Chain(chain, End::Batch, End::Batch)] => Some(chain.links.len()),
            _ => None,
        }
    }

    /// The rules a batch's output needs with these per-material constants (see [`Rules`]).
    pub(crate) fn rules(&self, slots: &[f64]) -> Rules {
        match self.steps.as_slice() {
            [Step::Chain(chain, End::Batch, End::Batch)] => {
                let values: Vec<f32> = self
                    .scalars
                    .iter()
                    .map(|scalar| match *scalar {
                        Scalar::Slot(k) => slots[k] as f32,
                        Scalar::Constant(c) => c as f32,
                    })
                    .collect();
                chain.rules(&values)
            }
            _ => Rules::ALL,
        }
    }

    /// The instructions one vector costs (the loads and stores between steps aside), with
    /// the shared rules.
    pub(crate) fn instructions(&self, applied: Rules) -> Instructions {
        // The clamp of t, and the rules applied on the way out.
        let mut rules = Instructions::of(&[(Class::MinMax, 2)]);
        if applied.clamp {
            rules = rules.plus(Class::MinMax, 2);
        }
        if applied.mask {
            rules = rules.plus(Class::Compare, 1).plus(Class::Logic, 1);
        }
        self.steps.iter().fold(rules, |total, step| {
            total.and(match step {
                Step::Chain(chain, ..) => chain
                    .links
                    .iter()
                    .fold(Instructions::NONE, |sum, link| sum.and(link.instructions())),
                Step::Fma(..) => Instructions::of(&[(Class::Fma, 1)]),
                Step::SelectLess(..) => Instructions::of(&[(Class::Compare, 1), (Class::Blend, 1)]),
                Step::Binary(b, ..) => match b {
                    Binary::Add | Binary::Sub => Instructions::of(&[(Class::Add, 1)]),
                    Binary::Mul => Instructions::of(&[(Class::Mul, 1)]),
                    Binary::Div => Instructions::of(&[(Class::Div, 1)]),
                    Binary::Min | Binary::Max => Instructions::of(&[(Class::MinMax, 1)]),
                    Binary::Pow => Link::Pow(0).instructions(),
                },
            })
        })
    }

    /// The formula at every cosine of `ts` into `out` (`slots` the per-material constants),
    /// with the shared rules: `t` clamped to `[0, 1]`, the value clamped to `[0, 1]` (NaN to
    /// 0), and 0 where `t <= 0` or NaN. The register file is the thread's, kept between
    /// calls: a renderer calls this per tile, and an allocation per call would cost more
    /// than the formula.
    #[inline(always)]
    pub(crate) fn run<V: Lanes>(
        &self,
        lanes: V,
        (slots, rules): (&[f64], Rules),
        ts: &[f32],
        out: &mut [f32],
    ) {
        let block = BLOCK_VECTORS * V::WIDTH;
        let count = self.scalars.len();
        let size = count + (count + self.registers) * block;
        // Taken out of the thread-local and put back, not used inside `with`: a closure is
        // compiled without the level's features, and every intrinsic in it would be a call.
        let mut storage = FILE.with(core::cell::RefCell::take);
        if storage.len() < size {
            storage.resize(size, 0.0);
        }
        let (values, file) = storage.split_at_mut(count);
        for (value, scalar) in values.iter_mut().zip(&self.scalars) {
            *value = match *scalar {
                Scalar::Slot(k) => slots[k] as f32,
                Scalar::Constant(c) => c as f32,
            };
        }
        if let [Step::Chain(chain, End::Batch, End::Batch)] = self.steps.as_slice() {
            if chain::runs_whole(chain, rules) {
                chain::run_whole(lanes, chain, values, rules, ts, out);
                FILE.with(|cell| cell.replace(storage));
                return;
            }
        }
        if self.steps.iter().any(|s| !matches!(s, Step::Chain(..))) {
            for (s, &value) in values.iter().enumerate() {
                file[s * block..(s + 1) * block].fill(value);
            }
        }
        let mut whole_ts = ts.chunks_exact(block);
        let mut whole_out = out.chunks_exact_mut(block);
        for (t_block, out_block) in (&mut whole_ts).zip(&mut whole_out) {
            self.run_block(lanes, (values, rules), file, t_block, out_block);
        }
        let (t_rest, out_rest) = (whole_ts.remainder(), whole_out.into_remainder());
        if !t_rest.is_empty() {
            let mut padded = [1.0_f32; BLOCK_VECTORS * MAX_WIDTH];
            padded[..t_rest.len()].copy_from_slice(t_rest);
            let mut result = [0.0_f32; BLOCK_VECTORS * MAX_WIDTH];
            self.run_block(
                lanes,
                (values, rules),
                file,
                &padded[..block],
                &mut result[..block],
            );
            out_rest.copy_from_slice(&result[..out_rest.len()]);
        }
        FILE.with(|cell| cell.replace(storage));
    }

    /// One whole block.
    #[inline(always)]
    fn run_block<V: Lanes>(
        &self,
        lanes: V,
        (values, rules): (&[f32], Rules),
        file: &mut [f32],
        ts: &[f32],
        out: &mut [f32],
    ) {
        let (width, block) = (V::WIDTH, BLOCK_VECTORS * V::WIDTH);
        let base = self.scalars.len() * block;
        let (zero, one) = (lanes.splat(0.0), lanes.splat(1.0));
        if self.needs_t {
            let mut at = 0;
            while at < block {
                let clamped = one.min(lanes.load(&ts[at..at + width])).max(zero);
                clamped.store(&mut file[base + at..base + at + width]);
                at += width;
            }
        }
        for step in &self.steps {
            match step {
                Step::Chain(chain, input, output) => {
                    let offset = |end: End| match end {
                        End::Register(r) => End::Register(base + r * block),
                        End::Batch => End::Batch,
                    };
                    let mut buffers = chain::Buffers {
                        rules,
                        values,
                        file,
                        ts,
                        out,
                    };
                    chain::run(
                        lanes,
                        chain,
                        &mut buffers,
                        (offset(*input), offset(*output)),
                        block,
                    );
                }
                step => run_step(lanes, step, file, base, block),
            }
        }
        let Some(result) = self.result else {
            return;
        };
        let result = match result {
            Source::Register(r) => base + r * block,
            Source::Scalar(s) => s * block,
        };
        let mut at = 0;
        while at < block {
            let t = lanes.load(&ts[at..at + width]);
            let value = lanes.load(&file[result + at..result + at + width]);
            value
                .max(zero)
                .min(one)
                .keep(t.gt(zero))
                .store(&mut out[at..at + width]);
            at += width;
        }
    }
}

/// The widest level's lanes (AVX2's 8).
const MAX_WIDTH: usize = 8;

thread_local! {
    static FILE: core::cell::RefCell<Vec<f32>> = const { core::cell::RefCell::new(Vec::new()) };
}
