//! One channel's best linear coefficients for given specular columns: `kd` and `K` (and, with
//! Fresnel, `K`'s split into `K F0` and `K (1 - F0)`), from the observations prepared once
//! (cosines, lobe cosines, the data's cube roots), the weighted linear start and the projected
//! Gauss-Newton steps on the cube-root error (see the module page of `fit`).

use core::f64::consts::FRAC_1_PI;

use glam::DVec3;

use super::Observations;
use crate::Geometry;

/// The most coefficients a channel has: `kd` and two specular columns.
pub(super) const MAX_COEFFICIENTS: usize = 3;

/// Observations with what every fit needs computed once.
pub(super) struct Prepared<'a> {
    pub(super) pairs: Vec<(DVec3, DVec3)>,
    pub(super) weight: &'a [f64],
    /// `cos(theta_i)`.
    pub(super) cosine: Vec<f64>,
    pub(super) t_phong: Vec<f64>,
    pub(super) t_blinn: Vec<f64>,
    /// Per channel, the cube root of the material's `f cos`.
    pub(super) target: [Vec<f64>; 3],
    /// Per channel, the weight that linearises the cube root at the data.
    pub(super) linearised: [Vec<f64>; 3],
}

/// A symmetric system of up to [`MAX_COEFFICIENTS`] unknowns, of which the first `size` are
/// used: `minimise x' N x - 2 x' r`.
#[derive(Clone, Copy)]
struct Quadratic {
    normal: [[f64; MAX_COEFFICIENTS]; MAX_COEFFICIENTS],
    rhs: [f64; MAX_COEFFICIENTS],
    size: usize,
}

impl Quadratic {
    fn new(size: usize) -> Self {
        Self {
            normal: [[0.0; MAX_COEFFICIENTS]; MAX_COEFFICIENTS],
            rhs: [0.0; MAX_COEFFICIENTS],
            size,
        }
    }

    /// Adds the row `row` with weight `w` and value `y`.
    fn add(&mut self, row: &[f64; MAX_COEFFICIENTS], w: f64, y: f64) {
        for a in 0..self.size {
            for b in a..self.size {
                self.normal[a][b] += w * row[a] * row[b];
            }
            self.rhs[a] += w * row[a] * y;
        }
    }

    fn value(&self, x: &[f64; MAX_COEFFICIENTS]) -> f64 {
        let mut value = 0.0;
        for a in 0..self.size {
            value -= 2.0 * x[a] * self.rhs[a];
            for b in 0..self.size {
                let (i, j) = if a <= b { (a, b) } else { (b, a) };
                value += x[a] * self.normal[i][j] * x[b];
            }
        }
        value
    }

    /// The minimiser with `x >= lower`: every choice of unknowns held at their bound is
    /// tried (at most eight), the others solved freely with them held, and the best feasible
    /// one kept. All held is always feasible, so there is an answer.
    fn minimise_above(&self, lower: &[f64; MAX_COEFFICIENTS]) -> [f64; MAX_COEFFICIENTS] {
        let mut best = (*lower, self.value(lower));
        for free_set in 1..(1usize << self.size) {
            let free: Vec<usize> = (0..self.size).filter(|i| free_set >> i & 1 == 1).collect();
            let Some(x) = self.solve_with_held(&free, lower) else {
                continue;
            };
            if (0..self.size).all(|i| x[i] >= lower[i]) {
                let value = self.value(&x);
                if value < best.1 {
                    best = (x, value);
                }
            }
        }
        best.0
    }

    /// The unknowns in `free` solved with the others held at `held`, by Gaussian elimination;
    /// `None` when the reduced system is singular.
    fn solve_with_held(
        &self,
        free: &[usize],
        held: &[f64; MAX_COEFFICIENTS],
    ) -> Option<[f64; MAX_COEFFICIENTS]> {
        let entry = |a: usize, b: usize| self.normal[a.min(b)][a.max(b)];
        let k = free.len();
        let mut system = [[0.0; MAX_COEFFICIENTS + 1]; MAX_COEFFICIENTS];
        for (r, &a) in free.iter().enumerate() {
            for (c, &b) in free.iter().enumerate() {
                system[r][c] = entry(a, b);
            }
            let pushed: f64 = (0..self.size)
                .filter(|i| !free.contains(i))
                .map(|i| entry(a, i) * held[i])
                .sum();
            system[r][k] = self.rhs[a] - pushed;
        }
        // The system is positive semi-definite, so elimination needs no pivoting; a pivot is
        // judged against its own diagonal entry (the columns' scales differ by many orders:
        // the cube root's weights are huge where the data are dark).
        for column in 0..k {
            let own = entry(free[column], free[column]);
            let pivot = system[column][column];
            if pivot.is_nan() || pivot <= 1e-12 * own {
                return None;
            }
            let pivot_row = system[column];
            for row in &mut system[column + 1..k] {
                let factor = row[column] / pivot;
                for (value, &above) in row.iter_mut().zip(&pivot_row).skip(column) {
                    *value -= factor * above;
                }
            }
        }
        let mut x = *held;
        for row in (0..k).rev() {
            let known: f64 = (row + 1..k).map(|c| system[row][c] * x[free[c]]).sum();
            x[free[row]] = (system[row][k] - known) / system[row][row];
        }
        x.iter().all(|v| v.is_finite()).then_some(x)
    }
}

