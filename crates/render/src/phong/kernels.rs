//! The SIMD kernels of Phong shading (`mod.rs` drives them): the surface's divides, the view
//! directions, one light's cosines and weights, and the sum, each one straight loop over
//! plain `f32` slices under `pulp`'s dispatch.

use glam::Vec3;

use crate::camera::{Camera, Projection};
use crate::material::{IlluminationModel, Light};
use specula::Geometry;

/// Positions and unit normals from the weighted sums of [`Sample`], in place.
pub(super) struct Surfaces<'a> {
    pub(super) weight_sum: &'a [f32],
    pub(super) face_normal: [&'a [f32]; 3],
    pub(super) position: [&'a mut [f32]; 3],
    pub(super) normal: [&'a mut [f32]; 3],
}

impl pulp::WithSimd for Surfaces<'_> {
    type Output = ();

    #[inline(always)]
    fn with_simd<S: pulp::Simd>(self, _simd: S) {
        let Surfaces {
            weight_sum,
            face_normal: [fx, fy, fz],
            position: [px, py, pz],
            normal: [nx, ny, nz],
        } = self;
        let len = weight_sum.len();
        let (fx, fy, fz) = (&fx[..len], &fy[..len], &fz[..len]);
        let (px, py, pz) = (&mut px[..len], &mut py[..len], &mut pz[..len]);
        let (nx, ny, nz) = (&mut nx[..len], &mut ny[..len], &mut nz[..len]);
        for i in 0..len {
            let inverse_sum = 1.0 / weight_sum[i];
            (px[i], py[i], pz[i]) = (
                px[i] * inverse_sum,
                py[i] * inverse_sum,
                pz[i] * inverse_sum,
            );
            let normal = Vec3::new(nx[i], ny[i], nz[i]);
            // `try_normalize`'s test: a finite, non-zero reciprocal length.
            let inverse_length = 1.0 / normal.length();
            let usable = inverse_length.is_finite() && inverse_length > 0.0;
            let normal = if usable {
                normal * inverse_length
            } else {
                Vec3::new(fx[i], fy[i], fz[i])
            };
            (nx[i], ny[i], nz[i]) = (normal.x, normal.y, normal.z);
        }
    }
}

/// `wo` at every position: [`Camera::towards_viewer`] per lane.
pub(super) struct ViewDirections<'a> {
    pub(super) camera: &'a Camera,
    pub(super) position: [&'a [f32]; 3],
    pub(super) wo: [&'a mut [f32]; 3],
}

impl pulp::WithSimd for ViewDirections<'_> {
    type Output = ();

    #[inline(always)]
    fn with_simd<S: pulp::Simd>(self, _simd: S) {
        let ViewDirections {
            camera,
            position: [px, py, pz],
            wo: [wx, wy, wz],
        } = self;
        let backwards = camera.backwards();
        let eye = match camera.projection() {
            Projection::Perspective { .. } => camera.eye(),
            Projection::Orthographic { .. } => {
                wx.fill(backwards.x);
                wy.fill(backwards.y);
                wz.fill(backwards.z);
                return;
            }
        };
        let len = px.len();
        let (py, pz, wx, wy, wz) = (
            &py[..len],
            &pz[..len],
            &mut wx[..len],
            &mut wy[..len],
            &mut wz[..len],
        );
        for i in 0..len {
            let d = eye - Vec3::new(px[i], py[i], pz[i]);
            let length_squared = d.length_squared();
            // `try_normalize`'s test: a finite, non-zero length.
            let inverse = 1.0 / length_squared.sqrt();
            let usable = inverse.is_finite() && inverse > 0.0;
            let w = if usable { d * inverse } else { backwards };
            (wx[i], wy[i], wz[i]) = (w.x, w.y, w.z);
        }
    }
}

/// One light at every sample of a group: the lobe's cosine `t` and the weights the light's
/// intensity gets on the diffuse and specular terms (0 where it does not reach the visible
/// side of the surface).
pub(super) struct Cosines<'a> {
    pub(super) light: &'a Light,
    pub(super) geometry: Geometry,
    pub(super) model: IlluminationModel,
    pub(super) position: [&'a [f32]; 3],
    pub(super) normal: [&'a [f32]; 3],
    pub(super) wo: [&'a [f32]; 3],
    pub(super) t: &'a mut [f32],
    pub(super) diffuse_weight: &'a mut [f32],
    pub(super) specular_weight: &'a mut [f32],
    /// `N.wo`, `N.wi` and `wo.h`, written in the microfacet model only.
    pub(super) cosines: [&'a mut [f32]; 3],
}

/// The illumination models as [`Cosines::run`]'s constant.
const CLASSIC: u8 = 0;
const PHYSICAL: u8 = 1;
const MICROFACET: u8 = 2;

impl pulp::WithSimd for Cosines<'_> {
    type Output = ();

    #[inline(always)]
    fn with_simd<S: pulp::Simd>(self, _simd: S) {
        let point = matches!(self.light, Light::Point { .. });
        // The microfacet model's geometry is Blinn's whatever the material says.
        match (point, self.geometry, self.model) {
            (false, Geometry::Phong, IlluminationModel::Classic) => {
                self.run::<false, false, CLASSIC>()
            }
            (false, Geometry::Phong, IlluminationModel::Physical) => {
                self.run::<false, false, PHYSICAL>()
            }
            (false, Geometry::Blinn, IlluminationModel::Classic) => {
                self.run::<false, true, CLASSIC>()
            }
            (false, Geometry::Blinn, IlluminationModel::Physical) => {
                self.run::<false, true, PHYSICAL>()
            }
            (false, _, IlluminationModel::Microfacet) => self.run::<false, true, MICROFACET>(),
            (true, Geometry::Phong, IlluminationModel::Classic) => {
                self.run::<true, false, CLASSIC>()
            }
            (true, Geometry::Phong, IlluminationModel::Physical) => {
                self.run::<true, false, PHYSICAL>()
            }
            (true, Geometry::Blinn, IlluminationModel::Classic) => {
                self.run::<true, true, CLASSIC>()
            }
            (true, Geometry::Blinn, IlluminationModel::Physical) => {
                self.run::<true, true, PHYSICAL>()
            }
            (true, _, IlluminationModel::Microfacet) => self.run::<true, true, MICROFACET>(),
        }
    }
}

impl Cosines<'_> {
    /// The loop for one light kind, geometry and model, with each choice a constant.
    #[inline(always)]
    fn run<const POINT: bool, const BLINN: bool, const MODEL: u8>(self) {
        // As `Shader::incoming`: a directional light without a direction lights nothing
        // (a zero `wi` makes every cosine 0).
        let (at, towards) = match *self.light {
            Light::Point { position, .. } => (position, Vec3::ZERO),
            Light::Directional { towards, .. } => (Vec3::ZERO, towards.normalize_or_zero()),
        };
        let len = self.t.len();
        let [px, py, pz] = self.position.map(|s| &s[..len]);
        let [nx, ny, nz] = self.normal.map(|s| &s[..len]);
        let [ox, oy, oz] = self.wo.map(|s| &s[..len]);
        let diffuse_weight = &mut self.diffuse_weight[..len];
        let specular_weight = &mut self.specular_weight[..len];
        let [cos_out, cos_ins, cos_half] = self.cosines;
        for (i, t) in self.t.iter_mut().enumerate() {
            let normal = Vec3::new(nx[i], ny[i], nz[i]);
            let wo = Vec3::new(ox[i], oy[i], oz[i]);
            // `Shader::incoming`: a point light's direction and, in the physical model, its
            // 1 / d^2 falloff; nothing reaches a sample at the light itself.
            let (wi, attenuation, reaches) = if POINT {
                let offset = at - Vec3::new(px[i], py[i], pz[i]);
                let distance_squared = offset.length_squared();
                let attenuation = if MODEL != CLASSIC {
                    1.0 / distance_squared.max(crate::material::MIN_DISTANCE_SQUARED)
                } else {
                    1.0
                };
                (
                    offset / distance_squared.sqrt(),
                    attenuation,
                    distance_squared > 0.0,
                )
            } else {
                (towards, 1.0, true)
            };
            // `Shader::cosines`.
            let cos_in = normal.dot(wi);
            let lit = reaches && normal.dot(wo) > 0.0 && cos_in > 0.0;
            let (cosine, wo_dot_h) = if BLINN {
                let sum = wi + wo;
                let length_squared = sum.length_squared();
                let inverse_length = 1.0 / length_squared.sqrt();
                if length_squared > 0.0 {
                    (
                        normal.dot(sum) * inverse_length,
                        wo.dot(sum) * inverse_length,
                    )
                } else {
                    (0.0, 0.0)
                }
            } else {
                (2.0 * normal.dot(wi) * normal.dot(wo) - wi.dot(wo), 0.0)
            };
            // `Shader::contribution`: the classic model has no cosine on the specular term; the
            // microfacet model's `1 / (4 N.wo N.wi)` cancels it (`MicrofacetTerms::factors`).
            let diffuse = attenuation * cos_in;
            let specular = if MODEL == PHYSICAL {
                diffuse
            } else {
                attenuation
            };
            *t = if lit { cosine } else { 0.0 };
            diffuse_weight[i] = if lit { diffuse } else { 0.0 };
            specular_weight[i] = if lit { specular } else { 0.0 };
            if MODEL == MICROFACET {
                cos_out[i] = normal.dot(wo);
                cos_ins[i] = cos_in;
                cos_half[i] = wo_dot_h;
            }
        }
    }
}

/// `radiance += diffuse * diffuse_weight + specular * specular_weight * lobe`, per channel.
pub(super) struct Accumulate<'a> {
    pub(super) diffuse: Vec3,
    pub(super) specular: Vec3,
    pub(super) diffuse_weight: &'a [f32],
    pub(super) specular_weight: &'a [f32],
    pub(super) lobe: &'a [f32],
    pub(super) radiance: [&'a mut [f32]; 3],
}

impl pulp::WithSimd for Accumulate<'_> {
    type Output = ();

    #[inline(always)]
    fn with_simd<S: pulp::Simd>(self, _simd: S) {
        let len = self.lobe.len();
        let (diffuse_weight, specular_weight) =
            (&self.diffuse_weight[..len], &self.specular_weight[..len]);
        for (c, channel) in self.radiance.into_iter().enumerate() {
            let channel = &mut channel[..len];
            let (diffuse, specular) = (self.diffuse[c], self.specular[c]);
            for i in 0..len {
                channel[i] +=
                    diffuse * diffuse_weight[i] + specular * specular_weight[i] * self.lobe[i];
            }
        }
    }
}
