//! The rendering pipeline: vertex shading, clipping, triangle setup, binning into tiles, and
//! per-tile visibility then shading, in parallel over tiles.
//!
//! Determinism: every tile draws its triangles in submission order with a strict depth test, so
//! a tile's pixels depend only on the scene, never on which thread drew it or when. Within a
//! tile, visibility is resolved first and each visible sample is shaded once (no overdraw
//! shading), then the `samples x samples` block of each pixel is averaged (supersampling).

use std::sync::atomic::{AtomicUsize, Ordering};

use glam::{Vec3, Vec4};
use rayon::prelude::*;
use thiserror::Error;

use crate::clip::{clip_triangle, ClipVertex, Varyings, MAX_SIDE};
use crate::image::Image;
use crate::material::{Shader, Shading};
use crate::phong;
use crate::raster::{Culling, EdgeWeights, PixelRect, ScreenVertex, Setup};
use crate::scene::{Analytic, Scene, Settings};

/// Output pixels per tile side.
const TILE: u32 = 32;

/// The largest supersampling factor per axis.
pub const MAX_SAMPLES: u32 = 8;

/// The most output pixels a render may have: 64 Mi (8192 x 8192), 768 MiB of linear RGB.
/// Larger requests are refused before anything is allocated.
pub const MAX_PIXELS: u64 = 1 << 26;

/// The most samples per pixel a Monte Carlo render (`ibl/`) may take.
pub const MAX_SPP: u32 = 1 << 16;

/// A render that cannot be done, and why.
#[derive(Clone, Debug, Error, PartialEq)]
#[non_exhaustive]
pub enum RenderError {
    /// The image or sample count is out of range.
    #[error(
        "cannot render {width}x{height} pixels with {samples}x{samples} samples: width and \
        height must be at least 1, width x height at most {MAX_PIXELS} pixels, samples in [1, \
        {MAX_SAMPLES}], and width or height times samples at most {MAX_SIDE}"
    )]
    Size {
        /// Width in pixels.
        width: u32,
        /// Height in pixels.
        height: u32,
        /// Samples per pixel per axis.
        samples: u32,
    },
    /// The samples per pixel of a Monte Carlo render are out of range.
    #[error("cannot render with {spp} samples per pixel: spp must be in [1, {MAX_SPP}]")]
    Spp {
        /// The samples asked for.
        spp: u32,
    },
}

/// A triangle after clipping and setup, with what its fragments need.
#[derive(Clone, Copy, Debug)]
struct Primitive {
    setup: Setup,
    varyings: [Varyings; 3],
    inverse_w: [f32; 3],
    shader: u32,
    face_normal: Vec3,
    flat_colour: Vec3,
}

impl Settings {
    /// Refuses an image or sample count outside what the renderers draw: width and height at
    /// least 1, at most [`MAX_PIXELS`] pixels, samples in `[1, MAX_SAMPLES]`, each side times
    /// samples at most the rasterizer's exact range.
    pub fn validate(&self) -> Result<(), RenderError> {
        let (width, height, samples) = (self.width, self.height, self.samples);
        let too_big = |side: u32| side.checked_mul(samples).is_none_or(|s| s > MAX_SIDE);
        if width == 0
            || height == 0
            || u64::from(width) * u64::from(height) > MAX_PIXELS
            || !(1..=MAX_SAMPLES).contains(&samples)
            || too_big(width)
            || too_big(height)
        {
            return Err(RenderError::Size {
                width,
                height,
                samples,
            });
        }
        Ok(())
    }
}

