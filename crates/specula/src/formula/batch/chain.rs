//! Chains: runs of operations that each take the previous one's value and otherwise only
//! per-material constants (`max(0, a * (t - 1) + 1) ^ 16` is one chain from `t`). A chain
//! runs a group of [`GROUP`] vectors through all its links in registers, so the value never
//! goes through memory between operations and a link's choice is paid once per group.

use super::{Inside, LaneFunction, Map, Rules, ACOS_DOMAIN, LOG2_DOMAIN, MAX_WIDTH};
use crate::simd::tally::{Class, Instructions};
use crate::simd::{math, Lanes};

/// Vectors a chain carries through its links at once (in registers).
pub(super) const GROUP: usize = 8;

/// One link: the value `x` and scalars (indices into the batch's constants).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) enum Link {
    Add(usize),
    /// `x - s`.
    Sub(usize),
    /// `s - x`.
    SubFrom(usize),
    Mul(usize),
    Div(usize),
    /// `s / x`.
    DivInto(usize),
    Min(usize),
    Max(usize),
    /// `x * a + b`, fused.
    Fma(usize, usize),
    Powi(i32),
    /// `x` squared this many times (an integer power of two, as `cosquad` computes it).
    Squarings(u32),
    /// `(x - c) * a + b`, the multiply-add fused: a subtraction and the multiply-add that
    /// reads it, in one link.
    Affine(usize, usize, usize),
    /// `x^s` as `exp2(s log2 x)`.
    Pow(usize),
    Neg,
    Abs,
    Sqrt,
    Log2,
    Ln,
    /// `exp2(scale x)`.
    Exp2(f32),
    Acos,
    /// A function without a vector form: the chain goes lane by lane.
    Lane(LaneFunction),
    /// Keeps the value, which a later link of the chain reads again (`u` in
    /// `u * (a + b * u)`): the chain's one saved value, held in registers beside it.
    Save,
    /// The value and the saved one combined: a polynomial of one value (Horner's rule)
    /// stays a chain.
    Saved(SavedOp),
}

/// How a chain's value meets its saved value.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum SavedOp {
    /// `x + saved`.
    Add,
    /// `x * saved`.
    Mul,
    /// `x - saved`.
    Sub,
    /// `saved - x`.
    SubFrom,
}

impl SavedOp {
    #[inline(always)]
    fn apply<V: Lanes>(self, x: V, saved: V) -> V {
        match self {
            SavedOp::Add => x + saved,
            SavedOp::Mul => x * saved,
            SavedOp::Sub => x - saved,
            SavedOp::SubFrom => saved - x,
        }
    }

    pub(super) fn scalar(self, x: f32, saved: f32) -> f32 {
        match self {
            SavedOp::Add => x + saved,
            SavedOp::Mul => x * saved,
            SavedOp::Sub => x - saved,
            SavedOp::SubFrom => saved - x,
        }
    }
}

impl Link {
    /// Whether the link's polynomial holds only on part of its inputs.
    pub(super) fn checked(self) -> bool {
        matches!(
            self,
            Link::Log2 | Link::Ln | Link::Pow(_) | Link::Exp2(_) | Link::Acos
        )
    }

    /// The link in scalar `f32`, as the formula's scalar path computes it; `saved` is the
    /// chain's saved value ([`Link::Save`] sets it).
    pub(super) fn scalar(self, x: f32, saved: &mut f32, values: &[f32]) -> f32 {
        match self {
            Link::Save => {
                *saved = x;
                x
            }
            Link::Saved(op) => op.scalar(x, *saved),
            Link::Add(s) => x + values[s],
            Link::Sub(s) => x - values[s],
            Link::SubFrom(s) => values[s] - x,
            Link::Mul(s) => x * values[s],
            Link::Div(s) => x / values[s],
            Link::DivInto(s) => values[s] / x,
            Link::Min(s) => x.min(values[s]),
            Link::Max(s) => x.max(values[s]),
            Link::Fma(a, b) => x.mul_add(values[a], values[b]),
            Link::Powi(k) => crate::formula::program::powi(x, k),
            Link::Squarings(m) => (0..m).fold(x, |v, _| v * v),
            Link::Affine(c, a, b) => (x - values[c]).mul_add(values[a], values[b]),
            Link::Pow(s) => x.powf(values[s]),
            Link::Neg => -x,
            Link::Abs => x.max(-x),
            Link::Sqrt => x.sqrt(),
            Link::Log2 => x.log2(),
            Link::Ln => x.log2() * core::f32::consts::LN_2,
            Link::Exp2(scale) => (x * scale).exp2(),
            Link::Acos => x.acos(),
            Link::Lane(f) => f.get()(x),
        }
    }