impl<'a> Prepared<'a> {
    pub(super) fn new(observations: &'a Observations) -> Self {
        let pairs: Vec<(DVec3, DVec3)> = observations
            .wo
            .iter()
            .zip(&observations.wi)
            .map(|(&wo, &wi)| (wo, wi))
            .collect();
        let channel =
            |c: usize| -> Vec<f64> { observations.value.iter().map(|v| v[c].cbrt()).collect() };
        let linearised = |c: usize| -> Vec<f64> {
            // d cbrt(y) = dy / (3 y^(2/3)): the squared slope, with a floor where y is ~0.
            observations
                .value
                .iter()
                .zip(&observations.weight)
                .map(|(v, w)| w / (9.0 * v[c].abs().max(1e-4).powf(4.0 / 3.0)))
                .collect()
        };
        Self {
            cosine: pairs.iter().map(|(_, wi)| wi.z).collect(),
            t_phong: pairs
                .iter()
                .map(|&(wo, wi)| Geometry::Phong.cos_lobe_local(wo, wi))
                .collect(),
            t_blinn: pairs
                .iter()
                .map(|&(wo, wi)| Geometry::Blinn.cos_lobe_local(wo, wi))
                .collect(),
            pairs,
            weight: &observations.weight,
            target: [channel(0), channel(1), channel(2)],
            linearised: [linearised(0), linearised(1), linearised(2)],
        }
    }

    /// Observation `j`'s row: the diffuse term's and each specular column's `f cos` per unit
    /// coefficient.
    fn row(&self, columns: &[Vec<f64>], j: usize) -> [f64; MAX_COEFFICIENTS] {
        let mut row = [0.0; MAX_COEFFICIENTS];
        row[0] = FRAC_1_PI * self.cosine[j];
        for (slot, column) in row[1..].iter_mut().zip(columns) {
            *slot = column[j] * self.cosine[j];
        }
        row
    }

    /// The error sum of channel `c` with coefficients `x` over specular `columns`; the
    /// model's cube roots are left in `roots` for the next Gauss-Newton step.
    fn cost(
        &self,
        c: usize,
        columns: &[Vec<f64>],
        x: &[f64; MAX_COEFFICIENTS],
        roots: &mut [f64],
    ) -> f64 {
        let mut sum = 0.0;
        for (j, root) in roots.iter_mut().enumerate() {
            let row = self.row(columns, j);
            let model: f64 = row.iter().zip(x).map(|(a, b)| a * b).sum();
            *root = cube_root(model);
            let r = self.target[c][j] - *root;
            sum += self.weight[j] * r * r;
        }
        sum
    }

    /// The best coefficients `>= 0` of channel `c` for these specular `columns` (one or two):
    /// `[kd, K]` or `[kd, K F0, K (1 - F0)]`, unused ones 0, and the cost.
    pub(super) fn solve_channel(
        &self,
        c: usize,
        columns: &[Vec<f64>],
    ) -> ([f64; MAX_COEFFICIENTS], f64) {
        let size = 1 + columns.len();
        let count = self.cosine.len();
        // The start: weighted least squares in f cos with the cube root's slope as weight.
        let mut start = Quadratic::new(size);
        for j in 0..count {
            let y = self.target[c][j].powi(3);
            start.add(&self.row(columns, j), self.linearised[c][j], y);
        }
        let mut x = start.minimise_above(&[0.0; MAX_COEFFICIENTS]);
        let (mut roots, mut trial_roots) = (vec![0.0; count], vec![0.0; count]);
        let mut cost = self.cost(c, columns, &x, &mut roots);
        for _ in 0..6 {
            let mut step = Quadratic::new(size);
            for (j, &root) in roots.iter().enumerate() {
                // The root's slope, bounded where the model vanishes.
                let slope = 1.0 / (3.0 * root.max(1e-4).powi(2));
                let row = self.row(columns, j).map(|a| slope * a);
                step.add(&row, self.weight[j], self.target[c][j] - root);
            }
            let direction = step.minimise_above(&x.map(|v| -v));
            let mut scale = 1.0;
            let improved = loop {
                let trial: [f64; MAX_COEFFICIENTS] =
                    core::array::from_fn(|i| (x[i] + scale * direction[i]).max(0.0));
                let trial_cost = self.cost(c, columns, &trial, &mut trial_roots);
                if trial_cost < cost {
                    break Some((trial, trial_cost));
                }
                scale *= 0.25;
                if scale < 1e-3 {
                    break None;
                }
            };
            let Some((trial, trial_cost)) = improved else {
                break;
            };
            let converged = cost - trial_cost < 1e-10 * cost;
            (x, cost) = (trial, trial_cost);
            core::mem::swap(&mut roots, &mut trial_roots);
            if converged {
                break;
            }
        }
        (x, cost)
    }
}

