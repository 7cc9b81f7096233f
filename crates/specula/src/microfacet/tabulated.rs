//! A normal distribution known only as a shape, `D(h) = C shape(cos theta_h)`, made a
//! microfacet distribution by quadrature, once per shape and exponent:
//!
//! - **`C`**, so that the projected microfacet area is one: `int D cos theta_h dw = 1`;
//! - **Smith's `Lambda`** from the projected area a direction sees,
//!   `int D(m) <wo, m>+ dm = (1 + Lambda(wo)) cos theta_o` (Heitz 2014, eq. 15, the identity
//!   Smith's masking is built to satisfy). Its azimuthal integral is closed:
//!   `int_0^2pi max(0, a cos phi + b) dphi` is `2 pi b` when `b >= a`, else
//!   `2 (a sin phi_c + b phi_c)` with `cos phi_c = -b / a` (`a = sin theta_o sin theta_m`,
//!   `b = cos theta_o cos theta_m`), so each `Lambda` is one integral over `theta_m`, tabulated
//!   at [`ANGLES`] angles of `theta_o`, closer together towards the horizon, and interpolated;
//! - **sampling** of `D cos theta_h`: its cumulative distribution over `theta_h` on a grid
//!   dense where the lobe lives, inverted by interpolation.
//!
//! The integrals are adaptive Gauss-Kronrod ([`crate::quadrature`]) split at breakpoints that
//! follow the lobe's own width (`sqrt(2 / (n + 2))`, Beckmann's `alpha` at Walter's
//! correspondence), doubling outwards, and where `wo` begins to see the microfacets' backs;
//! bisection finds the lobes' own kinks (a cut to 0).

use core::f64::consts::{FRAC_PI_2, PI, TAU};

use crate::quadrature::integrate_pieces;

/// Angles `theta_o` in `[0, pi/2]` at which `Lambda` is tabulated.
pub const ANGLES: usize = 257;

/// The `theta_m` integrals' absolute tolerance (adaptive Gauss-Kronrod): `Lambda` to a few
/// parts in a million at 88 degrees, where it is largest and Smith's slope-space integral
/// is held against it.
pub const TOLERANCE: f64 = 1e-8;

/// Points of the sampling table over `theta_h`.
const SAMPLING_POINTS: usize = 4096;

/// A shape made a microfacet distribution.
pub struct Tabulated {
    /// `C`: `D = C shape`.
    normaliser: f64,
    /// `int D(m) <wo, m>+ dm` at `theta_o` = [`table_angle`]`(k)`.
    projected: Vec<f64>,
    /// The shape, kept for the sampling table.
    shape: Box<dyn Fn(f64) -> f64 + Send + Sync>,
    /// The sampling table, made when a direction is first drawn (a fit evaluates hundreds of
    /// distributions and draws from none).
    sampling: std::sync::OnceLock<Sampling>,
}

impl core::fmt::Debug for Tabulated {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.debug_struct("Tabulated")
            .field("normaliser", &self.normaliser)
            .field("projected", &self.projected.len())
            .finish_non_exhaustive()
    }
}

/// The sampling table: the cumulative distribution of `D cos theta_h`.
#[derive(Debug)]
struct Sampling {
    /// `theta_h`, increasing from 0 to `pi / 2`.
    angles: Vec<f64>,
    /// The cumulative probability at each of `angles`, 0 to 1.
    cumulative: Vec<f64>,
}

impl Tabulated {
    /// `shape` (of `cos theta_h`, non-negative, peaked at 1) made a distribution; `width`
    /// the angle its peak spans (radians).
    #[must_use]
    pub fn new(shape: impl Fn(f64) -> f64 + Send + Sync + 'static, width: f64) -> Self {
        Self::with_tolerance(shape, width, TOLERANCE)
    }

