//! Batch evaluation: a lobe over a slice of cosines, with the explicit SIMD kernels of
//! [`simd`](crate::simd) at the best level the CPU has.
//!
//! Each model's kernel lives in its own file beside the scalar formula (`PowKernel` in
//! `pow.rs`, and so on) and states the instructions it executes per vector
//! ([`Lobe::batch_instructions`]); a test holds every statement to what the kernel runs.
//! Unrolled squarings (`schlick-mod`, `cosquad`) are const generics picked here.
//!
//! Against the scalar `f32` path ([`Lobe::eval`]) the kernels differ by fused multiply-adds
//! and by the polynomials standing in for `log2`, `exp2` and `acos`, within
//! [`Lobe::batch_ulp_bound`] (tested at every level and for the plain loop).

use super::{Lobe, Model};
use crate::simd::tally::{Class, Instructions};
use crate::simd::{dispatch, BatchLoop, Drive, Kernel, Lanes, Level};

/// A lobe's kernel, with the instructions it states it executes per vector.
pub(crate) trait LobeKernel: Kernel {
    /// Counted by hand from the kernel; a test compares it with [`crate::simd::tally`].
    fn instructions(self) -> Instructions;
}

/// `t` clamped to `[0, 1]`, NaN to 0 (`min` keeps a NaN, `max` then replaces it).
#[inline(always)]
pub(crate) fn clamp_unit<V: Lanes>(t: V) -> V {
    t.splat(1.0).min(t).max(t.splat(0.0))
}

/// [`clamp_unit`]'s instructions.
pub(crate) const CLAMP: Instructions = Instructions::of(&[(Class::MinMax, 2)]);

/// Runs `$body` with `$k` bound to the squaring count as a constant (0 to 10), so that the
/// kernel is straight-line.
#[rustfmt::skip]
macro_rules! with_squarings {
    ($count:expr, $k:ident => $body:expr) => {
        with_squarings!(@arms $count, $k, $body, 0 1 2 3 4 5 6 7 8 9)
    };
    (@arms $count:expr, $k:ident, $body:expr, $($value:literal)*) => {
        match $count {
            $($value => { const $k: u32 = $value; $body })*
            _ => { const $k: u32 = 10; $body }
        }
    };
}

pub(crate) use with_squarings;

/// What to do with a lobe's kernel, once its type is known.
pub(crate) trait WithKernel {
    type Output;
    fn call<K: LobeKernel>(self, kernel: K) -> Self::Output;
}

/// How far a model's `f32` evaluations may stray: the batch from the scalar `f32` path (ULPs
/// of 1, `2^-23`), the scalar `f32` path from the `f64` formula (absolute), and a GPU's
/// evaluation of the generated WGSL from the `f64` formula (ULPs of 1; set on llvmpipe, LLVM
/// 15.0.6, 256 bits, Mesa 22.3.6, whose `log2`, `exp2` and `acos` are coarser than IEEE's;
/// docs/gpu.md lists the measured worst). The shared cases are named here; a model with its
/// own states it in its file.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct F32Bounds {
    pub(crate) batch_ulps: f64,
    pub(crate) f32_tolerance: f64,
    pub(crate) gpu_ulps: f64,
}

impl F32Bounds {
    /// Exact IEEE operations only: one fused rounding in the batch (a few ULP of the value),
    /// `4e-6` for the scalar path, 32 ULP on a GPU.
    pub(crate) const EXACT: F32Bounds = F32Bounds {
        batch_ulps: 4.0,
        f32_tolerance: 4e-6,
        gpu_ulps: 32.0,
    };

    /// Through `log2 t` scaled by `n` (`exp2(n log2 t)`, the log/exp lobes): the error of
    /// `log2` (the batch's polynomial, the driver's function) multiplied by `n`.
    pub(crate) fn through_log2(n: f64) -> F32Bounds {
        F32Bounds {
            batch_ulps: 8.0 + 2.0 * n,
            gpu_ulps: 32.0 + 2.0 * n,
            ..F32Bounds::EXACT
        }
    }

