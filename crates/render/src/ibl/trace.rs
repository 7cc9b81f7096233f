//! The Monte Carlo estimator of environment lighting and the render loop around it.

use core::f64::consts::{FRAC_1_PI, TAU};
use std::sync::atomic::{AtomicUsize, Ordering};

use glam::{DVec3, Vec3, Vec4};
use rayon::prelude::*;
use specula::sampling::{power_heuristic, uniform, SpecularSampler};

use super::ahead::LightCells;
use super::packet::{shade, Frame32, PacketSurface, Point, Scratch};
use super::{Environment, IblSettings, Strategy, MAX_SPP};
use crate::grid::{check_grid, grid_renders, GridError, GridOptions};
use crate::image::Image;
use crate::material::Material;
use crate::pipeline::RenderError;
use crate::pipeline::{surfaces, SurfacePoint};
use crate::scene::{Overrides, Scene};
use specula::brdf::luminance;
use specula::LobeKind;

/// A BRDF as the estimator needs it, in the local frame (`z` the normal, `wo` the viewer):
/// its value with the density of its own sampler, and that sampler. Materials of the scene
/// format are one; a measured material or a fitted model rendered in their place
/// ([`render_ibl_with`]) are others.
pub trait Reflectance: Sync {
    /// `f(wo, wi)` per channel and the density with which [`Reflectance::sample`] draws
    /// `wi` (per unit solid angle); both zero below the horizon.
    fn f_and_pdf(&self, wo: DVec3, wi: DVec3) -> (DVec3, f64);

    /// Draws `wi` from three uniform numbers: `(wi, f(wo, wi), pdf)`, or `None`.
    fn sample(&self, wo: DVec3, u: [f64; 3]) -> Option<(DVec3, DVec3, f64)>;
}

/// A material prepared for environment lighting one sample at a time in `f64`: the physical
/// model's BRDF `kd C / pi + ks S N(n) lobe(t)` and how its directions are drawn. The
/// renderer shades scene materials by packets in `f32` ([`render_ibl`]); this is the same
/// estimator written plainly, the reference those packets are tested against
/// (`render_ibl_with(scene, env, settings, &MaterialReflectance::new(material), ..)`).
pub struct MaterialReflectance {
    /// `kd C / pi`.
    diffuse: DVec3,
    /// `ks S`; the sampler's value carries `N(n) lobe(t)`.
    specular: DVec3,
    sampler: SpecularSampler,
    /// The probability that a BRDF draw goes to the specular lobe rather than the cosine.
    specular_share: f64,
}

impl MaterialReflectance {
    /// `material`'s BRDF and sampler.
    #[must_use]
    pub fn new(material: &Material) -> Self {
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

    /// The BRDF from the lobe's value, and the BRDF strategy's density (the mixture of the
    /// cosine and the lobe) from the lobe's.
    fn combine(&self, wi: DVec3, lobe_value: f64, lobe_pdf: f64) -> (DVec3, f64) {
        let share = self.specular_share;
        (
            self.diffuse + self.specular * lobe_value,
            (1.0 - share) * wi.z * FRAC_1_PI + share * lobe_pdf,
        )
    }
}

/// A cosine-distributed direction about the normal from two uniform numbers.
#[must_use]
pub fn cosine_direction(u: [f64; 2]) -> DVec3 {
    let (sine, cosine) = (u[0].sqrt(), (1.0 - u[0]).sqrt());
    let (s, c) = (TAU * u[1]).sin_cos();
    DVec3::new(sine * c, sine * s, cosine)
}

impl Reflectance for MaterialReflectance {
    fn f_and_pdf(&self, wo: DVec3, wi: DVec3) -> (DVec3, f64) {
        if wi.z <= 0.0 {
            return (DVec3::ZERO, 0.0);
        }
        let lobe_pdf = if self.specular_share > 0.0 {
            self.sampler.pdf(wo, wi)
        } else {
            0.0
        };
        self.combine(wi, self.sampler.value(wo, wi), lobe_pdf)
    }

