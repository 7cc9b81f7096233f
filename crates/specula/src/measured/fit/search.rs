//! The search for a family's shape parameter: the error profile over `ln n` (or `ln alpha`)
//! scanned on a grid, the best cell refined by Brent's method, each parameter's linear
//! coefficients solved per channel from the last nearby solution.

use argmin::core::{CostFunction, Executor};
use argmin::solver::brent::BrentOpt;

use super::channel::Prepared;
use super::sums::MAX_COEFFICIENTS;
use super::{Fit, Observations, Sharing, Specular, Stage, GRID_POINTS};

/// A channel's coefficients (`kd`, then the specular columns') and its error sum.
type Solution = ([f64; MAX_COEFFICIENTS], f64);

/// One shape parameter's profile: its best error over the linear coefficients for some
/// channels. A search evaluates it at nearby parameters one after another, so each channel's
/// solve starts from the last one's coefficients (`last`): a step or two, not the whole
/// descent from the linearised start.
struct Profile<'p, 'a> {
    prepared: &'p Prepared<'a>,
    specular: Specular,
    channels: &'p [usize],
    last: core::cell::RefCell<Option<Vec<[f64; MAX_COEFFICIENTS]>>>,
}

impl Profile<'_, '_> {
    fn solve(&self, log_parameter: f64, stage: Stage) -> (Vec<Solution>, f64) {
        let columns = self
            .specular
            .columns(log_parameter.exp(), self.prepared, stage);
        let rows = self.prepared.rows(&columns);
        let last = self.last.borrow().clone();
        let solutions: Vec<Solution> = self
            .channels
            .iter()
            .enumerate()
            .map(|(k, &c)| {
                let warm = last.as_ref().map(|last| &last[k]);
                self.prepared.solve_channel(c, &rows, warm)
            })
            .collect();
        *self.last.borrow_mut() = Some(solutions.iter().map(|s| s.0).collect());
        let total = solutions.iter().map(|s| s.1).sum();
        (solutions, total)
    }
}

impl CostFunction for Profile<'_, '_> {
    type Param = f64;
    type Output = f64;

    fn cost(&self, log_parameter: &f64) -> Result<f64, argmin::core::Error> {
        Ok(self.solve(*log_parameter, Stage::Search).1)
    }
}

/// The scan of one family over the grid of log-parameters: per point, each channel's best
/// cost (the shared fit sums them, a per-channel fit takes its own).
fn scan(prepared: &Prepared, specular: Specular) -> (Vec<f64>, Vec<[f64; 3]>) {
    let [low, high] = specular.log_range();
    let grid: Vec<f64> = (0..GRID_POINTS)
        .map(|i| low + (high - low) * i as f64 / (GRID_POINTS - 1) as f64)
        .collect();
    // Each point's channels start from the previous point's coefficients.
    let mut last: Option<[Solution; 3]> = None;
    let costs = grid
        .iter()
        .map(|&p| {
            let rows = prepared.rows(&specular.columns(p.exp(), prepared, Stage::Search));
            let solved: [Solution; 3] = core::array::from_fn(|c| {
                prepared.solve_channel(c, &rows, last.as_ref().map(|last| &last[c].0))
            });
            last = Some(solved);
            solved.map(|(_, cost)| cost)
        })
        .collect();
    (grid, costs)
}

