//! Fitting a family's coefficients across a range of `n`: Nelder-Mead (argmin) on the
//! epicentre's largest relative error over the fitting exponents, with the whole lobe's
//! largest absolute error and, where asked, the energy's distance from `t^n`'s kept within
//! their bounds by a steep penalty. The figures here are on coarse grids, for speed; the
//! verification measures the
//! fitted formula with the analysis itself.

use argmin::core::{CostFunction, Executor, State};
use argmin::solver::neldermead::NelderMead;

use super::families::Family;

/// The bounds a design must meet, as fractions.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Bounds {
    /// The epicentre's largest relative error.
    pub epicentre: f64,
    /// The whole lobe's largest absolute error, as a fraction of the peak.
    pub whole: f64,
    /// The largest `|energy ratio - 1|`, where energy is asked to match `t^n`'s.
    pub energy: Option<f64>,
}

/// A family's figures on the fitting grids (the worst over the exponents).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Figures {
    /// The epicentre's largest relative error.
    pub epicentre: f64,
    /// The whole lobe's largest absolute error.
    pub whole: f64,
    /// The largest `|energy ratio - 1|` (0 where not asked).
    pub energy: f64,
}

impl Figures {
    /// The epicentre's error relative to its bound (at most 1 meets it), plus a steep
    /// penalty for each other bound exceeded: how far the fit is from meeting the request.
    /// Infinite where the lobe left `[0, 1]` or was not a number.
    fn score(self, bounds: Bounds) -> f64 {
        finite_or_infinite(self.epicentre / bounds.epicentre + self.penalty(bounds))
    }

    /// What the fit minimises: the epicentre's error itself, plus the penalty. The epicentre's
    /// bound does not scale it, so that two requests whose other bounds hold alike are fitted
    /// alike, bit for bit: one family designed for 2 % and for 10 % is one lobe, not two
    /// that differ in their last digits.
    fn objective(self, bounds: Bounds) -> f64 {
        finite_or_infinite(self.epicentre + self.penalty(bounds))
    }

    /// The whole lobe's and the energy's bounds exceeded, each by its excess over the bound
    /// less [`MARGIN`], steeply weighted: enough that the fit never trades one for the
    /// epicentre. The margin is room for what the coarse grids miss: a fit that sat on the
    /// bound there was over it on the verification's dense sweep.
    fn penalty(self, bounds: Bounds) -> f64 {
        let over = |figure: f64, bound: f64| PENALTY * (figure / (MARGIN * bound) - 1.0).max(0.0);
        over(self.whole, bounds.whole) + bounds.energy.map_or(0.0, |e| over(self.energy, e))
    }
}

fn finite_or_infinite(score: f64) -> f64 {
    if score.is_nan() {
        f64::INFINITY
    } else {
        score
    }
}

/// The part of the whole lobe's and the energy's bounds the fit may use on its grids.
const MARGIN: f64 = 0.95;

/// How steeply an exceeded whole-lobe or energy bound counts: 1 % over its bound weighs as
/// much as a 100 % epicentre error.
const PENALTY: f64 = 100.0;

/// Points of the epicentre and of the whole lobe, in `w = n u` (the lobe lives in
/// `w < 30`, where `t^n > 1e-13`).
const EPICENTRE_POINTS: usize = 48;
const WHOLE_POINTS: usize = 96;
const ENERGY_INTERVALS: usize = 256;

/// The points one exponent's figures are taken at, with `t^n` there (computed once per fit,
/// not per evaluation of the objective).
pub struct Grid {
    n: f64,
    epicentre: Vec<(f64, f64)>,
    whole: Vec<(f64, f64)>,
}

impl Grid {
    /// The grid of `n`.
    #[must_use]
    pub fn new(n: f64) -> Self {
        let exact = |u: f64| (u, (1.0 - u).powf(n));
        let u_half = 1.0 - 2f64.powf(-1.0 / n);
        Self {
            n,
            epicentre: (0..=EPICENTRE_POINTS)
                .map(|k| exact(u_half * k as f64 / EPICENTRE_POINTS as f64))
                .collect(),
            whole: (0..=WHOLE_POINTS)
                .map(|k| (30.0 * k as f64 / WHOLE_POINTS as f64 / n).min(1.0))
                .chain([0.25, 0.5, 0.75, 1.0])
                .map(exact)
                .collect(),
        }
    }
}

