//! # specula-gpu: the lobes on the GPU
//!
//! Every lobe, geometry, normalisation and shading method of the core and the CPU renderer,
//! written in WGSL and driven by wgpu: a headless renderer that draws the same scenes as
//! `specula-render`, a compute shader that evaluates any lobe over a batch of cosines, and
//! shader export to WGSL, GLSL, HLSL, MSL and SPIR-V through naga.
//!
//! ## Design
//! - **No transcription.** The lobe library is generated from each lobe's recorded
//!   expression (`lobe_library`): a function per shape of each lobe, a `switch` on the kind's
//!   index where Rust has its `match`, and the named parameters uploaded as the core
//!   prepared them in `f64`, so the GPU never re-derives anything and no lobe is typed twice.
//! - **Same images, measured.** The renderer uploads the materials exactly as the CPU's
//!   shader prepares them, supersamples at the same sample positions and box-filters on read
//!   back; parity tests compare the two images by FLIP and PSNR.
//! - **No GPU is not a crash.** Without an adapter, [`Gpu::new`] returns a [`GpuError`] that
//!   says how to get one (Mesa's lavapipe runs everything here on the CPU).

mod context;
mod evaluate;
pub mod export;
mod frame;
mod lobe_library;
mod render;
pub mod shader_ops;
pub mod throughput;
pub mod uniforms;
mod volume;
pub mod wgsl;

pub use context::{Gpu, GpuError};
pub use evaluate::{evaluate_wgsl_function, GpuEvaluator, LobeEvaluator};
pub use frame::{FrameTime, GpuFrame};
pub use render::GpuRenderer;
pub use volume::GpuVolumeRenderer;
