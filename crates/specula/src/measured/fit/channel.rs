//! One channel's best linear coefficients for given specular columns: `kd` and `K` (and, with
//! Fresnel, `K`'s split into `K F0` and `K (1 - F0)`), from the observations prepared once
//! (cosines, lobe cosines, the data's cube roots), the weighted linear start and the projected
//! Gauss-Newton steps on the cube-root error (see the module page of `fit`).

use core::f64::consts::FRAC_1_PI;
use core::sync::atomic::{AtomicU64, Ordering};

use glam::DVec3;

use super::Observations;
use crate::microfacet::{fresnel_schlick, TableIndex};
use crate::Geometry;

use super::sums::{cost_sum, step_sums, MAX_COEFFICIENTS};

/// Observations with what every fit needs computed once.
pub(super) struct Prepared<'a> {
    pub(super) weight: &'a [f64],
    /// `cos(theta_i)`.
    pub(super) cosine: Vec<f64>,
    pub(super) t_phong: Vec<f64>,
    pub(super) t_blinn: Vec<f64>,
    /// What a microfacet term needs of each pair besides the distribution, made once: the
    /// half vector's cosine, `4 cos(theta_o) cos(theta_i)`, Schlick's `(1 - wo.h)^5`, and
    /// both directions' places in the lobes' `Lambda` table.
    pub(super) microfacet: Vec<MicrofacetPair>,
    /// Per channel, the cube root of the material's `f cos`.
    pub(super) target: [Vec<f64>; 3],
    /// Per channel, the weight that linearises the cube root at the data.
    pub(super) linearised: [Vec<f64>; 3],
    /// Observations evaluated so far (each pass of [`Prepared::cost`] or [`Prepared::step`]
    /// counts them all): the work a fit did, which its time is judged by.
    pub(super) evaluations: AtomicU64,
}

/// A direction pair as every microfacet term sees it.
#[derive(Clone, Copy)]
pub(super) struct MicrofacetPair {
    /// Both directions above the horizon.
    pub(super) above: bool,
    pub(super) cos_h: f64,
    pub(super) four_cosines: f64,
    pub(super) schlick: f64,
    pub(super) wo: TableIndex,
    pub(super) wi: TableIndex,
}

/// The rows of the model at every observation for one shape parameter ([`Prepared::rows`]),
/// stored by column (a column per coefficient, unused ones 0) so that the sums over the
/// observations load whole vectors.
pub(super) struct Rows {
    columns: [Vec<f64>; MAX_COEFFICIENTS],
    /// The coefficients used: `kd` and the specular columns.
    size: usize,
}

