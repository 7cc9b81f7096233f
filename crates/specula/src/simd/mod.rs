//! Explicit SIMD: the batch path's kernels, written once over [`Lanes`], a vector of `f32`
//! whose every method is one machine instruction.
//!
//! Why explicit: left to the auto-vectoriser, Rust never fuses `a * b + c` (no FMA at all in
//! the old batch path's disassembly), scalarises saturating `as` conversions, and runs each
//! polynomial as one dependent chain. Here each kernel states its instructions, the driver
//! keeps [`UNROLL`] independent vectors in flight, and [`Tally`](tally::Tally) counts what a
//! kernel executes, so that its cost bound ([`cost`]) is read off the code, not guessed.
//!
//! Levels ([`Level`]), chosen at run time:
//! - [`Level::Avx2`]: 8 lanes, AVX2 + FMA, through `pulp`'s safe intrinsics. CPUs with
//!   AVX-512 run these kernels too: `pulp` 0.22's `truncate_f32x16` rounds as `f64` lanes,
//!   so its V4 wrappers are not trusted for the lobes' `f32` kernels (the material fit's
//!   `f64` sums, auto-vectorised, take AVX-512 through `pulp::Arch`).
//! - [`Level::Baseline`]: the same kernels over one-lane [`Scalar`](scalar::Scalar) values
//!   with unfused multiply-adds, compiled for the target's baseline (SSE2 on x86-64, NEON on
//!   AArch64), where the auto-vectoriser does what it can.

pub mod cost;
pub(crate) mod math;
pub mod peak;
pub(crate) mod scalar;
pub mod tally;
#[cfg(target_arch = "x86_64")]
pub(crate) mod x86;

use core::ops::{Add, Div, Mul, Sub};

/// `2^x` on every lane for `x` in `[-126, 0]` (within 2 ulp), 0 at or below `-127`, 1 for a
/// positive `x` or NaN (taken as 0): the kernels' polynomial, for code outside a lobe that
/// needs `exp` of a non-positive argument (an opacity's `exp(-sigma d)`) without a library
/// call.
#[inline(always)]
#[must_use]
pub fn exp2_nonpositive<V: Lanes>(x: V) -> V {
    math::exp2(x.min(x.splat(0.0)))
}

/// Independent vectors the driver evaluates per step: enough to cover a 4-cycle FMA latency
/// on two FMA pipes with the out-of-order window's help (`drive` writes the four out).
pub const UNROLL: usize = 4;

/// A vector of `f32` lanes. Every method is one instruction on the explicit levels (named in
/// [`tally::Class`]); values carry their level's token, so constants are made from a vector
/// (`t.splat(1.0)`).
///
/// Bit-level methods treat the lanes' bit patterns as 32-bit integers, as the registers do.
/// `min` and `max` have the x86 semantics: `a.min(b)` is `if a < b { a } else { b }`, so a NaN
/// in `a` gives `b` (kernels rely on this to send NaN to a defined value).
pub trait Lanes:
    Copy + Add<Output = Self> + Sub<Output = Self> + Mul<Output = Self> + Div<Output = Self>
{
    /// A lane mask from a comparison.
    type Mask: Copy;
    /// Lanes per vector.
    const WIDTH: usize;

    /// Every lane `value`.
    #[must_use]
    fn splat(self, value: f32) -> Self;
    /// `WIDTH` values from `src` (exactly `WIDTH` long).
    #[must_use]
    fn load(self, src: &[f32]) -> Self;
    /// The lanes into `dst` (exactly `WIDTH` long).
    fn store(self, dst: &mut [f32]);
    /// `self * b + c`, fused where the level has FMA.
    #[must_use]
    fn mul_add(self, b: Self, c: Self) -> Self;
    /// `c - self * b`, fused where the level has FMA.
    #[must_use]
    fn neg_mul_add(self, b: Self, c: Self) -> Self;
    /// Square root.
    #[must_use]
    fn sqrt(self) -> Self;
    /// `if self < other { self } else { other }`.
    #[must_use]
    fn min(self, other: Self) -> Self;
    /// `if self > other { self } else { other }`.
    #[must_use]
    fn max(self, other: Self) -> Self;
    /// `self < other` per lane (false with a NaN).
    #[must_use]
    fn lt(self, other: Self) -> Self::Mask;
    /// `self > other` per lane (false with a NaN).
    #[must_use]
    fn gt(self, other: Self) -> Self::Mask;
    /// `if mask { self } else { other }` per lane.
    #[must_use]
    fn select(self, mask: Self::Mask, other: Self) -> Self;
    /// `self` where `mask`, `+0.0` elsewhere.
    #[must_use]
    fn keep(self, mask: Self::Mask) -> Self;
    /// The bits `&` a constant.
    #[must_use]
    fn bits_and(self, bits: u32) -> Self;
    /// The bits plus a constant, as integers (wrapping).
    #[must_use]
    fn bits_add(self, bits: u32) -> Self;
    /// The bits shifted left by `S`.
    #[must_use]
    fn bits_shl<const S: i32>(self) -> Self;
    /// The bits as `i32`, shifted right by `S` with sign extension.
    #[must_use]
    fn bits_shr_signed<const S: i32>(self) -> Self;
    /// The bits, read as an `i32`, converted to the nearest float.
    #[must_use]
    fn int_to_float(self) -> Self;
    /// The value truncated to an `i32` (in range: callers clamp first), as bits.
    #[must_use]
    fn float_to_int(self) -> Self;
    /// Reinterprets the bits of an integer constant as a float vector.
    #[must_use]
    fn splat_bits(self, bits: u32) -> Self {
        self.splat(f32::from_bits(bits))
    }
}

