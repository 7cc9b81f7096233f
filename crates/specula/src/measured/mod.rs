//! Measured materials: the RGL database's isotropic RGB BRDFs (Dupuy and Jakob, "An Adaptive
//! Parameterization for Efficient Material Acquisition and Rendering", 2018).
//!
//! A measurement is tabulated in the material's own coordinates rather than in angles:
//! - `ndf` and `sigma`: the microfacet normal distribution `D(theta_m)` and the projected
//!   area `sigma(theta)` it implies, tables over `u = sqrt(2 theta / pi)` (and `phi`);
//! - `vndf`: for each tabulated viewing elevation `theta_i`, the distribution of visible
//!   normals, a 2D density over `(u_theta, u_phi)` of the half vector: the warp that turns
//!   the unit square into the directions the gonio-photometer measured;
//! - `luminance` and `rgb`: the measured reflectance at those directions, tabulated on the
//!   unit square *before* the warp (so that a narrow highlight gets as many samples as a
//!   broad one), `luminance` for sampling, `rgb` per channel for shading;
//! - `jacobian`: whether the stored values still carry the warp's Jacobian
//!   `D(m) / (4 sigma(theta_i))`, which evaluation then multiplies back.
//!
//! Evaluating `f(wo, wi)` (here `wo` the viewer, the table's "incident" direction, and `wi`
//! the light) therefore inverts the warp: the half vector's `(u_theta, u_phi - phi_o)` goes
//! through the VNDF's inverse to a point of the square, where `rgb` is interpolated (trilinear
//! across `theta_i` and the square). The tables hold `f cos(theta_light)`, which
//! [`MeasuredBrdf::f_cos`] returns and [`MeasuredBrdf::f`] divides. The definitions of every
//! step are those of the format's reference, Mitsuba 3's `measured` plugin, which the test
//! suite evaluates side by side with this one.
//!
//! Sampling follows the data too ([`MeasuredBrdf::sample`]): a uniform point is warped by the
//! luminance table, then by the VNDF, into a half vector, so a render draws directions where
//! the material reflects.

pub mod fit;
mod marginal;
pub mod tensor;

use core::f64::consts::PI;

use glam::DVec3;

pub use marginal::Marginal2D;
use tensor::{TensorError, TensorFile};

use crate::Rgb;

/// A measured isotropic RGB BRDF, ready to evaluate and sample.
#[derive(Clone, Debug)]
pub struct MeasuredBrdf {
    description: String,
    ndf: Marginal2D,
    sigma: Marginal2D,
    vndf: Marginal2D,
    luminance: Marginal2D,
    rgb: Marginal2D,
    jacobian: bool,
    /// The tabulated viewing elevations, radians, increasing.
    elevations: Vec<f32>,
}

/// A direction drawn from the measured material's own distribution.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MeasuredSample {
    /// The light direction drawn (local frame, above the surface).
    pub wi: DVec3,
    /// `f(wo, wi)`, per channel.
    pub f: Rgb,
    /// The density of `wi`, per unit solid angle.
    pub pdf: f64,
}

/// Why a file is not a measured material this reader takes.
pub type MeasuredError = TensorError;

fn refuse(message: impl Into<String>) -> MeasuredError {
    TensorError(message.into())
}

/// `theta` to the tables' coordinate `sqrt(2 theta / pi)`.
fn theta_to_u(theta: f64) -> f64 {
    (theta * (2.0 / PI)).sqrt()
}

fn u_to_theta(u: f64) -> f64 {
    u * u * (PI / 2.0)
}

fn phi_to_u(phi: f64) -> f64 {
    (phi + PI) / (2.0 * PI)
}

fn u_to_phi(u: f64) -> f64 {
    (2.0 * u - 1.0) * PI
}

/// `value`, or zero where a table's extreme values (a file may hold any finite `f32`)
/// overflow: no caller, a pixel or a fit, ever receives an infinity or a NaN.
fn finite_or_zero(value: Rgb) -> Rgb {
    if value.is_finite() {
        value
    } else {
        Rgb::ZERO
    }
}

/// Whether a direction is above the surface (a NaN component is not).
fn above(d: DVec3) -> bool {
    d.z > 0.0 && d.is_finite()
}

