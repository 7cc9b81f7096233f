//! A tabulated lobe's cosine distribution in `f32`, for renderers that shade in `f32`: the
//! same table as [`CosineDistribution`]'s (the lobe at each bin edge, the bins' trapezoid
//! masses), with the edges' cosines stored rather than recomputed, so that a draw is a
//! search and a square root and a density an `acos` and a square root, where the `f64`
//! path spends two `cos` on each. Its draws and its density agree with each other (the same
//! piecewise-linear density), so an estimator that uses both stays unbiased.

use super::cosine::{draw_from_table, CosineDistribution, TABLE_BINS};

/// [`CosineDistribution`]'s table in `f32` ([`CosineDistribution::table32`]).
#[derive(Clone, Debug)]
pub struct CosineTable32 {
    /// The cosine at each edge, from the peak (`edges[0] = 1`) to the horizon (0).
    edges: Vec<f32>,
    /// The lobe at each edge.
    values: Vec<f32>,
    /// The mass from the peak to each edge.
    cumulative: Vec<f32>,
    total: f32,
}

impl CosineTable32 {
    pub(super) fn new(edges: Vec<f32>, values: Vec<f32>, cumulative: Vec<f32>) -> Self {
        let total = cumulative[TABLE_BINS];
        Self {
            edges,
            values,
            cumulative,
            total,
        }
    }

    /// The cosine for the uniform number `u` in `[0, 1)`: [`CosineDistribution::sample`].
    #[must_use]
    pub fn sample(&self, u: f32) -> f32 {
        // NaN draws as 0.
        let u = if u.is_nan() { 0.0 } else { u.clamp(0.0, 1.0) };
        draw_from_table(
            &self.cumulative,
            &self.values,
            |k| self.edges[k],
            u * self.total,
        )
    }

    /// The density of the cosine at `t`: [`CosineDistribution::density`].
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

impl CosineDistribution {
    /// The table in `f32`, for a tabulated lobe ([`crate::lobe::Warp::Table`]).
    #[must_use]
    pub fn table32(&self) -> Option<CosineTable32> {
        self.table_parts().map(|(edges, values, cumulative)| {
            let narrow = |v: Vec<f64>| v.into_iter().map(|x| x as f32).collect();
            CosineTable32::new(narrow(edges), narrow(values), narrow(cumulative))
        })
    }
}

#[cfg(test)]
mod tests {
    use crate::{Exponent, Lobe, LobeKind};

    use super::*;

    /// Its draws and its density are the `f64` table's, to `f32` rounding: the same cosine
    /// for the same number, the same density at the same cosine (a second implementation of
    /// one table, checked against the first).
    #[test]
    fn the_f32_table_is_the_f64_table() {
        let mut tables = 0;
        for kind in LobeKind::ALL {
            for n in [2.0, 32.0, 500.0] {
                let distribution = CosineDistribution::new(Lobe::new(kind, Exponent::new(n)));
                let Some(table) = distribution.table32() else {
                    continue;
                };
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
}