/// A kernel: one lobe (or any `f32 -> f32` formula) over a vector.
pub trait Kernel: Copy {
    /// The formula on every lane of `t`.
    fn eval_lanes<V: Lanes>(self, t: V) -> V;
}

/// Where a batch runs.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, serde::Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum Level {
    /// AVX2 + FMA, 8 lanes (also taken on AVX-512 CPUs).
    Avx2,
    /// One-lane kernels compiled for the target's baseline, left to the auto-vectoriser.
    Baseline,
}

impl Level {
    /// The best level this CPU supports (cheap: feature detection is cached by `std`).
    #[must_use]
    pub fn detect() -> Self {
        #[cfg(target_arch = "x86_64")]
        if pulp::x86::V3::try_new().is_some() {
            return Level::Avx2;
        }
        Level::Baseline
    }

    /// Every level this CPU supports, best first.
    #[must_use]
    pub fn available() -> Vec<Level> {
        let mut levels = vec![Self::detect()];
        if levels[0] != Level::Baseline {
            levels.push(Level::Baseline);
        }
        levels
    }

    /// Lanes per vector.
    #[must_use]
    pub fn lanes(self) -> usize {
        match self {
            Level::Avx2 => 8,
            Level::Baseline => 1,
        }
    }

    /// A short name for tables.
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            Level::Avx2 => "avx2+fma",
            Level::Baseline => "baseline",
        }
    }
}

/// A hint to the CPU to bring a value's cache line in before it is read, so that reads of a
/// table of megabytes at random places (an environment map's) overlap rather than wait one
/// after another: issue the hints for a pass's reads first, then read. A hint changes no
/// result; where the CPU has none (not x86-64), it does nothing.
#[derive(Clone, Copy, Debug)]
pub struct Prefetch {
    #[cfg(target_arch = "x86_64")]
    sse: Option<pulp::core_arch::x86::Sse>,
}

impl Prefetch {
    /// The CPU's prefetch, if it has one.
    #[must_use]
    pub fn new() -> Self {
        Self {
            #[cfg(target_arch = "x86_64")]
            sse: pulp::core_arch::x86::Sse::try_new(),
        }
    }

    /// Asks for `item`'s cache line, into every level of cache.
    #[inline(always)]
    pub fn line<T>(self, item: &T) {
        #[cfg(target_arch = "x86_64")]
        if let Some(sse) = self.sse {
            sse._mm_prefetch::<{ core::arch::x86_64::_MM_HINT_T0 }>(
                core::ptr::from_ref(item).cast(),
            );
        }
        #[cfg(not(target_arch = "x86_64"))]
        let _ = item;
    }
}

impl Default for Prefetch {
    fn default() -> Self {
        Self::new()
    }
}

/// Work generic over the lane type, run with the level's target features enabled.
pub trait Job {
    /// What the work returns.
    type Output;
    /// The work; `lanes` is any vector of the level (for its token).
    fn run<V: Lanes>(self, lanes: V) -> Self::Output;
}