/// The angle from the normal, accurate near it (`acos` of `z` loses half the digits there).
fn elevation(d: DVec3) -> f64 {
    let distance = (d.x * d.x + d.y * d.y + (d.z - 1.0) * (d.z - 1.0)).sqrt();
    2.0 * (0.5 * distance).clamp(-1.0, 1.0).asin()
}

impl MeasuredBrdf {
    /// Reads a tensor file's bytes. Refused, in one line naming the problem: anything that
    /// is not a tensor file, a truncated one, a spectral one (this reader takes the RGB
    /// files), an anisotropic one, tables of the wrong shape, or values that are not finite
    /// (or, for the two tables sampled, negative or all zero).
    pub fn from_bytes(bytes: &[u8]) -> Result<Self, MeasuredError> {
        let file = TensorFile::parse(bytes)?;
        if file.field("rgb").is_err() && file.field("spectra").is_ok() {
            return Err(refuse(
                "spectral measurements are not supported: pass the material's RGB file (the \
                    '_rgb.bsdf' one)",
            ));
        }
        let description = String::from_utf8_lossy(file.u8s("description", 1)?)
            .trim_end_matches('\0')
            .to_owned();
        let (phi, _) = file.f32s("phi_i", 1)?;
        let (theta, _) = file.f32s("theta_i", 1)?;
        if phi.len() > 2 {
            return Err(refuse(format!(
                "anisotropic materials are not supported: phi_i has {} values (an isotropic file \
                    has 1 or 2)",
                phi.len()
            )));
        }
        if phi.is_empty() || theta.len() < 2 {
            return Err(refuse(format!(
                "phi_i and theta_i need at least 1 and 2 values (they have {} and {})",
                phi.len(),
                theta.len()
            )));
        }
        let elevations = 0.0..=core::f32::consts::FRAC_PI_2;
        if !theta.windows(2).all(|w| w[0] < w[1]) || !theta.iter().all(|t| elevations.contains(t)) {
            return Err(refuse(
                "theta_i is not an increasing list of elevations in [0, pi/2] radians",
            ));
        }
        if !phi.windows(2).all(|w| w[0] < w[1]) || !phi.iter().all(|p| p.is_finite()) {
            return Err(refuse("phi_i is not an increasing list of finite azimuths"));
        }
        let (ndf, ndf_shape) = finite(file.f32s("ndf", 2)?, "ndf")?;
        let (sigma, sigma_shape) = finite(file.f32s("sigma", 2)?, "sigma")?;
        let (vndf, vndf_shape) = finite(file.f32s("vndf", 4)?, "vndf")?;
        let (luminance, luminance_shape) = finite(file.f32s("luminance", 4)?, "luminance")?;
        let (rgb, rgb_shape) = finite(file.f32s("rgb", 5)?, "rgb")?;
        let jacobian = file.u8s("jacobian", 1)?;

        let (p, t) = (phi.len(), theta.len());
        let grid = |shape: &[usize]| shape.iter().rev().take(2).all(|&n| n >= 2);
        let shapes_agree = vndf_shape[..2] == [p, t]
            && luminance_shape[..2] == [p, t]
            && rgb_shape[..3] == [p, t, 3]
            && luminance_shape[2..] == rgb_shape[3..]
            && jacobian.len() == 1
            && [
                &ndf_shape[..],
                &sigma_shape,
                &vndf_shape,
                &luminance_shape,
                &rgb_shape,
            ]
            .iter()
            .all(|shape| grid(shape));
        if !shapes_agree {
            return Err(refuse(format!(
                "the tables' shapes disagree: phi_i {p}, theta_i {t}, vndf {vndf_shape:?}, \
                    luminance {luminance_shape:?}, rgb {rgb_shape:?} (expected [phi_i, theta_i, h, \
                    w], rgb [phi_i, theta_i, 3, h, w] on luminance's grid, tables at least 2 x 2)"
            )));
        }
        if jacobian[0] != 0 && !(sigma.iter().all(|&v| v > 0.0) && ndf.iter().all(|&v| v >= 0.0)) {
            return Err(refuse(
                "tables 'sigma' and 'ndf' must be positive and non-negative (the Jacobian divides \
                    by sigma)",
            ));
        }
        for (name, table, shape) in [
            ("vndf", &vndf, &vndf_shape),
            ("luminance", &luminance, &luminance_shape),
        ] {
            let slice = shape[2] * shape[3];
            let sampleable = table
                .chunks(slice)
                .all(|values| values.iter().all(|&v| v >= 0.0) && values.iter().any(|&v| v > 0.0));
            if !sampleable {
                return Err(refuse(format!(
                    "table '{name}' has a negative value or an all-zero slice (it must be a \
                        density)"
                )));
            }
        }
        let angles = |phi: &[f32]| vec![phi.to_vec(), theta.clone()];
        let density = |name: &str, table, shape: &[usize]| {
            Marginal2D::normalised(table, shape[3], shape[2], angles(&phi)).ok_or_else(|| {
                refuse(format!(
                    "table '{name}' has a slice whose integral is not a finite positive number"
                ))
            })
        };
        let vndf = density("vndf", vndf, &vndf_shape)?;
        let luminance = density("luminance", luminance, &luminance_shape)?;
        Ok(Self {
            description,
            ndf: Marginal2D::raw(ndf, ndf_shape[1], ndf_shape[0], Vec::new()),
            sigma: Marginal2D::raw(sigma, sigma_shape[1], sigma_shape[0], Vec::new()),
            vndf,
            luminance,
            rgb: Marginal2D::raw(
                rgb,
                rgb_shape[4],
                rgb_shape[3],
                vec![phi.clone(), theta.clone(), vec![0.0, 1.0, 2.0]],
            ),
            jacobian: jacobian[0] != 0,
            elevations: theta,
        })
    }

