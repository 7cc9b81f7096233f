//! Piecewise-constant distributions over `[0, 1)` and `[0, 1)^2`, for sampling what is
//! tabulated (an environment map's radiance) in proportion to its weights, as pbrt's
//! `PiecewiseConstant1D` and `2D` do.
//!
//! A 2D distribution is a marginal over rows and one conditional per row: a draw picks a row
//! by `u[1]`, then a column within it by `u[0]`, each by inverting its cumulative sum, and the
//! density of a point is its cell's weight over the mean weight. Inversion is continuous
//! within a cell, so stratified or low-discrepancy `u` stays so in the output.

/// The largest `f64` below 1.
const ONE_BELOW: f64 = 1.0 - f64::EPSILON / 2.0;

/// A distribution over `[0, 1)` whose density is constant on each of `n` equal cells, in
/// proportion to the cell's weight.
#[derive(Clone, Debug, PartialEq)]
pub struct Distribution1D {
    /// Cumulative weights, normalised: `cdf[0] = 0`, `cdf[n] = 1`.
    cdf: Vec<f64>,
    /// Each cell's density (its weight over the mean weight).
    density: Vec<f64>,
}

/// A draw from a [`Distribution1D`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Draw1D {
    /// The point in `[0, 1)`.
    pub x: f64,
    /// Its density.
    pub pdf: f64,
    /// The cell it lies in.
    pub cell: usize,
}

impl Distribution1D {
    /// The distribution with these cell weights, or `None` when there are none, or one is
    /// negative or not finite. All-zero weights give the uniform distribution (the draw must
    /// land somewhere; a zero map is then sampled as a constant one).
    #[must_use]
    pub fn new(weights: &[f64]) -> Option<Self> {
        let total = super::weights_total(weights)?;
        let n = weights.len() as f64;
        let (weights, total) = if total > 0.0 {
            (weights.to_vec(), total)
        } else {
            (vec![1.0; weights.len()], n)
        };
        let mut cdf = Vec::with_capacity(weights.len() + 1);
        let mut running = 0.0;
        cdf.push(0.0);
        for w in &weights {
            running += w;
            cdf.push(running / total);
        }
        *cdf.last_mut()? = 1.0;
        let density = weights.iter().map(|w| w * n / total).collect();
        Some(Self { cdf, density })
    }

    /// The number of cells.
    #[must_use]
    pub fn cells(&self) -> usize {
        self.density.len()
    }

    /// The density at `x` in `[0, 1)` (0 outside).
    #[must_use]
    pub fn pdf(&self, x: f64) -> f64 {
        if !(0.0..1.0).contains(&x) {
            return 0.0;
        }
        let cell = ((x * self.cells() as f64) as usize).min(self.cells() - 1);
        self.density[cell]
    }

    /// The point for the uniform number `u` in `[0, 1)`: the inverse of the cumulative
    /// distribution, linear within a cell. Cells of zero weight are never returned.
    #[must_use]
    pub fn sample(&self, u: f64) -> Draw1D {
        let u = u.clamp(0.0, ONE_BELOW);
        // The cell with `cdf[cell] <= u < cdf[cell + 1]`: its weight is positive.
        let cell = self.cdf.partition_point(|&c| c <= u) - 1;
        let (start, end) = (self.cdf[cell], self.cdf[cell + 1]);
        let within = ((u - start) / (end - start)).clamp(0.0, 1.0);
        let n = self.cells() as f64;
        let x = ((cell as f64 + within) / n).min(ONE_BELOW);
        Draw1D {
            x,
            pdf: self.density[cell],
            cell,
        }
    }
}

/// A distribution over `[0, 1)^2` whose density is constant on each cell of a
/// `columns x rows` grid, in proportion to the cell's weight.
#[derive(Clone, Debug, PartialEq)]
pub struct Distribution2D {
    rows: Vec<Distribution1D>,
    marginal: Distribution1D,
}

/// A draw from a [`Distribution2D`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Draw2D {
    /// The point: `[x, y]` in `[0, 1)^2`.
    pub point: [f64; 2],
    /// Its density.
    pub pdf: f64,
}

impl Distribution2D {
    /// The distribution of `weights`, row-major with `columns` per row, or `None` when the
    /// grid is empty or ragged or a weight is negative or not finite.
    #[must_use]
    pub fn new(weights: &[f64], columns: usize) -> Option<Self> {
        if columns == 0 || weights.is_empty() || !weights.len().is_multiple_of(columns) {
            return None;
        }
        let rows: Vec<Distribution1D> = weights
            .chunks_exact(columns)
            .map(Distribution1D::new)
            .collect::<Option<_>>()?;
        let row_sums: Vec<f64> = weights
            .chunks_exact(columns)
            .map(|row| row.iter().sum())
            .collect();
        let marginal = Distribution1D::new(&row_sums)?;
        Some(Self { rows, marginal })
    }

