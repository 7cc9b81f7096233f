//! Built-in volumes: no file needed.
//!
//! - **Shepp-Logan head** (3D): ten ellipsoids whose densities add, the standard tomography
//!   phantom. The table is the "modified" 3D version (Toft's contrast-enhanced densities:
//!   skull 1, brain 0.2, ventricles 0, tumours 0.3), as MATLAB's `phantom3d` (M. Schabel)
//!   gives it, in the phantom's own units on `[-1, 1]^3`, placed here as a 256 mm head.
//! - **Marschner-Lobb** (Marschner and Lobb, 1994): `rho(x, y, z) = (1 - sin(pi z / 2) +
//!   alpha (1 + rho_r(sqrt(x^2 + y^2)))) / (2 (1 + alpha))` with `rho_r(r) = cos(2 pi f_M
//!   cos(pi r / 2))`, `f_M = 6`, `alpha = 1/4`, on `[-1, 1]^3`: a signal with most of its
//!   energy near the Nyquist rate of the classic 40^3 grid, and an analytic gradient, the
//!   standard test of reconstruction and shading.

use core::f64::consts::PI;

use glam::{DMat3, DVec3, Vec3};

use crate::transfer::TransferFunction;
use crate::volume::{Units, Volume, VolumeError};

/// One ellipsoid: density added inside, semi-axes, centre, Euler angles (degrees, `phi`,
/// `theta`, `psi` in `phantom3d`'s z-x-z convention).
struct Ellipsoid {
    density: f64,
    axes: [f64; 3],
    centre: [f64; 3],
    angles: [f64; 3],
}

const fn e(density: f64, axes: [f64; 3], centre: [f64; 3], angles: [f64; 3]) -> Ellipsoid {
    Ellipsoid {
        density,
        axes,
        centre,
        angles,
    }
}

/// The modified 3D Shepp-Logan table (`phantom3d`'s "Modified Shepp-Logan").
const SHEPP_LOGAN: [Ellipsoid; 10] = [
    e(1.0, [0.69, 0.92, 0.81], [0.0, 0.0, 0.0], [0.0, 0.0, 0.0]),
    e(
        -0.8,
        [0.6624, 0.874, 0.78],
        [0.0, -0.0184, 0.0],
        [0.0, 0.0, 0.0],
    ),
    e(
        -0.2,
        [0.11, 0.31, 0.22],
        [0.22, 0.0, 0.0],
        [-18.0, 0.0, 10.0],
    ),
    e(
        -0.2,
        [0.16, 0.41, 0.28],
        [-0.22, 0.0, 0.0],
        [18.0, 0.0, 10.0],
    ),
    e(0.1, [0.21, 0.25, 0.41], [0.0, 0.35, -0.15], [0.0, 0.0, 0.0]),
    e(0.1, [0.046, 0.046, 0.05], [0.0, 0.1, 0.25], [0.0, 0.0, 0.0]),
    e(
        0.1,
        [0.046, 0.046, 0.05],
        [0.0, -0.1, 0.25],
        [0.0, 0.0, 0.0],
    ),
    e(
        0.1,
        [0.046, 0.023, 0.05],
        [-0.08, -0.605, 0.0],
        [0.0, 0.0, 0.0],
    ),
    e(
        0.1,
        [0.023, 0.023, 0.02],
        [0.0, -0.606, 0.0],
        [0.0, 0.0, 0.0],
    ),
    e(
        0.1,
        [0.023, 0.046, 0.02],
        [0.06, -0.605, 0.0],
        [0.0, 0.0, 0.0],
    ),
];

/// `phantom3d`'s rotation for Euler angles `phi`, `theta`, `psi` (degrees), applied to the
/// grid's coordinates before the centre is subtracted.
fn rotation([phi, theta, psi]: [f64; 3]) -> DMat3 {
    let (sp, cp) = phi.to_radians().sin_cos();
    let (st, ct) = theta.to_radians().sin_cos();
    let (ss, cs) = psi.to_radians().sin_cos();
    DMat3::from_cols(
        DVec3::new(cp * cs - ct * sp * ss, -sp * cs - ct * cp * ss, st * sp),
        DVec3::new(cp * ss + ct * sp * cs, -sp * ss + ct * cp * cs, -st * cp),
        DVec3::new(ss * st, cs * st, ct),
    )
}

/// An ellipsoid ready to test points against: its rotation, centre and inverse semi-axes.
struct Placed {
    turn: DMat3,
    centre: DVec3,
    inverse_axes: DVec3,
    density: f64,
}

/// The table's ellipsoids, placed once.
fn placed() -> &'static [Placed] {
    static PLACED: std::sync::OnceLock<Vec<Placed>> = std::sync::OnceLock::new();
    PLACED.get_or_init(|| {
        SHEPP_LOGAN
            .iter()
            .map(|e| Placed {
                turn: rotation(e.angles),
                centre: DVec3::from_array(e.centre),
                inverse_axes: DVec3::from_array(e.axes).recip(),
                density: e.density,
            })
            .collect()
    })
}

