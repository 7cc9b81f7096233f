//! Pearson's chi-square test of a sampler against its own density, as Mitsuba's `chi2.py`
//! and pbrt-v4's `bsdfs_test.cpp` run it: draw many directions, histogram them on a grid over
//! the sphere, integrate the density over each cell for the expected counts, pool the cells
//! expecting fewer than 5, and ask how likely a statistic this large is if the sampler draws
//! exactly the density it reports.
//!
//! The grid lives in the lobe's frame: azimuth about the mirror direction across, and down
//! the angle from it on a logarithmic scale `y = ln(1 + theta / s) / ln(1 + pi / s)`, with `s`
//! the lobe's epicentre (doubled for Blinn, whose `wi` spreads twice as far as its half
//! vector). Narrow and wide lobes then spread over many rows alike; a plain `(phi, cos theta)`
//! grid would put a lobe of `n = 512` in two or three cells. The whole sphere is covered, so a
//! sample anywhere counts. Each cell's expected count is integrated adaptively (Gauss-Legendre
//! on the cell and its quarters until they agree), so the horizon and the lobes' cut-offs,
//! which cross cells, do not bias it.
//!
//! The uniform numbers come from a counter-based hash of `(seed, index)`, so a run is
//! reproducible and splits across threads without changing.

use core::f64::consts::{PI, TAU};

use glam::DVec3;
use rayon::prelude::*;

use super::{mirror, uniform, SpecularSampler};
use crate::Geometry;

/// Cells with fewer expected samples than this are pooled, as Pearson's approximation needs.
pub const MIN_EXPECTED: f64 = 5.0;

/// What to run.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Settings {
    /// Directions drawn.
    pub samples: usize,
    /// Cells across (azimuth).
    pub columns: usize,
    /// Cells down (angle from the axis).
    pub rows: usize,
    /// The random stream.
    pub seed: u64,
}

impl Default for Settings {
    /// Mitsuba's sample count, one million, on a 64 x 64 grid.
    fn default() -> Self {
        Self {
            samples: 1_000_000,
            columns: 64,
            rows: 64,
            seed: 1,
        }
    }
}

/// A finished test.
#[derive(Clone, Debug, PartialEq)]
pub struct Outcome {
    /// Pearson's statistic over the pooled cells.
    pub statistic: f64,
    /// Degrees of freedom: cells after pooling, less one.
    pub dof: usize,
    /// The probability of a statistic at least this large if the sampler is right.
    pub p_value: f64,
    /// Samples that fell in a cell whose expected count is 0 (the sampler draws where its
    /// density says it never goes).
    pub impossible: u64,
    /// The density integrated over the sphere: the probability of a draw.
    pub pdf_integral: f64,
    /// The fraction of draws that returned a direction.
    pub drawn_fraction: f64,
    /// Newton iterations per returned direction: the mean and the most (0 for closed forms
    /// and tables).
    pub newton_iterations: (f64, u32),
    /// Counts per cell, row-major (`rows x columns`).
    pub histogram: Vec<f64>,
    /// Expected counts per cell, row-major.
    pub expected: Vec<f64>,
    /// Grid size.
    pub columns: usize,
    /// Grid size.
    pub rows: usize,
}

impl Outcome {
    /// Whether the sampler passes at significance `alpha` (already corrected for the number
    /// of tests, see [`sidak`]).
    #[must_use]
    pub fn passes(&self, alpha: f64) -> bool {
        self.impossible == 0 && self.dof >= 1 && self.p_value >= alpha
    }
}

/// The per-test significance that keeps the chance of any false rejection among `tests`
/// independent tests at `alpha` (Sidak's correction).
#[must_use]
pub fn sidak(alpha: f64, tests: usize) -> f64 {
    1.0 - (1.0 - alpha).powf(1.0 / tests.max(1) as f64)
}

/// The sphere in the lobe's frame, mapped to the unit square.
#[derive(Clone, Copy, Debug)]
struct Domain {
    axis: DVec3,
    b1: DVec3,
    b2: DVec3,
    scale: f64,
    log_span: f64,
}

