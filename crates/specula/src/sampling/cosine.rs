//! The lobe as a distribution of its cosine: `t` in `[0, 1]` with density `lobe(t) / L`,
//! `L = int_0^1 lobe`. Rotating it about an axis with a uniform azimuth gives directions
//! whose solid-angle density is `lobe(t) / (2 pi L)`, the lobe itself, normalised.

use std::sync::Arc;

use crate::lobe::{Inverted, Warp};
use crate::real::Real;
use crate::{zones, Lobe};

/// Bins of a tabulated lobe. Their edges are at angles `(pi/2) (k / BINS)^2`, dense near the
/// peak: at `n = 1000` (epicentre 0.037 rad) about 80 bins span the epicentre. Within a bin
/// the density is linear in `t` between the lobe's values at the edges (so it is continuous,
/// and the sampler's own density, which is all unbiasedness needs) and is drawn by solving
/// that bin's quadratic CDF.
pub const TABLE_BINS: usize = 1024;

/// A lobe prepared for sampling its cosine.
#[derive(Clone, Debug)]
pub struct CosineDistribution {
    lobe: Lobe,
    /// `int_0^1 lobe(t) dt`.
    total: f64,
    /// For a [`Warp::Table`] lobe: the lobe at each edge, and the cumulative mass at each
    /// edge from the peak (`TABLE_BINS + 1` values each).
    table: Option<Arc<Table>>,
}

#[derive(Debug)]
struct Table {
    values: Vec<f64>,
    cumulative: Vec<f64>,
}

/// The cosine at table edge `k` (`k = 0` is the peak, `t = 1`).
pub(super) fn edge(k: usize) -> f64 {
    if k >= TABLE_BINS {
        return 0.0;
    }
    let fraction = k as f64 / TABLE_BINS as f64;
    (core::f64::consts::FRAC_PI_2 * fraction * fraction).cos()
}

/// The table bin holding cosine `t` in `[0, 1]`.
fn bin_of(t: f64) -> usize {
    let angle = t.clamp(0.0, 1.0).acos() / core::f64::consts::FRAC_PI_2;
    ((angle.sqrt() * TABLE_BINS as f64) as usize).min(TABLE_BINS - 1)
}

/// The bin in which a table's mass from the peak reaches `target`: the first whose upper
/// cumulative value exceeds it, skipping empty bins.
pub(super) fn bin_of_mass<R: Real>(cumulative: &[R], target: R) -> usize {
    cumulative[1..]
        .partition_point(|&c| c <= target)
        .min(TABLE_BINS - 1)
}

/// The cosine in bin `k` at which a table's mass from the peak reaches `target`: the root of
/// the bin's quadratic CDF. Generic, so that the `f64` table and its `f32` copy
/// ([`super::CosineTable32`]) draw alike.
pub(super) fn draw_in_bin<R: Real>(
    k: usize,
    cumulative: &[R],
    values: &[R],
    edges: impl Fn(usize) -> R,
    target: R,
) -> R {
    let (zero, one) = (R::from_f64(0.0), R::from_f64(1.0));
    let (below, mass) = (cumulative[k], cumulative[k + 1] - cumulative[k]);
    let xi = if mass > zero {
        ((target - below) / mass).max(zero).min(one)
    } else {
        R::from_f64(0.5)
    };
    // The density falls linearly from `a` at the bin's upper edge to `b`: its CDF
    // (a s + (b - a) s^2 / 2) / ((a + b) / 2) = xi, solved without cancellation.
    let (a, b) = (values[k], values[k + 1]);
    let root = (a * a + xi * (b * b - a * a)).max(zero).sqrt();
    let s = if a + root > zero {
        (xi * (a + b) / (a + root)).max(zero).min(one)
    } else {
        xi
    };
    let (high, low) = (edges(k), edges(k + 1));
    high - s * (high - low)
}

/// `lobe` at every edge, and the cumulative trapezoid masses from the peak to each edge.
pub(super) fn tabulate(lobe: &Lobe) -> (Vec<f64>, Vec<f64>) {
    let values: Vec<f64> = (0..=TABLE_BINS).map(|k| lobe.eval(edge(k))).collect();
    let mut cumulative = Vec::with_capacity(TABLE_BINS + 1);
    cumulative.push(0.0);
    let mut sum = 0.0;
    for k in 0..TABLE_BINS {
        sum += 0.5 * (values[k] + values[k + 1]) * (edge(k) - edge(k + 1));
        cumulative.push(sum);
    }
    (values, cumulative)
}

impl CosineDistribution {
    /// Prepares `lobe`: its total from the closed form, or, for a tabulated lobe, the lobe
    /// at every edge and the bins' trapezoid masses.
    #[must_use]
    pub fn new(lobe: Lobe) -> Self {
        if let Some(total) = lobe.tail(0.0) {
            return Self {
                lobe,
                total,
                table: None,
            };
        }
        let (values, cumulative) = tabulate(&lobe);
        Self {
            lobe,
            total: cumulative[TABLE_BINS],
            table: Some(Arc::new(Table { values, cumulative })),
        }
    }

    /// The lobe.
    #[must_use]
    pub fn lobe(&self) -> &Lobe {
        &self.lobe
    }

    /// How the cosine is drawn.
    #[must_use]
    pub fn warp(&self) -> Warp {
        if self.table.is_some() {
            Warp::Table
        } else {
            self.lobe.warp()
        }
    }

    /// `int_0^1 lobe(t) dt` (for a table, its trapezoid sum, the integral of its density).
    #[must_use]
    pub fn total(&self) -> f64 {
        self.total
    }

    /// The cosine for the uniform number `u` in `[0, 1)`, and the Newton iterations spent.
    #[must_use]
    pub fn sample(&self, u: f64) -> Inverted {
        let u = u.clamp(0.0, 1.0);
        match &self.table {
            None => self.lobe.tail_inverse(u).unwrap_or(Inverted {
                x: 1.0,
                iterations: 0,
            }),
            Some(table) => {
                let target = u * self.total;
                let k = bin_of_mass(&table.cumulative, target);
                let x = draw_in_bin(k, &table.cumulative, &table.values, edge, target);
                Inverted { x, iterations: 0 }
            }
        }
    }

    /// The density of the cosine at `t`: `lobe(t) / L`, or the table's, linear between the
    /// lobe's values at the edges of `t`'s bin.
    #[must_use]
    pub fn density(&self, t: f64) -> f64 {
        if !(t > 0.0 && t <= 1.0) || self.total <= 0.0 {
            return 0.0;
        }
        match &self.table {
            None => self.lobe.eval(t) / self.total,
            Some(table) => {
                let k = bin_of(t);
                let (high, low) = (edge(k), edge(k + 1));
                let s = ((high - t) / (high - low)).clamp(0.0, 1.0);
                ((1.0 - s) * table.values[k] + s * table.values[k + 1]) / self.total
            }
        }
    }

    /// The angle from the axis within which the lobe's sampled directions mostly fall (its
    /// epicentre, `t^n = 1/2`): the scale of a histogram that resolves it.
    #[must_use]
    pub fn width(&self) -> f64 {
        zones::epicentre_angle(self.lobe.exponent())
    }
}