/// Renders `scene`; `progress(done, total)` is called as tiles finish (from any thread).
pub fn render(
    scene: &Scene,
    progress: &(dyn Fn(usize, usize) + Sync),
) -> Result<Image, RenderError> {
    let settings = &scene.settings;
    let shaders = prepare(scene)?;
    let (width, height, samples) = (settings.width, settings.height, settings.samples);
    let primitives = setup_primitives(scene, &shaders, settings.shading);
    let tiles_x = width.div_ceil(TILE);
    let tiles_y = height.div_ceil(TILE);
    let bins = bin(&primitives, tiles_x, tiles_y, TILE * samples);
    let total = bins.len();
    let done = AtomicUsize::new(0);
    let mut image = Image::new(width, height, Vec3::ZERO);
    // Each band of tile rows is written in place by one thread, its tiles in turn.
    image
        .pixels_mut()
        .par_chunks_mut((width * TILE) as usize)
        .enumerate()
        .for_each_init(TileScratch::default, |scratch, (ty, band)| {
            for tx in 0..tiles_x {
                let bin = &bins[(ty as u32 * tiles_x + tx) as usize];
                let tile = (tx, ty as u32);
                render_tile(scene, &shaders, &primitives, bin, tile, band, scratch);
                progress(done.fetch_add(1, Ordering::Relaxed) + 1, total);
            }
        });
    Ok(image)
}

/// What one sample position sees: the nearest surface's interpolated position and unit
/// normal, and the index of its object in the scene.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SurfacePoint {
    /// World position.
    pub position: Vec3,
    /// Unit shading normal: a sphere's own at the point, or else the vertex normals
    /// interpolated (the face's where that vanishes).
    pub normal: Vec3,
    /// The object's index in `scene.objects`.
    pub object: u32,
}

/// The visible surface at every sample position (`width * samples` by `height * samples`,
/// row-major), `None` where nothing is drawn: the rasterizer's coverage and visibility,
/// with the surface handed back instead of shaded (a G-buffer, for renderers that light
/// the surface themselves, such as the environment lighting of `ibl/`).
pub fn surfaces(scene: &Scene) -> Result<Vec<Option<SurfacePoint>>, RenderError> {
    let settings = &scene.settings;
    let shaders = prepare(scene)?;
    let primitives = setup_primitives(scene, &shaders, Shading::Phong);
    let s = settings.samples;
    let (tiles_x, tiles_y) = (
        settings.width.div_ceil(TILE),
        settings.height.div_ceil(TILE),
    );
    let bins = bin(&primitives, tiles_x, tiles_y, TILE * s);
    let (width, height) = (settings.width * s, settings.height * s);
    let mut points = crate::buffers::filled(None, (width * height) as usize);
    // Each band (a row of tiles) is written in place by one thread, its tiles in turn.
    points
        .par_chunks_mut((width * TILE * s) as usize)
        .enumerate()
        .for_each_init(
            || (Vec::new(), Vec::new()),
            |(depth, visible), (ty, band)| {
                let ty = ty as u32;
                for tx in 0..tiles_x {
                    let bin = &bins[(ty * tiles_x + tx) as usize];
                    let rect = PixelRect {
                        x0: tx * TILE * s,
                        y0: ty * TILE * s,
                        x1: ((tx + 1) * TILE * s).min(width) - 1,
                        y1: ((ty + 1) * TILE * s).min(height) - 1,
                    };
                    resolve_visibility(&primitives, bin, rect, depth, visible);
                    let sample_width = rect.x1 - rect.x0 + 1;
                    // A triangle's edge planes about the tile, made again only where the
                    // visible triangle changes (neighbouring samples mostly share one).
                    let mut planes = None;
                    for (k, &slot) in visible.iter().enumerate() {
                        if slot == u32::MAX {
                            continue;
                        }
                        let primitive = &primitives[bin[slot as usize] as usize];
                        let (x, y) = (
                            rect.x0 + k as u32 % sample_width,
                            rect.y0 + k as u32 / sample_width,
                        );
                        let edges = match planes {
                            Some((made_for, edges)) if made_for == slot => edges,
                            _ => {
                                let edges = primitive.setup.edge_weights_near(rect.x0, rect.y0);
                                planes = Some((slot, edges));
                                edges
                            }
                        };
                        let weights = perspective_weights(primitive, edges.at(x, y));
                        let position = blend(primitive, weights, |v| v.position);
                        let interpolated = || {
                            blend(primitive, weights, |v| v.normal)
                                .try_normalize()
                                .unwrap_or(primitive.face_normal)
                        };
                        // A sphere is shaded with its own normal at the point, as a ray
                        // tracer given the exact shape shades it, not its tessellation's.
                        let normal = match scene.objects[primitive.shader as usize].analytic {
                            Some(Analytic::Sphere { centre, .. }) => (position - centre)
                                .try_normalize()
                                .unwrap_or_else(interpolated),
                            None => interpolated(),
                        };
                        band[((y - rect.y0) * width + x) as usize] = Some(SurfacePoint {
                            position,
                            normal,
                            object: primitive.shader,
                        });
                    }
                }
            },
        );
    Ok(points)
}

