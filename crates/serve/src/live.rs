//! The views the browser draws itself (`assets/live.js`, WebGL2): each lobe's GLSL ES 3.00
//! function from the shader export (`specula shader --lang glsl --glsl-version 300es`), and
//! the one lit sphere both sides draw, described here once.
//!
//! - `GET /api/shader?lobe&n&geometry&normalisation`: `{glsl, n_range, tonemap}`, the lobe's
//!   exported functions and the tone map the renders use with that normalisation. Where the
//!   lobe's constants and its normalisation are closed forms of `n`, the functions take it
//!   (`specula_specular(n, normal, wo, wi)`, `--n-input`) and `n_range` is the range they
//!   serve, so the page changes `n` as a uniform within it; elsewhere (`n_range` null) `n` is
//!   baked in (`specula_specular(normal, wo, wi)`) and a new `n` fetches new functions;
//! - `GET /api/microfacet?lobe&n`: `{normaliser, masking}`, what the microfacet model adds to
//!   the lobe at `n` ([`MicrofacetTerms`]: `C(n)` and the 64-entry `G1` table the renderers
//!   read), for the page's live microfacet shading, which draws the lobe's Blinn export as `D`;
//! - `GET /api/live-sphere?lobe&n&geometry&normalisation&model&light_theta&light_phi&size`:
//!   the sphere the page draws live, computed here per pixel with the renderer's shading
//!   ([`Shader::shade`]) and display encoding, as a PNG: what the browser check compares the
//!   WebGL image against, pixel by pixel.
//!
//! - `GET /api/teapot`: the explorer's teapot as `specula render` tessellates and places it
//!   (world-space positions, normals and triangles) with the renderer's camera matrix and eye,
//!   so the page rasterizes exactly the triangles the CPU renderer does.
//!
//! The sphere is analytic (a ray per pixel centre hits the unit sphere), not the renderer's
//! tessellated one, so that both sides draw exactly the same surface.

use axum::extract::State;
use axum::response::{IntoResponse, Response};
use axum::Json;
use glam::Vec3;
use serde_json::json;
use specula::{Geometry, Lobe, Normalisation};
use specula_gpu::export::{functions_taking_n_where_possible, Language};
use specula_render::{Display, IlluminationModel, Image, Light, Material, MicrofacetTerms, Shader};

use crate::api::{compute, compute_with, png, AppState};
use crate::explorer::{scene, Object, RenderRequest};
use crate::query::{pairs, ApiError, Params, QueryPairs};
use crate::scene_setup::{light_towards, tonemap_for, LIVE_SCENE};

/// The largest live-sphere reference, in pixels a side.
pub const MAX_LIVE_SIZE: u32 = 512;

/// What one live-sphere reference is drawn with.
#[derive(Clone, Copy, Debug)]
pub struct SphereRequest {
    pub geometry: Geometry,
    pub normalisation: Normalisation,
    pub model: IlluminationModel,
    /// Towards the light, unit.
    pub light: Vec3,
    pub size: u32,
}

/// The sphere's linear radiance per pixel, row-major from the top left: a ray through each
/// pixel centre, the first hit on the unit sphere shaded by the renderer's [`Shader`].
#[must_use]
pub fn sphere_radiance(lobe: Lobe, request: &SphereRequest) -> Vec<Vec3> {
    let scene = LIVE_SCENE;
    let material = Material {
        ka: scene.ka,
        kd: scene.kd,
        ks: scene.ks,
        colour: Vec3::from(scene.colour),
        specular_colour: Vec3::ONE,
        lobe,
        geometry: request.geometry,
        normalisation: request.normalisation,
    };
    let shader = Shader::new(&material, request.model);
    let lights = [Light::Directional {
        towards: request.light,
        intensity: Vec3::ONE,
    }];
    let eye = Vec3::new(0.0, -scene.eye_distance, 0.0);
    let half = (scene.fov_y_deg.to_radians() / 2.0).tan();
    let size = request.size as f32;
    let mut pixels = Vec::with_capacity((request.size * request.size) as usize);
    for row in 0..request.size {
        for column in 0..request.size {
            let x = (2.0 * (column as f32 + 0.5) / size - 1.0) * half;
            let z = (1.0 - 2.0 * (row as f32 + 0.5) / size) * half;
            let direction = Vec3::new(x, 1.0, z).normalize();
            pixels.push(match unit_sphere_hit(eye, direction) {
                Some(point) => {
                    shader.shade(point, point, -direction, &lights, Vec3::from(scene.ambient))
                }
                None => Vec3::from(scene.background),
            });
        }
    }
    pixels
}

/// Where the ray from `origin` along unit `direction` first meets the unit sphere.
fn unit_sphere_hit(origin: Vec3, direction: Vec3) -> Option<Vec3> {
    let b = origin.dot(direction);
    let discriminant = b * b - (origin.length_squared() - 1.0);
    (discriminant >= 0.0).then(|| origin + (-b - discriminant.sqrt()) * direction)
}

