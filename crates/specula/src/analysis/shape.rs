//! What a lobe of one's own is checked for before use: where it peaks and how high, its value
//! at `t = 1`, how far it lies from `t^n` where the highlight is, and its energy.
//!
//! A lobe that replaces `cos^n` should peak at 1 at `t = 1` (the mirror direction): a lobe
//! that does not (`t^n / (1 + t)` peaks at 0.5) dims every highlight, and one that peaks
//! elsewhere moves it off the mirror direction.

use serde::Serialize;

use super::accuracy::{error_figures, Precision};
use super::energy_ratio;
use crate::Lobe;

/// A lobe's shape at one `n`.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Shape {
    /// The exponent.
    pub n: f64,
    /// The lobe's largest value over `t` in `[0, 1]`.
    pub peak: f64,
    /// The cosine where it lies (the first such, searching from `t = 1`).
    pub peak_cos: f64,
    /// The lobe at `t = 1`.
    pub at_one: f64,
    /// `max |lobe - t^n| / t^n` over the epicentre (SPEC section 3), in `f64`.
    pub epicentre_max_rel: f64,
    /// `(n + 1) int_0^{pi/2} lobe(cos g) sin g dg`: 1 when the lobe carries `t^n`'s energy.
    pub energy_ratio: f64,
}

impl Shape {
    /// How far from 1 the value at `t = 1` may be and still count as reaching it.
    pub const REACHES_ONE: f64 = 1e-6;

    /// Whether the lobe is 1 at `t = 1`, within [`Shape::REACHES_ONE`].
    #[must_use]
    pub fn reaches_one(&self) -> bool {
        (self.at_one - 1.0).abs() <= Self::REACHES_ONE
    }

    /// The peak's angle from the mirror direction, in degrees.
    #[must_use]
    pub fn peak_angle_degrees(&self) -> f64 {
        self.peak_cos.clamp(-1.0, 1.0).acos().to_degrees()
    }
}

/// Angles sampled from the mirror direction to the horizon before the peak is refined.
const SCAN: usize = 4096;

/// `lobe`'s shape: its peak found on [`SCAN`] angles uniform in `[0, pi/2]` and refined by a
/// golden-section search between the best one's neighbours, its errors on the default
/// samples of each zone.
#[must_use]
pub fn shape(lobe: &Lobe) -> Shape {
    let value = |angle: f64| lobe.eval(angle.cos());
    let step = core::f64::consts::FRAC_PI_2 / SCAN as f64;
    let (mut best, mut best_value) = (0, value(0.0));
    for i in 1..=SCAN {
        let v = value(i as f64 * step);
        if v > best_value {
            (best, best_value) = (i, v);
        }
    }
    let low = best.saturating_sub(1) as f64 * step;
    let high = (best + 1).min(SCAN) as f64 * step;
    let (angle, refined) = golden_section_maximum(value, low, high);
    let (peak_angle, peak) = if refined > best_value {
        (angle, refined)
    } else {
        (best as f64 * step, best_value)
    };
    let errors = error_figures(
        lobe,
        &mut Precision::F64,
        super::accuracy::DEFAULT_SAMPLES_PER_ZONE,
    );
    Shape {
        n: lobe.exponent().get(),
        peak,
        peak_cos: peak_angle.cos(),
        at_one: lobe.eval(1.0),
        epicentre_max_rel: errors.epicentre_max_rel,
        energy_ratio: energy_ratio(lobe),
    }
}

/// The largest of `f` on `[low, high]` (where it has one maximum) and where it lies.
fn golden_section_maximum(f: impl Fn(f64) -> f64, low: f64, high: f64) -> (f64, f64) {
    let ratio = (5.0_f64.sqrt() - 1.0) / 2.0;
    let (mut a, mut b) = (low, high);
    let mut c = b - ratio * (b - a);
    let mut d = a + ratio * (b - a);
    let (mut fc, mut fd) = (f(c), f(d));
    for _ in 0..80 {
        if fc >= fd {
            b = d;
            (d, fd) = (c, fc);
            c = b - ratio * (b - a);
            fc = f(c);
        } else {
            a = c;
            (c, fc) = (d, fd);
            d = a + ratio * (b - a);
            fd = f(d);
        }
    }
    if fc >= fd {
        (c, fc)
    } else {
        (d, fd)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{Exponent, LobeKind};

    /// `t^n` itself: peak 1 at the mirror direction, no error, energy ratio 1.
    #[test]
    fn pow_peaks_at_one_in_the_mirror_direction_with_no_error() {
        let shape = shape(&Lobe::new(LobeKind::Pow, Exponent::new(32.0)));
        assert!((shape.peak - 1.0).abs() < 1e-12, "{shape:?}");
        assert!(shape.peak_angle_degrees() < 1e-3, "{shape:?}");
        assert!(shape.reaches_one());
        assert!(shape.epicentre_max_rel < 1e-12);
        assert!((shape.energy_ratio - 1.0).abs() < 1e-6, "{shape:?}");
    }

    /// `t^n / (1 + t)`: 1/2 at `t = 1` (its peak, found there), 1/2 of `t^n` or less
    /// everywhere, so its epicentre error is at least 1/2 and its energy, `(n + 1) int
    /// t^n / (1 + t) dt` over `[0, 1]`, lies between 1/2 and 1 (closed form checked by a
    /// second quadrature below).
    #[test]
    fn a_lobe_that_peaks_at_one_half_is_caught() {
        let kind = LobeKind::parse("=t^n/(1+t)").unwrap();
        let n = 8.0;
        let shape = shape(&Lobe::new(kind, Exponent::new(n)));
        assert!((shape.peak - 0.5).abs() < 1e-9, "{shape:?}");
        assert!((shape.at_one - 0.5).abs() < 1e-12);
        assert!(!shape.reaches_one());
        assert!((shape.epicentre_max_rel - 0.5).abs() < 1e-3, "{shape:?}");
        // (n + 1) int_0^1 t^n / (1 + t) dt by the midpoint rule on a fine grid.
        let steps = 200_000;
        let integral: f64 = (0..steps)
            .map(|i| {
                let t = (i as f64 + 0.5) / steps as f64;
                t.powf(n) / (1.0 + t)
            })
            .sum::<f64>()
            / steps as f64;
        assert!(
            (shape.energy_ratio - (n + 1.0) * integral).abs() < 1e-5,
            "{shape:?} against {}",
            (n + 1.0) * integral
        );
    }

    /// A lobe peaking away from the mirror direction: `4 t (1 - t)` peaks at 1 where
    /// `t = 1/2` (60 degrees), and is 0 at `t = 1`.
    #[test]
    fn a_peak_away_from_the_mirror_direction_is_found_where_it_is() {
        let kind = LobeKind::parse("=4*t*(1-t)").unwrap();
        let shape = shape(&Lobe::new(kind, Exponent::new(4.0)));
        assert!((shape.peak - 1.0).abs() < 1e-9, "{shape:?}");
        assert!((shape.peak_cos - 0.5).abs() < 1e-5, "{shape:?}");
        assert!((shape.peak_angle_degrees() - 60.0).abs() < 1e-3);
        assert!(shape.at_one.abs() < 1e-12);
    }
}
