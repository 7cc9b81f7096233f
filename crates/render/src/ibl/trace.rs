//! The Monte Carlo estimator of environment lighting and the render loop around it.

use core::f64::consts::{FRAC_1_PI, TAU};
use std::sync::atomic::{AtomicUsize, Ordering};

use glam::{DVec3, Vec3, Vec4};
use rayon::prelude::*;
use specula::sampling::{power_heuristic, uniform, SpecularSampler};

use super::environment::LUMINANCE;
use super::{Environment, IblSettings, Strategy, MAX_SPP};
use crate::pipeline::{surfaces, SurfacePoint};
use crate::{Image, Material, RenderError, Scene};

fn luminance(colour: DVec3) -> f64 {
    colour.dot(LUMINANCE.as_dvec3())
}

/// A material prepared for environment lighting: the physical model's BRDF
/// `kd C / pi + ks S N(n) lobe(t)` and how its directions are drawn.
pub(super) struct Surface {
    /// `kd C / pi`.
    diffuse: DVec3,
    /// `ks S`; the sampler's value carries `N(n) lobe(t)`.
    specular: DVec3,
    sampler: SpecularSampler,
    /// The probability that a BRDF draw goes to the specular lobe rather than the cosine.
    specular_share: f64,
}

impl Surface {
    pub(super) fn new(material: &Material) -> Self {
        let diffuse = (material.kd * material.colour).as_dvec3();
        let specular = (material.ks * material.specular_colour).as_dvec3();
        let (d, s) = (luminance(diffuse), luminance(specular));
        Self {
            diffuse: diffuse * FRAC_1_PI,
            specular,
            sampler: SpecularSampler::new(material.lobe, material.geometry, material.normalisation),
            specular_share: if d + s > 0.0 { s / (d + s) } else { 0.0 },
        }
    }

    /// The BRDF for local `wo` and `wi` (both above the surface, else 0).
    fn brdf(&self, wo: DVec3, wi: DVec3) -> DVec3 {
        if wo.z <= 0.0 || wi.z <= 0.0 {
            return DVec3::ZERO;
        }
        self.diffuse + self.specular * self.sampler.value(wo, wi)
    }

    /// The density of the BRDF strategy: the mixture of the cosine and the lobe.
    fn brdf_pdf(&self, wo: DVec3, wi: DVec3) -> f64 {
        if wi.z <= 0.0 {
            return 0.0;
        }
        let share = self.specular_share;
        let lobe = if share > 0.0 {
            self.sampler.pdf(wo, wi)
        } else {
            0.0
        };
        (1.0 - share) * wi.z * FRAC_1_PI + share * lobe
    }

    /// A direction from the BRDF strategy: `u[0]` picks the term, `u[1..3]` draw in it.
    fn brdf_sample(&self, wo: DVec3, u: [f64; 3]) -> Option<DVec3> {
        if u[0] < self.specular_share {
            self.sampler.sample(wo, [u[1], u[2]]).map(|s| s.wi)
        } else {
            let (sine, cosine) = (u[1].sqrt(), (1.0 - u[1]).sqrt());
            let (s, c) = (TAU * u[2]).sin_cos();
            (cosine > 0.0).then(|| DVec3::new(sine * c, sine * s, cosine))
        }
    }

    /// One sample of the radiance leaving towards `wo` (local) at a surface with the
    /// orthonormal `frame` (tangent, bitangent, normal), lit by `environment`: one draw from
    /// the environment and one from the BRDF, combined as `strategy` says. `u` holds five
    /// uniform numbers.
    pub(super) fn estimate(
        &self,
        environment: &Environment,
        frame: [DVec3; 3],
        wo: DVec3,
        strategy: Strategy,
        u: [f64; 5],
    ) -> DVec3 {
        let to_local = |v: DVec3| DVec3::new(v.dot(frame[0]), v.dot(frame[1]), v.dot(frame[2]));
        let to_world = |v: DVec3| frame[0] * v.x + frame[1] * v.y + frame[2] * v.z;
        let mut radiance = DVec3::ZERO;
        if strategy != Strategy::Brdf {
            if let Some(light) = environment.sample([u[0], u[1]]) {
                let wi = to_local(light.wi);
                let f = self.brdf(wo, wi);
                if f != DVec3::ZERO {
                    let weight = match strategy {
                        Strategy::Mis => power_heuristic(light.pdf, self.brdf_pdf(wo, wi)),
                        _ => 1.0,
                    };
                    radiance += f * light.radiance.as_dvec3() * (wi.z * weight / light.pdf);
                }
            }
        }
        if strategy != Strategy::Environment {
            if let Some(wi) = self.brdf_sample(wo, [u[2], u[3], u[4]]) {
                let pdf = self.brdf_pdf(wo, wi);
                let f = self.brdf(wo, wi);
                if pdf > 0.0 && f != DVec3::ZERO {
                    let world = to_world(wi);
                    let weight = match strategy {
                        Strategy::Mis => power_heuristic(pdf, environment.pdf(world)),
                        _ => 1.0,
                    };
                    radiance += f * environment.radiance(world).as_dvec3() * (wi.z * weight / pdf);
                }
            }
        }
        radiance
    }
}