/// A symmetric system of up to [`MAX_COEFFICIENTS`] unknowns, of which the first `size` are
/// used: `minimise x' N x - 2 x' r`.
#[derive(Clone, Copy)]
pub(super) struct Quadratic {
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
        let microfacet = pairs
            .iter()
            .map(|&(wo, wi)| {
                let h = (wo + wi).normalize();
                MicrofacetPair {
                    above: wo.z > 0.0 && wi.z > 0.0,
                    cos_h: h.z,
                    four_cosines: 4.0 * wo.z * wi.z,
                    schlick: fresnel_schlick(0.0, wo.dot(h)),
                    wo: TableIndex::of(wo.z),
                    wi: TableIndex::of(wi.z),
                }
            })
            .collect();
        Self {
            microfacet,
            cosine: pairs.iter().map(|(_, wi)| wi.z).collect(),
            t_phong: pairs
                .iter()
                .map(|&(wo, wi)| Geometry::Phong.cos_lobe_local(wo, wi))
                .collect(),
            t_blinn: pairs
                .iter()
                .map(|&(wo, wi)| Geometry::Blinn.cos_lobe_local(wo, wi))
                .collect(),
            weight: &observations.weight,
            target: [channel(0), channel(1), channel(2)],
            linearised: [linearised(0), linearised(1), linearised(2)],
            evaluations: AtomicU64::new(0),
        }
    }

    /// Every observation's row for specular `columns` (one or two): the diffuse term's and
    /// each column's `f cos` per unit coefficient. Made once per shape parameter and shared by
    /// the three channels and every step of their solves.
    pub(super) fn rows(&self, columns: &[Vec<f64>]) -> Rows {
        let diffuse = self
            .cosine
            .iter()
            .map(|&cosine| FRAC_1_PI * cosine)
            .collect();
        let specular = |k: usize| match columns.get(k) {
            Some(column) => column
                .iter()
                .zip(&self.cosine)
                .map(|(f, c)| f * c)
                .collect(),
            None => vec![0.0; self.cosine.len()],
        };
        Rows {
            columns: [diffuse, specular(0), specular(1)],
            size: 1 + columns.len(),
        }
    }

    /// The error sum of channel `c` with coefficients `x`; the model's cube roots are left in
    /// `roots` for the next Gauss-Newton step. Most of a fit's time is here and in
    /// [`Prepared::step`], so both run on the widest vectors the CPU has (`pulp` picks AVX-512
    /// or AVX2 and compiles the loop for it): eight lanes of running sums and a cube root
    /// without branches.
    pub(super) fn cost(
        &self,
        c: usize,
        rows: &Rows,
        x: &[f64; MAX_COEFFICIENTS],
        roots: &mut [f64],
    ) -> f64 {
        self.count_pass();
        struct Cost<'a> {
            columns: &'a [Vec<f64>; MAX_COEFFICIENTS],
            target: &'a [f64],
            weight: &'a [f64],
            x: [f64; MAX_COEFFICIENTS],
            roots: &'a mut [f64],
        }
        impl pulp::WithSimd for Cost<'_> {
            type Output = f64;
            #[inline(always)]
            fn with_simd<S: pulp::Simd>(self, _: S) -> f64 {
                cost_sum(self.columns, self.target, self.weight, self.x, self.roots)
            }
        }
        pulp::Arch::new().dispatch(Cost {
            columns: &rows.columns,
            target: &self.target[c],
            weight: self.weight,
            x: *x,
            roots,
        })
    }

    /// The Gauss-Newton step's system at the model's cube roots `roots`: each row scaled by
    /// the root's slope (bounded where the model vanishes), weighted, against the residual.
    /// Run as [`Prepared::cost`] is.
    pub(super) fn step(&self, c: usize, rows: &Rows, roots: &[f64]) -> Quadratic {
        self.count_pass();
        struct Step<'a> {
            columns: &'a [Vec<f64>; MAX_COEFFICIENTS],
            target: &'a [f64],
            weight: &'a [f64],
            roots: &'a [f64],
        }
        impl pulp::WithSimd for Step<'_> {
            type Output = [f64; 9];
            #[inline(always)]
            fn with_simd<S: pulp::Simd>(self, _: S) -> [f64; 9] {
                step_sums(self.columns, self.target, self.weight, self.roots)
            }
        }
        let sums = pulp::Arch::new().dispatch(Step {
            columns: &rows.columns,
            target: &self.target[c],
            weight: self.weight,
            roots,
        });
        let mut step = Quadratic::new(rows.size);
        let [n00, n01, n02, n11, n12, n22, r0, r1, r2] = sums;
        step.normal = [[n00, n01, n02], [0.0, n11, n12], [0.0, 0.0, n22]];
        step.rhs = [r0, r1, r2];
        step
    }

    /// One pass over every observation, counted in [`Prepared::evaluations`].
    fn count_pass(&self) {
        self.evaluations
            .fetch_add(self.cosine.len() as u64, Ordering::Relaxed);
    }

    /// The best coefficients `>= 0` of channel `c` for the specular columns of `rows`:
    /// `[kd, K]` or `[kd, K F0, K (1 - F0)]`, unused ones 0, and the cost. The steps start
    /// from `warm` where given (a solution at a nearby shape parameter, which a search over
    /// the parameter passes on), else from the linearised least squares.
    pub(super) fn solve_channel(
        &self,
        c: usize,
        rows: &Rows,
        warm: Option<&[f64; MAX_COEFFICIENTS]>,
    ) -> ([f64; MAX_COEFFICIENTS], f64) {
        let size = rows.size;
        let count = self.cosine.len();
        let mut x = match warm {
            Some(warm) => core::array::from_fn(|i| if i < size { warm[i].max(0.0) } else { 0.0 }),
            None => {
                // Weighted least squares in f cos with the cube root's slope as weight.
                let mut start = Quadratic::new(size);
                for j in 0..count {
                    let row = rows.columns.each_ref().map(|column| column[j]);
                    let y = self.target[c][j].powi(3);
                    start.add(&row, self.linearised[c][j], y);
                }
                start.minimise_above(&[0.0; MAX_COEFFICIENTS])
            }
        };
        let (mut roots, mut trial_roots) = (vec![0.0; count], vec![0.0; count]);
        let mut cost = self.cost(c, rows, &x, &mut roots);
        for _ in 0..6 {
            let step = self.step(c, rows, &roots);
            let direction = step.minimise_above(&x.map(|v| -v));
            let mut scale = 1.0;
            let improved = loop {
                let trial: [f64; MAX_COEFFICIENTS] =
                    core::array::from_fn(|i| (x[i] + scale * direction[i]).max(0.0));
                let trial_cost = self.cost(c, rows, &trial, &mut trial_roots);
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

#[cfg(test)]
mod tests {
    use super::{Quadratic, MAX_COEFFICIENTS};

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
}
