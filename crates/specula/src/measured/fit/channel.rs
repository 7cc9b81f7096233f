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

/// The most coefficients a channel has: `kd` and two specular columns.
pub(super) const MAX_COEFFICIENTS: usize = 3;

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

/// Lanes of the sums over the observations: a whole AVX-512 register of `f64`, two of AVX2's.
const LANES: usize = 8;

/// `sum_j w_j (target_j - cbrt(row_j . x))^2`, each cube root left in `roots`: [`LANES`]
/// observations at a time into as many running sums (which the compiler vectorises), then
/// the remainder. Written out, not with `array::from_fn`: a library closure is compiled
/// without the target features the dispatch enables.
#[inline(always)]
fn cost_sum(
    columns: &[Vec<f64>; MAX_COEFFICIENTS],
    target: &[f64],
    weight: &[f64],
    x: [f64; MAX_COEFFICIENTS],
    roots: &mut [f64],
) -> f64 {
    let [a0, a1, a2] = columns;
    let count = target.len();
    let whole = count / LANES * LANES;
    let mut sums = [0.0; LANES];
    for start in (0..whole).step_by(LANES) {
        let end = start + LANES;
        let (a0, a1, a2) = (&a0[start..end], &a1[start..end], &a2[start..end]);
        let (target, weight) = (&target[start..end], &weight[start..end]);
        let mut model = [0.0; LANES];
        for k in 0..LANES {
            model[k] = a0[k] * x[0] + a1[k] * x[1] + a2[k] * x[2];
        }
        let root = cube_roots(model);
        roots[start..end].copy_from_slice(&root);
        for k in 0..LANES {
            let r = target[k] - root[k];
            sums[k] += weight[k] * r * r;
        }
    }
    let mut rest = 0.0;
    for j in whole..count {
        let root = cube_roots([a0[j] * x[0] + a1[j] * x[1] + a2[j] * x[2]; LANES])[0];
        roots[j] = root;
        let r = target[j] - root;
        rest += weight[j] * r * r;
    }
    sums.iter().sum::<f64>() + rest
}

/// The Gauss-Newton system's sums over the observations: `sum w s^2 a_i a_k` for the upper
/// triangle (`i <= k`) and `sum w s a_i r`, with `a` the row, `s = 1 / (3 root^2)` the cube
/// root's slope (the root at least `1e-4`) and `r = target - root`; [`LANES`] running sums
/// each, so the compiler vectorises the loop. Unused columns are 0 and sum to 0.
#[inline(always)]
fn step_sums(
    columns: &[Vec<f64>; MAX_COEFFICIENTS],
    target: &[f64],
    weight: &[f64],
    roots: &[f64],
) -> [f64; 9] {
    let [a0, a1, a2] = columns;
    let count = target.len();
    let whole = count / LANES * LANES;
    let mut sums = [[0.0; LANES]; 9];
    let lanes = |values: &[f64], start: usize| -> [f64; LANES] {
        values[start..start + LANES]
            .try_into()
            .expect("a whole chunk of lanes")
    };
    for start in (0..whole).step_by(LANES) {
        let rows = [lanes(a0, start), lanes(a1, start), lanes(a2, start)];
        let observed = [
            lanes(target, start),
            lanes(weight, start),
            lanes(roots, start),
        ];
        add_step_terms(&mut sums, rows, observed);
    }
    // The remainder padded with weight 0.
    let padded = |values: &[f64]| -> [f64; LANES] {
        let mut lanes = [0.0; LANES];
        lanes[..count - whole].copy_from_slice(&values[whole..count]);
        lanes
    };
    let rows = [padded(a0), padded(a1), padded(a2)];
    add_step_terms(
        &mut sums,
        rows,
        [padded(target), padded(weight), padded(roots)],
    );
    let mut out = [0.0; 9];
    for (total, lanes) in out.iter_mut().zip(&sums) {
        *total = lanes.iter().sum();
    }
    out
}

/// [`step_sums`]' terms of [`LANES`] observations (`rows` by column; target, weight and root)
/// into the sums' lanes: each sum in its own lanes, each line a loop over the lanes alone,
/// the form the compiler turns into one vector instruction per line.
#[inline(always)]
fn add_step_terms(
    sums: &mut [[f64; LANES]; 9],
    [a0, a1, a2]: [[f64; LANES]; MAX_COEFFICIENTS],
    [target, weight, roots]: [[f64; LANES]; 3],
) {
    let (mut s0, mut s1, mut s2, mut residual) =
        ([0.0; LANES], [0.0; LANES], [0.0; LANES], [0.0; LANES]);
    for k in 0..LANES {
        let bounded = if roots[k] > 1e-4 { roots[k] } else { 1e-4 };
        let slope = 1.0 / (3.0 * bounded * bounded);
        s0[k] = slope * a0[k];
        s1[k] = slope * a1[k];
        s2[k] = slope * a2[k];
        residual[k] = target[k] - roots[k];
    }
    for k in 0..LANES {
        let (w0, w1, w2) = (weight[k] * s0[k], weight[k] * s1[k], weight[k] * s2[k]);
        sums[0][k] += w0 * s0[k];
        sums[1][k] += w0 * s1[k];
        sums[2][k] += w0 * s2[k];
        sums[3][k] += w1 * s1[k];
        sums[4][k] += w1 * s2[k];
        sums[5][k] += w2 * s2[k];
        sums[6][k] += w0 * residual[k];
        sums[7][k] += w1 * residual[k];
        sums[8][k] += w2 * residual[k];
    }
}