    /// The instructions one vector costs.
    pub(super) fn instructions(self) -> Instructions {
        let one = |class| Instructions::of(&[(class, 1)]);
        match self {
            Link::Add(_) | Link::Sub(_) | Link::SubFrom(_) => one(Class::Add),
            Link::Save => Instructions::NONE,
            Link::Saved(SavedOp::Mul) => one(Class::Mul),
            Link::Saved(_) => one(Class::Add),
            Link::Mul(_) | Link::Neg => one(Class::Mul),
            Link::Squarings(m) => Instructions::of(&[(Class::Mul, m)]),
            Link::Affine(..) => Instructions::of(&[(Class::Add, 1), (Class::Fma, 1)]),
            Link::Div(_) | Link::DivInto(_) => one(Class::Div),
            Link::Min(_) | Link::Max(_) => one(Class::MinMax),
            Link::Fma(..) => one(Class::Fma),
            Link::Powi(k) => {
                let bits = 32 - k.unsigned_abs().leading_zeros();
                let multiplies = bits.saturating_sub(1) + k.unsigned_abs().count_ones().max(1) - 1;
                Instructions::of(&[(Class::Mul, multiplies), (Class::Div, u32::from(k < 0))])
            }
            Link::Pow(_) => math::LOG2.and(math::EXP2).plus(Class::Mul, 1),
            Link::Abs => Instructions::of(&[(Class::Mul, 1), (Class::MinMax, 1)]),
            Link::Sqrt => one(Class::Sqrt),
            Link::Log2 => math::LOG2,
            Link::Ln => math::LOG2.plus(Class::Mul, 1),
            Link::Exp2(_) => math::EXP2.plus(Class::Mul, 1),
            Link::Acos => math::ACOS,
            // A call per lane, counted as a division's worth each.
            Link::Lane(_) => Instructions::of(&[(Class::Div, 8)]),
        }
    }
}

/// A chain, and where its value starts and ends.
#[derive(Clone, Debug, PartialEq)]
pub(super) struct Chain {
    pub links: Vec<Link>,
    /// Whether any link's polynomial needs its range checked.
    pub checked: bool,
    /// Whether a link has no vector form.
    pub lane_only: bool,
}

impl Chain {
    pub(super) fn new(links: Vec<Link>) -> Self {
        Self {
            checked: links.iter().any(|l| l.checked()),
            lane_only: links.iter().any(|l| matches!(l, Link::Lane(_))),
            links,
        }
    }
}

/// Where a chain reads and writes, by offsets into the register file, or the batch's own
/// cosines (clamped to `[0, 1]` on the way in) and outputs (with the shared rules on the
/// way out).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) enum End {
    Register(usize),
    Batch,
}

/// Applies `$body` (an expression of `$v`) to every vector of the group.
macro_rules! each {
    ($x:ident, |$v:ident| $body:expr) => {
        for k in 0..GROUP {
            let $v = $x[k];
            $x[k] = $body;
        }
    };
}

/// Whether every lane of `ok` is 1.
#[inline(always)]
fn all_set<V: Lanes>(ok: V) -> bool {
    let mut lanes = [0.0_f32; 64];
    ok.store(&mut lanes[..V::WIDTH]);
    lanes[..V::WIDTH].iter().all(|&v| v == 1.0)
}

/// The batch's buffers a chain reads and writes.
pub(super) struct Buffers<'a> {
    pub rules: Rules,
    pub values: &'a [f32],
    pub file: &'a mut [f32],
    pub ts: &'a [f32],
    pub out: &'a mut [f32],
}

