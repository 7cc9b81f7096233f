//! Transfer functions: what a value looks like. Each maps a sample to an extinction
//! coefficient (opacity per millimetre: a ray through `d` mm of it keeps `exp(-sigma d)` of
//! the light behind) and a colour, linearly between control points and constant beyond them.
//!
//! Presets, as a radiologist's viewer offers them:
//! - `ct-bone` (Hounsfield units): transparent below 150 HU, bone opaque and ivory from
//!   about 400 HU;
//! - `ct-soft-tissue` (Hounsfield units): skin and muscle (-200 to 100 HU) faintly red and
//!   translucent, bone opaque;
//! - `mr` (relative to the volume's range, since MR has no absolute scale): the lowest tenth
//!   transparent, the low values (brain on the phantom, 0.2) faint, a band at 0.3 (the
//!   phantom's tumours) dense and yellow, the top (bone) translucent ivory;
//! - `surface` (relative): transparent below 45 % of the range and opaque (60 per mm) above
//!   half of it, an isosurface at mid-range drawn by the ray marcher: how Marschner-Lobb's
//!   0.5 isosurface is shown.
//!
//! A file (`--transfer FILE`) is TOML: `units = "hounsfield"` or `"relative"`, and `points =
//! [[value, sigma, r, g, b], ...]` with values increasing.

use glam::Vec3;
use serde::Deserialize;

use crate::volume::{Units, Volume, VolumeError};

/// One control point: at `value`, extinction `sigma` (per mm) and linear RGB `colour`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ControlPoint {
    /// The sample value (in the function's units).
    pub value: f32,
    /// Extinction per millimetre, `>= 0`.
    pub sigma: f32,
    /// Linear RGB in `[0, 1]`.
    pub colour: Vec3,
}

/// Whether control points are in the volume's values or in fractions of its range.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Scale {
    /// In the volume's own values (CT: Hounsfield units).
    Absolute,
    /// `0` the volume's smallest value, `1` its largest.
    Relative,
}

/// A piecewise-linear transfer function.
#[derive(Clone, Debug, PartialEq)]
pub struct TransferFunction {
    points: Vec<ControlPoint>,
    scale: Scale,
}

/// The presets' names.
pub const PRESETS: [&str; 4] = ["ct-bone", "ct-soft-tissue", "mr", "surface"];

/// The most control points a file may give.
pub const MAX_POINTS: usize = 256;

const fn point(value: f32, sigma: f32, r: f32, g: f32, b: f32) -> ControlPoint {
    ControlPoint {
        value,
        sigma,
        colour: Vec3::new(r, g, b),
    }
}

impl TransferFunction {
    /// A function from control points in increasing value order; refused when there are none,
    /// more than [`MAX_POINTS`], values do not increase, or an extinction or colour is not a
    /// finite number in range.
    pub fn try_new(points: Vec<ControlPoint>, scale: Scale) -> Result<Self, VolumeError> {
        if points.is_empty() || points.len() > MAX_POINTS {
            return Err(VolumeError(format!(
                "a transfer function needs 1 to {MAX_POINTS} control points, not {}",
                points.len()
            )));
        }
        for (k, p) in points.iter().enumerate() {
            if !(p.value.is_finite() && p.sigma.is_finite() && p.sigma >= 0.0) {
                return Err(VolumeError(format!(
                    "control point {k}: value and sigma must be finite, sigma >= 0 (got value {}, \
                        sigma {})",
                    p.value, p.sigma
                )));
            }
            if !(p.colour.is_finite()
                && p.colour.min_element() >= 0.0
                && p.colour.max_element() <= 1.0)
            {
                return Err(VolumeError(format!(
                    "control point {k}: colour components must be in [0, 1]"
                )));
            }
            if k > 0 && p.value <= points[k - 1].value {
                return Err(VolumeError(format!(
                    "control point {k}: values must increase ({} after {})",
                    p.value,
                    points[k - 1].value
                )));
            }
        }
        Ok(Self { points, scale })
    }