/// The cube roots of [`LANES`] values `>= 0` (0 for 0), each to a relative `1e-13` (see the
/// test): a first guess from the `f32` bits (Kahan's: the exponent divided by three, within
/// 3.5 %) and two Halley steps, each tripling the correct digits. The fit compares roots
/// whose residuals are `1e-2` and more, so a third step (full `f64` precision) would change
/// no fit and cost a third of the loop. No branch and no 64-bit integer division, so the
/// lanes run on vector registers: the fit takes hundreds of millions, and this is several
/// times faster than `f64::cbrt`. For the model's values, `f cos` of a BRDF within `f32`'s
/// normal range (below it the guess is that of `f32`'s smallest normal, and a value under
/// `1e-38` is 0 for the fit's purposes).
#[inline(always)]
fn cube_roots(x: [f64; LANES]) -> [f64; LANES] {
    let mut y = [0.0; LANES];
    for k in 0..LANES {
        let single = (x[k] as f32).clamp(f32::MIN_POSITIVE, f32::MAX);
        y[k] = f64::from(f32::from_bits(single.to_bits() / 3 + 0x2A51_37A0));
    }
    for _ in 0..2 {
        for k in 0..LANES {
            let cube = y[k] * y[k] * y[k];
            y[k] *= (cube + 2.0 * x[k]) / (2.0 * cube + x[k]);
        }
    }
    for k in 0..LANES {
        // 0 for 0 (and for a NaN, which no model gives).
        if x[k].partial_cmp(&0.0) != Some(core::cmp::Ordering::Greater) {
            y[k] = 0.0;
        }
    }
    y
}

#[cfg(test)]
mod tests {
    use super::{cube_roots, Quadratic, MAX_COEFFICIENTS};

    fn cube_root(x: f64) -> f64 {
        cube_roots([x; super::LANES])[0]
    }

    /// The bounded minimiser meets Karush, Kuhn and Tucker's conditions, the second method:
    /// the gradient `2 (N x - r)` vanishes in every unknown off its bound and points up
    /// (is non-negative) in every unknown at it, on random positive definite systems with
    /// random bounds, the unknowns' scales apart by up to eight orders (as a dark channel's
    /// cube-root weights make them).
    /// The vector passes agree with plain loops (within rounding of the sums' order) at
    /// every remainder of the lanes, and at counts below one chunk: the padded lanes add
    /// nothing, and the cube roots left behind are the model's.
    #[test]
    fn the_vector_sums_are_the_plain_sums_at_every_remainder() {
        let mut state = 0x2545_F491_4F6C_DD1D_u64;
        let mut uniform = || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state >> 11) as f64 / (1u64 << 53) as f64
        };
        for count in (0..20).chain([8 * 7 + 3, 8 * 40, 8 * 40 + 7]) {
            let columns: [Vec<f64>; MAX_COEFFICIENTS] =
                core::array::from_fn(|_| (0..count).map(|_| uniform()).collect());
            let target: Vec<f64> = (0..count).map(|_| uniform()).collect();
            let weight: Vec<f64> = (0..count).map(|_| uniform() / 50.0).collect();
            let x = [0.3, 1.7, 0.02];
            let mut roots = vec![f64::NAN; count];
            let cost = super::cost_sum(&columns, &target, &weight, x, &mut roots);
            let row = |j: usize| [columns[0][j], columns[1][j], columns[2][j]];
            let model = |j: usize| row(j).iter().zip(x).map(|(a, x)| a * x).sum::<f64>();
            let mut plain = 0.0;
            for j in 0..count {
                let root = model(j).cbrt();
                assert!((roots[j] - root).abs() <= 1e-13 * root, "{count}: root {j}");
                plain += weight[j] * (target[j] - root).powi(2);
            }
            assert!(
                (cost - plain).abs() <= 1e-12 * plain,
                "{count}: {cost} {plain}"
            );
            let sums = super::step_sums(&columns, &target, &weight, &roots);
            let (mut expected, mut magnitude) = ([0.0; 9], [0.0_f64; 9]);
            for j in 0..count {
                let slope = 1.0 / (3.0 * roots[j].max(1e-4).powi(2));
                let a = row(j).map(|a| slope * a);
                let residual = target[j] - roots[j];
                let pairs = [(0, 0), (0, 1), (0, 2), (1, 1), (1, 2), (2, 2)];
                let terms = pairs
                    .map(|(p, q)| weight[j] * a[p] * a[q])
                    .into_iter()
                    .chain((0..3).map(|p| weight[j] * a[p] * residual));
                for (k, term) in terms.enumerate() {
                    expected[k] += term;
                    magnitude[k] += term.abs();
                }
            }
            for k in 0..9 {
                assert!(
                    (sums[k] - expected[k]).abs() <= 1e-12 * magnitude[k],
                    "{count}: sum {k}: {} {}",
                    sums[k],
                    expected[k]
                );
            }
        }
    }

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

    /// Two Halley steps from Kahan's guess: within `1e-13` of the library's root (relative)
    /// over the range of a model's `f cos`, `f32`'s normal numbers, at every scale of the
    /// mantissa; a residual of the fit is `1e-2` and more.
    #[test]
    fn the_cube_root_agrees_with_the_library_within_its_stated_precision() {
        let mut worst: f64 = 0.0;
        let mut x = 1e-37_f64;
        while x < 1e37 {
            for step in 0..64 {
                let v = x * 2f64.powf(f64::from(step) / 64.0 * 3.0);
                let (ours, reference) = (cube_root(v), v.cbrt());
                worst = worst.max((ours - reference).abs() / reference);
            }
            x *= 10.0;
        }
        assert!(worst < 1e-13, "{worst}");
        assert_eq!(cube_root(0.0), 0.0);
    }
}
