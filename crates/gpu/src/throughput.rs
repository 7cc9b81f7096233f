//! How fast a GPU evaluates a lobe: a compute shader in which every invocation evaluates the
//! exported lobe (constants baked in, as a material's shader has them) at [`CHAIN`] cosines
//! in sequence and sums the values. The sum is written only when it equals an impossible value,
//! so no driver can drop the work, and almost nothing is written. The dispatch grows until it
//! takes [`LONG_ENOUGH`], so the same code measures lavapipe and a data-centre GPU; at that
//! length the submission and the 4-byte read-back inside the timed wall time are noise.

use std::time::{Duration, Instant};

use specula::{Geometry, Lobe, Normalisation};
use wgpu::util::DeviceExt;

use crate::context::{Gpu, GpuError};
use crate::export::export_wgsl_source;

/// Lobe evaluations per invocation.
pub const CHAIN: u32 = 256;
const WORKGROUP: u32 = 256;
/// A dispatch this long is timed; shorter ones are doubled.
const LONG_ENOUGH: Duration = Duration::from_millis(20);
/// The largest dispatch tried, in workgroups (2^18 x 256 x 256 = 2^34 evaluations).
const MOST_WORKGROUPS: u32 = 1 << 18;
/// Rows of workgroups are at most this long (WebGPU's per-dimension limit).
const ROW: u32 = 32_768;

/// The step between an invocation's cosines, and between invocations' starting cosines.
const STEP: f32 = 1.0 / 65_536.0;

/// A lobe's measured throughput on the GPU.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LobeThroughput {
    /// Lobe evaluations per second (each with one add into the sum and one subtract for the
    /// next cosine, which every lobe pays alike).
    pub evals_per_second: f64,
    /// Evaluations in the timed dispatch.
    pub evaluations: u64,
    /// The best of the timed dispatches.
    pub time: Duration,
    /// Their median: with the best, the spread of a rate (a run whose spreads overlap
    /// another's cannot tell the two apart).
    pub median: Duration,
}

impl LobeThroughput {
    /// Evaluations per second at the median dispatch.
    #[must_use]
    pub fn median_evals_per_second(&self) -> f64 {
        self.evaluations as f64 / self.median.as_secs_f64()
    }
}

/// Timed dispatches per lobe, after the size is found.
pub const TIMED: usize = 9;

/// The benchmark's WGSL: the exported lobe and an entry point `throughput`.
#[must_use]
pub fn throughput_source(lobe: &Lobe) -> String {
    format!(
        "{}
@group(0) @binding(0) var<storage, read_write> specula_sums: array<f32>;

@compute @workgroup_size({WORKGROUP})
fn throughput(@builtin(global_invocation_id) id: vec3<u32>) {{
    let invocation = id.x + id.y * {ROW}u * {WORKGROUP}u;
    var t = 1.0 - f32(invocation & 1023u) * {STEP:e};
    var sum = 0.0;
    for (var k = 0u; k < {CHAIN}u; k++) {{
        sum += specula_lobe(t);
        t -= {STEP:e};
    }}
    if sum == -1.0 || invocation == 0u {{
        specula_sums[0] = sum;
    }}
}}
",
        export_wgsl_source(lobe, Geometry::Phong, Normalisation::None)
    )
}

/// The sum invocation 0 computes, in `f32` on the CPU, for checking that the shader did the
/// work it is timed for.
#[must_use]
pub fn first_invocation_sum(lobe: &Lobe) -> f32 {
    let mut t = 1.0_f32;
    let mut sum = 0.0_f32;
    for _ in 0..CHAIN {
        sum += lobe.eval(t);
        t -= STEP;
    }
    sum
}

/// Compiles and times `lobe`'s throughput shader; also returns invocation 0's sum.
pub fn measure(gpu: &Gpu, lobe: &Lobe) -> Result<(LobeThroughput, f32), GpuError> {
    let device = &gpu.device;
    let (pipeline, sums, readback, bind_group) = gpu.checked(|| {
        let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("specula throughput"),
            source: wgpu::ShaderSource::Wgsl(throughput_source(lobe).into()),
        });
        let pipeline = device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
            label: Some("specula throughput"),
            layout: None,
            module: &module,
            entry_point: Some("throughput"),
            compilation_options: wgpu::PipelineCompilationOptions::default(),
            cache: None,
        });
        let sums = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("sums"),
            contents: bytemuck::bytes_of(&0.0_f32),
            usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC,
        });
        let readback = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("sums readback"),
            size: 4,
            usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let bind_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("throughput"),
            layout: &pipeline.get_bind_group_layout(0),
            entries: &[wgpu::BindGroupEntry {
                binding: 0,
                resource: sums.as_entire_binding(),
            }],
        });
        (pipeline, sums, readback, bind_group)
    })?;
    let dispatch = |workgroups: u32| -> Result<Duration, GpuError> {
        let started = Instant::now();
        gpu.checked(|| {
            let mut encoder =
                device.create_command_encoder(&wgpu::CommandEncoderDescriptor::default());
            {
                let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor::default());
                pass.set_pipeline(&pipeline);
                pass.set_bind_group(0, &bind_group, &[]);
                pass.dispatch_workgroups(workgroups.min(ROW), workgroups.div_ceil(ROW), 1);
            }
            encoder.copy_buffer_to_buffer(&sums, 0, &readback, 0, 4);
            gpu.queue.submit([encoder.finish()]);
        })?;
        gpu.read_buffer(&readback)?;
        Ok(started.elapsed())
    };
    dispatch(1)?;
    let mut workgroups = 1;
    while workgroups < MOST_WORKGROUPS && dispatch(workgroups)? < LONG_ENOUGH {
        workgroups *= 2;
    }
    let mut times = (0..TIMED)
        .map(|_| dispatch(workgroups))
        .collect::<Result<Vec<_>, _>>()?;
    times.sort();
    let (time, median) = (times[0], times[TIMED / 2]);
    let bytes = gpu.read_buffer(&readback)?;
    let first = f32::from_le_bytes([bytes[0], bytes[1], bytes[2], bytes[3]]);
    let evaluations = u64::from(workgroups) * u64::from(WORKGROUP) * u64::from(CHAIN);
    Ok((
        LobeThroughput {
            evals_per_second: evaluations as f64 / time.as_secs_f64(),
            evaluations,
            time,
            median,
        },
        first,
    ))
}