    /// [`Tabulated::new`] with its integrals to within `tolerance` (positive; 0 refines
    /// until [`crate::quadrature::MAX_PANELS`]) rather than
    /// [`TOLERANCE`]: a search that only compares distributions near each other (a fit's)
    /// takes them looser and faster.
    #[must_use]
    pub fn with_tolerance(
        shape: impl Fn(f64) -> f64 + Send + Sync + 'static,
        width: f64,
        tolerance: f64,
    ) -> Self {
        let points = breakpoints(width);
        // The projected area splits at `theta_m = pi / 2 - theta_o`: below it every microfacet
        // faces `wo` (`b >= a`), and the azimuthal integral is `2 pi cos theta_o cos theta_m`,
        // so that part is `cos theta_o` times the area's share up to there; above it, the
        // integral is taken. One pass over the pieces between every table angle's split gives
        // the area up to each (and the whole area, `C`), where 257 integrals over the whole
        // range redid it per angle.
        let splits: Vec<f64> = (0..ANGLES).map(|k| FRAC_PI_2 - table_angle(k)).collect();
        let mut cuts: Vec<f64> = points.iter().chain(&splits).copied().collect();
        cuts.sort_by(f64::total_cmp);
        cuts.dedup();
        let area_density = |theta: f64| {
            let (s, c) = theta.sin_cos();
            shape(c) * c * s
        };
        // The area below each cut, `int_0^cut shape cos sin`.
        let mut below = Vec::with_capacity(cuts.len());
        let mut running = 0.0;
        below.push(0.0);
        let piece_tolerance = tolerance / cuts.len() as f64;
        for pair in cuts.windows(2) {
            running += integrate_pieces(area_density, pair, piece_tolerance);
            below.push(running);
        }
        let area = TAU * running;
        let normaliser = 1.0 / area;
        let area_below = |x: f64| below[cuts.partition_point(|&c| c < x).min(cuts.len() - 1)];
        let projected = splits
            .iter()
            .enumerate()
            .map(|(k, &split)| {
                let (sin_o, cos_o) = table_angle(k).sin_cos();
                let facing = TAU * cos_o * area_below(split);
                let beyond: Vec<f64> = points
                    .iter()
                    .copied()
                    .filter(|&p| p > split)
                    .chain([split, FRAC_PI_2])
                    .collect();
                let seen_edge_on = integrate_pieces(
                    |theta_m: f64| {
                        let (s, c) = theta_m.sin_cos();
                        shape(c) * s * azimuthal(sin_o * s, cos_o * c)
                    },
                    &beyond,
                    tolerance,
                );
                normaliser * (facing + seen_edge_on)
            })
            .collect();
        Self {
            normaliser,
            projected,
            shape: Box::new(shape),
            sampling: std::sync::OnceLock::new(),
        }
    }

    /// The sampling table of `D cos theta_h`: trapezoids on the table's own grid, then scaled
    /// to end at 1 (the table draws what it integrates, and `pdf` reports the exact density).
    fn sampling(&self) -> &Sampling {
        self.sampling.get_or_init(|| {
            let angles: Vec<f64> = (0..SAMPLING_POINTS)
                .map(|k| FRAC_PI_2 * (k as f64 / (SAMPLING_POINTS - 1) as f64).powi(2))
                .collect();
            let density = |theta: f64| {
                let (s, c) = theta.sin_cos();
                (self.shape)(c) * c * s
            };
            let mut cumulative = Vec::with_capacity(SAMPLING_POINTS);
            let mut total = 0.0;
            cumulative.push(0.0);
            for pair in angles.windows(2) {
                total += 0.5 * (pair[1] - pair[0]) * (density(pair[0]) + density(pair[1]));
                cumulative.push(total);
            }
            for c in &mut cumulative {
                *c /= total;
            }
            Sampling { angles, cumulative }
        })
    }

    /// `C`.
    #[must_use]
    pub fn normaliser(&self) -> f64 {
        self.normaliser
    }

    /// Smith's `Lambda` at a direction of cosine `cos_theta` (infinite at or below the
    /// horizon, where nothing is seen).
    #[must_use]
    pub fn lambda(&self, cos_theta: f64) -> f64 {
        self.lambda_at(&TableIndex::of(cos_theta))
    }

