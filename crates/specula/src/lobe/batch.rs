//! Batch evaluation: a lobe over a slice of cosines, compiled for the widest SIMD the CPU has.
//!
//! [`Lobe::eval_batch`] dispatches at run time (through `pulp`) to a copy of the loop compiled
//! for AVX-512, AVX2+FMA or the baseline, and each model's loop is written branch-free over
//! plain `f32` so that the compiler vectorises it: the rules every lobe obeys become selects,
//! the squarings of `schlick-mod` and `cosquad` are unrolled per count, and `log2`, `exp2` and
//! `acos` are the polynomials of [`fast_math`](super::fast_math).
//!
//! Against the scalar `f32` path ([`Lobe::eval`]): `schlick`, `schlick-mod` and `cosquad` are
//! bit-identical (the same IEEE operations in the same order); the others differ by the
//! polynomials' rounding, bounded by [`Lobe::batch_ulp_bound`] (tested).

use super::fast_math::{acos, exp2, log2};
use super::{Lobe, Model};

/// `t^(2^K)` by `K` squarings, unrolled.
#[inline(always)]
fn squarings<const K: u32>(mut x: f32) -> f32 {
    for _ in 0..K {
        x *= x;
    }
    x
}

/// Runs `kernel` with the squaring count as a constant, so that the loop is straight-line.
macro_rules! with_squarings {
    ($count:expr, $kernel:ident, $($arg:expr),*) => {
        match $count {
            0 => $kernel::<0>($($arg),*),
            1 => $kernel::<1>($($arg),*),
            2 => $kernel::<2>($($arg),*),
            3 => $kernel::<3>($($arg),*),
            4 => $kernel::<4>($($arg),*),
            5 => $kernel::<5>($($arg),*),
            6 => $kernel::<6>($($arg),*),
            7 => $kernel::<7>($($arg),*),
            8 => $kernel::<8>($($arg),*),
            9 => $kernel::<9>($($arg),*),
            _ => $kernel::<10>($($arg),*),
        }
    };
}

/// Applies `$body` (an expression in the cosine `$c`, clamped into `(0, 1]`) to every cosine,
/// giving 0 where `t <= 0` or NaN. A macro rather than a function taking a closure: the body
/// must be inlined into the SIMD-enabled copy of the loop for it to vectorise, and a closure
/// is not always inlined.
macro_rules! each {
    ($ts:expr, $out:expr, |$c:ident| $body:expr) => {{
        let (ts, out): (&[f32], &mut [f32]) = ($ts, $out);
        for (value, &t) in out.iter_mut().zip(ts) {
            let $c = t.min(1.0).max(f32::MIN_POSITIVE);
            let v = $body;
            *value = if t > 0.0 { v } else { 0.0 };
        }
    }};
}

#[inline(always)]
fn schlick_mod<const K: u32>(ts: &[f32], out: &mut [f32], n: f32) {
    each!(ts, out, |c| squarings::<K>(c) / (n * (1.0 - c) + c));
}

#[inline(always)]
fn cosquad<const K: u32>(ts: &[f32], out: &mut [f32], slope: f32) {
    each!(ts, out, |c| squarings::<K>(
        (slope * (c - 1.0) + 1.0).max(0.0)
    ));
}

/// One batch evaluation, as `pulp` runs it: `with_simd` is `#[inline(always)]`, so the whole
/// body lands in the copy compiled for the CPU's SIMD level. (A closure passed to `dispatch`
/// is only inlined when it is small; the log/exp and angle loops were not, and ran at scalar
/// speed: measured.)
struct Job<'a> {
    lobe: &'a Lobe,
    ts: &'a [f32],
    out: &'a mut [f32],
}