/// How many fragments each sample position receives, before the depth test: an overdraw map
/// of `width * samples` by `height * samples` counts, row-major. The same vertex stage,
/// clipping, culling and rasterization as [`render`]; a closed convex surface seen from
/// outside (or from inside, flipped) covers every sample it hides exactly once.
pub fn overdraw(scene: &Scene) -> Result<Vec<u32>, RenderError> {
    let settings = &scene.settings;
    let shaders = prepare(scene)?;
    let (width, height) = (
        settings.width * settings.samples,
        settings.height * settings.samples,
    );
    let mut counts = vec![0; (width * height) as usize];
    let all = PixelRect {
        x0: 0,
        y0: 0,
        x1: width - 1,
        y1: height - 1,
    };
    for primitive in setup_primitives(scene, &shaders, settings.shading) {
        primitive.setup.for_each_covered(all, |x, y, _| {
            counts[(y * width + x) as usize] += 1;
        });
    }
    Ok(counts)
}

/// Checks the settings and prepares each object's material for the illumination model.
fn prepare(scene: &Scene) -> Result<Vec<Shader>, RenderError> {
    scene.settings.validate()?;
    Ok(scene
        .objects
        .iter()
        .map(|object| Shader::new(&object.material, scene.settings.model))
        .collect())
}

/// Vertex stage, clipping and triangle setup for every object, in submission order; the
/// vertices (Gouraud) or faces (flat) are lit here when `shading` asks for it.
fn setup_primitives(scene: &Scene, shaders: &[Shader], shading: Shading) -> Vec<Primitive> {
    let settings = &scene.settings;
    let (width, height) = (
        settings.width * settings.samples,
        settings.height * settings.samples,
    );
    let view_projection = scene.camera.view_projection(width as f32 / height as f32);
    let culling = if settings.cull_back_faces {
        Culling::Back
    } else {
        Culling::None
    };
    let shade = |shader: &Shader, position: Vec3, normal: Vec3| {
        let wo = scene.camera.towards_viewer(position);
        shader.shade(position, normal, wo, &scene.lights, scene.ambient)
    };
    let to_screen = |clip: Vec4| {
        let ndc = clip.truncate() / clip.w;
        ScreenVertex {
            x: (ndc.x + 1.0) * 0.5 * width as f32,
            y: (1.0 - ndc.y) * 0.5 * height as f32,
            z: ndc.z,
        }
    };
    let mut primitives = Vec::new();
    for (object_index, object) in scene.objects.iter().enumerate() {
        let shader = &shaders[object_index];
        let mesh = &object.mesh;
        let vertices: Vec<ClipVertex> = mesh
            .positions()
            .par_iter()
            .zip(mesh.normals())
            .map(|(&position, &normal)| ClipVertex {
                clip: view_projection * position.extend(1.0),
                varyings: Varyings {
                    position,
                    normal,
                    colour: if shading == Shading::Gouraud {
                        shade(shader, position, normal)
                    } else {
                        Vec3::ZERO
                    },
                },
            })
            .collect();
        let pieces: Vec<Vec<Primitive>> = mesh
            .triangles()
            .par_iter()
            .map_init(
                || (Vec::new(), Vec::new()),
                |(polygon, scratch), triangle| {
                    let corners = triangle.map(|i| vertices[i as usize]);
                    let [a, b, c] = corners.map(|v| v.varyings.position);
                    let Some(face_normal) = (b - a).cross(c - a).try_normalize() else {
                        return Vec::new();
                    };
                    let flat_colour = if shading == Shading::Flat {
                        shade(shader, (a + b + c) / 3.0, face_normal)
                    } else {
                        Vec3::ZERO
                    };
                    clip_triangle(corners, polygon, scratch);
                    (1..polygon.len().saturating_sub(1))
                        .filter_map(|k| {
                            let fan = [polygon[0], polygon[k], polygon[k + 1]];
                            let setup =
                                Setup::new(fan.map(|v| to_screen(v.clip)), culling, width, height)?;
                            Some(Primitive {
                                setup,
                                varyings: fan.map(|v| v.varyings),
                                inverse_w: fan.map(|v| 1.0 / v.clip.w),
                                shader: object_index as u32,
                                face_normal,
                                flat_colour,
                            })
                        })
                        .collect()
                },
            )
            .collect();
        primitives.extend(pieces.into_iter().flatten());
    }
    primitives
}