/// The cube root of `x >= 0`, to within an ulp or two: a bit-level first guess (the
/// exponent divided by three) and three Halley steps, each tripling the correct digits. The
/// fit takes millions of them, and this is several times faster than `f64::cbrt`.
fn cube_root(x: f64) -> f64 {
    if x <= 0.0 || !x.is_finite() || x < f64::MIN_POSITIVE {
        return x.cbrt();
    }
    let mut y = f64::from_bits(x.to_bits() / 3 + 0x2A9F_7893_782D_A1CE);
    for _ in 0..3 {
        let cube = y * y * y;
        y *= (cube + 2.0 * x) / (2.0 * cube + x);
    }
    y
}

#[cfg(test)]
mod tests {
    use super::{cube_root, Quadratic, MAX_COEFFICIENTS};

    /// The bounded minimiser meets Karush, Kuhn and Tucker's conditions, the second method:
    /// the gradient `2 (N x - r)` vanishes in every unknown off its bound and points up
    /// (is non-negative) in every unknown at it, on random positive definite systems with
    /// random bounds, the unknowns' scales apart by up to eight orders (as a dark channel's
    /// cube-root weights make them).
    #[test]
    fn the_bounded_minimiser_meets_the_optimality_conditions() {
        let mut state = 0x9E37_79B9_7F4A_7C15_u64;
        let mut uniform = || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0
        };
        let mut held_somewhere = 0;
        for case in 0..2000 {
            let size = 2 + case % 2;
            let mut q = Quadratic::new(size);
            let scales: [f64; MAX_COEFFICIENTS] =
                core::array::from_fn(|_| 10f64.powf(4.0 * uniform()));
            for _ in 0..6 {
                let row: [f64; MAX_COEFFICIENTS] = core::array::from_fn(|i| uniform() * scales[i]);
                q.add(&row, 1.0, 3.0 * uniform());
            }
            let lower: [f64; MAX_COEFFICIENTS] =
                core::array::from_fn(|i| (uniform() - 0.5) / scales[i]);
            let x = q.minimise_above(&lower);
            for a in 0..size {
                let gradient: f64 = (0..size)
                    .map(|b| q.normal[a.min(b)][a.max(b)] * x[b])
                    .sum::<f64>()
                    - q.rhs[a];
                // The gradient's scale: its terms' sizes.
                let scale: f64 = (0..size)
                    .map(|b| (q.normal[a.min(b)][a.max(b)] * x[b]).abs())
                    .sum::<f64>()
                    + q.rhs[a].abs();
                assert!(x[a] >= lower[a], "case {case}: below the bound");
                if x[a] > lower[a] {
                    assert!(gradient.abs() < 1e-9 * scale, "case {case}: {gradient}");
                } else {
                    held_somewhere += 1;
                    assert!(gradient > -1e-9 * scale, "case {case}: {gradient}");
                }
            }
        }
        assert!(
            held_somewhere > 100,
            "the bounds never bound: {held_somewhere}"
        );
    }

    #[test]
    fn the_cube_root_agrees_with_the_library_to_rounding() {
        let mut x = 1e-300_f64;
        while x < 1e300 {
            for scale in [1.0, 1.37, 2.0, 5.9] {
                let v = x * scale;
                let (ours, reference) = (cube_root(v), v.cbrt());
                assert!(
                    (ours - reference).abs() <= 4.0 * f64::EPSILON * reference,
                    "{v}: {ours} {reference}"
                );
            }
            x *= 10.0;
        }
        assert_eq!(cube_root(0.0), 0.0);
        assert_eq!(cube_root(-8.0), -2.0);
    }
}