    /// The bit-trick powers against their exact `f64` models: the `f32` log's rounding (a sum
    /// of terms near 1, about `2^-22`) times `n`, plus the result's grid of `2^-17` relative
    /// steps (64 ULP) where the two paths round it apart.
    pub(crate) fn bit_trick(n: f64) -> F32Bounds {
        F32Bounds {
            batch_ulps: 72.0 + 2.0 * n,
            f32_tolerance: 2f64.powi(-16) + n * 2f64.powi(-21),
            gpu_ulps: 128.0 + 4.0 * n,
        }
    }
}

/// What a model states of its `f32` paths, in its own file: its batch kernel, and how far
/// each `f32` evaluation may stray (the batch from the scalar `f32` path, the scalar `f32` path
/// and a GPU's from the `f64` formula).
pub(crate) trait ModelF32 {
    /// Calls `f` with the model's kernel (one monomorphised path per constant it unrolls).
    fn with_kernel<F: WithKernel>(&self, f: F) -> F::Output;

    /// How far its `f32` evaluations may stray at exponent `n`.
    fn bounds(&self, n: f64) -> F32Bounds;

    /// For a model drawn in closed form: its draw kernel over `us` into `out` on `level`'s
    /// lanes, and `true` ([`Lobe::tail_inverse_batch`]); `false`, `out` untouched, otherwise.
    fn draw_batch(&self, _level: Level, _us: &[f32], _out: &mut [f32]) -> bool {
        false
    }

    /// The least slope of the drawn inverse in its base, which divides the draw's rounding
    /// ([`Lobe::tail_inverse_batch_bound`]): 1 unless the model's base is flatter.
    fn draw_batch_slope(&self) -> f64 {
        1.0
    }
}

impl Lobe {
    /// Calls `f` with this lobe's kernel.
    pub(crate) fn with_kernel<F: WithKernel>(&self, f: F) -> F::Output {
        each_model!(&self.model, m => m.with_kernel(f))
    }
}

struct Run<'a> {
    level: Level,
    batch_loop: BatchLoop,
    ts: &'a [f32],
    out: &'a mut [f32],
}

impl WithKernel for Run<'_> {
    type Output = ();
    fn call<K: LobeKernel>(self, kernel: K) {
        let job = Drive {
            kernel,
            ts: self.ts,
            out: self.out,
            batch_loop: self.batch_loop,
        };
        dispatch(self.level, job);
    }
}

struct Stated;

impl WithKernel for Stated {
    type Output = Instructions;
    fn call<K: LobeKernel>(self, kernel: K) -> Instructions {
        kernel.instructions()
    }
}

#[cfg(test)]
struct Tallied(f32);

#[cfg(test)]
impl WithKernel for Tallied {
    type Output = Instructions;
    fn call<K: LobeKernel>(self, kernel: K) -> Instructions {
        crate::simd::tally::count(kernel, self.0)
    }
}

impl Lobe {
    /// The lobe at every cosine of `ts`, into `out`, vectorised (see the module docs for how
    /// it relates to [`Lobe::eval`]).
    ///
    /// # Panics
    /// If `ts` and `out` differ in length.
    pub fn eval_batch(&self, ts: &[f32], out: &mut [f32]) {
        self.eval_batch_with(Level::detect(), BatchLoop::Explicit, ts, out);
    }

    /// [`Lobe::eval_batch`] at a chosen level and loop (for benchmarks and tests).
    ///
    /// # Panics
    /// If `ts` and `out` differ in length, or `level` is not available on this CPU.
    pub fn eval_batch_with(
        &self,
        level: Level,
        batch_loop: BatchLoop,
        ts: &[f32],
        out: &mut [f32],
    ) {
        assert_eq!(ts.len(), out.len(), "eval_batch: one output per cosine");
        if let (Model::Formula(m), BatchLoop::Explicit) = (&self.model, batch_loop) {
            return m.eval_compiled(level, ts, out);
        }
        self.with_kernel(Run {
            level,
            batch_loop,
            ts,
            out,
        });
    }

