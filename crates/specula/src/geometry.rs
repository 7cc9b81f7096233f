//! Lobe geometry: how the cosine `t` a lobe is a function of comes from the directions.
//!
//! - **Phong**: `t = R.V`, with `R` the mirror of the light direction about the normal,
//!   evaluated as `2 (N.wi)(N.wo) - wi.wo`, which is symmetric in `wi` and `wo` by
//!   construction (so Helmholtz reciprocity holds to the bit).
//! - **Blinn**: `t = N.H`, `H = normalize(wi + wo)`; for `wi = -wo` the half vector is
//!   undefined and `t = 0`.
//!
//! Directions point away from the surface and are unit length; `normal` too.

use glam::{DVec3, Vec3};
use serde::Serialize;

use crate::error::{parse_choice, Error, Result};

/// Which cosine a lobe is evaluated at.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum Geometry {
    /// `t = R.V` (Phong, 1975).
    #[default]
    Phong,
    /// `t = N.H` (Blinn, 1977).
    Blinn,
}

macro_rules! cos_lobe_fn {
    ($name:ident, $vec:ty, $float:ty) => {
        /// The lobe's cosine `t` for the given unit normal and directions.
        #[inline]
        #[must_use]
        pub fn $name(self, normal: $vec, wo: $vec, wi: $vec) -> $float {
            match self {
                Geometry::Phong => 2.0 * normal.dot(wi) * normal.dot(wo) - wi.dot(wo),
                Geometry::Blinn => {
                    let sum = wi + wo;
                    let length_squared = sum.length_squared();
                    if length_squared > 0.0 {
                        normal.dot(sum) / length_squared.sqrt()
                    } else {
                        0.0
                    }
                }
            }
        }
    };
}

impl Geometry {
    /// Both geometries.
    pub const ALL: [Geometry; 2] = [Geometry::Phong, Geometry::Blinn];

    /// The name used on the command line.
    #[must_use]
    pub fn id(self) -> &'static str {
        match self {
            Geometry::Phong => "phong",
            Geometry::Blinn => "blinn",
        }
    }

    /// What `t` is, in words (`R.V` or `N.H`).
    #[must_use]
    pub fn cosine_name(self) -> &'static str {
        match self {
            Geometry::Phong => "R.V",
            Geometry::Blinn => "N.H",
        }
    }

    /// Parses `phong` or `blinn`.
    pub fn parse(text: &str) -> Result<Self> {
        parse_choice("geometry", text, &Self::ALL, Geometry::id)
    }

    cos_lobe_fn!(cos_lobe, DVec3, f64);
    cos_lobe_fn!(cos_lobe_f32, Vec3, f32);

    /// The lobe's cosine in the local shading frame (normal = `+z`).
    #[inline]
    #[must_use]
    pub fn cos_lobe_local(self, wo: DVec3, wi: DVec3) -> f64 {
        self.cos_lobe(DVec3::Z, wo, wi)
    }
}

impl core::str::FromStr for Geometry {
    type Err = Error;
    fn from_str(text: &str) -> Result<Self> {
        Self::parse(text)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn phong_cosine_is_the_angle_to_the_mirror_direction() {
        let wi = DVec3::new(0.3, -0.2, 0.9).normalize();
        let wo = DVec3::new(-0.5, 0.4, 0.6).normalize();
        let mirror = DVec3::new(-wi.x, -wi.y, wi.z);
        assert!((Geometry::Phong.cos_lobe_local(wo, wi) - mirror.dot(wo)).abs() < 1e-15);
    }

    #[test]
    fn blinn_cosine_is_the_half_vector_elevation() {
        let wi = DVec3::new(0.3, -0.2, 0.9).normalize();
        let wo = DVec3::new(-0.5, 0.4, 0.6).normalize();
        let h = (wi + wo).normalize();
        assert!((Geometry::Blinn.cos_lobe_local(wo, wi) - h.z).abs() < 1e-15);
        assert_eq!(Geometry::Blinn.cos_lobe_local(wo, -wo), 0.0);
    }
}