/// Runs `chain` over one block (`block` floats): from `input` to `output`.
#[inline(always)]
pub(super) fn run<V: Lanes>(
    lanes: V,
    chain: &Chain,
    buffers: &mut Buffers<'_>,
    ends: (End, End),
    block: usize,
) {
    let mut at = 0;
    if chain.checked || chain.lane_only {
        while at < block {
            let mut x = load_group(lanes, buffers, ends.0, at);
            let mut saved = x;
            let mut ok = lanes.splat(1.0);
            if !chain.lane_only {
                for &link in &chain.links {
                    apply(lanes, link, buffers.values, (&mut x, &mut saved), &mut ok);
                }
            }
            if chain.lane_only || !all_set(ok) {
                lane_by_lane(chain, buffers, ends.0, at, &mut x);
            }
            store_group(lanes, buffers, ends.1, at, x);
            at += GROUP * V::WIDTH;
        }
    } else {
        // Without polynomials or a fallback the group's values never leave registers.
        while at < block {
            let mut x = load_group(lanes, buffers, ends.0, at);
            let mut saved = x;
            for &link in &chain.links {
                apply_arithmetic(lanes, link, buffers.values, (&mut x, &mut saved));
            }
            store_group(lanes, buffers, ends.1, at, x);
            at += GROUP * V::WIDTH;
        }
    }
}

/// A whole formula that is one arithmetic chain, over the whole batch: no blocks and no
/// register file, the shared rules picked once (as `cosquad`'s kernel picks its mask).
#[inline(always)]
pub(super) fn run_whole<V: Lanes>(
    lanes: V,
    chain: &Chain,
    values: &[f32],
    rules: Rules,
    ts: &[f32],
    out: &mut [f32],
) {
    match (rules.clamp, rules.mask) {
        (false, false) => whole::<V, false, false>(lanes, &chain.links, values, ts, out),
        (false, true) => whole::<V, false, true>(lanes, &chain.links, values, ts, out),
        (true, false) => whole::<V, true, false>(lanes, &chain.links, values, ts, out),
        (true, true) => whole::<V, true, true>(lanes, &chain.links, values, ts, out),
    }
}

/// Whether a chain can run as [`run_whole`] under `rules`: every link has a vector form and
/// no polynomial needs its inputs checked.
pub(super) fn runs_whole(chain: &Chain, rules: Rules) -> bool {
    !chain.lane_only && (!chain.checked || !rules.checked)
}

#[inline(always)]
fn whole<V: Lanes, const CLAMP: bool, const MASK: bool>(
    lanes: V,
    links: &[Link],
    values: &[f32],
    ts: &[f32],
    out: &mut [f32],
) {
    let step = GROUP * V::WIDTH;
    let mut t_groups = ts.chunks_exact(step);
    let mut o_groups = out.chunks_exact_mut(step);
    for (t, o) in (&mut t_groups).zip(&mut o_groups) {
        whole_group::<V, CLAMP, MASK>(lanes, links, values, t, o);
    }
    let (t, o) = (t_groups.remainder(), o_groups.into_remainder());
    if !t.is_empty() {
        let mut padded = [1.0_f32; GROUP * MAX_WIDTH];
        padded[..t.len()].copy_from_slice(t);
        let mut result = [0.0_f32; GROUP * MAX_WIDTH];
        whole_group::<V, CLAMP, MASK>(lanes, links, values, &padded[..step], &mut result[..step]);
        o.copy_from_slice(&result[..o.len()]);
    }
}