/// For each tile (row-major), the primitives that may cover it, in submission order.
fn bin(primitives: &[Primitive], tiles_x: u32, tiles_y: u32, tile_samples: u32) -> Vec<Vec<u32>> {
    let mut bins = vec![Vec::new(); (tiles_x * tiles_y) as usize];
    for (index, primitive) in primitives.iter().enumerate() {
        let bounds = primitive.setup.bounds();
        for ty in bounds.y0 / tile_samples..=(bounds.y1 / tile_samples).min(tiles_y - 1) {
            for tx in bounds.x0 / tile_samples..=(bounds.x1 / tile_samples).min(tiles_x - 1) {
                bins[(ty * tiles_x + tx) as usize].push(index as u32);
            }
        }
    }
    bins
}

/// A thread's buffers, reused from tile to tile.
#[derive(Default)]
struct TileScratch {
    depth: Vec<f32>,
    visible: Vec<u32>,
    radiance: Vec<Vec3>,
    edge_weights: Vec<EdgeWeights>,
    samples: Vec<phong::Sample>,
    phong: phong::Scratch,
}

/// Visibility, shading and the supersampling filter for one tile, written into its `band`
/// (the image rows of its tile row).
fn render_tile(
    scene: &Scene,
    shaders: &[Shader],
    primitives: &[Primitive],
    bin: &[u32],
    (tx, ty): (u32, u32),
    band: &mut [Vec3],
    scratch: &mut TileScratch,
) {
    let settings = &scene.settings;
    let s = settings.samples;
    let (x0, y0) = (tx * TILE, ty * TILE);
    let (tile_width, tile_height) = (
        TILE.min(settings.width - x0),
        TILE.min(settings.height - y0),
    );
    let (sample_width, sample_height) = (tile_width * s, tile_height * s);
    let rect = PixelRect {
        x0: x0 * s,
        y0: y0 * s,
        x1: x0 * s + sample_width - 1,
        y1: y0 * s + sample_height - 1,
    };
    let count = (sample_width * sample_height) as usize;
    let TileScratch {
        depth,
        visible,
        radiance,
        edge_weights,
        samples,
        phong: phong_scratch,
    } = scratch;
    resolve_visibility(primitives, bin, rect, depth, visible);
    radiance.clear();
    radiance.resize(count, settings.background);
    let position = |k: usize| {
        (
            rect.x0 + k as u32 % sample_width,
            rect.y0 + k as u32 / sample_width,
        )
    };
    // Per primitive of the bin, its edge functions as planes around the tile's corner: a
    // sample's weights are then three multiply-adds (exact integer evaluation per sample cost
    // a quarter of a Phong frame: measured).
    edge_weights.clear();
    if settings.shading != Shading::Flat {
        edge_weights.extend(bin.iter().map(|&index| {
            primitives[index as usize]
                .setup
                .edge_weights_near(rect.x0, rect.y0)
        }));
    }
    let visible_samples = visible
        .iter()
        .enumerate()
        .filter(|&(_, &slot)| slot != u32::MAX)
        .map(|(k, &slot)| (k, slot as usize, &primitives[bin[slot as usize] as usize]));
    match settings.shading {
        Shading::Phong => {
            samples.clear();
            samples.extend(visible_samples.map(|(k, slot, primitive)| {
                let (x, y) = position(k);
                let edges = edge_weights[slot].at(x, y);
                let weights: [f32; 3] = core::array::from_fn(|k| edges[k] * primitive.inverse_w[k]);
                phong::Sample {
                    slot: k as u32,
                    shader: primitive.shader,
                    weight_sum: weights[0] + weights[1] + weights[2],
                    weighted_position: blend(primitive, weights, |v| v.position),
                    weighted_normal: blend(primitive, weights, |v| v.normal),
                    face_normal: primitive.face_normal,
                }
            }));
            phong::shade(
                shaders,
                &scene.lights,
                scene.ambient,
                &scene.camera,
                samples,
                radiance,
                phong_scratch,
            );
        }
        Shading::Gouraud => {
            for (k, slot, primitive) in visible_samples {
                let (x, y) = position(k);
                let weights = perspective_weights(primitive, edge_weights[slot].at(x, y));
                radiance[k] = blend(primitive, weights, |v| v.colour);
            }
        }
        Shading::Flat => {
            for (k, _, primitive) in visible_samples {
                radiance[k] = primitive.flat_colour;
            }
        }
    }
    let scale = 1.0 / (s * s) as f32;
    let width = settings.width as usize;
    for py in 0..tile_height {
        let row = &mut band[py as usize * width + x0 as usize..][..tile_width as usize];
        for (px, pixel) in (0..tile_width).zip(row) {
            let mut sum = Vec3::ZERO;
            for sy in 0..s {
                let start = ((py * s + sy) * sample_width + px * s) as usize;
                sum += radiance[start..start + s as usize]
                    .iter()
                    .copied()
                    .sum::<Vec3>();
            }
            *pixel = sum * scale;
        }
    }
}