/// The family's figures on `grid`.
fn figures_at(family: Family, beta: &[f64], grid: &Grid, energy: bool) -> Figures {
    let n = grid.n;
    let lobe = family.at(beta, n);
    let mut epicentre = 0.0_f64;
    for &(u, exact) in &grid.epicentre {
        epicentre = epicentre.max((lobe.eval(u) / exact - 1.0).abs());
    }
    let mut whole = 0.0_f64;
    for &(u, exact) in &grid.whole {
        let value = lobe.eval(u);
        if !(0.0..=1.0).contains(&value) {
            return Figures {
                epicentre: f64::INFINITY,
                whole: f64::INFINITY,
                energy: f64::INFINITY,
            };
        }
        whole = whole.max((value - exact).abs());
    }
    let energy = if energy {
        // (n + 1) int_0^1 lobe(1 - u) du by Simpson's rule over u in [0, min(1, 40 / n)],
        // the rest beyond the lobe.
        let end = (40.0 / n).min(1.0);
        let h = end / ENERGY_INTERVALS as f64;
        let sum: f64 = (0..=ENERGY_INTERVALS)
            .map(|k| {
                let weight = match k {
                    0 => 1.0,
                    k if k == ENERGY_INTERVALS => 1.0,
                    k if k % 2 == 1 => 4.0,
                    _ => 2.0,
                };
                weight * lobe.eval(h * k as f64)
            })
            .sum();
        (sum * h / 3.0 * (n + 1.0) - 1.0).abs()
    } else {
        0.0
    };
    Figures {
        epicentre,
        whole,
        energy,
    }
}

/// The family's figures, the worst over the grids.
#[must_use]
pub fn figures(family: Family, beta: &[f64], grids: &[Grid], energy: bool) -> Figures {
    grids.iter().fold(
        Figures {
            epicentre: 0.0,
            whole: 0.0,
            energy: 0.0,
        },
        |worst, grid| {
            let at = figures_at(family, beta, grid, energy);
            Figures {
                epicentre: worst.epicentre.max(at.epicentre),
                whole: worst.whole.max(at.whole),
                energy: worst.energy.max(at.energy),
            }
        },
    )
}

struct Objective<'a> {
    family: Family,
    grids: &'a [Grid],
    bounds: Bounds,
}

impl CostFunction for Objective<'_> {
    type Param = Vec<f64>;
    type Output = f64;

    fn cost(&self, beta: &Vec<f64>) -> Result<f64, argmin::core::Error> {
        let objective = figures(self.family, beta, self.grids, self.bounds.energy.is_some())
            .objective(self.bounds);
        // Nelder-Mead compares values: an infinite one is a wall, kept finite so that the
        // simplex's centroid stays a number.
        Ok(objective.min(1e12))
    }
}

/// Nelder-Mead runs from the start and from each result (a simplex can stall on the
/// kinks of a worst-case objective; a fresh one around the best point moves on).
const RESTARTS: usize = 3;
const ITERATIONS: u64 = 600;

/// The family's coefficients fitted over the exponents of `grids` against `bounds`, and their
/// score (at most 1 where the coarse grids meet every bound).
#[must_use]
pub fn fit(family: Family, grids: &[Grid], bounds: Bounds) -> (Vec<f64>, f64) {
    let objective = || Objective {
        family,
        grids,
        bounds,
    };
    let mut best = family.start();
    let mut best_value = objective().cost(&best).unwrap_or(f64::INFINITY);
    for restart in 0..RESTARTS {
        let spread = 0.2 / (1 + restart) as f64;
        let mut simplex = vec![best.clone()];
        for i in 0..best.len() {
            let mut vertex = best.clone();
            vertex[i] += if vertex[i] == 0.0 {
                0.05 * spread
            } else {
                vertex[i] * spread
            };
            simplex.push(vertex);
        }
        let Ok(solver) = NelderMead::new(simplex).with_sd_tolerance(1e-12) else {
            break;
        };
        let Ok(result) = Executor::new(objective(), solver)
            .configure(|state| state.max_iters(ITERATIONS))
            .run()
        else {
            break;
        };
        let state = result.state();
        if let Some(found) = state.get_best_param() {
            if state.get_best_cost() < best_value {
                best_value = state.get_best_cost();
                best = found.clone();
            }
        }
    }
    let score = figures(family, &best, grids, bounds.energy.is_some()).score(bounds);
    (best, score)
}