/// The unit camera ray through each sample position's centre, for the background.
struct Rays {
    inverse: glam::Mat4,
    size: (f32, f32),
}

impl Rays {
    fn new(scene: &Scene) -> Self {
        let settings = &scene.settings;
        let (width, height) = (
            (settings.width * settings.samples) as f32,
            (settings.height * settings.samples) as f32,
        );
        Self {
            inverse: scene.camera.view_projection(width / height).inverse(),
            size: (width, height),
        }
    }

    fn direction(&self, x: u32, y: u32) -> DVec3 {
        let ndc_x = (x as f32 + 0.5) / self.size.0 * 2.0 - 1.0;
        let ndc_y = 1.0 - (y as f32 + 0.5) / self.size.1 * 2.0;
        let at = |depth: f32| {
            let p = self.inverse * Vec4::new(ndc_x, ndc_y, depth, 1.0);
            p.truncate() / p.w
        };
        (at(1.0) - at(0.0)).as_dvec3().normalize_or_zero()
    }
}

/// Renders `scene` lit by `environment` alone (its lights and ambient term are not used):
/// the rasterizer finds the visible surface at each of a pixel's `samples x samples`
/// positions, the pixel's `spp` samples take those positions in turn, and each estimates the
/// reflected radiance by [`Strategy`]. Pixels where nothing is drawn show the environment.
/// `progress(done, total)` is called as rows finish.
pub fn render_ibl(
    scene: &Scene,
    environment: &Environment,
    settings: &IblSettings,
    progress: &(dyn Fn(usize, usize) + Sync),
) -> Result<Image, RenderError> {
    if !(1..=MAX_SPP).contains(&settings.spp) {
        return Err(RenderError::Spp { spp: settings.spp });
    }
    let points = surfaces(scene)?;
    let surfaces: Vec<Surface> = scene
        .objects
        .iter()
        .map(|object| Surface::new(&object.material))
        .collect();
    let rays = Rays::new(scene);
    let (width, height, s) = (
        scene.settings.width,
        scene.settings.height,
        scene.settings.samples,
    );
    let done = AtomicUsize::new(0);
    let mut image = Image::new(width, height, Vec3::ZERO);
    image
        .pixels_mut()
        .par_chunks_mut(width as usize)
        .enumerate()
        .for_each(|(y, row)| {
            let y = y as u32;
            for (x, pixel) in (0..width).zip(row.iter_mut()) {
                let index = u64::from(y * width + x);
                let mut sum = DVec3::ZERO;
                for i in 0..settings.spp {
                    let position = i % (s * s);
                    let (sx, sy) = (x * s + position % s, y * s + position / s);
                    let point = points[(sy * width * s + sx) as usize];
                    let u = core::array::from_fn(|d| {
                        uniform(
                            settings.seed,
                            index * u64::from(settings.spp) + u64::from(i),
                            d as u64,
                        )
                    });
                    let radiance = match point {
                        None => environment.radiance(rays.direction(sx, sy)).as_dvec3(),
                        Some(point) => {
                            shade(&surfaces, environment, scene, point, settings.strategy, u)
                        }
                    };
                    if radiance.is_finite() {
                        sum += radiance;
                    }
                }
                *pixel = (sum / f64::from(settings.spp)).as_vec3();
            }
            progress(done.fetch_add(1, Ordering::Relaxed) + 1, height as usize);
        });
    Ok(image)
}

/// One sample at a visible surface point.
fn shade(
    surfaces: &[Surface],
    environment: &Environment,
    scene: &Scene,
    point: SurfacePoint,
    strategy: Strategy,
    u: [f64; 5],
) -> DVec3 {
    let normal = point.normal.as_dvec3();
    let (tangent, bitangent) = normal.any_orthonormal_pair();
    let frame = [tangent, bitangent, normal];
    let wo_world = scene.camera.towards_viewer(point.position).as_dvec3();
    let wo = DVec3::new(
        wo_world.dot(tangent),
        wo_world.dot(bitangent),
        wo_world.dot(normal),
    );
    surfaces[point.object as usize].estimate(environment, frame, wo, strategy, u)
}