/// The samples of `rect` (a tile's sample positions), row-major: the depth of the nearest
/// fragment and its primitive's slot in `bin`, `u32::MAX` where none covers the sample.
fn resolve_visibility(
    primitives: &[Primitive],
    bin: &[u32],
    rect: PixelRect,
    depth: &mut Vec<f32>,
    visible: &mut Vec<u32>,
) {
    let sample_width = rect.x1 - rect.x0 + 1;
    let count = (sample_width * (rect.y1 - rect.y0 + 1)) as usize;
    depth.clear();
    depth.resize(count, f32::INFINITY);
    visible.clear();
    visible.resize(count, u32::MAX);
    for (slot, &index) in bin.iter().enumerate() {
        primitives[index as usize]
            .setup
            .for_each_covered(rect, |x, y, z| {
                let k = ((y - rect.y0) * sample_width + (x - rect.x0)) as usize;
                if z < depth[k] {
                    depth[k] = z;
                    visible[k] = slot as u32;
                }
            });
    }
}

/// The weights of the vertices' attributes at a sample, from its screen-space weights (in
/// any common scale: the sum normalises them). Perspective-correct: attributes are affine in
/// world space, so their values over `w` are affine on screen.
fn perspective_weights(primitive: &Primitive, screen_weights: [f32; 3]) -> [f32; 3] {
    let over_w: [f32; 3] = core::array::from_fn(|k| screen_weights[k] * primitive.inverse_w[k]);
    let inverse_sum = 1.0 / (over_w[0] + over_w[1] + over_w[2]);
    over_w.map(|w| w * inverse_sum)
}

/// `sum_k weights[k] field(vertex k)`.
fn blend(primitive: &Primitive, weights: [f32; 3], field: fn(&Varyings) -> Vec3) -> Vec3 {
    let v = &primitive.varyings;
    weights[0] * field(&v[0]) + weights[1] * field(&v[1]) + weights[2] * field(&v[2])
}