/// One group of [`whole`] (a function, not a closure: see [`super::Map`]).
#[inline(always)]
fn whole_group<V: Lanes, const CLAMP: bool, const MASK: bool>(
    lanes: V,
    links: &[Link],
    values: &[f32],
    t: &[f32],
    o: &mut [f32],
) {
    let width = V::WIDTH;
    let (zero, one) = (lanes.splat(0.0), lanes.splat(1.0));
    let mut x = [zero; GROUP];
    for (k, value) in x.iter_mut().enumerate() {
        *value = one
            .min(lanes.load(&t[k * width..(k + 1) * width]))
            .max(zero);
    }
    let mut saved = x;
    for &link in links {
        apply_arithmetic(lanes, link, values, (&mut x, &mut saved));
    }
    for (k, value) in x.into_iter().enumerate() {
        let mut value = value;
        if CLAMP {
            value = value.max(zero).min(one);
        }
        if MASK {
            value = value.keep(lanes.load(&t[k * width..(k + 1) * width]).gt(zero));
        }
        value.store(&mut o[k * width..(k + 1) * width]);
    }
}

/// The group's inputs: the batch's cosines clamped to `[0, 1]`, or a register's values.
#[inline(always)]
fn load_group<V: Lanes>(lanes: V, buffers: &Buffers<'_>, input: End, at: usize) -> [V; GROUP] {
    let width = V::WIDTH;
    let (zero, one) = (lanes.splat(0.0), lanes.splat(1.0));
    let mut x = [zero; GROUP];
    for (k, value) in x.iter_mut().enumerate() {
        let start = at + k * width;
        *value = match input {
            End::Batch => one
                .min(lanes.load(&buffers.ts[start..start + width]))
                .max(zero),
            End::Register(r) => lanes.load(&buffers.file[r + start..r + start + width]),
        };
    }
    x
}

/// The group's results: into a register, or the batch's outputs with the shared rules.
#[inline(always)]
fn store_group<V: Lanes>(
    lanes: V,
    buffers: &mut Buffers<'_>,
    output: End,
    at: usize,
    x: [V; GROUP],
) {
    let width = V::WIDTH;
    let (zero, one) = (lanes.splat(0.0), lanes.splat(1.0));
    for (k, value) in x.into_iter().enumerate() {
        let start = at + k * width;
        match output {
            End::Batch => {
                let mut value = value;
                if buffers.rules.clamp {
                    value = value.max(zero).min(one);
                }
                if buffers.rules.mask {
                    value = value.keep(lanes.load(&buffers.ts[start..start + width]).gt(zero));
                }
                value.store(&mut buffers.out[start..start + width]);
            }
            End::Register(r) => value.store(&mut buffers.file[r + start..r + start + width]),
        }
    }
}

/// The group recomputed lane by lane in scalar `f32` (a link's polynomial met a lane outside
/// its range, or a link has no vector form).
#[inline(never)]
fn lane_by_lane<V: Lanes>(
    chain: &Chain,
    buffers: &Buffers<'_>,
    input: End,
    at: usize,
    x: &mut [V; GROUP],
) {
    let (width, values) = (V::WIDTH, buffers.values);
    let mut lanes = [0.0_f32; 64];
    for (k, value) in x.iter_mut().enumerate() {
        let start = at + k * width;
        for (lane, slot) in lanes[..width].iter_mut().enumerate() {
            let mut v = match input {
                // As the vector clamp: NaN and t <= 0 to 0.
                End::Batch => match buffers.ts[start + lane] {
                    t if t > 0.0 => t.min(1.0),
                    _ => 0.0,
                },
                End::Register(r) => buffers.file[r + start + lane],
            };
            let mut saved = v;
            for &link in &chain.links {
                v = link.scalar(v, &mut saved, values);
            }
            *slot = v;
        }
        *value = value.load(&lanes[..width]);
    }
}

