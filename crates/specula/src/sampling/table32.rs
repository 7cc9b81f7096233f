//! A lobe's cosine distribution tabulated in `f32`, for renderers that shade in `f32`: the
//! table [`CosineDistribution`](super::CosineDistribution) draws a tabulated lobe from (the lobe at
//! each bin edge, the
//! bins' trapezoid masses), built for any lobe, with the edges' cosines stored rather than
//! recomputed and a guide that finds a mass's bin in a step or two: a draw costs a square
//! root and a density an `acos` and a square root, where the `f64` path spends two `cos`, a
//! binary search, or Newton's iterations of the lobe's integral. Its draws and its density
//! agree with each other (one piecewise-linear density), so an estimator that uses both
//! stays unbiased.

use super::cosine::{bin_of_mass, draw_in_bin, edge, tabulate, TABLE_BINS};
use crate::simd::{BatchLoop, Drive, Kernel, Lanes};
use crate::Lobe;

/// Cells of the guide: cell `g` holds the masses from `g / GUIDE` to `(g + 1) / GUIDE` of the
/// total.
const GUIDE: usize = 1024;

/// A lobe's cosine table in `f32` ([`CosineTable32::of`]).
#[derive(Clone, Debug)]
pub struct CosineTable32 {
    /// The cosine at each edge, from the peak (`edges[0] = 1`) to the horizon (0).
    edges: Vec<f32>,
    /// The lobe at each edge.
    values: Vec<f32>,
    /// The mass from the peak to each edge.
    cumulative: Vec<f32>,
    total: f32,
    /// Per guide cell, a bin at or before the one holding the cell's smallest mass.
    guide: Vec<u16>,
}

impl CosineTable32 {
    /// `lobe`'s table: the same edges, values and masses as
    /// [`CosineDistribution`](super::CosineDistribution)'s for a
    /// tabulated lobe.
    #[must_use]
    pub fn of(lobe: &Lobe) -> Self {
        let (values, cumulative) = tabulate(lobe);
        let narrow = |v: &[f64]| v.iter().map(|&x| x as f32).collect::<Vec<f32>>();
        let (values, cumulative) = (narrow(&values), narrow(&cumulative));
        let total = cumulative[TABLE_BINS];
        // One bin back from where the cell's first mass falls, so that rounding in
        // `u * total` never starts a search past its bin.
        let guide = (0..GUIDE)
            .map(|g| {
                let mass = g as f32 / GUIDE as f32 * total;
                bin_of_mass(&cumulative, mass).saturating_sub(1) as u16
            })
            .collect();
        Self {
            edges: (0..=TABLE_BINS).map(|k| edge(k) as f32).collect(),
            values,
            cumulative,
            total,
            guide,
        }
    }

    /// The cosine for the uniform number `u` in `[0, 1)`, as
    /// [`CosineDistribution::sample`](super::CosineDistribution::sample)
    /// draws a tabulated lobe.
    #[must_use]
    pub fn sample(&self, u: f32) -> f32 {
        // NaN draws as 0.
        let u = if u.is_nan() { 0.0 } else { u.clamp(0.0, 1.0) };
        let target = u * self.total;
        let cell = ((u * GUIDE as f32) as usize).min(GUIDE - 1);
        let mut k = usize::from(self.guide[cell]);
        while k < TABLE_BINS - 1 && self.cumulative[k + 1] <= target {
            k += 1;
        }
        draw_in_bin(k, &self.cumulative, &self.values, |k| self.edges[k], target)
    }

    /// The density of the cosine at `t`, as
    /// [`CosineDistribution::density`](super::CosineDistribution::density) reads a
    /// tabulated lobe's.
    #[must_use]
    pub fn density(&self, t: f32) -> f32 {
        let angle = t.acos() / core::f32::consts::FRAC_PI_2;
        self.density_near(t, (angle.sqrt() * TABLE_BINS as f32) as usize)
    }