/// The reference sphere as an 8-bit sRGB PNG, tone mapped as the renders are.
pub fn sphere_png(lobe: Lobe, request: &SphereRequest) -> Result<Vec<u8>, String> {
    let pixels = sphere_radiance(lobe, request);
    let image = Image::from_pixels(request.size, request.size, pixels)
        .ok_or_else(|| "the sphere's pixels do not fill the image".to_owned())?;
    let display = Display {
        exposure: 1.0,
        tonemap: tonemap_for(request.normalisation),
    };
    specula_render::encode_png_srgb8(request.size, request.size, &image.to_srgb8(display))
        .map_err(|e| e.to_string())
}

/// `GET /api/shader`: the lobe's GLSL ES 3.00 functions and the tone map.
pub async fn shader(
    State(state): State<AppState>,
    query: QueryPairs,
) -> Result<Response, Response> {
    let params = Params::new(pairs(query)?, &["lobe", "n", "geometry", "normalisation"])?;
    let (kind, n) = (params.lobe()?, params.exponent()?);
    let (geometry, normalisation) = (
        params.geometry()?,
        params.normalisation(Normalisation::None)?,
    );
    let shader = compute_with(&state, kind, n, move |lobe| {
        functions_taking_n_where_possible(&lobe, geometry, normalisation, Language::Glsl)
    })
    .await?
    .map_err(|e| ApiError::internal(e.to_string()))?;
    Ok(Json(json!({
        "lobe": kind.to_string(),
        "n": n.get(),
        "glsl": shader.text,
        "n_range": shader.n_range,
        "tonemap": tonemap_for(normalisation).id(),
    }))
    .into_response())
}

/// `GET /api/microfacet`: the lobe's microfacet terms at `n`.
pub async fn microfacet(
    State(state): State<AppState>,
    query: QueryPairs,
) -> Result<Response, Response> {
    let params = Params::new(pairs(query)?, &["lobe", "n"])?;
    let (kind, n) = (params.lobe()?, params.exponent()?);
    let terms = compute_with(&state, kind, n, |lobe| MicrofacetTerms::new(&lobe, 1.0)).await?;
    Ok(Json(json!({
        "lobe": kind.to_string(),
        "n": n.get(),
        "normaliser": terms.normaliser(),
        "masking": terms.masking().to_vec(),
    }))
    .into_response())
}

/// What `/api/live-sphere` reads.
const SPHERE_PARAMETERS: [&str; 8] = [
    "lobe",
    "n",
    "geometry",
    "normalisation",
    "model",
    "light_theta",
    "light_phi",
    "size",
];

/// `GET /api/live-sphere`: the sphere the page draws live, drawn here.
pub async fn live_sphere(
    State(state): State<AppState>,
    query: QueryPairs,
) -> Result<Response, Response> {
    let params = Params::new(pairs(query)?, &SPHERE_PARAMETERS)?;
    let (kind, n) = (params.lobe()?, params.exponent()?);
    let (theta, phi) = params.light()?;
    let request = SphereRequest {
        geometry: params.geometry()?,
        normalisation: params.normalisation(Normalisation::None)?,
        model: params.model()?,
        light: Vec3::from(light_towards(theta, phi).map(|c| c as f32)),
        size: params.number("size", 16.0..=f64::from(MAX_LIVE_SIZE), 256.0)? as u32,
    };
    let encoded = compute_with(&state, kind, n, move |lobe| sphere_png(lobe, &request)).await?;
    Ok(png(encoded.map_err(ApiError::internal)?))
}

/// `GET /api/teapot`: the teapot's mesh in world space and the camera that sees it, from the
/// scene `/api/render?object=teapot` renders (its lobe, light and size do not change them).
pub async fn teapot(
    State(state): State<AppState>,
    query: QueryPairs,
) -> Result<Response, Response> {
    Params::new(pairs(query)?, &[])?;
    let body = compute(&state, teapot_body)
        .await?
        .map_err(ApiError::internal)?;
    Ok(Json(body).into_response())
}

fn teapot_body() -> Result<serde_json::Value, String> {
    let scene = scene(&RenderRequest {
        object: Object::Teapot,
        kind: specula::LobeKind::Pow,
        n: specula::Exponent::new(64.0),
        geometry: Geometry::Phong,
        normalisation: Normalisation::None,
        shading: specula_render::Shading::Phong,
        model: IlluminationModel::Classic,
        light_theta: 0.0,
        light_phi: 0.0,
        size: 64,
    })?;
    let mesh = &scene
        .objects
        .first()
        .ok_or("the teapot scene has no object")?
        .mesh;
    let flat = |vectors: &[Vec3]| {
        vectors
            .iter()
            .flat_map(|v| v.to_array())
            .collect::<Vec<_>>()
    };
    Ok(json!({
        "positions": flat(mesh.positions()),
        "normals": flat(mesh.normals()),
        "triangles": mesh.triangles().iter().flatten().collect::<Vec<_>>(),
        // Column-major, world to clip space (D3D's depth in [0, 1], which WebGL's clip space
        // contains), for a square image.
        "view_projection": scene.camera.view_projection(1.0).to_cols_array(),
        "eye": scene.camera.eye().to_array(),
        // Whether the renderer drops the faces clockwise on screen.
        "cull_back_faces": scene.settings.cull_back_faces,
    }))
}