/// The Shepp-Logan density at `p` in `[-1, 1]^3`.
#[must_use]
pub fn shepp_logan_density(p: DVec3) -> f64 {
    placed()
        .iter()
        .filter(|e| ((e.turn * p - e.centre) * e.inverse_axes).length_squared() <= 1.0)
        .map(|e| e.density)
        .sum()
}

/// Side of the head the phantom represents, in millimetres.
pub const HEAD_MM: f32 = 256.0;

/// A built-in volume: no file needed.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum BuiltIn {
    /// The 3D Shepp-Logan head ([`shepp_logan`]).
    SheppLogan,
    /// The Marschner-Lobb signal ([`marschner_lobb`]).
    MarschnerLobb,
}

impl BuiltIn {
    /// Every built-in volume.
    pub const ALL: [BuiltIn; 2] = [BuiltIn::SheppLogan, BuiltIn::MarschnerLobb];

    /// The sides (voxels) a built-in volume may be made at.
    pub const SIDES: std::ops::RangeInclusive<usize> = 8..=512;

    /// Its name as `--input` takes it.
    #[must_use]
    pub fn id(self) -> &'static str {
        match self {
            BuiltIn::SheppLogan => "phantom",
            BuiltIn::MarschnerLobb => "marschner-lobb",
        }
    }

    /// The built-in volume called `name`, if one is.
    #[must_use]
    pub fn parse(name: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|b| b.id() == name)
    }

    /// The volume on a `side^3` grid, `side` in [`BuiltIn::SIDES`].
    pub fn make(self, side: usize) -> Result<Volume, VolumeError> {
        if !Self::SIDES.contains(&side) {
            return Err(VolumeError(format!(
                "a built-in volume of side {side}: the side must be {} to {} voxels",
                Self::SIDES.start(),
                Self::SIDES.end()
            )));
        }
        match self {
            BuiltIn::SheppLogan => shepp_logan(side),
            BuiltIn::MarschnerLobb => marschner_lobb(side),
        }
    }

    /// The transfer function it is drawn with unless another is asked for: `mr` for the head
    /// (its densities are relative, like MR's), `surface` for Marschner-Lobb (its 0.5
    /// isosurface is how the signal is always shown).
    #[must_use]
    pub fn transfer(self) -> TransferFunction {
        let name = match self {
            BuiltIn::SheppLogan => "mr",
            BuiltIn::MarschnerLobb => "surface",
        };
        TransferFunction::preset(name).expect("presets are valid")
    }
}

/// The 3D Shepp-Logan head on a `side^3` grid spanning [`HEAD_MM`], centred on the origin,
/// `x` the phantom's first axis (towards the patient's right), `y` anterior, `z` superior.
///
/// Each voxel is the density's mean over its cell (3 x 3 x 3 points), as a scanner's
/// detector integrates it: voxels that straddle a boundary take a value between the two
/// tissues (the partial-volume effect). Point samples would make every surface a staircase
/// whose gradients, and so whose highlights, follow the grid rather than the ellipsoids.
pub fn shepp_logan(side: usize) -> Result<Volume, VolumeError> {
    let cell = 2.0 / (side - 1) as f64;
    grid(side, HEAD_MM, |p| {
        let centre = shepp_logan_density(p);
        let probes = [
            DVec3::X,
            DVec3::NEG_X,
            DVec3::Y,
            DVec3::NEG_Y,
            DVec3::Z,
            DVec3::NEG_Z,
        ];
        if probes
            .iter()
            .all(|&d| shepp_logan_density(p + 0.5 * cell * d) == centre)
        {
            return centre;
        }
        let offsets = [-1.0 / 3.0, 0.0, 1.0 / 3.0];
        let mut sum = 0.0;
        for dz in offsets {
            for dy in offsets {
                for dx in offsets {
                    sum += shepp_logan_density(p + cell * DVec3::new(dx, dy, dz));
                }
            }
        }
        sum / 27.0
    })
}

/// `f_M`, the Marschner-Lobb signal's frequency.
pub const ML_FREQUENCY: f64 = 6.0;
/// `alpha`, the weight of the radial term.
pub const ML_ALPHA: f64 = 0.25;

/// The Marschner-Lobb signal at `p` in `[-1, 1]^3`.
#[must_use]
pub fn marschner_lobb_value(p: DVec3) -> f64 {
    let r = p.x.hypot(p.y);
    let radial = (2.0 * PI * ML_FREQUENCY * (PI * r / 2.0).cos()).cos();
    (1.0 - (PI * p.z / 2.0).sin() + ML_ALPHA * (1.0 + radial)) / (2.0 * (1.0 + ML_ALPHA))
}

