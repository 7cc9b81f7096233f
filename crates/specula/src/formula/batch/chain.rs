//! Chains: runs of operations that each take the previous one's value and otherwise only
//! per-material constants (`max(0, a * (t - 1) + 1) ^ 16` is one chain from `t`). A chain
//! runs a group of [`GROUP`] vectors through all its links in registers, so the value never
//! goes through memory between operations and a link's choice is paid once per group.

use super::links::{Link, SavedOp};
use super::{Inside, Map, Rules, ACOS_DOMAIN, LOG2_DOMAIN, MAX_WIDTH};
use crate::simd::{math, Lanes};

/// Vectors a chain carries through its links at once, in registers.
pub(super) const GROUP: usize = 8;

/// Vectors a chain that keeps a saved value carries: the values and the saved ones then fill
/// 8 of AVX2's 16 vector registers, where 8 and 8 with the links' constants went through the
/// stack at every link.
pub(super) const SAVING_GROUP: usize = 4;

/// A chain, and where its value starts and ends.
#[derive(Clone, Debug, PartialEq)]
pub(super) struct Chain {
    pub links: Vec<Link>,
    /// Whether any link's polynomial needs its range checked.
    pub checked: bool,
    /// Whether a link has no vector form.
    pub lane_only: bool,
    /// Whether a link keeps a saved value (Horner's rule).
    pub saves: bool,
}

