//! The zones of a highlight (SPEC section 3), measured on the reference lobe `t^n`.
//!
//! - **epicentre**: `t^n >= 1/2`, i.e. `t >= 2^(-1/n)`, angle `g <= acos(2^(-1/n))`;
//! - **bloom**: `1/256 <= t^n < 1/2`, i.e. `2^(-8/n) <= t < 2^(-1/n)`;
//! - **tail**: `t^n < 1/256`.
//!
//! The boundaries are closed forms, so they are exact to the last bit of `f64`.

use serde::Serialize;

use crate::{Exponent, Lobe};

/// One of the three zones of a highlight.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum Zone {
    /// The core, where the reference is at least half its peak.
    Epicentre,
    /// The visible halo of an 8-bit image: between 1/256 and 1/2 of the peak.
    Bloom,
    /// Everything dimmer than 1/256 of the peak.
    Tail,
}

impl Zone {
    /// All zones, from the centre outwards.
    pub const ALL: [Zone; 3] = [Zone::Epicentre, Zone::Bloom, Zone::Tail];

    /// The zone's name as used in reports.
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            Zone::Epicentre => "epicentre",
            Zone::Bloom => "bloom",
            Zone::Tail => "tail",
        }
    }

    /// The zone that the cosine `t` falls in for exponent `n`.
    #[must_use]
    pub fn of_cos(t: f64, n: Exponent) -> Zone {
        if t >= epicentre_cos(n) {
            Zone::Epicentre
        } else if t >= bloom_cos(n) {
            Zone::Bloom
        } else {
            Zone::Tail
        }
    }

    /// The zone's angular interval `[from, to]` in radians, within `[0, pi/2]`.
    #[must_use]
    pub fn angles(self, n: Exponent) -> (f64, f64) {
        match self {
            Zone::Epicentre => (0.0, epicentre_angle(n)),
            Zone::Bloom => (epicentre_angle(n), bloom_angle(n)),
            Zone::Tail => (bloom_angle(n), core::f64::consts::FRAC_PI_2),
        }
    }
}

/// The cosine at which `t^n = 1/2`: `2^(-1/n)`.
#[must_use]
pub fn epicentre_cos(n: Exponent) -> f64 {
    (-1.0 / n.get()).exp2()
}

/// The cosine at which `t^n = 1/256`: `2^(-8/n)`.
#[must_use]
pub fn bloom_cos(n: Exponent) -> f64 {
    (-8.0 / n.get()).exp2()
}

/// `g_half(n) = acos(2^(-1/n))`, the epicentre's angular radius.
#[must_use]
pub fn epicentre_angle(n: Exponent) -> f64 {
    epicentre_cos(n).acos()
}

/// `acos(2^(-8/n))`, the bloom zone's outer angular radius.
#[must_use]
pub fn bloom_angle(n: Exponent) -> f64 {
    bloom_cos(n).acos()
}

/// The angles in `[0, pi/2]` where an integrand built on `lobe` changes character: the zone
/// edges, the quarter circle, and the lobe's own cut-off if it has one. Quadrature splits
/// there first.
#[must_use]
pub fn breakpoints(lobe: &Lobe) -> Vec<f64> {
    let n = lobe.exponent();
    let mut points = vec![
        0.0,
        epicentre_angle(n),
        bloom_angle(n),
        core::f64::consts::FRAC_PI_2,
    ];
    if let Some(quadratic) = lobe.angle_quadratic() {
        points.push(quadratic.cutoff());
    }
    points
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn boundaries_are_where_the_reference_crosses_the_thresholds() {
        for n in [1.0, 2.5, 16.0, 333.0, 1000.0] {
            let n = Exponent::new(n);
            assert!((epicentre_cos(n).powf(n.get()) - 0.5).abs() < 1e-14);
            assert!((bloom_cos(n).powf(n.get()) - 1.0 / 256.0).abs() < 1e-15);
            assert!((epicentre_angle(n).cos().powf(n.get()) - 0.5).abs() < 1e-12);
        }
    }

    #[test]
    fn zones_partition_the_quarter_circle() {
        let n = Exponent::new(40.0);
        assert_eq!(Zone::Epicentre.angles(n).0, 0.0);
        assert_eq!(Zone::Epicentre.angles(n).1, Zone::Bloom.angles(n).0);
        assert_eq!(Zone::Bloom.angles(n).1, Zone::Tail.angles(n).0);
        assert_eq!(Zone::of_cos(1.0, n), Zone::Epicentre);
        assert_eq!(Zone::of_cos(0.9, n), Zone::Bloom);
        assert_eq!(Zone::of_cos(0.1, n), Zone::Tail);
    }
}
