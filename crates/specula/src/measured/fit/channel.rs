//! One channel's best `(kd, K)` for given specular values: the observations prepared once
//! (cosines, lobe cosines, the data's cube roots), the weighted linear start and the projected
//! Gauss-Newton steps on the cube-root error (see the module page of `fit`).

use core::f64::consts::FRAC_1_PI;

use glam::DVec3;

use super::Observations;
use crate::Geometry;

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

    /// The error sum of channel `c` with `(kd, K)` over specular values `specular`; the
    /// model's cube roots are left in `roots` for the next Gauss-Newton step.
    fn cost(&self, c: usize, specular: &[f64], [kd, k]: [f64; 2], roots: &mut [f64]) -> f64 {
        let mut sum = 0.0;
        for (j, root) in roots.iter_mut().enumerate() {
            *root = cube_root((kd * FRAC_1_PI + k * specular[j]) * self.cosine[j]);
            let r = self.target[c][j] - *root;
            sum += self.weight[j] * r * r;
        }
        sum
    }

    /// The best `(kd, K) >= 0` of channel `c` for these specular values, and its cost.
    pub(super) fn solve_channel(&self, c: usize, specular: &[f64]) -> ([f64; 2], f64) {
        let p = |j: usize| FRAC_1_PI * self.cosine[j];
        let q = |j: usize| specular[j] * self.cosine[j];
        // The start: weighted least squares in f cos with the cube root's slope as weight.
        let mut normal = [[0.0; 2]; 2];
        let mut rhs = [0.0; 2];
        for j in 0..specular.len() {
            let (a, b, w) = (p(j), q(j), self.linearised[c][j]);
            let y = self.target[c][j].powi(3);
            normal[0][0] += w * a * a;
            normal[0][1] += w * a * b;
            normal[1][1] += w * b * b;
            rhs[0] += w * a * y;
            rhs[1] += w * b * y;
        }
        let mut x = solve_nonnegative(normal, rhs);
        let (mut roots, mut trial_roots) = (vec![0.0; specular.len()], vec![0.0; specular.len()]);
        let mut cost = self.cost(c, specular, x, &mut roots);
        for _ in 0..6 {
            let mut normal = [[0.0; 2]; 2];
            let mut rhs = [0.0; 2];
            for (j, &root) in roots.iter().enumerate() {
                // The root's slope, bounded where the model vanishes.
                let slope = 1.0 / (3.0 * root.max(1e-4).powi(2));
                let (a, b) = (slope * p(j), slope * q(j));
                let (w, r) = (self.weight[j], self.target[c][j] - root);
                normal[0][0] += w * a * a;
                normal[0][1] += w * a * b;
                normal[1][1] += w * b * b;
                rhs[0] += w * a * r;
                rhs[1] += w * b * r;
            }
            let step = solve_nonnegative_step(normal, rhs, x);
            let mut scale = 1.0;
            let improved = loop {
                let trial = [
                    (x[0] + scale * step[0]).max(0.0),
                    (x[1] + scale * step[1]).max(0.0),
                ];
                let trial_cost = self.cost(c, specular, trial, &mut trial_roots);
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

/// The 2x2 symmetric system `normal x = rhs` solved with `x >= 0` (each bound tried when
/// the unconstrained solution breaks it).
fn solve_nonnegative(normal: [[f64; 2]; 2], rhs: [f64; 2]) -> [f64; 2] {
    let det = normal[0][0] * normal[1][1] - normal[0][1] * normal[0][1];
    if det > 1e-300 {
        let x = [
            (rhs[0] * normal[1][1] - rhs[1] * normal[0][1]) / det,
            (rhs[1] * normal[0][0] - rhs[0] * normal[0][1]) / det,
        ];
        if x[0] >= 0.0 && x[1] >= 0.0 {
            return x;
        }
    }
    let only_diffuse = [(rhs[0] / normal[0][0]).max(0.0), 0.0];
    let only_specular = [0.0, (rhs[1] / normal[1][1]).max(0.0)];
    let residual = |x: [f64; 2]| {
        // The quadratic's value up to a constant: x' N x - 2 x' rhs.
        x[0] * x[0] * normal[0][0] + 2.0 * x[0] * x[1] * normal[0][1] + x[1] * x[1] * normal[1][1]
            - 2.0 * (x[0] * rhs[0] + x[1] * rhs[1])
    };
    let candidates = [only_diffuse, only_specular].map(|x| {
        if x.iter().all(|v| v.is_finite()) {
            x
        } else {
            [0.0; 2]
        }
    });
    if residual(candidates[0]) <= residual(candidates[1]) {
        candidates[0]
    } else {
        candidates[1]
    }
}

/// The Gauss-Newton step from `x` within `x + step >= 0`: the free step where it stays
/// inside, else the better (by the Gauss-Newton model) of the two steps with one parameter
/// moved to its bound 0 and the other solved with it there.
fn solve_nonnegative_step(normal: [[f64; 2]; 2], rhs: [f64; 2], x: [f64; 2]) -> [f64; 2] {
    let det = normal[0][0] * normal[1][1] - normal[0][1] * normal[0][1];
    if det > 1e-300 {
        let free = [
            (rhs[0] * normal[1][1] - rhs[1] * normal[0][1]) / det,
            (rhs[1] * normal[0][0] - rhs[0] * normal[0][1]) / det,
        ];
        if x[0] + free[0] >= 0.0 && x[1] + free[1] >= 0.0 {
            return free;
        }
    }
    // The model's value of a step, up to a constant: step' N step - 2 step' rhs.
    let model = |d: [f64; 2]| {
        d[0] * d[0] * normal[0][0] + 2.0 * d[0] * d[1] * normal[0][1] + d[1] * d[1] * normal[1][1]
            - 2.0 * (d[0] * rhs[0] + d[1] * rhs[1])
    };
    let pinned = |at: usize| {
        let other = 1 - at;
        let mut step = [0.0; 2];
        step[at] = -x[at];
        if normal[other][other] > 0.0 {
            step[other] =
                ((rhs[other] - normal[0][1] * step[at]) / normal[other][other]).max(-x[other]);
        }
        step
    };
    let (a, b) = (pinned(0), pinned(1));
    if model(a) <= model(b) {
        a
    } else {
        b
    }
}

#[cfg(test)]
mod tests {
    use super::cube_root;

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