    /// `u[0]` picks the term, `u[1..3]` draw in it; a lobe draw brings its own value and
    /// density.
    fn sample(&self, wo: DVec3, u: [f64; 3]) -> Option<(DVec3, DVec3, f64)> {
        if u[0] < self.specular_share {
            let drawn = self.sampler.sample(wo, [u[1], u[2]])?;
            let (f, pdf) = self.combine(drawn.wi, drawn.value, drawn.pdf);
            Some((drawn.wi, f, pdf))
        } else {
            let wi = cosine_direction([u[1], u[2]]);
            let (f, pdf) = self.f_and_pdf(wo, wi);
            Some((wi, f, pdf))
        }
    }
}

/// One sample of the radiance leaving towards `wo` (local, above the surface) at a
/// surface with `frame`, lit by `environment`: one draw from the environment and one from
/// the BRDF, combined as `strategy` says. `u` holds five uniform numbers.
fn estimate(
    surface: &dyn Reflectance,
    environment: &Environment,
    frame: &Frame,
    wo: DVec3,
    strategy: Strategy,
    u: [f64; 5],
) -> DVec3 {
    let mut radiance = DVec3::ZERO;
    if strategy != Strategy::Brdf {
        if let Some(light) = environment.sample([u[0], u[1]]) {
            let wi = frame.to_local(light.wi);
            let (f, brdf_pdf) = surface.f_and_pdf(wo, wi);
            if f != DVec3::ZERO {
                let weight = match strategy {
                    Strategy::Mis => power_heuristic(light.pdf, brdf_pdf),
                    _ => 1.0,
                };
                radiance += f * light.radiance.as_dvec3() * (wi.z * weight / light.pdf);
            }
        }
    }
    if strategy != Strategy::Environment {
        if let Some((wi, f, pdf)) = surface.sample(wo, [u[2], u[3], u[4]]) {
            if pdf > 0.0 && f != DVec3::ZERO {
                let world = frame.to_world(wi);
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

/// An orthonormal frame about a unit normal: world directions to the local frame (`z` the
/// normal) and back.
struct Frame {
    tangent: DVec3,
    bitangent: DVec3,
    normal: DVec3,
}

impl Frame {
    fn new(normal: DVec3) -> Self {
        let (tangent, bitangent) = normal.any_orthonormal_pair();
        Self {
            tangent,
            bitangent,
            normal,
        }
    }

    fn to_local(&self, v: DVec3) -> DVec3 {
        DVec3::new(
            v.dot(self.tangent),
            v.dot(self.bitangent),
            v.dot(self.normal),
        )
    }

    fn to_world(&self, v: DVec3) -> DVec3 {
        self.tangent * v.x + self.bitangent * v.y + self.normal * v.z
    }

    fn as_f32(&self) -> Frame32 {
        Frame32::new(
            self.tangent.as_vec3(),
            self.bitangent.as_vec3(),
            self.normal.as_vec3(),
        )
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
    let surfaces: Vec<Vec<PacketSurface>> = scene
        .objects
        .iter()
        .map(|object| vec![PacketSurface::new(&object.material)])
        .collect();
    render_one(
        scene,
        environment,
        settings,
        Shading::Packets {
            surfaces: &surfaces,
            images: 1,
        },
        progress,
    )
}

/// [`render_ibl`] of `scene` with every material's lobe replaced by each of `lobes` in turn
/// (as `Overrides { lobe }` replaces it), one image per lobe, bit for bit the images
/// [`render_ibl`] gives each alone. Every lobe takes the same random numbers, so the
/// environment's draws, and the cosine-weighted BRDF draws, are computed once for all of
/// them: a comparison of lobes under one light costs little more than its lobe-specific
/// work.
pub fn render_ibl_lobes(
    scene: &Scene,
    lobes: &[LobeKind],
    environment: &Environment,
    settings: &IblSettings,
    progress: &(dyn Fn(usize, usize) + Sync),
) -> Result<Vec<Image>, RenderError> {
    if lobes.is_empty() {
        return Ok(Vec::new());
    }
    let variants: Vec<Scene> = lobes
        .iter()
        .map(|&kind| {
            let mut variant = scene.clone();
            variant.apply(&Overrides {
                lobe: Some(kind),
                ..Overrides::default()
            });
            variant
        })
        .collect();
    let surfaces: Vec<Vec<PacketSurface>> = (0..scene.objects.len())
        .map(|object| {
            variants
                .iter()
                .map(|variant| PacketSurface::new(&variant.objects[object].material))
                .collect()
        })
        .collect();
    render(
        &variants[0],
        environment,
        settings,
        Shading::Packets {
            surfaces: &surfaces,
            images: lobes.len(),
        },
        progress,
    )
}

/// The renders a grid of `options`'s lobes asks for ([`grid_renders`]), by index,
/// from one pass of [`render_ibl_lobes`], for [`crate::grid::made_renders`] to hand to
/// `render_grid_with`; a grid it refuses ([`check_grid`]) is refused first.
pub fn render_ibl_grid(
    scene: &Scene,
    options: &GridOptions,
    environment: &Environment,
    settings: &IblSettings,
    progress: &(dyn Fn(usize, usize) + Sync),
) -> Result<Vec<Option<Image>>, GridError> {
    check_grid(scene, options)?;
    let asked = grid_renders(options);
    let kinds: Vec<LobeKind> = asked.iter().flatten().copied().collect();
    let mut rendered = render_ibl_lobes(scene, &kinds, environment, settings, progress)
        .map_err(|e| GridError::Render(e.to_string()))?
        .into_iter();
    Ok(asked
        .iter()
        .map(|kind| kind.and_then(|_| rendered.next()))
        .collect())
}

/// [`render_ibl`] with every object's material replaced by `reflectance` (a measured
/// material, a fitted model).
pub fn render_ibl_with(
    scene: &Scene,
    environment: &Environment,
    settings: &IblSettings,
    reflectance: &dyn Reflectance,
    progress: &(dyn Fn(usize, usize) + Sync),
) -> Result<Image, RenderError> {
    let reflectances = vec![reflectance; scene.objects.len()];
    render_ibl_each(scene, environment, settings, &reflectances, progress)
}

/// [`render_ibl_with`] with each object's own [`Reflectance`] (`reflectances[i]` for
/// `scene.objects[i]`).
///
/// # Panics
/// If there is not one reflectance per object.
pub fn render_ibl_each(
    scene: &Scene,
    environment: &Environment,
    settings: &IblSettings,
    reflectances: &[&dyn Reflectance],
    progress: &(dyn Fn(usize, usize) + Sync),
) -> Result<Image, RenderError> {
    assert_eq!(
        reflectances.len(),
        scene.objects.len(),
        "one reflectance per object"
    );
    render_one(
        scene,
        environment,
        settings,
        Shading::Reflectances(reflectances),
        progress,
    )
}

/// How the visible surfaces are shaded: the scene's materials by the packet estimator (per
/// object, one surface per image), or any [`Reflectance`] one sample at a time in `f64` (one
/// image).
#[derive(Clone, Copy)]
enum Shading<'a> {
    Packets {
        /// Per object, one surface per image.
        surfaces: &'a [Vec<PacketSurface>],
        /// Images made (also for a scene without objects).
        images: usize,
    },
    Reflectances(&'a [&'a dyn Reflectance]),
}

impl Shading<'_> {
    /// How many images the shading makes.
    fn images(&self) -> usize {
        match self {
            Shading::Packets { images, .. } => *images,
            Shading::Reflectances(_) => 1,
        }
    }
}

/// [`render`] of a shading that makes one image.
fn render_one(
    scene: &Scene,
    environment: &Environment,
    settings: &IblSettings,
    shading: Shading,
    progress: &(dyn Fn(usize, usize) + Sync),
) -> Result<Image, RenderError> {
    debug_assert_eq!(shading.images(), 1);
    let mut images = render(scene, environment, settings, shading, progress)?;
    Ok(images.remove(0))
}

/// The render loop, object `i` shown with `shading`'s `i`th surface(s): one image per
/// surface of an object.
fn render(
    scene: &Scene,
    environment: &Environment,
    settings: &IblSettings,
    shading: Shading,
    progress: &(dyn Fn(usize, usize) + Sync),
) -> Result<Vec<Image>, RenderError> {
    if !(1..=MAX_SPP).contains(&settings.spp) {
        return Err(RenderError::Spp { spp: settings.spp });
    }
    let points = surfaces(scene)?;
    let rays = Rays::new(scene);
    let (width, height, s) = (
        scene.settings.width,
        scene.settings.height,
        scene.settings.samples,
    );
    let images = shading.images();
    let positions = (s * s).min(settings.spp);
    // Sample `i` of a pixel takes position `i % positions`; its draw index follows the
    // pixel's first.
    let draws_of = |x: u32, y: u32, position: u32| {
        let first = u64::from(y * width + x) * u64::from(settings.spp);
        (position..settings.spp)
            .step_by(positions as usize)
            .map(move |i| first + u64::from(i))
    };
    let done = AtomicUsize::new(0);
    // Row by row, each row holding the images' rows one after another.
    let row_length = width as usize * images;
    let mut rows = crate::buffers::filled(Vec3::ZERO, row_length * height as usize);
    let level = specula::simd::Level::detect();
    // A row is shaded a run of pixels at a time, the run's environment draws made first.
    let run = (RUN_DRAWS / settings.spp).max(1);
    // Each thread's columns and lists, made once and reused row after row.
    let made = || {
        (
            vec![DVec3::ZERO; images * run as usize],
            Scratch::new(),
            LightCells::default(),
            Vec::new(),
        )
    };
    rows.par_chunks_mut(row_length).enumerate().for_each_init(
        made,
        |(sums, scratch, cells, visits), (y, row)| {
            let y = y as u32;
            for start in (0..width).step_by(run as usize) {
                let end = (start + run).min(width);
                sums.fill(DVec3::ZERO);
                cells.clear();
                visits.clear();
                for x in start..end {
                    let sums = &mut sums[(x - start) as usize * images..][..images];
                    for position in 0..positions {
                        let (sx, sy) = (x * s + position % s, y * s + position / s);
                        let Some(point) = points[(sy * width * s + sx) as usize] else {
                            let direction = rays.direction(sx, sy);
                            let samples = draws_of(x, y, position).len() as f64;
                            let background = environment.radiance(direction).as_dvec3() * samples;
                            sums.iter_mut().for_each(|sum| *sum += background);
                            continue;
                        };
                        let Some((frame, wo)) = view(scene, point) else {
                            continue;
                        };
                        if let Shading::Packets { .. } = shading {
                            cells.push(environment, settings.seed, draws_of(x, y, position));
                        }
                        visits.push(Visit {
                            x,
                            position,
                            object: point.object as usize,
                            frame,
                            wo,
                        });
                    }
                }
                cells.resolve(environment);
                for visit in visits.iter() {
                    let sums = &mut sums[(visit.x - start) as usize * images..][..images];
                    let draws = draws_of(visit.x, y, visit.position);
                    match shading {
                        Shading::Packets { surfaces, .. } => shade(
                            &Point {
                                surfaces: &surfaces[visit.object],
                                frame: visit.frame.as_f32(),
                                wo: visit.wo.as_vec3(),
                            },
                            environment,
                            (settings.strategy, level),
                            settings.seed,
                            draws,
                            (&mut *cells, &mut *scratch, sums),
                        ),
                        Shading::Reflectances(surfaces) => {
                            sums[0] += draws
                                .map(|draw| {
                                    let u = core::array::from_fn(|d| {
                                        uniform(settings.seed, draw, d as u64)
                                    });
                                    estimate(
                                        surfaces[visit.object],
                                        environment,
                                        &visit.frame,
                                        visit.wo,
                                        settings.strategy,
                                        u,
                                    )
                                })
                                .sum::<DVec3>();
                        }
                    }
                }
                for x in start..end {
                    let sums = &sums[(x - start) as usize * images..][..images];
                    for (image, sum) in sums.iter().enumerate() {
                        row[image * width as usize + x as usize] =
                            (*sum / f64::from(settings.spp)).as_vec3();
                    }
                }
            }
            progress(done.fetch_add(1, Ordering::Relaxed) + 1, height as usize);
        },
    );
    if images == 1 {
        let image = Image::from_pixels(width, height, rows).expect("a row a line of the image");
        return Ok(vec![image]);
    }
    let mut out = vec![Image::new(width, height, Vec3::ZERO); images];
    for (row, y) in rows.chunks_exact(row_length).zip(0..) {
        for (image, pixels) in out.iter_mut().zip(row.chunks_exact(width as usize)) {
            let start = y * width as usize;
            image.pixels_mut()[start..start + width as usize].copy_from_slice(pixels);
        }
    }
    Ok(out)
}

/// The environment draws a run of pixels makes ahead of shading it (`ahead.rs`): enough
/// to keep the reads of the alias table in flight together, few enough that the records
/// they ask for stay in cache until read.
const RUN_DRAWS: u32 = 1024;

/// A pixel's sample position that sees a surface, as the run's first pass found it.
struct Visit {
    x: u32,
    position: u32,
    object: usize,
    frame: Frame,
    wo: DVec3,
}

/// A visible surface point's frame and `wo` in it, or `None` where the surface faces away
/// from the camera (an interpolated normal past the silhouette: black).
fn view(scene: &Scene, point: SurfacePoint) -> Option<(Frame, DVec3)> {
    let frame = Frame::new(point.normal.as_dvec3());
    let wo = frame.to_local(scene.camera.towards_viewer(point.position).as_dvec3());
    (wo.z > 0.0).then_some((frame, wo))
}