    /// The density at `point` (0 outside the unit square).
    #[must_use]
    pub fn pdf(&self, [x, y]: [f64; 2]) -> f64 {
        if !(0.0..1.0).contains(&x) || !(0.0..1.0).contains(&y) {
            return 0.0;
        }
        let row = ((y * self.rows.len() as f64) as usize).min(self.rows.len() - 1);
        self.marginal.pdf(y) * self.rows[row].pdf(x)
    }

    /// The point for the uniform numbers `u`: the row from `u[1]`, the column from `u[0]`.
    #[must_use]
    pub fn sample(&self, u: [f64; 2]) -> Draw2D {
        let row = self.marginal.sample(u[1]);
        let column = self.rows[row.cell].sample(u[0]);
        Draw2D {
            point: [column.x, row.x],
            pdf: row.pdf * column.pdf,
        }
    }
}

/// Veach's power heuristic (exponent 2): the weight of a sample drawn with density `pdf`
/// when the other strategy would have drawn it with density `other`, each with one sample.
#[must_use]
pub fn power_heuristic(pdf: f64, other: f64) -> f64 {
    let (a, b) = (pdf * pdf, other * other);
    if a == 0.0 {
        return 0.0;
    }
    if !b.is_finite() {
        return 0.0;
    }
    if !a.is_finite() {
        return 1.0;
    }
    a / (a + b)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_draw_lands_in_proportion_to_the_weights() {
        let distribution = Distribution1D::new(&[1.0, 0.0, 3.0]).unwrap();
        // Cumulative 0, 1/4, 1/4, 1: u below 1/4 is the first cell, above is the third.
        assert_eq!(distribution.sample(0.1).cell, 0);
        assert_eq!(distribution.sample(0.25).cell, 2);
        assert_eq!(distribution.sample(0.9).cell, 2);
        let draw = distribution.sample(0.625);
        assert!((draw.x - (2.0 + 0.5) / 3.0).abs() < 1e-12, "{draw:?}");
        assert!((draw.pdf - 3.0 * 3.0 / 4.0).abs() < 1e-12);
        assert_eq!(distribution.pdf(0.5), 0.0);
        assert!((distribution.pdf(0.1) - 0.75).abs() < 1e-12);
    }

    #[test]
    fn zero_weights_are_uniform_and_bad_weights_refused() {
        let distribution = Distribution1D::new(&[0.0, 0.0]).unwrap();
        assert_eq!(distribution.pdf(0.3), 1.0);
        assert!((distribution.sample(0.75).x - 0.75).abs() < 1e-12);
        assert!(Distribution1D::new(&[]).is_none());
        assert!(Distribution1D::new(&[1.0, f64::NAN]).is_none());
        assert!(Distribution1D::new(&[1.0, -1.0]).is_none());
        assert!(Distribution1D::new(&[f64::MAX, f64::MAX]).is_none());
        assert!(Distribution2D::new(&[1.0, 2.0, 3.0], 2).is_none());
        assert!(Distribution2D::new(&[1.0], 0).is_none());
    }

    #[test]
    fn the_2d_density_is_the_cell_weight_over_the_mean_and_matches_the_draw() {
        let weights = [1.0, 2.0, 0.0, 5.0, 4.0, 3.0];
        let distribution = Distribution2D::new(&weights, 3).unwrap();
        let mean = weights.iter().sum::<f64>() / weights.len() as f64;
        for (index, w) in weights.iter().enumerate() {
            let centre = [
                (index % 3) as f64 / 3.0 + 1.0 / 6.0,
                (index / 3) as f64 / 2.0 + 0.25,
            ];
            assert!(
                (distribution.pdf(centre) - w / mean).abs() < 1e-12,
                "cell {index}"
            );
        }
        for i in 0..64 {
            let u = [(i as f64 + 0.5) / 64.0, ((i * 37) % 64) as f64 / 64.0];
            let draw = distribution.sample(u);
            assert!(
                (draw.pdf - distribution.pdf(draw.point)).abs() < 1e-12,
                "{u:?}"
            );
            assert!(draw.pdf > 0.0);
        }
    }

    #[test]
    fn the_power_heuristic_splits_one() {
        assert!((power_heuristic(1.0, 3.0) + power_heuristic(3.0, 1.0) - 1.0).abs() < 1e-15);
        assert_eq!(power_heuristic(2.0, 0.0), 1.0);
        assert_eq!(power_heuristic(0.0, 2.0), 0.0);
        assert_eq!(power_heuristic(f64::INFINITY, 2.0), 1.0);
    }
}