impl pulp::WithSimd for Job<'_> {
    type Output = ();

    #[inline(always)]
    fn with_simd<S: pulp::Simd>(self, _simd: S) {
        let Job { lobe, ts, out } = self;
        let n = lobe.n.get() as f32;
        match &lobe.model {
            Model::Pow(_) => each!(ts, out, |c| exp2(n * log2(c))),
            Model::Schlick(_) => each!(ts, out, |c| c / (n * (1.0 - c) + c)),
            Model::SchlickMod(m) => with_squarings!(m.squarings(), schlick_mod, ts, out, n),
            Model::AngleQuadratic(q) => {
                let [c0, b, a] = q.coeffs().map(|v| v as f32);
                let cutoff = q.cutoff() as f32;
                each!(ts, out, |c| {
                    let g = acos(c);
                    let value = (c0 + g * (b + a * g)).min(1.0);
                    if g < cutoff {
                        value
                    } else {
                        0.0
                    }
                });
            }
            Model::LogExp(_) => each!(ts, out, |c| {
                let y = n * log2(c);
                (1.0 - 0.5 * log2(1.0 - y)).max(0.0)
            }),
            Model::LogExpRr(_) => each!(ts, out, |c| {
                let y = n * log2(c);
                let k = y.ceil();
                let r = 1.0 - 0.5 * log2(1.0 - (y - k));
                // 2^k from its exponent field (k is integral, at most 0); 0 below the normals.
                let scale = f32::from_bits(((k.max(-127.0) + 127.0) as u32) << 23);
                if k > -127.0 {
                    r * scale
                } else {
                    0.0
                }
            }),
            Model::CosQuad(m) => {
                let slope = m.slope() as f32;
                with_squarings!(m.squarings(), cosquad, ts, out, slope);
            }
        }
    }
}

fn kernel(arch: pulp::Arch, lobe: &Lobe, ts: &[f32], out: &mut [f32]) {
    arch.dispatch(Job { lobe, ts, out });
}

impl Lobe {
    /// The lobe at every cosine of `ts`, into `out`, vectorised (see the module docs for how
    /// it relates to [`Lobe::eval`]).
    ///
    /// # Panics
    /// If `ts` and `out` differ in length.
    pub fn eval_batch(&self, ts: &[f32], out: &mut [f32]) {
        assert_eq!(ts.len(), out.len(), "eval_batch: one output per cosine");
        kernel(pulp::Arch::new(), self, ts, out);
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
        let arch = pulp::Arch::new();
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
                kernel(arch, self, &ts[..chunk.len()], chunk);
            }
        }
    }

    /// The largest difference, in ULPs of 1 (`2^-23`), between [`Lobe::eval_batch`] and the
    /// scalar `f32` [`Lobe::eval`] at the same cosine.
    #[must_use]
    pub fn batch_ulp_bound(&self) -> f64 {
        let n = self.n.get();
        match self.model {
            Model::Schlick(_) | Model::SchlickMod(_) | Model::CosQuad(_) => 0.0,
            // exp2(n log2 t): log2's error is multiplied by n.
            Model::Pow(_) | Model::LogExp(_) | Model::LogExpRr(_) => 8.0 + 2.0 * n,
            // acos within 2.5e-7 rad, times the quadratic's slope (at most ~2n^(1/2) per rad).
            Model::AngleQuadratic(_) => 16.0 + 8.0 * n.sqrt(),
        }
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

    /// The dispatched (SIMD) loop and the same loop compiled without SIMD agree bit for bit:
    /// vectorisation changes speed, not results.
    #[test]
    fn simd_and_scalar_compilations_agree_bitwise() {
        let ts: Vec<f32> = (0..4099)
            .map(|i| 1.0 - (i as f32 / 4099.0).powi(2))
            .collect();
        for kind in LobeKind::ALL {
            for n in [1.0, 9.5, 100.0, 1000.0] {
                let lobe = Lobe::new(kind, Exponent::new(n));
                let mut simd = vec![0.0; ts.len()];
                let mut scalar = vec![0.0; ts.len()];
                lobe.eval_batch(&ts, &mut simd);
                kernel(pulp::Arch::Scalar, &lobe, &ts, &mut scalar);
                let same = simd
                    .iter()
                    .zip(&scalar)
                    .all(|(a, b)| a.to_bits() == b.to_bits());
                assert!(same, "{kind} n = {n}");
            }
        }
    }
}