    /// The instructions the explicit kernel executes per vector (a statement counted by hand
    /// from the kernel and tested against what it runs).
    #[must_use]
    pub fn batch_instructions(&self) -> Instructions {
        self.with_kernel(Stated)
    }

    /// The specular lobe for structure-of-arrays shading data: element `i` has the unit normal
    /// `(normal[0][i], normal[1][i], normal[2][i])` and unit directions `wo`, `wi` laid out the
    /// same way; `out[i]` is the lobe at their `geometry` cosine.
    ///
    /// # Panics
    /// If the slices differ in length.
    pub fn eval_directions(
        &self,
        geometry: crate::Geometry,
        normal: [&[f32]; 3],
        wo: [&[f32]; 3],
        wi: [&[f32]; 3],
        out: &mut [f32],
    ) {
        let len = out.len();
        assert!(
            normal.iter().chain(&wo).chain(&wi).all(|s| s.len() == len),
            "eval_directions: every component slice needs one entry per output"
        );
        const CHUNK: usize = 256;
        let level = Level::detect();
        {
            let mut ts = [0.0_f32; CHUNK];
            for (start, chunk) in (0..len).step_by(CHUNK).zip(out.chunks_mut(CHUNK)) {
                for (k, t) in ts[..chunk.len()].iter_mut().enumerate() {
                    let i = start + k;
                    let dot = |a: [&[f32]; 3], b: [&[f32]; 3]| {
                        a[0][i] * b[0][i] + a[1][i] * b[1][i] + a[2][i] * b[2][i]
                    };
                    *t = match geometry {
                        crate::Geometry::Phong => {
                            2.0 * dot(normal, wi) * dot(normal, wo) - dot(wi, wo)
                        }
                        crate::Geometry::Blinn => {
                            let h = [0, 1, 2].map(|c| wi[c][i] + wo[c][i]);
                            let length_squared = h[0] * h[0] + h[1] * h[1] + h[2] * h[2];
                            let n_dot_h =
                                normal[0][i] * h[0] + normal[1][i] * h[1] + normal[2][i] * h[2];
                            if length_squared > 0.0 {
                                n_dot_h / length_squared.sqrt()
                            } else {
                                0.0
                            }
                        }
                    };
                }
                self.eval_batch_with(level, BatchLoop::Explicit, &ts[..chunk.len()], chunk);
            }
        }
    }

    /// The largest difference, in ULPs of 1 (`2^-23`), between [`Lobe::eval_batch`] and the
    /// scalar `f32` [`Lobe::eval`] at the same cosine.
    #[must_use]
    pub fn batch_ulp_bound(&self) -> f64 {
        self.bounds().batch_ulps
    }

    /// The largest absolute difference between [`Lobe::eval`] in `f32` and in `f64` at the
    /// same cosine.
    #[must_use]
    pub fn f32_tolerance(&self) -> f64 {
        self.bounds().f32_tolerance
    }

    /// The largest difference, in ULPs of 1 (`2^-23`), between a GPU's evaluation of the
    /// lobe's generated WGSL and [`Lobe::eval`] in `f64` (a driver's `log2`, `exp2` and `acos`
    /// are approximations).
    #[must_use]
    pub fn gpu_ulp_bound(&self) -> f64 {
        self.bounds().gpu_ulps
    }