impl Domain {
    fn new(sampler: &SpecularSampler, wo: DVec3) -> Self {
        let axis = mirror(wo);
        let (b1, b2) = axis.any_orthonormal_pair();
        let spread = match sampler.geometry() {
            Geometry::Phong => 1.0,
            Geometry::Blinn => 2.0,
        };
        let scale = (spread * sampler.cosine().width()).clamp(1e-4, PI);
        Self {
            axis,
            b1,
            b2,
            scale,
            log_span: (PI / scale).ln_1p(),
        }
    }

    /// The direction at `(x, y)` and the solid angle per unit area there.
    fn forward(&self, x: f64, y: f64) -> (DVec3, f64) {
        let phi = TAU * x - PI;
        let growth = (y * self.log_span).exp();
        let theta = self.scale * (growth - 1.0);
        let (sin_theta, cos_theta) = theta.sin_cos();
        let (s, c) = phi.sin_cos();
        let direction = cos_theta * self.axis + sin_theta * (c * self.b1 + s * self.b2);
        let jacobian = TAU * sin_theta.abs() * self.scale * self.log_span * growth;
        (direction, jacobian)
    }

    /// `(x, y)` of a unit direction.
    fn backward(&self, w: DVec3) -> (f64, f64) {
        let theta = w.dot(self.axis).clamp(-1.0, 1.0).acos();
        let phi = w.dot(self.b2).atan2(w.dot(self.b1));
        let x = (phi + PI) / TAU;
        let y = (theta / self.scale).ln_1p() / self.log_span;
        (x, y)
    }
}

/// Three-point Gauss-Legendre nodes and weights on `[0, 1]`.
const NODES: [(f64, f64); 3] = [
    (0.112_701_665_379_258_3, 5.0 / 18.0),
    (0.5, 8.0 / 18.0),
    (0.887_298_334_620_741_7, 5.0 / 18.0),
];

/// Deepest subdivision of a cell: a 64th of its side.
const MAX_DEPTH: u32 = 6;

/// `int f` over the rectangle `[x0, x1] x [y0, y1]` by the 3 x 3 Gauss-Legendre rule.
fn rule(f: &impl Fn(f64, f64) -> f64, (x0, x1): (f64, f64), (y0, y1): (f64, f64)) -> f64 {
    let mut sum = 0.0;
    for (a, wa) in NODES {
        for (b, wb) in NODES {
            sum += wa * wb * f(x0 + a * (x1 - x0), y0 + b * (y1 - y0));
        }
    }
    sum * (x1 - x0) * (y1 - y0)
}

/// Whether `f` is zero at some points of a 5 x 5 lattice over the rectangle (its edges
/// included) and not at others: the rectangle straddles the edge of the density's support
/// (the horizon, a cut-off), where the Gauss-Legendre nodes, all inside, can miss a corner.
fn straddles(f: &impl Fn(f64, f64) -> f64, (x0, x1): (f64, f64), (y0, y1): (f64, f64)) -> bool {
    let (mut zero, mut positive) = (false, false);
    for i in 0..5 {
        for j in 0..5 {
            let value = f(
                x0 + (x1 - x0) * (f64::from(i) / 4.0).clamp(1e-9, 1.0 - 1e-9),
                y0 + (y1 - y0) * (f64::from(j) / 4.0).clamp(1e-9, 1.0 - 1e-9),
            );
            if value > 0.0 {
                positive = true;
            } else {
                zero = true;
            }
        }
    }
    zero && positive
}

/// `int f` over the rectangle, subdividing until the quarters agree with the whole to
/// `tolerance` (absolute, shared out among the quarters) and, down to the deepest level,
/// wherever the rectangle straddles the edge of the support.
fn adaptive(
    f: &impl Fn(f64, f64) -> f64,
    x: (f64, f64),
    y: (f64, f64),
    whole: f64,
    tolerance: f64,
    depth: u32,
) -> f64 {
    let (xm, ym) = (0.5 * (x.0 + x.1), 0.5 * (y.0 + y.1));
    let quarters = [
        ((x.0, xm), (y.0, ym)),
        ((xm, x.1), (y.0, ym)),
        ((x.0, xm), (ym, y.1)),
        ((xm, x.1), (ym, y.1)),
    ];
    let parts = quarters.map(|(qx, qy)| rule(f, qx, qy));
    let sum: f64 = parts.iter().sum();
    if depth >= MAX_DEPTH || ((sum - whole).abs() <= tolerance && !straddles(f, x, y)) {
        return sum;
    }
    quarters
        .iter()
        .zip(parts)
        .map(|(&(qx, qy), part)| adaptive(f, qx, qy, part, 0.25 * tolerance, depth + 1))
        .sum()
}