    /// [`CosineTable32::density`] of every `ts[i]` into `out[i]`, the same values: each
    /// cosine's bin estimated on SIMD lanes (a polynomial `acos`, no library call), then its
    /// line read lane by lane.
    ///
    /// # Panics
    /// If the slices' lengths differ.
    pub fn density_batch(&self, ts: &[f32], out: &mut [f32]) {
        assert_eq!(ts.len(), out.len(), "one density per cosine");
        crate::simd::dispatch(
            crate::simd::Level::detect(),
            Drive {
                kernel: BinEstimate,
                ts,
                out,
                batch_loop: BatchLoop::Explicit,
            },
        );
        for (&t, estimate) in ts.iter().zip(out) {
            *estimate = self.density_near(t, *estimate as usize);
        }
    }

    /// The density at `t` from an estimate of its bin that is right to within one.
    fn density_near(&self, t: f32, estimate: usize) -> f32 {
        if !(t > 0.0 && t <= 1.0) || self.total <= 0.0 {
            return 0.0;
        }
        let mut k = estimate.min(TABLE_BINS - 1);
        // `acos` and the square root may round `t` into a neighbouring bin.
        if t > self.edges[k] && k > 0 {
            k -= 1;
        } else if t < self.edges[k + 1] && k + 1 < TABLE_BINS {
            k += 1;
        }
        let (high, low) = (self.edges[k], self.edges[k + 1]);
        let s = ((high - t) / (high - low)).clamp(0.0, 1.0);
        ((1.0 - s) * self.values[k] + s * self.values[k + 1]) / self.total
    }
}

/// The bin of a cosine in `(0, 1]`, to within one: `sqrt(acos(t) / (pi/2))` of the bins.
#[derive(Clone, Copy)]
struct BinEstimate;