    /// A preset by name (see the module's documentation), or the reason it does not exist.
    pub fn preset(name: &str) -> Result<Self, VolumeError> {
        let (points, scale) = match name {
            "ct-bone" => (
                vec![
                    point(150.0, 0.0, 0.9, 0.8, 0.7),
                    point(400.0, 0.08, 0.95, 0.9, 0.8),
                    point(1000.0, 0.5, 1.0, 0.97, 0.9),
                ],
                Scale::Absolute,
            ),
            "ct-soft-tissue" => (
                vec![
                    point(-300.0, 0.0, 0.8, 0.5, 0.4),
                    point(-200.0, 0.004, 0.85, 0.55, 0.45),
                    point(100.0, 0.01, 0.8, 0.3, 0.25),
                    point(200.0, 0.05, 0.95, 0.9, 0.8),
                    point(700.0, 0.5, 1.0, 0.97, 0.9),
                ],
                Scale::Absolute,
            ),
            "mr" => (
                vec![
                    point(0.1, 0.0, 0.7, 0.5, 0.45),
                    point(0.2, 0.002, 0.8, 0.55, 0.5),
                    point(0.3, 0.06, 1.0, 0.8, 0.35),
                    point(0.5, 0.01, 0.9, 0.85, 0.8),
                    point(1.0, 0.03, 1.0, 0.98, 0.92),
                ],
                Scale::Relative,
            ),
            "surface" => (
                vec![
                    point(0.45, 0.0, 0.9, 0.85, 0.8),
                    point(0.5, 60.0, 0.95, 0.9, 0.85),
                    point(1.0, 80.0, 1.0, 0.95, 0.9),
                ],
                Scale::Relative,
            ),
            _ => {
                return Err(VolumeError(format!(
                    "unknown transfer function '{}'; presets: {}, or a .toml file{}",
                    specula::excerpt(name),
                    PRESETS.join(", "),
                    specula::did_you_mean(name, PRESETS)
                )))
            }
        };
        Self::try_new(points, scale)
    }

    /// The default for a volume: `ct-bone` for CT, `mr` otherwise.
    #[must_use]
    pub fn default_for(volume: &Volume) -> Self {
        let name = match volume.units() {
            Units::Hounsfield => "ct-bone",
            Units::Arbitrary => "mr",
        };
        Self::preset(name).expect("presets are valid")
    }

    /// Reads a function from TOML text (see the module's documentation).
    pub fn from_toml(text: &str) -> Result<Self, VolumeError> {
        #[derive(Deserialize)]
        #[serde(deny_unknown_fields)]
        struct File {
            units: String,
            points: Vec<[f32; 5]>,
        }
        let file: File =
            toml::from_str(text).map_err(|e| VolumeError(e.message().replace('\n', " ")))?;
        let scale = match file.units.as_str() {
            "hounsfield" | "absolute" => Scale::Absolute,
            "relative" => Scale::Relative,
            other => {
                return Err(VolumeError(format!(
                    "units '{}': use \"hounsfield\" (or \"absolute\") or \"relative\"",
                    specula::excerpt(other)
                )))
            }
        };
        let points = file
            .points
            .iter()
            .map(|&[value, sigma, r, g, b]| point(value, sigma, r, g, b))
            .collect();
        Self::try_new(points, scale)
    }

    /// This function with relative values turned into `volume`'s values.
    #[must_use]
    pub fn for_volume(&self, volume: &Volume) -> Self {
        match self.scale {
            Scale::Absolute => self.clone(),
            Scale::Relative => {
                let (lo, hi) = volume.range();
                let span = (hi - lo).max(f32::MIN_POSITIVE);
                let mut points: Vec<ControlPoint> = self
                    .points
                    .iter()
                    .map(|p| ControlPoint {
                        value: lo + p.value * span,
                        ..*p
                    })
                    .collect();
                // A flat volume collapses the values; keep them increasing.
                for k in 1..points.len() {
                    if points[k].value <= points[k - 1].value {
                        points[k].value = points[k - 1].value.next_up();
                    }
                }
                Self {
                    points,
                    scale: Scale::Absolute,
                }
            }
        }
    }