/// Expected counts per cell for `samples` draws.
fn expected_counts(
    sampler: &SpecularSampler,
    wo: DVec3,
    domain: &Domain,
    settings: &Settings,
) -> Vec<f64> {
    let density = |x: f64, y: f64| {
        let (w, jacobian) = domain.forward(x, y);
        sampler.pdf(wo, w) * jacobian
    };
    let (columns, rows) = (settings.columns, settings.rows);
    // A hundredth of a count, or a hundred-thousandth of the cell's count if larger: errors
    // that change Pearson's statistic by far less than one of its cells' terms.
    let floor = 1e-2 / settings.samples as f64;
    (0..rows * columns)
        .into_par_iter()
        .map(|cell| {
            let (row, column) = (cell / columns, cell % columns);
            let x = (
                column as f64 / columns as f64,
                (column + 1) as f64 / columns as f64,
            );
            let y = (row as f64 / rows as f64, (row + 1) as f64 / rows as f64);
            let whole = rule(&density, x, y);
            let tolerance = floor.max(1e-5 * whole.abs());
            settings.samples as f64 * adaptive(&density, x, y, whole, tolerance, 0)
        })
        .collect()
}

/// Counts per cell of `samples` draws, and how many returned a direction.
/// Where the draws fell, and what drawing them cost.
#[derive(Default)]
struct Histogram {
    /// Draws per cell, row-major.
    counts: Vec<f64>,
    /// Draws that returned a direction.
    drawn: u64,
    /// Newton iterations over those draws.
    iterations: u64,
    /// The most any draw took.
    most_iterations: u32,
}

/// Draws `settings.samples` directions and counts them per cell.
fn histogram(
    sampler: &SpecularSampler,
    wo: DVec3,
    domain: &Domain,
    settings: &Settings,
) -> Histogram {
    const CHUNK: usize = 1 << 14;
    let (columns, rows) = (settings.columns, settings.rows);
    let chunks = settings.samples.div_ceil(CHUNK);
    let empty = || Histogram {
        counts: vec![0.0; rows * columns],
        ..Histogram::default()
    };
    (0..chunks)
        .into_par_iter()
        .map(|chunk| {
            let mut part = empty();
            let end = ((chunk + 1) * CHUNK).min(settings.samples);
            for index in chunk * CHUNK..end {
                let u = [0, 1].map(|d| uniform(settings.seed, index as u64, d));
                let Some(sample) = sampler.sample(wo, u) else {
                    continue;
                };
                part.drawn += 1;
                part.iterations += u64::from(sample.iterations);
                part.most_iterations = part.most_iterations.max(sample.iterations);
                let (x, y) = domain.backward(sample.wi);
                let column = ((x * columns as f64) as usize).min(columns - 1);
                let row = ((y * rows as f64) as usize).min(rows - 1);
                part.counts[row * columns + column] += 1.0;
            }
            part
        })
        .reduce(empty, |mut a, b| {
            a.counts.iter_mut().zip(b.counts).for_each(|(x, y)| *x += y);
            a.drawn += b.drawn;
            a.iterations += b.iterations;
            a.most_iterations = a.most_iterations.max(b.most_iterations);
            a
        })
}

/// Pearson's statistic with cells expecting fewer than [`MIN_EXPECTED`] pooled (smallest
/// first), its degrees of freedom, and the samples seen where none were expected.
#[must_use]
pub fn pearson(observed: &[f64], expected: &[f64]) -> (f64, usize, u64) {
    let mut order: Vec<usize> = (0..expected.len()).collect();
    order.sort_by(|&a, &b| expected[a].total_cmp(&expected[b]));
    let (mut statistic, mut cells, mut impossible) = (0.0, 0usize, 0u64);
    let (mut pooled_expected, mut pooled_observed) = (0.0, 0.0);
    let term = |o: f64, e: f64| (o - e) * (o - e) / e;
    for k in order {
        let (o, e) = (observed[k], expected[k]);
        if e <= 0.0 {
            impossible += o as u64;
        } else if e < MIN_EXPECTED {
            pooled_expected += e;
            pooled_observed += o;
            if pooled_expected >= MIN_EXPECTED {
                statistic += term(pooled_observed, pooled_expected);
                cells += 1;
                (pooled_expected, pooled_observed) = (0.0, 0.0);
            }
        } else {
            statistic += term(o, e);
            cells += 1;
        }
    }
    if pooled_expected > 0.0 {
        statistic += term(pooled_observed, pooled_expected);
        cells += 1;
    }
    (statistic, cells.saturating_sub(1), impossible)
}