impl Chain {
    pub(super) fn new(links: Vec<Link>) -> Self {
        Self {
            checked: links.iter().any(|l| l.checked()),
            lane_only: links.iter().any(|l| matches!(l, Link::Lane(_))),
            saves: links.contains(&Link::Save),
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
        for value in $x.iter_mut() {
            let $v = *value;
            *value = $body;
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

/// Runs `chain` over one block (`block` floats, a whole number of groups): from `input` to
/// `output`.
#[inline(always)]
pub(super) fn run<V: Lanes>(
    lanes: V,
    chain: &Chain,
    buffers: &mut Buffers<'_>,
    ends: (End, End),
    block: usize,
) {
    if chain.saves {
        run_groups::<V, SAVING_GROUP>(lanes, chain, buffers, ends, block);
    } else {
        run_groups::<V, GROUP>(lanes, chain, buffers, ends, block);
    }
}

/// [`run`] with `G` vectors a group.
#[inline(always)]
fn run_groups<V: Lanes, const G: usize>(
    lanes: V,
    chain: &Chain,
    buffers: &mut Buffers<'_>,
    ends: (End, End),
    block: usize,
) {
    let mut at = 0;
    if chain.checked || chain.lane_only {
        while at < block {
            let mut x = load_group::<V, G>(lanes, buffers, ends.0, at);
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
            at += G * V::WIDTH;
        }
    } else {
        // Without polynomials or a fallback the group's values never leave registers.
        while at < block {
            let mut x = load_group::<V, G>(lanes, buffers, ends.0, at);
            let mut saved = x;
            for &link in &chain.links {
                apply_arithmetic::<V, G, false>(lanes, link, buffers.values, (&mut x, &mut saved));
            }
            store_group(lanes, buffers, ends.1, at, x);
            at += G * V::WIDTH;
        }
    }
}

/// A whole formula that is one chain run unchecked, over the whole batch: no blocks and no
/// register file, the shared rules picked once (as `cosquad`'s kernel picks its mask). Each
/// shape of chain is its own loop: a chain that saves a value carries fewer vectors, and one
/// without polynomials is compiled without their arms, whose constants would otherwise hold
/// registers the group needs.
#[inline(always)]
pub(super) fn run_whole<V: Lanes>(
    lanes: V,
    chain: &Chain,
    values: &[f32],
    rules: Rules,
    ts: &[f32],
    out: &mut [f32],
) {
    let polynomial = chain.links.iter().any(|l| l.checked());
    let run = (lanes, chain.links.as_slice(), values, ts, out);
    match (chain.saves, polynomial) {
        (false, false) => whole_with_rules::<V, GROUP, false>(run, rules),
        (false, true) => whole_with_rules::<V, GROUP, true>(run, rules),
        (true, false) => whole_with_rules::<V, SAVING_GROUP, false>(run, rules),
        (true, true) => whole_with_rules::<V, SAVING_GROUP, true>(run, rules),
    }
}

/// Whether a chain can run as [`run_whole`] under `rules`: every link has a vector form and
/// no polynomial needs its inputs checked.
pub(super) fn runs_whole(chain: &Chain, rules: Rules) -> bool {
    !chain.lane_only && (!chain.checked || !rules.checked)
}

/// What [`whole`] runs: the lanes, the links, the batch's constants, cosines and outputs.
type Whole<'a, V> = (V, &'a [Link], &'a [f32], &'a [f32], &'a mut [f32]);

#[inline(always)]
fn whole_with_rules<V: Lanes, const G: usize, const POLY: bool>(run: Whole<'_, V>, rules: Rules) {
    match (rules.clamp, rules.mask) {
        (false, false) => whole::<V, G, POLY, false, false>(run),
        (false, true) => whole::<V, G, POLY, false, true>(run),
        (true, false) => whole::<V, G, POLY, true, false>(run),
        (true, true) => whole::<V, G, POLY, true, true>(run),
    }
}

#[inline(always)]
fn whole<V: Lanes, const G: usize, const POLY: bool, const CLAMP: bool, const MASK: bool>(
    (lanes, links, values, ts, out): Whole<'_, V>,
) {
    let step = G * V::WIDTH;
    let mut t_groups = ts.chunks_exact(step);
    let mut o_groups = out.chunks_exact_mut(step);
    for (t, o) in (&mut t_groups).zip(&mut o_groups) {
        whole_group::<V, G, POLY, CLAMP, MASK>(lanes, links, values, t, o);
    }
    let (t, o) = (t_groups.remainder(), o_groups.into_remainder());
    if !t.is_empty() {
        let mut padded = [1.0_f32; GROUP * MAX_WIDTH];
        padded[..t.len()].copy_from_slice(t);
        let mut result = [0.0_f32; GROUP * MAX_WIDTH];
        whole_group::<V, G, POLY, CLAMP, MASK>(
            lanes,
            links,
            values,
            &padded[..step],
            &mut result[..step],
        );
        o.copy_from_slice(&result[..o.len()]);
    }
}

/// One group of [`whole`] (a function, not a closure: see [`super::Map`]).
#[inline(always)]
fn whole_group<V: Lanes, const G: usize, const POLY: bool, const CLAMP: bool, const MASK: bool>(
    lanes: V,
    links: &[Link],
    values: &[f32],
    t: &[f32],
    o: &mut [f32],
) {
    let width = V::WIDTH;
    let (zero, one) = (lanes.splat(0.0), lanes.splat(1.0));
    let mut x = [zero; G];
    for (k, value) in x.iter_mut().enumerate() {
        *value = one
            .min(lanes.load(&t[k * width..(k + 1) * width]))
            .max(zero);
    }
    let mut saved = x;
    for &link in links {
        apply_arithmetic::<V, G, POLY>(lanes, link, values, (&mut x, &mut saved));
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
fn load_group<V: Lanes, const G: usize>(
    lanes: V,
    buffers: &Buffers<'_>,
    input: End,
    at: usize,
) -> [V; G] {
    let width = V::WIDTH;
    let (zero, one) = (lanes.splat(0.0), lanes.splat(1.0));
    let mut x = [zero; G];
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
fn store_group<V: Lanes, const G: usize>(
    lanes: V,
    buffers: &mut Buffers<'_>,
    output: End,
    at: usize,
    x: [V; G],
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
fn lane_by_lane<V: Lanes, const G: usize>(
    chain: &Chain,
    buffers: &Buffers<'_>,
    input: End,
    at: usize,
    x: &mut [V; G],
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
fn apply<V: Lanes, const G: usize>(
    lanes: V,
    link: Link,
    values: &[f32],
    (x, saved): (&mut [V; G], &mut [V; G]),
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
        _ => apply_arithmetic::<V, G, false>(lanes, link, values, (x, saved)),
    }
}

/// One link over the group, unchecked: arithmetic, or (with `POLY`) a polynomial proven in its
/// domain. Without `POLY` the polynomials' arms are not compiled in.
#[inline(always)]
fn apply_arithmetic<V: Lanes, const G: usize, const POLY: bool>(
    lanes: V,
    link: Link,
    values: &[f32],
    (x, saved): (&mut [V; G], &mut [V; G]),
) {
    let s = |index: usize| lanes.splat(values[index]);
    match link {
        Link::Save => *saved = *x,
        // Each operation its own loop: one choice per group, not one per vector.
        Link::Saved(SavedOp::Add) => with_saved(x, saved, |v, kept| v + kept),
        Link::Saved(SavedOp::Mul) => with_saved(x, saved, |v, kept| v * kept),
        Link::Saved(SavedOp::Sub) => with_saved(x, saved, |v, kept| v - kept),
        Link::Saved(SavedOp::SubFrom) => with_saved(x, saved, |v, kept| kept - v),
        Link::Saved(SavedOp::MulAdd(b)) => {
            let b = s(b);
            with_saved(x, saved, |v, kept| v.mul_add(kept, b));
        }
        Link::Saved(SavedOp::NegMulAdd(b)) => {
            let b = s(b);
            with_saved(x, saved, |v, kept| v.neg_mul_add(kept, b));
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
        Link::NegFma(a, b) => {
            let (a, b) = (s(a), s(b));
            each!(x, |v| v.neg_mul_add(a, b));
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
        Link::Pow(_) | Link::Log2 | Link::Ln | Link::Exp2(_) | Link::Acos if !POLY => {
            unreachable!("a chain with a polynomial runs with its arms")
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

/// Each value of the group combined with its saved value by `op`.
#[inline(always)]
fn with_saved<V: Lanes, const G: usize>(x: &mut [V; G], saved: &[V; G], op: impl Fn(V, V) -> V) {
    for (v, &kept) in x.iter_mut().zip(saved.iter()) {
        *v = op(*v, kept);
    }
}

/// `(-inf, 0]`, NaN excluded: where the `exp2` polynomial holds (0 below -127).
pub(super) const EXP2_DOMAIN: Inside = Inside {
    scale: 1.0,
    low: -f32::MAX,
    high: f32::MIN_POSITIVE,
};
