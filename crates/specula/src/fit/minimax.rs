//! Minimax polynomial fits by the Remez exchange algorithm.
//!
//! The alternative to the thesis's Chebyshev fit: the polynomial of a given degree whose
//! largest weighted error on the interval is smallest. With [`ErrorWeight::Relative`] it
//! minimises the largest *relative* error, the figure the thesis quotes for the epicentre.
//! The fit works in the normalised variable `y in [-1, 1]` (for conditioning) and converts to
//! the caller's variable at the end.

use serde::Serialize;

use super::Polynomial;

/// What the fit makes as small as possible.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum ErrorWeight {
    /// `max |p - f|`.
    Absolute,
    /// `max |p - f| / |f|`; `f` must not vanish on the interval.
    Relative,
}

/// The result of a minimax fit.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct MinimaxFit {
    /// The polynomial in the caller's variable.
    pub polynomial: Polynomial,
    /// The largest weighted error found on a dense scan of the interval.
    pub max_error: f64,
    /// Exchange iterations used.
    pub iterations: usize,
}

/// Why a minimax fit failed.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum MinimaxError {
    /// The reference system was singular (e.g. a function that vanishes under relative weight).
    #[error("the Remez reference system is singular")]
    Singular,
    /// The interval is empty or not finite.
    #[error("the interval [{0}, {1}] is empty or not finite")]
    BadInterval(f64, f64),
}

const SCAN_POINTS: usize = 4096;
const MAX_ITERATIONS: usize = 64;
const LEVELLED: f64 = 1e-9;

/// The degree-`degree` polynomial minimising the weighted maximum error of `f` on
/// `[lower, upper]`.
pub fn minimax(
    f: impl Fn(f64) -> f64,
    lower: f64,
    upper: f64,
    degree: usize,
    weight: ErrorWeight,
) -> Result<MinimaxFit, MinimaxError> {
    if !(lower.is_finite() && upper.is_finite() && lower < upper) {
        return Err(MinimaxError::BadInterval(lower, upper));
    }
    let half_width = 0.5 * (upper - lower);
    let centre = 0.5 * (upper + lower);
    let g = |y: f64| f(y * half_width + centre);
    let weighted_error = |p: &Polynomial, y: f64| {
        let target = g(y);
        let error = p.eval(y) - target;
        match weight {
            ErrorWeight::Absolute => error,
            ErrorWeight::Relative => error / target.abs(),
        }
    };

    let points = degree + 2;
    let mut reference: Vec<f64> = (0..points)
        .map(|i| -(core::f64::consts::PI * i as f64 / (points - 1) as f64).cos())
        .collect();
    let mut best = None;
    for iteration in 1..=MAX_ITERATIONS {
        let p = solve_reference(&g, &reference, degree, weight).ok_or(MinimaxError::Singular)?;
        let extrema = alternating_extrema(|y| weighted_error(&p, y), points);
        let magnitudes: Vec<f64> = extrema
            .iter()
            .map(|&y| weighted_error(&p, y).abs())
            .collect();
        let largest = magnitudes.iter().copied().fold(0.0, f64::max);
        let smallest = magnitudes.iter().copied().fold(f64::INFINITY, f64::min);
        best = Some((p, largest, iteration));
        if extrema.len() != points || largest - smallest <= LEVELLED * largest {
            break;
        }
        reference = extrema;
    }
    let (p, max_error, iterations) = best.ok_or(MinimaxError::Singular)?;
    Ok(MinimaxFit {
        polynomial: p.compose_linear(1.0 / half_width, -centre / half_width),
        max_error,
        iterations,
    })
}

/// Solves `p(y_i) + (-1)^i E / w(y_i) = g(y_i)` for the coefficients of `p` (and `E`).
fn solve_reference(
    g: &impl Fn(f64) -> f64,
    reference: &[f64],
    degree: usize,
    weight: ErrorWeight,
) -> Option<Polynomial> {
    let size = degree + 2;
    let mut system: Vec<Vec<f64>> = reference
        .iter()
        .enumerate()
        .map(|(i, &y)| {
            let target = g(y);
            let mut row: Vec<f64> = (0..=degree).map(|k| y.powi(k as i32)).collect();
            let sign = if i % 2 == 0 { 1.0 } else { -1.0 };
            let scale = match weight {
                ErrorWeight::Absolute => 1.0,
                ErrorWeight::Relative => target.abs(),
            };
            row.push(sign * scale);
            row.push(target);
            row
        })
        .collect();
    let solution = gaussian_elimination(&mut system, size)?;
    Some(Polynomial::new(solution[..=degree].to_vec()))
}