/// One link over the group; `ok` keeps 1 in the lanes where every polynomial was in range.
#[inline(always)]
fn apply<V: Lanes>(
    lanes: V,
    link: Link,
    values: &[f32],
    (x, saved): (&mut [V; GROUP], &mut [V; GROUP]),
    ok: &mut V,
) {
    let s = |index: usize| lanes.splat(values[index]);
    match link {
        Link::Pow(i) => {
            let c = s(i);
            for v in x.iter_mut() {
                *ok = ok.min(LOG2_DOMAIN.apply([*v]));
                let y = c * math::log2(*v);
                *ok = ok.min(EXP2_DOMAIN.apply([y]));
                *v = math::exp2(y);
            }
        }
        Link::Log2 | Link::Ln => {
            let scale = lanes.splat(if link == Link::Ln {
                core::f32::consts::LN_2
            } else {
                1.0
            });
            for v in x.iter_mut() {
                *ok = ok.min(LOG2_DOMAIN.apply([*v]));
                *v = math::log2(*v) * scale;
            }
        }
        Link::Exp2(scale) => {
            let scale = lanes.splat(scale);
            for v in x.iter_mut() {
                let y = *v * scale;
                *ok = ok.min(EXP2_DOMAIN.apply([y]));
                *v = math::exp2(y);
            }
        }
        Link::Acos => {
            for v in x.iter_mut() {
                *ok = ok.min(ACOS_DOMAIN.apply([*v]));
                *v = math::acos(*v);
            }
        }
        Link::Lane(_) => {}
        _ => apply_arithmetic(lanes, link, values, (x, saved)),
    }
}

/// One link over the group, unchecked: arithmetic, or a polynomial proven in its domain.
#[inline(always)]
fn apply_arithmetic<V: Lanes>(
    lanes: V,
    link: Link,
    values: &[f32],
    (x, saved): (&mut [V; GROUP], &mut [V; GROUP]),
) {
    let s = |index: usize| lanes.splat(values[index]);
    match link {
        Link::Save => *saved = *x,
        Link::Saved(op) => {
            for (v, &kept) in x.iter_mut().zip(saved.iter()) {
                *v = op.apply(*v, kept);
            }
        }
        Link::Add(i) => {
            let c = s(i);
            each!(x, |v| v + c);
        }
        Link::Sub(i) => {
            let c = s(i);
            each!(x, |v| v - c);
        }
        Link::SubFrom(i) => {
            let c = s(i);
            each!(x, |v| c - v);
        }
        Link::Mul(i) => {
            let c = s(i);
            each!(x, |v| v * c);
        }
        Link::Div(i) => {
            let c = s(i);
            each!(x, |v| v / c);
        }
        Link::DivInto(i) => {
            let c = s(i);
            each!(x, |v| c / v);
        }
        Link::Min(i) => {
            let c = s(i);
            each!(x, |v| v.min(c));
        }
        Link::Max(i) => {
            let c = s(i);
            each!(x, |v| v.max(c));
        }
        Link::Fma(a, b) => {
            let (a, b) = (s(a), s(b));
            each!(x, |v| v.mul_add(a, b));
        }
        Link::Powi(k) => {
            each!(x, |v| super::columns::powi(v, k));
        }
        Link::Squarings(m) => {
            for _ in 0..m {
                each!(x, |v| v * v);
            }
        }
        Link::Affine(c, a, b) => {
            let (c, a, b) = (s(c), s(a), s(b));
            each!(x, |v| (v - c).mul_add(a, b));
        }
        Link::Neg => {
            let minus = lanes.splat(-1.0);
            each!(x, |v| v * minus);
        }
        Link::Abs => {
            let minus = lanes.splat(-1.0);
            each!(x, |v| v.max(v * minus));
        }
        Link::Sqrt => {
            each!(x, |v| v.sqrt());
        }
        // Polynomials whose inputs the range analysis proved inside their domains.
        Link::Pow(i) => {
            let c = s(i);
            each!(x, |v| math::exp2(c * math::log2(v)));
        }
        Link::Log2 => {
            each!(x, |v| math::log2(v));
        }
        Link::Ln => {
            let scale = lanes.splat(core::f32::consts::LN_2);
            each!(x, |v| math::log2(v) * scale);
        }
        Link::Exp2(scale) => {
            let scale = lanes.splat(scale);
            each!(x, |v| math::exp2(v * scale));
        }
        Link::Acos => {
            each!(x, |v| math::acos(v));
        }
        Link::Lane(_) => unreachable!("a chain with a lane-only link runs lane by lane"),
    }
}

/// `(-inf, 0]`, NaN excluded: where the `exp2` polynomial holds (0 below -127).
pub(super) const EXP2_DOMAIN: Inside = Inside {
    scale: 1.0,
    low: -f32::MAX,
    high: f32::MIN_POSITIVE,
};