    /// [`Tabulated::lambda`] at a direction already placed in the table: every distribution
    /// shares the table's angles, so a fit places its directions once.
    #[must_use]
    pub fn lambda_at(&self, index: &TableIndex) -> f64 {
        let TableIndex { k, f, cos_theta } = *index;
        if cos_theta <= 0.0 {
            return f64::INFINITY;
        }
        let projected = self.projected[k] * (1.0 - f) + self.projected[k + 1] * f;
        (projected / cos_theta - 1.0).max(0.0)
    }

    /// `theta_h` drawn with density `D cos theta_h` (per solid angle; the azimuth is the
    /// caller's, uniform) from `u` in `[0, 1)`.
    #[must_use]
    pub fn sample_theta(&self, u: f64) -> f64 {
        let Sampling { angles, cumulative } = self.sampling();
        let k = cumulative
            .partition_point(|&c| c <= u)
            .clamp(1, SAMPLING_POINTS - 1);
        let (c0, c1) = (cumulative[k - 1], cumulative[k]);
        let f = if c1 > c0 { (u - c0) / (c1 - c0) } else { 0.0 };
        angles[k - 1] + f * (angles[k] - angles[k - 1])
    }
}

/// A direction's place in the `Lambda` table, the same for every distribution: the entry
/// below it and the fraction of the way to the next.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TableIndex {
    k: usize,
    f: f64,
    cos_theta: f64,
}

impl TableIndex {
    /// The place of a direction of cosine `cos_theta`.
    #[must_use]
    pub fn of(cos_theta: f64) -> Self {
        if cos_theta <= 0.0 {
            return Self {
                k: 0,
                f: 0.0,
                cos_theta,
            };
        }
        let theta = cos_theta.min(1.0).acos();
        let x = (1.0 - (1.0 - theta / FRAC_PI_2).max(0.0).sqrt()) * (ANGLES - 1) as f64;
        let k = (x.floor() as usize).min(ANGLES - 2);
        let (a, b) = (table_angle(k), table_angle(k + 1));
        let f = ((theta - a) / (b - a)).clamp(0.0, 1.0);
        Self { k, f, cos_theta }
    }

    /// The direction's cosine.
    #[must_use]
    pub fn cos_theta(&self) -> f64 {
        self.cos_theta
    }
}

/// The `k`-th angle of the `Lambda` table: `pi/2 (1 - (1 - k / (ANGLES - 1))^2)`, closer
/// together towards the horizon, where a narrow distribution's masking changes within a few
/// of its widths.
fn table_angle(k: usize) -> f64 {
    let from_horizon = 1.0 - k as f64 / (ANGLES - 1) as f64;
    FRAC_PI_2 * (1.0 - from_horizon * from_horizon)
}

/// `int_0^2pi max(0, a cos phi + b) dphi` for `a, b >= 0`: `a sin phi_c` is
/// `sqrt(a^2 - b^2)`, as `cos phi_c = -b / a`.
fn azimuthal(a: f64, b: f64) -> f64 {
    if b >= a {
        TAU * b
    } else {
        let phi_c = (-b / a).acos();
        2.0 * ((a * a - b * b).sqrt() + b * phi_c)
    }
}

/// Breakpoints over `theta` in `[0, pi/2]`: the width's quarters, doubling outwards.
fn breakpoints(width: f64) -> Vec<f64> {
    let mut points: Vec<f64> = (0..16)
        .map(|k| width * 0.25 * 2f64.powi(k))
        .filter(|p| *p < FRAC_PI_2)
        .collect();
    points.extend([0.0, FRAC_PI_2]);
    points
}

/// The width a lobe of exponent `n` spans: Beckmann's `alpha` at Walter's correspondence.
#[must_use]
pub fn lobe_width(n: f64) -> f64 {
    (2.0 / (n + 2.0)).sqrt().min(PI / 2.0)
}