impl Kernel for BinEstimate {
    #[inline(always)]
    fn eval_lanes<V: Lanes>(self, t: V) -> V {
        let c = |value: f32| t.splat(value);
        // NaN and cosines out of range land in a bin; `density_near` gives them 0.
        let t = t.max(c(0.0)).min(c(1.0));
        let angle = crate::simd::math::acos(t) * c(core::f32::consts::FRAC_2_PI);
        (angle.sqrt() * c(TABLE_BINS as f32))
            .min(c(TABLE_BINS as f32 - 1.0))
            .max(c(0.0))
            .float_to_int()
            .int_to_float()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sampling::CosineDistribution;
    use crate::{Exponent, LobeKind};

    /// For a tabulated lobe, its draws and its density are the `f64` table's, to `f32`
    /// rounding: the same cosine for the same number, the same density at the same cosine (a
    /// second implementation of one table, checked against the first).
    #[test]
    fn the_f32_table_is_the_f64_table() {
        let mut tables = 0;
        for kind in LobeKind::ALL {
            for n in [2.0, 32.0, 500.0] {
                let lobe = Lobe::new(kind, Exponent::new(n));
                let distribution = CosineDistribution::new(lobe);
                if distribution.warp() != crate::lobe::Warp::Table {
                    continue;
                }
                let table = CosineTable32::of(&lobe);
                tables += 1;
                for i in 0..2000 {
                    let u = (i as f64 + 0.5) / 2000.0;
                    let (wide, narrow) = (distribution.sample(u).x, table.sample(u as f32));
                    assert!(
                        (wide - f64::from(narrow)).abs() <= 2e-5,
                        "{kind} n = {n} u = {u}: {narrow} against {wide}"
                    );
                    let t = f64::from(narrow);
                    let (wide, narrow) = (distribution.density(t), table.density(narrow));
                    assert!(
                        (wide - f64::from(narrow)).abs() <= 1e-3 * wide.max(1.0),
                        "{kind} n = {n} t = {t}: density {narrow} against {wide}"
                    );
                }
                // The batch gives the same densities, out-of-range cosines included.
                let ts: Vec<f32> = (0..2000)
                    .map(|i| table.sample((i as f32 + 0.5) / 2000.0))
                    .chain([
                        0.0,
                        -0.5,
                        1.0,
                        1.5,
                        f32::NAN,
                        f32::MIN_POSITIVE,
                        1.0 - f32::EPSILON,
                    ])
                    .collect();
                let mut batch = vec![0.0; ts.len()];
                table.density_batch(&ts, &mut batch);
                for (&t, &density) in ts.iter().zip(&batch) {
                    assert_eq!(
                        density.to_bits(),
                        table.density(t).to_bits(),
                        "{kind} n = {n} t = {t}"
                    );
                }
                assert_eq!(table.density(0.0), 0.0);
                assert_eq!(table.density(f32::NAN), 0.0);
                assert!(table.sample(f32::NAN).is_finite());
            }
        }
        assert!(tables >= 3, "only {tables} tabulated lobes");
    }

    /// A Newton-sampled lobe drawn for an `f32` renderer, Newton starting from its table's
    /// draw and stopping at `f32` resolution, gives the `f32` its exact draw rounds to, in
    /// fewer than 2.5 iterations on average where the `f64` draw from the model's guess
    /// takes more (a root at the seam of a tail's series and its closed form takes
    /// bisections from either start).
    #[test]
    fn newton_from_the_tables_draw_is_the_exact_draw_in_f32() {
        let mut lobes = 0;
        for kind in LobeKind::ALL {
            for n in [2.0, 32.0, 500.0] {
                let lobe = Lobe::new(kind, Exponent::new(n));
                if lobe.warp() != crate::lobe::Warp::Newton {
                    continue;
                }
                lobes += 1;
                let table = CosineTable32::of(&lobe);
                let (mut fast, mut exact) = (0, 0);
                for i in 0..5000 {
                    let u = (f64::from(i) + 0.5) / 5000.0;
                    let near = f64::from(table.sample(u as f32));
                    let drawn = lobe.tail_inverse_f32(u, near).unwrap();
                    let reference = lobe.tail_inverse(u).unwrap();
                    assert_eq!(drawn.x as f32, reference.x as f32, "{kind} n = {n} u = {u}");
                    (fast, exact) = (fast + drawn.iterations, exact + reference.iterations);
                }
                assert!(
                    fast < exact,
                    "{kind} n = {n}: {fast} iterations against {exact}"
                );
            }
        }
        assert!(lobes >= 2, "only {lobes} Newton-sampled lobes");
    }

    /// For any lobe (a Newton-sampled one too), the draws follow the table's own density:
    /// the fraction of 200,000 draws in each of 40 cosine intervals matches the density's
    /// integral over it (by the trapezoid rule on a fine grid) within 4 standard errors.
    #[test]
    fn the_draws_follow_the_tables_density() {
        for kind in [LobeKind::Schlick, LobeKind::Cheb2, LobeKind::LogExp] {
            let table = CosineTable32::of(&Lobe::new(kind, Exponent::new(16.0)));
            let draws = 200_000;
            let mut counts = [0_u32; 40];
            for i in 0..draws {
                let t = table.sample((i as f32 + 0.5) / draws as f32);
                counts[((t * 40.0) as usize).min(39)] += 1;
            }
            for (bin, &count) in counts.iter().enumerate() {
                let steps = 400;
                let expected: f64 = (0..steps)
                    .map(|s| {
                        let t = (bin as f64 + (s as f64 + 0.5) / steps as f64) / 40.0;
                        f64::from(table.density(t as f32)) / (40.0 * steps as f64)
                    })
                    .sum();
                let observed = f64::from(count) / f64::from(draws);
                let error = (expected.max(1e-7) / f64::from(draws)).sqrt();
                assert!(
                    (observed - expected).abs() <= 4.0 * error + 1e-4,
                    "{kind} bin {bin}: {observed} drawn, {expected} expected"
                );
            }
        }
    }
}