/// Tests `sampler` for `wo`.
#[must_use]
pub fn run(sampler: &SpecularSampler, wo: DVec3, settings: &Settings) -> Outcome {
    let domain = Domain::new(sampler, wo);
    let expected = expected_counts(sampler, wo, &domain, settings);
    let Histogram {
        counts: histogram,
        drawn,
        iterations,
        most_iterations,
    } = histogram(sampler, wo, &domain, settings);
    let (statistic, dof, impossible) = pearson(&histogram, &expected);
    let n = settings.samples as f64;
    Outcome {
        statistic,
        dof,
        p_value: chi_square_survival(statistic, dof),
        impossible,
        pdf_integral: expected.iter().sum::<f64>() / n,
        drawn_fraction: drawn as f64 / n,
        newton_iterations: (iterations as f64 / drawn.max(1) as f64, most_iterations),
        histogram,
        expected,
        columns: settings.columns,
        rows: settings.rows,
    }
}

/// `P(X >= statistic)` for `X` chi-square distributed with `dof` degrees of freedom.
#[must_use]
pub fn chi_square_survival(statistic: f64, dof: usize) -> f64 {
    if dof == 0 {
        return f64::NAN;
    }
    regularized_gamma_q(0.5 * dof as f64, 0.5 * statistic.max(0.0))
}

/// `ln Gamma(x)` for `x > 0` (Lanczos, `g = 7`, nine terms: about 15 digits).
fn ln_gamma(x: f64) -> f64 {
    const G: f64 = 7.0;
    const C: [f64; 9] = [
        0.999_999_999_999_809_9,
        676.520_368_121_885_1,
        -1_259.139_216_722_402_8,
        771.323_428_777_653_1,
        -176.615_029_162_140_6,
        12.507_343_278_686_905,
        -0.138_571_095_265_720_12,
        9.984_369_578_019_572e-6,
        1.505_632_735_149_311_6e-7,
    ];
    if x < 0.5 {
        // Reflection: Gamma(x) Gamma(1 - x) = pi / sin(pi x).
        return (PI / (PI * x).sin()).ln() - ln_gamma(1.0 - x);
    }
    let x = x - 1.0;
    let t = x + G + 0.5;
    let sum = C[1..]
        .iter()
        .enumerate()
        .fold(C[0], |sum, (k, &c)| sum + c / (x + (k + 1) as f64));
    0.5 * TAU.ln() + (x + 0.5) * t.ln() - t + sum.ln()
}

