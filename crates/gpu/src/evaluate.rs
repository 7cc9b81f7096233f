//! Lobes evaluated by a compute shader, over batches of cosines: the GPU's `f32` arithmetic
//! measured against the core's `f64` reference (`specula analyze --backend gpu`).

use specula::analysis::Evaluator;
use specula::Lobe;
use wgpu::util::DeviceExt;

use crate::context::{Gpu, GpuError};
use crate::uniforms::LobeBlock;
use crate::wgsl;

const WORKGROUP: u32 = 64;
/// Workgroups per dispatch row (WebGPU's per-dimension limit).
const ROW: u32 = 65_535;

/// A compiled compute shader with entry point `evaluate` over `array<f32>` inputs (binding 1)
/// and outputs (binding 2), optionally with a uniform at binding 0.
#[derive(Debug)]
struct Kernel {
    pipeline: wgpu::ComputePipeline,
}

impl Kernel {
    fn new(gpu: &Gpu, source: String) -> Result<Self, GpuError> {
        gpu.checked(|| {
            let module = gpu
                .device
                .create_shader_module(wgpu::ShaderModuleDescriptor {
                    label: Some("specula evaluate"),
                    source: wgpu::ShaderSource::Wgsl(source.into()),
                });
            let pipeline = gpu
                .device
                .create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
                    label: Some("specula evaluate"),
                    layout: None,
                    module: &module,
                    entry_point: Some("evaluate"),
                    compilation_options: wgpu::PipelineCompilationOptions::default(),
                    cache: None,
                });
            Self { pipeline }
        })
    }

    fn run(&self, gpu: &Gpu, uniform: Option<&[u8]>, inputs: &[f32]) -> Result<Vec<f32>, GpuError> {
        if inputs.is_empty() {
            return Ok(Vec::new());
        }
        let device = &gpu.device;
        let bytes = std::mem::size_of_val(inputs) as u64;
        let limit = device.limits().max_storage_buffer_binding_size;
        if bytes > limit {
            return Err(GpuError::Unsupported(format!(
                "{} inputs need {bytes} bytes; the adapter binds at most {limit}",
                inputs.len()
            )));
        }
        let readback = gpu.checked(|| {
            let uniform = uniform.map(|contents| {
                device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                    label: Some("uniform"),
                    contents,
                    usage: wgpu::BufferUsages::UNIFORM,
                })
            });
            let input = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some("inputs"),
                contents: bytemuck::cast_slice(inputs),
                usage: wgpu::BufferUsages::STORAGE,
            });
            let output = device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("outputs"),
                size: bytes,
                usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC,
                mapped_at_creation: false,
            });
            let readback = device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("outputs readback"),
                size: bytes,
                usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            });
            let mut entries = vec![
                wgpu::BindGroupEntry {
                    binding: 1,
                    resource: input.as_entire_binding(),
                },
                wgpu::BindGroupEntry {
                    binding: 2,
                    resource: output.as_entire_binding(),
                },
            ];
            if let Some(uniform) = &uniform {
                entries.push(wgpu::BindGroupEntry {
                    binding: 0,
                    resource: uniform.as_entire_binding(),
                });
            }
            let bind_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
                label: Some("evaluate"),
                layout: &self.pipeline.get_bind_group_layout(0),
                entries: &entries,
            });
            let groups = (inputs.len() as u32).div_ceil(WORKGROUP);
            let mut encoder =
                device.create_command_encoder(&wgpu::CommandEncoderDescriptor::default());
            {
                let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor::default());
                pass.set_pipeline(&self.pipeline);
                pass.set_bind_group(0, &bind_group, &[]);
                pass.dispatch_workgroups(groups.min(ROW), groups.div_ceil(ROW), 1);
            }
            encoder.copy_buffer_to_buffer(&output, 0, &readback, 0, bytes);
            gpu.queue.submit([encoder.finish()]);
            readback
        })?;
        let values = gpu.read_buffer(&readback)?;
        Ok(values
            .chunks_exact(4)
            .map(|b| f32::from_le_bytes([b[0], b[1], b[2], b[3]]))
            .collect())
    }
}

/// The lobe library's compute shader, compiled.
#[derive(Debug)]
pub struct LobeEvaluator<'gpu> {
    gpu: &'gpu Gpu,
    kernel: Kernel,
}

impl<'gpu> LobeEvaluator<'gpu> {
    /// Compiles the compute shader on `gpu`.
    pub fn new(gpu: &'gpu Gpu) -> Result<Self, GpuError> {
        Ok(Self {
            gpu,
            kernel: Kernel::new(gpu, wgsl::evaluate_module())?,
        })
    }

    /// The lobe at each cosine, computed on the GPU in `f32`.
    pub fn eval(&self, lobe: &Lobe, cosines: &[f32]) -> Result<Vec<f32>, GpuError> {
        let block = LobeBlock::new(lobe);
        self.kernel
            .run(self.gpu, Some(bytemuck::bytes_of(&block)), cosines)
    }
}

/// Runs `function: fn(f32) -> f32` of the WGSL `source` on the GPU over `inputs` (for
/// checking generated code, such as an exported lobe, by executing it).
pub fn evaluate_wgsl_function(
    gpu: &Gpu,
    source: &str,
    function: &str,
    inputs: &[f32],
) -> Result<Vec<f32>, GpuError> {
    let source = format!(
        "{source}
@group(0) @binding(1) var<storage, read> specula_inputs: array<f32>;
@group(0) @binding(2) var<storage, read_write> specula_outputs: array<f32>;

@compute @workgroup_size(64)
fn evaluate(@builtin(global_invocation_id) id: vec3<u32>) {{
    let i = id.x + id.y * 65535u * 64u;
    if i < arrayLength(&specula_inputs) {{
        specula_outputs[i] = {function}(specula_inputs[i]);
    }}
}}
"
    );
    Kernel::new(gpu, source)?.run(gpu, None, inputs)
}

/// The GPU as an [`Evaluator`] of the core's analysis: cosines rounded to `f32`, as an `f32`
/// pipeline sees them, values widened back. A GPU failure mid-analysis cannot be reported
/// through the trait, so it is kept and the values are NaN; check [`GpuEvaluator::error`].
#[derive(Debug)]
pub struct GpuEvaluator<'a> {
    evaluator: &'a LobeEvaluator<'a>,
    error: Option<GpuError>,
}

impl<'a> GpuEvaluator<'a> {
    /// Wraps a compiled evaluator (shareable between threads: one wrapper per thread).
    #[must_use]
    pub fn new(evaluator: &'a LobeEvaluator<'a>) -> Self {
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

    fn evaluate(&mut self, lobe: &Lobe, cosines: &[f64]) -> Vec<f64> {
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