/// Runs `job` at `level` (which must be available; [`Level::Baseline`] always is).
///
/// # Panics
/// If `level` is not supported by this CPU.
pub fn dispatch<J: Job>(level: Level, job: J) -> J::Output {
    match level {
        #[cfg(target_arch = "x86_64")]
        Level::Avx2 => {
            let simd = pulp::x86::V3::try_new().expect("AVX2 + FMA is not available on this CPU");
            <pulp::x86::V3 as pulp::Simd>::vectorize(simd, x86::Avx2Job(simd, job))
        }
        #[cfg(not(target_arch = "x86_64"))]
        Level::Avx2 => panic!("AVX2 + FMA is not available on this CPU"),
        Level::Baseline => job.run(scalar::Scalar(0.0)),
    }
}

/// Evaluates `kernel` on every `ts[i]` into `out[i]`, [`UNROLL`] vectors per step.
#[inline(always)]
pub(crate) fn drive<V: Lanes, K: Kernel>(lanes: V, kernel: K, ts: &[f32], out: &mut [f32]) {
    let step = V::WIDTH * UNROLL;
    let whole = ts.len() / step * step;
    let (ts_whole, ts_rest) = ts.split_at(whole);
    let (out_whole, out_rest) = out.split_at_mut(whole);
    // Written out, not `array::from_fn`: a closure called from a library function is compiled
    // without the level's target features, and every intrinsic in it becomes a call.
    for (t, o) in ts_whole
        .chunks_exact(step)
        .zip(out_whole.chunks_exact_mut(step))
    {
        let (t, o) = (t.split_at(2 * V::WIDTH), o.split_at_mut(2 * V::WIDTH));
        let (t01, t23) = (t.0.split_at(V::WIDTH), t.1.split_at(V::WIDTH));
        let v0 = kernel.eval_lanes(lanes.load(t01.0));
        let v1 = kernel.eval_lanes(lanes.load(t01.1));
        let v2 = kernel.eval_lanes(lanes.load(t23.0));
        let v3 = kernel.eval_lanes(lanes.load(t23.1));
        let (o01, o23) = (o.0.split_at_mut(V::WIDTH), o.1.split_at_mut(V::WIDTH));
        v0.store(o01.0);
        v1.store(o01.1);
        v2.store(o23.0);
        v3.store(o23.1);
    }
    // The rest, one vector at a time; the last partial vector through a padded buffer.
    let mut t_chunks = ts_rest.chunks_exact(V::WIDTH);
    let mut o_chunks = out_rest.chunks_exact_mut(V::WIDTH);
    for (t, o) in (&mut t_chunks).zip(&mut o_chunks) {
        kernel.eval_lanes(lanes.load(t)).store(o);
    }
    let (t, o) = (t_chunks.remainder(), o_chunks.into_remainder());
    if !t.is_empty() {
        let mut buffer = [1.0_f32; 64];
        buffer[..t.len()].copy_from_slice(t);
        let value = kernel.eval_lanes(lanes.load(&buffer[..V::WIDTH]));
        value.store(&mut buffer[..V::WIDTH]);
        o.copy_from_slice(&buffer[..o.len()]);
    }
}

/// The plain loop of a kernel's formula: one lane at a time, unfused, as a `for` loop any
/// Rust program would write, compiled for `level`'s features and left to the auto-vectoriser.
/// It is the peer the explicit kernels are measured against (`specula bench lobes`).
#[inline(always)]
pub(crate) fn plain_loop<K: Kernel>(kernel: K, ts: &[f32], out: &mut [f32]) {
    for (o, &t) in out.iter_mut().zip(ts) {
        *o = kernel.eval_lanes(scalar::Scalar(t)).0;
    }
}

/// Which loop a batch runs.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, serde::Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum BatchLoop {
    /// The explicit kernel ([`drive`]; what `Lobe::eval_batch` runs).
    Explicit,
    /// The same formula as a plain per-element loop ([`plain_loop`]): the peer the explicit
    /// kernels are measured against.
    Plain,
}

/// [`drive`] or [`plain_loop`] as a [`Job`].
pub(crate) struct Drive<'a, K> {
    pub kernel: K,
    pub ts: &'a [f32],
    pub out: &'a mut [f32],
    pub batch_loop: BatchLoop,
}

impl<K: Kernel> Job for Drive<'_, K> {
    type Output = ();

    #[inline(always)]
    fn run<V: Lanes>(self, lanes: V) {
        match self.batch_loop {
            BatchLoop::Explicit => drive(lanes, self.kernel, self.ts, self.out),
            BatchLoop::Plain => plain_loop(self.kernel, self.ts, self.out),
        }
    }
}
