//! The closed-form draw over a slice of uniforms: [`Lobe::closed_form_sampling`]'s inverse
//! tail on SIMD lanes, for the renderers that draw many cosines of one lobe at once.
//!
//! Each model's draw kernel lives in its own file beside its scalar inverse (`PowDraw` in
//! `pow.rs`, and so on): `log2` and `exp2` by the kernels' polynomials where the scalar path
//! calls `ln_1p`, `exp` and `expm1`, within [`Lobe::tail_inverse_batch_bound`] of the `f64`
//! inverse (tested).

use super::batch::ModelF32;
use super::{Lobe, Model};
use crate::simd::{dispatch, BatchLoop, Drive, Kernel, Lanes, Level};

/// The share of a lobe's integral beyond the drawn point, `(1 - u) + u floor`, for a
/// uniform `u` and the share `floor` left at `t = 0`: `1 - u` is exact for the samplers'
/// 24-bit uniforms, so the sum keeps its relative precision where it is tiny (the form
/// `1 - u (1 - floor)` in `f32` would not). Raised to the smallest normal where it reaches
/// 0, which `log2` takes.
#[inline(always)]
pub(crate) fn remaining_share<V: Lanes>(u: V, floor: f32) -> V {
    u.mul_add(u.splat(floor), u.splat(1.0) - u)
        .max(u.splat(f32::MIN_POSITIVE))
}

/// Runs `kernel` over `us` into `out` on `level`'s lanes.
pub(crate) fn run<K: Kernel>(level: Level, kernel: K, us: &[f32], out: &mut [f32]) {
    let job = Drive {
        kernel,
        ts: us,
        out,
        batch_loop: BatchLoop::Explicit,
    };
    dispatch(level, job);
}

impl Lobe {
    /// For a lobe sampled in closed form ([`super::Warp::Analytic`]): the cosine whose tail
    /// is the fraction `us[i]` of the whole, into `out[i]`, on `level`'s lanes; `false`, with
    /// `out` untouched, for a lobe without a closed-form inverse.
    ///
    /// # Panics
    /// If `us` and `out` differ in length, or `level` is not available on this CPU.
    pub fn tail_inverse_batch(&self, level: Level, us: &[f32], out: &mut [f32]) -> bool {
        assert_eq!(
            us.len(),
            out.len(),
            "tail_inverse_batch: one cosine per uniform"
        );
        each_model!(&self.model, m => m.draw_batch(level, us, out))
    }

    /// The largest difference between [`Lobe::tail_inverse_batch`]'s cosine and the `f64`
    /// inverse at the same uniform, over the uniforms a sampler draws (multiples of `2^-24`
    /// in `[0, 1)`): the base's few roundings near 1 (3 ULP of 1 at most), through the
    /// inverse's slope in it, 1 but for `cosquad`'s `1 / a` where its slope `a` is below 1.
    #[must_use]
    pub fn tail_inverse_batch_bound(&self) -> f64 {
        3.0 * f64::from(f32::EPSILON) / each_model!(&self.model, m => m.draw_batch_slope())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::lobe::Warp;
    use crate::{Exponent, LobeKind};

    /// Every lobe with a closed-form inverse draws on lanes, at every level, within
    /// its stated bound of the `f64` inverse, inside `[0, 1]`; every other lobe declines.
    #[test]
    fn the_lanes_draw_what_the_f64_inverse_does() {
        // Uniforms on the samplers' 24-bit grid, dense at both ends.
        let us: Vec<f32> = (0..4096)
            .map(|i| i as f32 / 4096.0)
            .chain((1..=64).map(|i| 1.0 - i as f32 * (1.0 / (1 << 24) as f32)))
            .chain((1..=64).map(|i| i as f32 * (1.0 / (1 << 24) as f32)))
            .collect();
        let kinds = LobeKind::ALL
            .into_iter()
            .chain((0..=10).map(|v| LobeKind::CosQuad { v }));
        for kind in kinds {
            for n in [1.0, 2.0, 9.5, 64.0, 300.0, 1000.0] {
                let lobe = Lobe::new(kind, Exponent::new(n));
                for level in Level::available() {
                    let mut out = vec![f32::NAN; us.len()];
                    let drawn = lobe.tail_inverse_batch(level, &us, &mut out);
                    assert_eq!(drawn, lobe.warp() == Warp::Analytic, "{kind}");
                    if !drawn {
                        assert!(out.iter().all(|t| t.is_nan()), "{kind}: out was written");
                        continue;
                    }
                    let bound = lobe.tail_inverse_batch_bound();
                    for (&u, &t) in us.iter().zip(&out) {
                        let (expected, _) = lobe.closed_form_sampling(f64::from(u)).unwrap();
                        assert!(
                            (f64::from(t) - expected).abs() <= bound && (0.0..=1.0).contains(&t),
                            "{kind} n = {n} {level:?} u = {u}: {t} against {expected}"
                        );
                    }
                }
            }
        }
    }
}