/// The Marschner-Lobb signal's exact gradient at `p`.
#[must_use]
pub fn marschner_lobb_gradient(p: DVec3) -> DVec3 {
    let scale = 1.0 / (2.0 * (1.0 + ML_ALPHA));
    let r = p.x.hypot(p.y);
    // d/dr cos(2 pi f cos(pi r / 2)) = pi^2 f sin(pi r / 2) sin(2 pi f cos(pi r / 2)).
    let d_radial = PI
        * PI
        * ML_FREQUENCY
        * (PI * r / 2.0).sin()
        * (2.0 * PI * ML_FREQUENCY * (PI * r / 2.0).cos()).sin();
    let (dx, dy) = if r > 0.0 {
        (d_radial * p.x / r, d_radial * p.y / r)
    } else {
        (0.0, 0.0)
    };
    let dz = -(PI / 2.0) * (PI * p.z / 2.0).cos();
    scale * DVec3::new(ML_ALPHA * dx, ML_ALPHA * dy, dz)
}

/// The Marschner-Lobb signal on a `side^3` grid spanning `[-1, 1]^3` (world units as given).
pub fn marschner_lobb(side: usize) -> Result<Volume, VolumeError> {
    grid(side, 2.0, marschner_lobb_value)
}

/// `side^3` samples of `f` over `[-1, 1]^3`, as a volume `extent` world units wide.
fn grid(side: usize, extent: f32, f: impl Fn(DVec3) -> f64 + Sync) -> Result<Volume, VolumeError> {
    use rayon::prelude::*;
    Volume::check_dims([side; 3])?;
    let coordinate = |i: usize| -1.0 + 2.0 * i as f64 / (side - 1) as f64;
    let samples: Vec<f32> = (0..side * side * side)
        .into_par_iter()
        .map(|v| {
            let (i, j, k) = (v % side, v / side % side, v / (side * side));
            f(DVec3::new(coordinate(i), coordinate(j), coordinate(k))) as f32
        })
        .collect();
    let spacing = extent / (side - 1) as f32;
    Volume::centred([side; 3], Vec3::splat(spacing), samples, Units::Arbitrary)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_shepp_logan_densities_are_the_tables() {
        // Centre: skull (1) + brain (-0.8); the skull ring; outside; a ventricle (-0.2 more).
        assert!((shepp_logan_density(DVec3::ZERO) - 0.2).abs() < 1e-12);
        assert!((shepp_logan_density(DVec3::new(0.0, 0.9, 0.0)) - 1.0).abs() < 1e-12);
        assert_eq!(shepp_logan_density(DVec3::new(0.95, 0.95, 0.0)), 0.0);
        assert!((shepp_logan_density(DVec3::new(0.22, 0.0, 0.0)) - 0.0).abs() < 1e-12);
    }

    #[test]
    fn the_marschner_lobb_gradient_matches_finite_differences_of_the_signal() {
        let h = 1e-6;
        for p in [
            DVec3::new(0.3, -0.2, 0.1),
            DVec3::new(-0.7, 0.05, -0.6),
            DVec3::new(0.01, 0.02, 0.9),
        ] {
            let numeric = DVec3::new(
                marschner_lobb_value(p + DVec3::X * h) - marschner_lobb_value(p - DVec3::X * h),
                marschner_lobb_value(p + DVec3::Y * h) - marschner_lobb_value(p - DVec3::Y * h),
                marschner_lobb_value(p + DVec3::Z * h) - marschner_lobb_value(p - DVec3::Z * h),
            ) / (2.0 * h);
            assert!(
                (numeric - marschner_lobb_gradient(p)).length() < 1e-6,
                "{p}: {numeric} against {}",
                marschner_lobb_gradient(p)
            );
        }
    }

    /// The sampled gradient converges to the analytic one at second order: doubling the grid
    /// divides the RMS error by about 4 (central differences and trilinear reconstruction are
    /// both O(h^2)), so it is more than 3 for each doubling.
    #[test]
    fn sampled_marschner_lobb_gradients_converge_at_second_order() {
        let rms = |side: usize| {
            let volume = marschner_lobb(side).unwrap();
            let mut sum = 0.0;
            let mut count = 0;
            for a in 0..9 {
                for b in 0..9 {
                    for c in 0..9 {
                        let p = DVec3::new(a as f64, b as f64, c as f64) / 8.0 * 1.2 - 0.6 + 0.013;
                        let world = p.as_vec3();
                        let got = volume.gradient(volume.index(world)).as_dvec3();
                        sum += (got - marschner_lobb_gradient(p)).length_squared();
                        count += 1;
                    }
                }
            }
            (sum / f64::from(count)).sqrt()
        };
        let (coarse, medium, fine) = (rms(81), rms(161), rms(321));
        assert!(coarse / medium > 3.0, "{coarse} / {medium}");
        assert!(medium / fine > 3.0, "{medium} / {fine}");
    }
}
