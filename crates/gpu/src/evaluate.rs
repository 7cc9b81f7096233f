//! Lobes evaluated by a compute shader, over batches of cosines: the GPU's `f32` arithmetic
//! measured against the core's `f64` reference (`specula analyze --backend gpu`).

use specula::analysis::Evaluator;
use specula::Lobe;
use wgpu::util::DeviceExt;

use crate::uniforms::LobeBlock;
use crate::{wgsl, Gpu, GpuError};

const WORKGROUP: u32 = 64;
/// Workgroups per dispatch row (WebGPU's per-dimension limit).
const ROW: u32 = 65_535;

/// The compiled compute pipeline.
#[derive(Debug)]
pub struct LobeEvaluator<'gpu> {
    gpu: &'gpu Gpu,
    pipeline: wgpu::ComputePipeline,
}

impl<'gpu> LobeEvaluator<'gpu> {
    /// Compiles the compute shader on `gpu`.
    pub fn new(gpu: &'gpu Gpu) -> Result<Self, GpuError> {
        gpu.checked(|| {
            let module = gpu.device.create_shader_module(wgpu::ShaderModuleDescriptor {
                label: Some("specula evaluate"),
                source: wgpu::ShaderSource::Wgsl(wgsl::evaluate_module().into()),
            });
            let pipeline = gpu.device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
                label: Some("specula evaluate"),
                layout: None,
                module: &module,
                entry_point: Some("evaluate"),
                compilation_options: wgpu::PipelineCompilationOptions::default(),
                cache: None,
            });
            Self { gpu, pipeline }
        })
    }

    /// The lobe at each cosine, computed on the GPU in `f32`.
    pub fn eval(&self, lobe: &Lobe, cosines: &[f32]) -> Result<Vec<f32>, GpuError> {
        if cosines.is_empty() {
            return Ok(Vec::new());
        }
        let device = &self.gpu.device;
        let bytes = std::mem::size_of_val(cosines) as u64;
        let limit = device.limits().max_storage_buffer_binding_size;
        if bytes > limit {
            return Err(GpuError::Unsupported(format!(
                "{} cosines need {bytes} bytes; the adapter binds at most {limit}",
                cosines.len()
            )));
        }
        let (output, readback) = self.gpu.checked(|| {
            let uniform = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some("lobe"),
                contents: bytemuck::bytes_of(&LobeBlock::new(lobe)),
                usage: wgpu::BufferUsages::UNIFORM,
            });
            let input = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some("cosines"),
                contents: bytemuck::cast_slice(cosines),
                usage: wgpu::BufferUsages::STORAGE,
            });
            let output = device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("values"),
                size: bytes,
                usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC,
                mapped_at_creation: false,
            });
            let readback = device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("values readback"),
                size: bytes,
                usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            });
            let bind_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
                label: Some("evaluate"),
                layout: &self.pipeline.get_bind_group_layout(0),
                entries: &[
                    wgpu::BindGroupEntry {
                        binding: 0,
                        resource: uniform.as_entire_binding(),
                    },
                    wgpu::BindGroupEntry {
                        binding: 1,
                        resource: input.as_entire_binding(),
                    },
                    wgpu::BindGroupEntry {
                        binding: 2,
                        resource: output.as_entire_binding(),
                    },
                ],
            });
            let groups = (cosines.len() as u32).div_ceil(WORKGROUP);
            let mut encoder = device.create_command_encoder(&wgpu::CommandEncoderDescriptor::default());
            {
                let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor::default());
                pass.set_pipeline(&self.pipeline);
                pass.set_bind_group(0, &bind_group, &[]);
                pass.dispatch_workgroups(groups.min(ROW), groups.div_ceil(ROW), 1);
            }
            encoder.copy_buffer_to_buffer(&output, 0, &readback, 0, bytes);
            self.gpu.queue.submit([encoder.finish()]);
            (output, readback)
        })?;
        let values = self.gpu.read_buffer(&readback)?;
        drop(output);
        Ok(bytemuck::cast_slice(&values).to_vec())
    }
}

/// The GPU as an [`Evaluator`] of the core's analysis: cosines rounded to `f32`, as an `f32`
/// pipeline sees them, values widened back. A GPU failure mid-analysis cannot be reported
/// through the trait, so it is kept and the values are NaN; check [`GpuEvaluator::error`].
#[derive(Debug)]
pub struct GpuEvaluator<'gpu> {
    evaluator: LobeEvaluator<'gpu>,
    error: Option<GpuError>,
}

impl<'gpu> GpuEvaluator<'gpu> {
    /// Wraps a compiled evaluator.
    #[must_use]
    pub fn new(evaluator: LobeEvaluator<'gpu>) -> Self {
        Self {
            evaluator,
            error: None,
        }
    }

    /// The first GPU failure, if there was one.
    pub fn error(&mut self) -> Option<GpuError> {
        self.error.take()
    }
}

impl Evaluator for GpuEvaluator<'_> {
    fn name(&self) -> &'static str {
        "gpu"
    }

    fn eval_batch(&mut self, lobe: &Lobe, cosines: &[f64]) -> Vec<f64> {
        let narrow: Vec<f32> = cosines.iter().map(|&t| t as f32).collect();
        match self.evaluator.eval(lobe, &narrow) {
            Ok(values) => values.into_iter().map(f64::from).collect(),
            Err(error) => {
                self.error.get_or_insert(error);
                vec![f64::NAN; cosines.len()]
            }
        }
    }
}