    /// This function (in the volume's values) with its control points moved so that the first
    /// lies at `level - window / 2` and the last at `level + window / 2`, those between in
    /// proportion: how a radiologist's window and level drag a volume's ramp. A function of
    /// one point moves it to `level`.
    pub fn windowed(&self, window: f32, level: f32) -> Result<Self, VolumeError> {
        if !(window.is_finite() && window > 0.0 && level.is_finite()) {
            return Err(VolumeError(format!(
                "--window {window} --level {level}: the window must be a positive width and the \
                    level a finite centre, in the volume's values"
            )));
        }
        let (first, last) = (
            self.points[0].value,
            self.points[self.points.len() - 1].value,
        );
        let span = last - first;
        let points = self
            .points
            .iter()
            .map(|p| ControlPoint {
                value: if span > 0.0 {
                    level - 0.5 * window + (p.value - first) / span * window
                } else {
                    level
                },
                ..*p
            })
            .collect();
        Self::try_new(points, self.scale).map_err(|e| {
            VolumeError(format!(
                "--window {window} --level {level} squeezes the transfer function's points \
                    together ({e}); widen the window"
            ))
        })
    }

    /// The control points, by increasing value.
    #[must_use]
    pub fn points(&self) -> &[ControlPoint] {
        &self.points
    }

    /// Extinction (per mm) and colour at `value`.
    #[must_use]
    pub fn at(&self, value: f32) -> (f32, Vec3) {
        let points = &self.points;
        let first = points[0];
        if value <= first.value {
            return (first.sigma, first.colour);
        }
        for pair in points.windows(2) {
            let (a, b) = (pair[0], pair[1]);
            if value <= b.value {
                let t = (value - a.value) / (b.value - a.value);
                return (
                    a.sigma + (b.sigma - a.sigma) * t,
                    a.colour.lerp(b.colour, t),
                );
            }
        }
        let last = points[points.len() - 1];
        (last.sigma, last.colour)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn values_between_points_are_interpolated_and_clamped_beyond() {
        let f = TransferFunction::try_new(
            vec![
                point(0.0, 0.0, 0.0, 0.0, 0.0),
                point(10.0, 1.0, 1.0, 0.5, 0.0),
            ],
            Scale::Absolute,
        )
        .unwrap();
        assert_eq!(f.at(-5.0).0, 0.0);
        let (sigma, colour) = f.at(2.5);
        assert!(
            (sigma - 0.25).abs() < 1e-6 && (colour - Vec3::new(0.25, 0.125, 0.0)).length() < 1e-6
        );
        assert_eq!(f.at(50.0).0, 1.0);
    }

    #[test]
    fn bad_functions_and_names_are_refused_with_the_choices() {
        let refused = TransferFunction::preset("ct-boen").unwrap_err();
        assert!(
            refused.0.contains("ct-bone, ct-soft-tissue, mr, surface"),
            "{refused}"
        );
        let refused = TransferFunction::from_toml(
            "units = \"relative\"\npoints = [[0.5, 0, 0, 0, 0], [0.2, 1, 1, 1, 1]]",
        )
        .unwrap_err();
        assert!(refused.0.contains("values must increase"), "{refused}");
        let refused =
            TransferFunction::from_toml("units = \"hu\"\npoints = [[0, 0, 0, 0, 0]]").unwrap_err();
        assert!(refused.0.contains("\"relative\""), "{refused}");
        assert!(
            TransferFunction::from_toml("units = \"relative\"\npoints = [[0, -1, 0, 0, 0]]")
                .is_err()
        );
        assert!(
            TransferFunction::from_toml("units = \"relative\"\npoints = [[0, 1, 0, 2, 0]]")
                .is_err()
        );
    }
}