/// The best log-parameter of `profile`: the scan's best point for its channels, then Brent
/// between that point's neighbours.
fn minimise(profile: &Profile, grid: &[f64], costs: &[[f64; 3]]) -> f64 {
    let total = |i: usize| profile.channels.iter().map(|&c| costs[i][c]).sum::<f64>();
    let best = (0..grid.len())
        .min_by(|&a, &b| total(a).total_cmp(&total(b)))
        .unwrap_or(0);
    let (a, b) = (
        grid[best.saturating_sub(1)],
        grid[(best + 1).min(grid.len() - 1)],
    );
    let brent = |low: f64, high: f64, tolerance: f64| {
        Executor::new(
            Profile {
                last: core::cell::RefCell::new(None),
                ..*profile
            },
            BrentOpt::new(low, high).set_tolerance(1e-8, tolerance),
        )
        .configure(|state| state.max_iters(60))
        .run()
        .ok()
        .and_then(|result| {
            let state = result.state();
            state.best_param.map(|p| (p, state.best_cost))
        })
    };
    // Near a real material's optimum the error grows with the square of the step in ln n, so
    // 2e-4 leaves it where it is to a few parts in a million; a model the data fit exactly
    // (zero residual) grows linearly, and is polished again, closer.
    let mut polished = brent(a, b, COARSE_TOLERANCE);
    if let Some((p, cost)) = polished.filter(|&(_, cost)| cost < EXACT_COST) {
        let (low, high) = (p - 4.0 * COARSE_TOLERANCE, p + 4.0 * COARSE_TOLERANCE);
        polished = brent(low.max(a), high.min(b), 1e-7)
            .filter(|q| q.1 <= cost)
            .or(polished);
    }
    match polished {
        Some((p, cost)) if cost <= total(best) => p,
        _ => grid[best],
    }
}

/// Brent's tolerance on the log-parameter.
const COARSE_TOLERANCE: f64 = 2e-4;

/// An error sum below which the model fits the data exactly but for the search (an error
/// `E` of 1e-4 and below, where a measured material's is 1e-2 and above).
const EXACT_COST: f64 = 1e-8;

/// Fits `specular` to the observations with `n` shared or per channel.
#[must_use]
pub fn fit(observations: &Observations, specular: Specular, sharing: Sharing) -> Fit {
    let [shared, per_channel] = fit_family(&Prepared::new(observations), specular);
    match sharing {
        Sharing::Shared => shared,
        Sharing::PerChannel => per_channel,
    }
}

/// Both fits of one family, from one scan.
pub(super) fn fit_family(prepared: &Prepared, specular: Specular) -> [Fit; 2] {
    let (grid, costs) = scan(prepared, specular);
    let fit = |sharing, parameter: [f64; 3], solutions: [Solution; 3]| {
        let channel_error = solutions.map(|(_, cost)| cost.sqrt());
        // With Fresnel the coefficients are `K F0` and `K (1 - F0)`; `F0` is 0 (any) where
        // `K` is.
        let k = solutions.map(|(x, _)| x[1] + x[2]);
        let f0 = specular.has_fresnel().then(|| {
            core::array::from_fn(|c| {
                if k[c] > 0.0 {
                    solutions[c].0[1] / k[c]
                } else {
                    0.0
                }
            })
        });
        Fit {
            specular,
            sharing,
            parameter: parameter.map(f64::exp),
            kd: solutions.map(|(x, _)| x[0]),
            k,
            f0,
            error: (channel_error.iter().map(|e| e * e).sum::<f64>() / 3.0).sqrt(),
            channel_error,
        }
    };
    let profile = |channels| Profile {
        prepared,
        specular,
        channels,
        last: core::cell::RefCell::new(None),
    };
    let all = profile(&[0, 1, 2]);
    let shared = minimise(&all, &grid, &costs);
    let at_shared = all.solve(shared, Stage::Answer).0;
    let shared_solutions = [at_shared[0], at_shared[1], at_shared[2]];
    // Each channel from its own scan, or from the shared optimum where that is better (a
    // second start: a channel's scan can bracket another basin than the sum's).
    let mut parameter = [shared; 3];
    let mut solutions = shared_solutions;
    for (c, channel) in [[0], [1], [2]].iter().enumerate() {
        let own = profile(channel);
        let best = minimise(&own, &grid, &costs);
        let (solved, cost) = own.solve(best, Stage::Answer);
        if cost < solutions[c].1 {
            (parameter[c], solutions[c]) = (best, solved[0]);
        }
    }
    [
        fit(Sharing::Shared, [shared; 3], shared_solutions),
        fit(Sharing::PerChannel, parameter, solutions),
    ]
}
