//! A lobe's cosine distribution tabulated in `f32`, for renderers that shade in `f32`: the
//! table [`CosineDistribution`](super::CosineDistribution) draws a tabulated lobe from (the lobe at each bin edge, the
//! bins' trapezoid masses), built for any lobe, with the edges' cosines stored rather than
//! recomputed and a guide that finds a mass's bin in a step or two: a draw costs a square
//! root and a density an `acos` and a square root, where the `f64` path spends two `cos`, a
//! binary search, or Newton's iterations of the lobe's integral. Its draws and its density
//! agree with each other (one piecewise-linear density), so an estimator that uses both
//! stays unbiased.

use super::cosine::{bin_of_mass, draw_in_bin, edge, tabulate, TABLE_BINS};
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
    /// `lobe`'s table: the same edges, values and masses as [`CosineDistribution`](super::CosineDistribution)'s for a
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

    /// The cosine for the uniform number `u` in `[0, 1)`, as [`CosineDistribution::sample`](super::CosineDistribution::sample)
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

    /// The density of the cosine at `t`, as [`CosineDistribution::density`](super::CosineDistribution::density) reads a
    /// tabulated lobe's.
    #[must_use]
    pub fn density(&self, t: f32) -> f32 {
        if !(t > 0.0 && t <= 1.0) || self.total <= 0.0 {
            return 0.0;
        }
        let angle = t.acos() / core::f32::consts::FRAC_PI_2;
        let mut k = ((angle.sqrt() * TABLE_BINS as f32) as usize).min(TABLE_BINS - 1);
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
                assert_eq!(table.density(0.0), 0.0);
                assert_eq!(table.density(f32::NAN), 0.0);
                assert!(table.sample(f32::NAN).is_finite());
            }
        }
        assert!(tables >= 3, "only {tables} tabulated lobes");
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