/// Solves the augmented `size x (size + 1)` system with partial pivoting.
fn gaussian_elimination(system: &mut [Vec<f64>], size: usize) -> Option<Vec<f64>> {
    for column in 0..size {
        let pivot = (column..size)
            .max_by(|&a, &b| system[a][column].abs().total_cmp(&system[b][column].abs()))?;
        if system[pivot][column].abs() < 1e-300 {
            return None;
        }
        system.swap(column, pivot);
        let (above, below) = system.split_at_mut(column + 1);
        let pivot_row = &above[column];
        for row in below.iter_mut().take(size - column - 1) {
            let factor = row[column] / pivot_row[column];
            for (target, &source) in row[column..=size].iter_mut().zip(&pivot_row[column..=size]) {
                *target -= factor * source;
            }
        }
    }
    let mut solution = vec![0.0; size];
    for row in (0..size).rev() {
        let known: f64 = (row + 1..size).map(|k| system[row][k] * solution[k]).sum();
        solution[row] = (system[row][size] - known) / system[row][row];
    }
    solution.iter().all(|x| x.is_finite()).then_some(solution)
}

/// The abscissae of the error's sign-alternating extrema on `[-1, 1]`: a dense scan split
/// into runs of one sign, the largest point of each run refined by golden-section search,
/// then trimmed to `wanted` points by dropping the smaller end.
fn alternating_extrema(error: impl Fn(f64) -> f64, wanted: usize) -> Vec<f64> {
    let step = 2.0 / (SCAN_POINTS - 1) as f64;
    let mut runs: Vec<(f64, f64)> = Vec::new(); // (abscissa, signed error) of each run's peak
    for i in 0..SCAN_POINTS {
        let y = -1.0 + step * i as f64;
        let e = error(y);
        match runs.last_mut() {
            Some(last) if last.1.signum() == e.signum() => {
                if e.abs() > last.1.abs() {
                    *last = (y, e);
                }
            }
            _ => runs.push((y, e)),
        }
    }
    let mut peaks: Vec<f64> = runs
        .iter()
        .map(|&(y, e)| refine_peak(&error, y, step, e.signum()))
        .collect();
    while peaks.len() > wanted {
        let first = error(peaks[0]).abs();
        let last = error(peaks[peaks.len() - 1]).abs();
        if first < last {
            peaks.remove(0);
        } else {
            peaks.pop();
        }
    }
    peaks
}

fn refine_peak(error: &impl Fn(f64) -> f64, centre: f64, step: f64, sign: f64) -> f64 {
    let objective = |y: f64| -sign * error(y);
    let (mut a, mut b) = ((centre - step).max(-1.0), (centre + step).min(1.0));
    let ratio = 0.5 * (5f64.sqrt() - 1.0);
    for _ in 0..60 {
        let x1 = b - ratio * (b - a);
        let x2 = a + ratio * (b - a);
        if objective(x1) < objective(x2) {
            b = x2;
        } else {
            a = x1;
        }
    }
    let inside = 0.5 * (a + b);
    // The interval ends are candidates too: equioscillation often peaks there.
    [
        inside,
        (centre - step).max(-1.0),
        (centre + step).min(1.0),
        centre,
    ]
    .into_iter()
    .min_by(|&p, &q| objective(p).total_cmp(&objective(q)))
    .unwrap_or(centre)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The best linear approximation of `x^2` on [0, 1] is `x - 1/8` (error 1/8), a classic
    /// closed form.
    #[test]
    fn finds_the_known_best_line_for_a_parabola() {
        let fit = minimax(|x| x * x, 0.0, 1.0, 1, ErrorWeight::Absolute).unwrap();
        let c = fit.polynomial.coeffs();
        assert!((c[0] + 0.125).abs() < 1e-8, "{c:?}");
        assert!((c[1] - 1.0).abs() < 1e-8, "{c:?}");
        assert!((fit.max_error - 0.125).abs() < 1e-8);
    }

    /// Minimax is never worse than the Chebyshev interpolant of the same degree.
    #[test]
    fn beats_chebyshev_interpolation_in_relative_error() {
        let f = |g: f64| g.cos().powf(100.0);
        let upper = (0.5f64.powf(0.01)).acos();
        let fit = minimax(f, 0.0, upper, 2, ErrorWeight::Relative).unwrap();
        let cheb = super::super::ChebyshevSeries::fit(f, 0.0, upper, 3).to_power_basis();
        let max_rel = |p: &Polynomial| {
            (0..=20_000)
                .map(|i| upper * i as f64 / 20_000.0)
                .map(|g| ((p.eval(g) - f(g)) / f(g)).abs())
                .fold(0.0, f64::max)
        };
        let (minimax_error, cheb_error) = (max_rel(&fit.polynomial), max_rel(&cheb));
        assert!(
            minimax_error <= cheb_error,
            "{minimax_error} vs {cheb_error}"
        );
        assert!((minimax_error - fit.max_error).abs() < 1e-6 * fit.max_error.max(1e-12));
    }
}