    /// The file's own description of the material.
    #[must_use]
    pub fn description(&self) -> &str {
        &self.description
    }

    /// The viewing elevations measured, in radians.
    #[must_use]
    pub fn elevations(&self) -> &[f32] {
        &self.elevations
    }

    /// `f(wo, wi) cos(theta_wi)`, what the tables hold; zero below the horizon. Channels may
    /// dip slightly below zero where a spectrum's RGB does.
    #[must_use]
    pub fn f_cos(&self, wo: DVec3, wi: DVec3) -> Rgb {
        if !above(wo) || !above(wi) {
            return Rgb::ZERO;
        }
        let m = (wo + wi).normalize();
        let (theta_o, phi_o) = (elevation(wo), wo.y.atan2(wo.x));
        let (theta_m, phi_m) = (elevation(m), m.y.atan2(m.x));
        let u_o = [theta_to_u(theta_o), phi_to_u(phi_o)];
        let mut u_m = [theta_to_u(theta_m), phi_to_u(phi_m - phi_o)];
        u_m[1] -= u_m[1].floor();
        let angles = [phi_o, theta_o];
        let (square, _) = self.vndf.invert(u_m, &angles);
        finite_or_zero(self.shade(square, angles, u_m, u_o))
    }

    /// The reflectance at the point `square` of the unit square, for a half vector at `u_m`.
    fn shade(&self, square: [f64; 2], angles: [f64; 2], u_m: [f64; 2], u_o: [f64; 2]) -> Rgb {
        let channel = |c: f64| self.rgb.eval(square, &[angles[0], angles[1], c]);
        let rgb = Rgb::new(channel(0.0), channel(1.0), channel(2.0));
        if self.jacobian {
            rgb * (self.ndf.eval(u_m, &[]) / (4.0 * self.sigma.eval(u_o, &[])))
        } else {
            rgb
        }
    }

    /// `f(wo, wi)`: [`MeasuredBrdf::f_cos`] without the light's cosine.
    #[must_use]
    pub fn f(&self, wo: DVec3, wi: DVec3) -> Rgb {
        if !above(wi) {
            return Rgb::ZERO;
        }
        self.f_cos(wo, wi) / wi.z
    }

