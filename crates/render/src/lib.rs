//! # specula-render: geometry for the CPU renderer
//!
//! Built on the core (`specula`): meshes with validated data, the built-in shapes (sphere,
//! torus, plane) and Newell's teapot tessellated from its Bezier patches. Everything here is
//! `f32`, the renderer's arithmetic; positions are in world units, normals unit length.

mod mesh;
mod shapes;
mod teapot;

pub use mesh::{Mesh, MeshError};
pub use shapes::{plane, sphere, torus};
pub use teapot::{teapot, BezierPatch, TEAPOT_PATCHES};