    fn bounds(&self) -> F32Bounds {
        each_model!(&self.model, m => m.bounds(self.n.get()))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{Exponent, LobeKind};

    /// The structure-of-arrays entry point equals the scalar geometry followed by the batch.
    #[test]
    fn directions_match_the_scalar_geometry_then_the_batch() {
        use glam::Vec3;
        let count = 1000;
        let direction = |k: usize, phase: f32| {
            let a = k as f32 * 0.37 + phase;
            Vec3::new(0.3 * a.cos(), 0.3 * a.sin(), 1.0).normalize()
        };
        let (ns, wos, wis): (Vec<Vec3>, Vec<Vec3>, Vec<Vec3>) = (0..count)
            .map(|k| (direction(k, 0.0), direction(k, 1.0), direction(k, 2.5)))
            .fold((vec![], vec![], vec![]), |mut acc, (a, b, c)| {
                acc.0.push(a);
                acc.1.push(b);
                acc.2.push(c);
                acc
            });
        let soa = |v: &[Vec3]| [0, 1, 2].map(|c| v.iter().map(|p| p[c]).collect::<Vec<f32>>());
        let (n, wo, wi) = (soa(&ns), soa(&wos), soa(&wis));
        for geometry in crate::Geometry::ALL {
            let lobe = Lobe::new(LobeKind::SchlickMod, Exponent::new(40.0));
            let mut out = vec![0.0; count];
            lobe.eval_directions(geometry, view(&n), view(&wo), view(&wi), &mut out);
            let ts: Vec<f32> = (0..count)
                .map(|k| geometry.cos_lobe_f32(ns[k], wos[k], wis[k]))
                .collect();
            let mut expected = vec![0.0; count];
            lobe.eval_batch(&ts, &mut expected);
            for (a, b) in out.iter().zip(&expected) {
                assert!((a - b).abs() <= 4.0 * f32::EPSILON, "{geometry:?}: {a} {b}");
            }
        }
    }

    fn view(s: &[Vec<f32>; 3]) -> [&[f32]; 3] {
        [s[0].as_slice(), s[1].as_slice(), s[2].as_slice()]
    }

    /// Every level, explicit and plain, agrees with the scalar path within the stated bound.
    #[test]
    fn every_level_and_loop_matches_the_scalar_path() {
        let ts: Vec<f32> = (0..4099)
            .map(|i| 1.0 - (i as f32 / 4099.0).powi(2))
            .chain([
                0.0,
                -0.0,
                -1.0,
                f32::NAN,
                1.5,
                f32::INFINITY,
                f32::MIN_POSITIVE,
                1e-30,
            ])
            .collect();
        let kinds = LobeKind::ALL
            .into_iter()
            .chain((0..=10).map(|v| LobeKind::CosQuad { v }));
        for kind in kinds {
            for n in [1.0, 9.5, 100.0, 1000.0] {
                let lobe = Lobe::new(kind, Exponent::new(n));
                let bound = lobe.batch_ulp_bound() * f64::from(f32::EPSILON);
                for level in Level::available() {
                    for batch_loop in [BatchLoop::Explicit, BatchLoop::Plain] {
                        let mut out = vec![0.0; ts.len()];
                        lobe.eval_batch_with(level, batch_loop, &ts, &mut out);
                        for (&t, &value) in ts.iter().zip(&out) {
                            let scalar = lobe.eval(t);
                            assert!(
                                f64::from((value - scalar).abs()) <= bound
                                    && (0.0..=1.0).contains(&value),
                                "{kind} n = {n} {level:?} {batch_loop:?} t = {t}: {value} vs \
                                    {scalar}"
                            );
                        }
                    }
                }
            }
        }
    }

    /// What each kernel states it executes is what it executes, for every model and every
    /// unrolled constant.
    #[test]
    fn stated_instructions_are_what_each_kernel_executes() {
        let kinds = LobeKind::ALL
            .into_iter()
            .chain((0..=10).map(|v| LobeKind::CosQuad { v }));
        for kind in kinds {
            for n in [1.0, 3.0, 9.5, 64.0, 1000.0] {
                let lobe = Lobe::new(kind, Exponent::new(n));
                for t in [0.9, 0.3, -0.5] {
                    assert_eq!(
                        lobe.with_kernel(Tallied(t)),
                        lobe.batch_instructions(),
                        "{kind} n = {n} t = {t}"
                    );
                }
            }
        }
    }
}