    /// The Jacobian from the unit square's density to solid angle about `wi`, at a half
    /// vector `m` whose table coordinate is `u_theta`.
    fn to_solid_angle(u_theta: f64, m: DVec3, wo: DVec3) -> f64 {
        let sin_theta = (1.0 - m.z * m.z).max(0.0).sqrt();
        (2.0 * PI * PI * u_theta * sin_theta).max(1e-6) * 4.0 * wo.dot(m)
    }

    /// Draws `wi` for the viewer at `wo` from two uniform numbers, as the data is
    /// distributed (luminance, then visible normals); `None` below the horizon.
    #[must_use]
    pub fn sample(&self, wo: DVec3, u: [f64; 2]) -> Option<MeasuredSample> {
        if !above(wo) || !u.iter().all(|v| v.is_finite()) {
            return None;
        }
        let (theta_o, phi_o) = (elevation(wo), wo.y.atan2(wo.x));
        let angles = [phi_o, theta_o];
        let (square, luminance_pdf) = self.luminance.sample([u[1], u[0]], &angles);
        let (u_m, vndf_pdf) = self.vndf.sample(square, &angles);
        let (theta_m, phi_m) = (u_to_theta(u_m[0]), u_to_phi(u_m[1]) + phi_o);
        let (sin_phi, cos_phi) = phi_m.sin_cos();
        let (sin_theta, cos_theta) = theta_m.sin_cos();
        let m = DVec3::new(cos_phi * sin_theta, sin_phi * sin_theta, cos_theta);
        let wi = 2.0 * wo.dot(m) * m - wo;
        let pdf = vndf_pdf * luminance_pdf / Self::to_solid_angle(u_m[0], m, wo);
        if wi.z <= 0.0 || pdf.is_nan() || pdf <= 0.0 {
            return None;
        }
        let u_o = [theta_to_u(theta_o), phi_to_u(phi_o)];
        let f = finite_or_zero(self.shade(square, angles, u_m, u_o) / wi.z);
        (pdf.is_finite() && wi.is_finite()).then_some(MeasuredSample { wi, f, pdf })
    }

    /// The directional albedo `int f(wo, wi) cos(theta_i) dwi`, estimated by importance
    /// sampling the data at the midpoints of a `strata x strata` grid of the unit square (no
    /// random numbers: the figure is reproducible).
    #[must_use]
    pub fn albedo(&self, wo: DVec3, strata: usize) -> Rgb {
        let total: Rgb = (0..strata * strata)
            .filter_map(|i| {
                let u = [
                    ((i % strata) as f64 + 0.5) / strata as f64,
                    ((i / strata) as f64 + 0.5) / strata as f64,
                ];
                self.sample(wo, u)
            })
            .map(|drawn| drawn.f * (drawn.wi.z / drawn.pdf))
            .sum();
        total / (strata * strata) as f64
    }

    /// The density with which [`MeasuredBrdf::sample`] draws `wi`, per unit solid angle.
    #[must_use]
    pub fn pdf(&self, wo: DVec3, wi: DVec3) -> f64 {
        if !above(wo) || !above(wi) {
            return 0.0;
        }
        let m = (wo + wi).normalize();
        let (theta_o, phi_o) = (elevation(wo), wo.y.atan2(wo.x));
        let (theta_m, phi_m) = (elevation(m), m.y.atan2(m.x));
        let mut u_m = [theta_to_u(theta_m), phi_to_u(phi_m - phi_o)];
        u_m[1] -= u_m[1].floor();
        let angles = [phi_o, theta_o];
        let (square, vndf_pdf) = self.vndf.invert(u_m, &angles);
        let luminance_pdf = self.luminance.eval(square, &angles);
        let pdf = vndf_pdf * luminance_pdf / Self::to_solid_angle(u_m[0], m, wo);
        if pdf.is_finite() {
            pdf
        } else {
            0.0
        }
    }
}

fn finite(
    (values, shape): (Vec<f32>, Vec<usize>),
    name: &str,
) -> Result<(Vec<f32>, Vec<usize>), MeasuredError> {
    match values.iter().position(|v| !v.is_finite()) {
        Some(at) => Err(refuse(format!(
            "table '{name}' holds a value that is not finite ({} at element {at})",
            values[at]
        ))),
        None => Ok((values, shape)),
    }
}
