//! # specula-render: the CPU renderer
//!
//! Built on the core (`specula`): scenes (TOML, with an embedded default), meshes (built-in
//! shapes, Newell's teapot, OBJ/STL/PLY files), a tiled parallel rasterizer, flat, Gouraud and
//! Phong shading with any lobe, geometry and normalisation, images (PNG, OpenEXR) and image
//! metrics (PSNR, FLIP), and image-based lighting (environment maps, Monte Carlo with multiple
//! importance sampling). Volumes are `specula-volume`'s, which draws with these.
//!
//! ## Design
//! - **Exact coverage.** Vertices are snapped to 1/256 pixel and edge functions evaluated in
//!   integers with the top-left rule: shared edges neither gap nor overlap (`raster.rs`).
//! - **Deterministic parallelism.** Triangles are binned into 32x32 tiles; each tile resolves
//!   visibility in submission order with a strict depth test, then shades each visible sample
//!   once. Output is bit-identical for any thread count (`pipeline.rs`).
//! - **Linear until written.** The renderer produces linear radiance; exposure, tone map and
//!   the sRGB curve are applied only when a PNG is written (`image.rs`).
//! - **`f32` throughout**, with the core's lobes on their fast paths (Phong shading: the batch,
//!   SIMD path, a tile's samples at a time); each material's
//!   normalisation constant is computed once, in `f64`.
//! - Conventions: right-handed world, `z` up, counter-clockwise front faces, depth in
//!   `[0, 1]` (wgpu's), `wo` towards the viewer and `wi` towards the light.

mod buffers;
mod camera;
mod clip;
mod description;
mod grid;
pub mod ibl;
mod image;
mod image_error;
pub mod input;
mod load;
pub mod lobe_file;
mod material;
pub mod measured;
mod mesh;
pub mod metrics;
pub mod microfacet_scene;
mod microfacet_terms;
mod mitsuba_scene;
mod output;
mod phong;
mod pipeline;
mod raster;
mod scene;
mod shapes;
mod srgb8;
mod teapot;

pub use camera::{Camera, InvalidCamera, Projection, MAX_COORDINATE};
pub use description::{set_max_triangles, LoadedScene, SceneError, MAX_OBJECTS, MAX_TRIANGLES};
pub use grid::{
    check_grid, grid_renders, made_renders, render_grid, render_grid_columns, render_grid_with,
    Grid, GridColumn, GridError, GridOptions, Srgb8Image,
};
pub use image::{
    check_output_path, encode_png_srgb8, is_linear_output, read_image, write_image,
    write_png_srgb8, Display, Image, ToneMap, MAX_IMAGE_PIXELS,
};
pub use image_error::ImageError;
pub use load::{load_mesh, parse_mesh, LoadError, LoadedMesh, MeshFormat, MESH_EXTENSIONS};
pub use material::{IlluminationModel, Light, Material, Shader, Shading};
pub use mesh::{Mesh, MeshError};
pub use microfacet_terms::{MicrofacetTerms, MASKING_ENTRIES};
pub use mitsuba_scene::write_mitsuba_scene;
pub use output::{write_atomically, SeekWrite};
pub use pipeline::{
    overdraw, render, surfaces, RenderError, SurfacePoint, MAX_PIXELS, MAX_SAMPLES,
};
pub use scene::{Analytic, Object, Overrides, Scene, Settings, DEFAULT_SCENE, IBL_SCENE};
pub use shapes::{plane, sphere, torus};
pub use srgb8::{srgb_decode, srgb_encode};
pub use teapot::{teapot, BezierPatch, TEAPOT_PATCHES};
