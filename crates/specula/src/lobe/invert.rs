//! Inverting a lobe's closed-form tail integral where no closed-form inverse exists:
//! Newton's method safeguarded by bisection, so that it converges from any start and never
//! leaves the bracket.

/// The most iterations; each at least halves the bracket when Newton's step is refused, so
/// 80 reach `f64` resolution on any interval of length at most 2.
const MAX_ITERATIONS: u32 = 80;

/// How close a root is solved for, relative to it: [`F64_RESOLUTION`] for the `f64` paths,
/// [`F32_RESOLUTION`] for a root an `f32` renderer rounds.
pub const F64_RESOLUTION: f64 = 4.0 * f64::EPSILON;

/// `2^-26`, a quarter of `f32`'s relative rounding: Newton stopped once its step is this
/// small a part of the solver's variable (for the lobes, `1 - t` or the angle, not the
/// cosine itself) is, by its quadratic convergence, far closer than that to the root, and
/// the cosine rounds to the exact root's `f32` (tested for every Newton-sampled lobe).
pub const F32_RESOLUTION: f64 = 1.0 / 67_108_864.0;

/// Where a lobe's Newton starts and how close it stops.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct NewtonStart {
    /// A cosine near the root (a table's draw), or `None` for the model's own first guess.
    pub near: Option<f64>,
    /// [`F64_RESOLUTION`] or [`F32_RESOLUTION`].
    pub resolution: f64,
}

/// A root found, and the iterations it took.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Inverted {
    /// `x` with `f(x) = target`, to `f64` resolution.
    pub x: f64,
    /// Iterations spent (Newton steps and bisections).
    pub iterations: u32,
}

/// `x` in `[lo, hi]` with `f(x) = target`, for `f` non-decreasing with derivative `df`,
/// starting from `guess`, stopping once a step moves `x` by at most `resolution` of it.
pub fn solve_increasing(
    f: impl Fn(f64) -> f64,
    df: impl Fn(f64) -> f64,
    target: f64,
    (mut lo, mut hi): (f64, f64),
    (guess, resolution): (f64, f64),
) -> Inverted {
    let mut x = guess.clamp(lo, hi);
    for iteration in 1..=MAX_ITERATIONS {
        let residual = f(x) - target;
        if residual == 0.0 {
            return Inverted {
                x,
                iterations: iteration,
            };
        }
        if residual < 0.0 {
            lo = x;
        } else {
            hi = x;
        }
        let slope = df(x);
        let newton = x - residual / slope;
        let next = if slope > 0.0 && newton > lo && newton < hi {
            newton
        } else {
            0.5 * (lo + hi)
        };
        if (next - x).abs() <= resolution * x.abs().max(f64::MIN_POSITIVE) || hi <= lo {
            return Inverted {
                x: next,
                iterations: iteration,
            };
        }
        x = next;
    }
    Inverted {
        x,
        iterations: MAX_ITERATIONS,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `x^3 = 2` from a poor start, and a flat start (zero slope) that needs the bisection.
    #[test]
    fn finds_roots_from_any_start() {
        let cube = |x: f64| x * x * x;
        let root = solve_increasing(
            cube,
            |x| 3.0 * x * x,
            2.0,
            (0.0, 2.0),
            (0.0, F64_RESOLUTION),
        );
        assert!((root.x - 2f64.cbrt()).abs() < 1e-15, "{root:?}");
        assert!(root.iterations < 40, "{root:?}");
        let far = solve_increasing(
            cube,
            |x| 3.0 * x * x,
            2.0,
            (0.0, 2.0),
            (2.0, F64_RESOLUTION),
        );
        assert!((far.x - 2f64.cbrt()).abs() < 1e-15, "{far:?}");
    }
}