/// The regularized upper incomplete gamma function `Q(a, x) = Gamma(a, x) / Gamma(a)`: by
/// its series below `x = a + 1` and by its continued fraction (modified Lentz) above.
#[must_use]
pub fn regularized_gamma_q(a: f64, x: f64) -> f64 {
    const ITERATIONS: usize = 100_000;
    const TINY: f64 = 1e-300;
    if x <= 0.0 {
        return 1.0;
    }
    let prefactor = (-x + a * x.ln() - ln_gamma(a)).exp();
    if x < a + 1.0 {
        let (mut term, mut sum, mut ap) = (1.0 / a, 1.0 / a, a);
        for _ in 0..ITERATIONS {
            ap += 1.0;
            term *= x / ap;
            sum += term;
            if term.abs() < sum.abs() * f64::EPSILON {
                break;
            }
        }
        (1.0 - sum * prefactor).max(0.0)
    } else {
        let mut b = x + 1.0 - a;
        let (mut c, mut d) = (1.0 / TINY, 1.0 / b);
        let mut h = d;
        for i in 1..ITERATIONS {
            let an = -(i as f64) * (i as f64 - a);
            b += 2.0;
            d = an * d + b;
            d = if d.abs() < TINY { TINY } else { d };
            c = b + an / c;
            c = if c.abs() < TINY { TINY } else { c };
            d = 1.0 / d;
            let step = d * c;
            h *= step;
            if (step - 1.0).abs() < f64::EPSILON {
                break;
            }
        }
        (prefactor * h).clamp(0.0, 1.0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Closed forms: `Q(1, x) = exp(-x)`, `Q(1/2, x) = erfc(sqrt x)`, and for 2 degrees of
    /// freedom the survival is `exp(-s / 2)`; a large `dof` against the normal limit.
    #[test]
    fn the_incomplete_gamma_matches_closed_forms() {
        for x in [0.01, 0.5, 1.0, 3.0, 20.0] {
            assert!(
                (regularized_gamma_q(1.0, x) - (-x).exp()).abs() < 1e-14,
                "{x}"
            );
            assert!((chi_square_survival(2.0 * x, 2) - (-x).exp()).abs() < 1e-14);
        }
        // erfc(1) = 0.157299207050285130658...
        assert!((regularized_gamma_q(0.5, 1.0) - 0.157_299_207_050_285_13).abs() < 1e-13);
        // Q(3, 2) = exp(-2) (1 + 2 + 2) = 5 exp(-2).
        assert!((regularized_gamma_q(3.0, 2.0) - 5.0 * (-2.0f64).exp()).abs() < 1e-14);
        // At the mean of 4000 degrees of freedom the survival is just under 1/2 (skewness
        // sqrt(8/k) moves the median below the mean by about 2/3).
        let p = chi_square_survival(4000.0, 4000);
        assert!((p - 0.5).abs() < 0.01 && p < 0.5, "{p}");
    }

    /// Pooling: cells under 5 are merged, smallest first; a sample where none is expected is
    /// counted, not divided by zero.
    #[test]
    fn pearson_pools_small_cells_and_flags_impossible_samples() {
        let expected = [2.0, 3.0, 10.0, 0.0];
        let observed = [1.0, 4.0, 12.0, 2.0];
        let (statistic, dof, impossible) = pearson(&observed, &expected);
        // Pooled (5, 5) adds 0; (12 - 10)^2 / 10 = 0.4; two cells, one degree of freedom.
        assert!((statistic - 0.4).abs() < 1e-15);
        assert_eq!((dof, impossible), (1, 2));
    }

    /// The uniform stream is uniform: mean 1/2, variance 1/12, within 5 sigma.
    #[test]
    fn the_stream_is_uniform() {
        let n = 100_000;
        let values: Vec<f64> = (0..n).map(|i| uniform(7, i, 0)).collect();
        let mean = values.iter().sum::<f64>() / n as f64;
        let variance = values.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / n as f64;
        assert!(
            (mean - 0.5).abs() < 5.0 * (1.0 / 12.0 / n as f64).sqrt(),
            "{mean}"
        );
        assert!((variance - 1.0 / 12.0).abs() < 1e-3, "{variance}");
        assert!(values.iter().all(|v| (0.0..1.0).contains(v)));
    }

    /// The domain's maps invert each other, and the Jacobian integrates to the sphere's
    /// solid angle.
    #[test]
    fn the_domain_covers_the_sphere() {
        let lobe = crate::Lobe::new(crate::LobeKind::Pow, crate::Exponent::new(64.0));
        let sampler = SpecularSampler::new(lobe, Geometry::Phong, crate::Normalisation::None);
        let wo = DVec3::new(0.5, 0.1, 0.8).normalize();
        let domain = Domain::new(&sampler, wo);
        for (x, y) in [(0.1, 0.2), (0.7, 0.05), (0.4, 0.9)] {
            let (w, _) = domain.forward(x, y);
            let (bx, by) = domain.backward(w);
            assert!((bx - x).abs() < 1e-12 && (by - y).abs() < 1e-12, "{x} {y}");
        }
        let area = rule(&|x, y| domain.forward(x, y).1, (0.0, 1.0), (0.0, 1.0));
        let whole = adaptive(
            &|x, y| domain.forward(x, y).1,
            (0.0, 1.0),
            (0.0, 1.0),
            area,
            1e-10,
            0,
        );
        assert!((whole - 4.0 * PI).abs() < 1e-8, "{whole}");
    }
}
