//! The headless GPU renderer: the scenes of `specula-render`, drawn by wgpu.
//!
//! The image is rendered at `samples` times the resolution into an `Rgba32Float` target,
//! read back and box-filtered on the CPU, exactly as the CPU renderer filters its samples, so
//! the two backends differ only in rasterization and arithmetic details.

use std::sync::{Arc, Mutex, PoisonError};

use glam::Vec3;
use specula_render::{Image, Scene};

use crate::context::{Gpu, GpuError};
use crate::wgsl::{self, FunctionKey};

pub(crate) const COLOUR_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba32Float;
pub(crate) const DEPTH_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Depth32Float;
/// Position, normal, anchor: nine floats per vertex.
pub(crate) const VERTEX_FLOATS: usize = 9;

/// The render pipelines of one GPU: one per scene's set of lobes and culling mode, compiled
/// when a scene first needs it ([`wgsl::render_module_for`]: a material's shader holds the
/// lobes it draws, not every lobe) and kept for the renderer's life, as an engine keeps its
/// shader permutations.
#[derive(Debug)]
pub struct GpuRenderer<'gpu> {
    pub(crate) gpu: &'gpu Gpu,
    pipelines: Mutex<Vec<(PipelineKey, Arc<wgpu::RenderPipeline>)>>,
}

/// The lobes a pipeline's module holds (sorted, each once) and whether it culls back faces.
type PipelineKey = (Vec<FunctionKey>, bool);

impl<'gpu> GpuRenderer<'gpu> {
    /// The renderer for `gpu`; each scene's pipeline is compiled when first drawn.
    #[must_use]
    pub fn new(gpu: &'gpu Gpu) -> Self {
        Self {
            gpu,
            pipelines: Mutex::new(Vec::new()),
        }
    }

    /// The pipeline for materials whose lobes are `keys` (sorted, each once).
    pub(crate) fn pipeline(
        &self,
        keys: &[FunctionKey],
        cull_back_faces: bool,
    ) -> Result<Arc<wgpu::RenderPipeline>, GpuError> {
        let compiled = || {
            self.pipelines
                .lock()
                .unwrap_or_else(PoisonError::into_inner)
        };
        let known = |(key, _): &&(PipelineKey, _)| key.0 == keys && key.1 == cull_back_faces;
        if let Some((_, pipeline)) = compiled().iter().find(known) {
            return Ok(Arc::clone(pipeline));
        }
        let pipeline = Arc::new(self.compile(keys, cull_back_faces)?);
        let mut compiled = compiled();
        // Another thread may have compiled the same pipeline meanwhile: keep the first.
        if let Some((_, known)) = compiled.iter().find(known) {
            return Ok(Arc::clone(known));
        }
        compiled.push(((keys.to_vec(), cull_back_faces), Arc::clone(&pipeline)));
        Ok(pipeline)
    }

    fn compile(
        &self,
        keys: &[FunctionKey],
        cull_back_faces: bool,
    ) -> Result<wgpu::RenderPipeline, GpuError> {
        let gpu = self.gpu;
        gpu.checked(|| {
            let module = gpu
                .device
                .create_shader_module(wgpu::ShaderModuleDescriptor {
                    label: Some("specula render"),
                    source: wgpu::ShaderSource::Wgsl(wgsl::render_module_for(keys).into()),
                });
            gpu.device
                .create_render_pipeline(&wgpu::RenderPipelineDescriptor {
                    label: Some("specula render"),
                    layout: None,
                    vertex: wgpu::VertexState {
                        module: &module,
                        entry_point: Some("vs_main"),
                        compilation_options: wgpu::PipelineCompilationOptions::default(),
                        buffers: &[Some(wgpu::VertexBufferLayout {
                            array_stride: (VERTEX_FLOATS * 4) as u64,
                            step_mode: wgpu::VertexStepMode::Vertex,
                            attributes: &wgpu::vertex_attr_array![
                                0 => Float32x3, 1 => Float32x3, 2 => Float32x3
                            ],
                        })],
                    },
                    primitive: wgpu::PrimitiveState {
                        topology: wgpu::PrimitiveTopology::TriangleList,
                        front_face: wgpu::FrontFace::Ccw,
                        cull_mode: cull_back_faces.then_some(wgpu::Face::Back),
                        ..wgpu::PrimitiveState::default()
                    },
                    depth_stencil: Some(wgpu::DepthStencilState {
                        format: DEPTH_FORMAT,
                        depth_write_enabled: Some(true),
                        depth_compare: Some(wgpu::CompareFunction::Less),
                        stencil: wgpu::StencilState::default(),
                        bias: wgpu::DepthBiasState::default(),
                    }),
                    multisample: wgpu::MultisampleState::default(),
                    fragment: Some(wgpu::FragmentState {
                        module: &module,
                        entry_point: Some("fs_main"),
                        compilation_options: wgpu::PipelineCompilationOptions::default(),
                        targets: &[Some(COLOUR_FORMAT.into())],
                    }),
                    multiview_mask: None,
                    cache: None,
                })
        })
    }

    /// Refuses sizes the CPU renderer refuses or the adapter cannot hold.
    pub(crate) fn check_size(&self, settings: &specula_render::Settings) -> Result<(), GpuError> {
        settings
            .validate()
            .map_err(|e| GpuError::Unsupported(e.to_string()))?;
        let limit = self.gpu.device.limits().max_texture_dimension_2d;
        let largest = settings.width.max(settings.height) * settings.samples;
        if largest > limit {
            return Err(GpuError::Unsupported(format!(
                "{largest} samples per side exceed this adapter's largest texture side, {limit}"
            )));
        }
        Ok(())
    }

    /// Renders `scene` and reads the image back (a renderer drawing it again would keep the
    /// `GpuFrame` from [`prepare`](Self::prepare)).
    pub fn render(&self, scene: &Scene) -> Result<Image, GpuError> {
        self.prepare(scene)?.image()
    }
}

/// Box-filters the `samples x samples` blocks of the read-back `Rgba32Float` rows.
pub(crate) fn downsample(
    bytes: &[u8],
    row_bytes: usize,
    width: u32,
    height: u32,
    samples: u32,
) -> Image {
    let texel = |x: u32, y: u32| {
        let offset = y as usize * row_bytes + x as usize * 16;
        let channel = |k: usize| {
            let at = offset + 4 * k;
            f32::from_le_bytes([bytes[at], bytes[at + 1], bytes[at + 2], bytes[at + 3]])
        };
        Vec3::new(channel(0), channel(1), channel(2))
    };
    let scale = 1.0 / (samples * samples) as f32;
    let mut image = Image::new(width, height, Vec3::ZERO);
    for y in 0..height {
        for x in 0..width {
            let mut sum = Vec3::ZERO;
            for sy in 0..samples {
                for sx in 0..samples {
                    sum += texel(x * samples + sx, y * samples + sy);
                }
            }
            image.set(x, y, sum * scale);
        }
    }
    image
}
