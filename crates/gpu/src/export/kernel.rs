//! The lobe as a compute kernel in SPIR-V, the source AMD's compiler is given (`specula-isa`
//! runs Mesa's RADV on it): the export's module with an entry point that reads `input[i]` and
//! writes `output[i]`, one evaluation per thread, as the CUDA C and OpenCL C kernels of
//! [`specula_targets::compute`] do for NVIDIA's and Intel's compilers.

use specula::{Geometry, Lobe, Normalisation};
use specula_targets::compute::{Work, KERNEL};

use super::{export_wgsl_source, ExportError};
use crate::wgsl;

/// The threads a workgroup of the kernel has.
pub const WORKGROUP_SIZE: u32 = 64;

/// The WGSL of `lobe`'s compute kernel computing `work`.
#[must_use]
pub fn compute_kernel_wgsl(lobe: &Lobe, work: Work) -> String {
    let (geometry, normalisation) = match work {
        Work::Shading(geometry, normalisation) => (geometry, normalisation),
        Work::Lobe | Work::Baseline => (Geometry::Phong, Normalisation::None),
    };
    let mut source = match work {
        Work::Baseline => String::new(),
        _ => export_wgsl_source(lobe, geometry, normalisation)
            .split("@fragment")
            .next()
            .unwrap_or_default()
            .to_owned(),
    };
    let body = match work {
        Work::Lobe => "output[i] = specula_lobe(input[i]);",
        Work::Shading(..) => {
            "let v = 9u * i;
    output[i] = specula_specular(
        vec3<f32>(input[v], input[v + 1u], input[v + 2u]),
        vec3<f32>(input[v + 3u], input[v + 4u], input[v + 5u]),
        vec3<f32>(input[v + 6u], input[v + 7u], input[v + 8u]),
    );"
        }
        Work::Baseline => "output[i] = input[i];",
    };
    source.push_str(&format!(
        "
@group(0) @binding(0) var<storage, read> input: array<f32>;
@group(0) @binding(1) var<storage, read_write> output: array<f32>;

@compute @workgroup_size({WORKGROUP_SIZE})
fn {KERNEL}(@builtin(global_invocation_id) id: vec3<u32>) {{
    let i = id.x;
    {body}
}}
"
    ));
    source
}

/// `lobe`'s compute kernel computing `work`, as naga writes it in SPIR-V.
pub fn compute_kernel_spirv(lobe: &Lobe, work: Work) -> Result<Vec<u32>, ExportError> {
    let source = compute_kernel_wgsl(lobe, work);
    let fail = |message: String| ExportError {
        language: "spirv",
        message,
    };
    let (mut module, _) = wgsl::validate(&source).map_err(fail)?;
    naga::compact::compact(&mut module, naga::compact::KeepUnused::No);
    let info = naga::valid::Validator::new(
        naga::valid::ValidationFlags::all(),
        naga::valid::Capabilities::all(),
    )
    .validate(&module)
    .map_err(|e| fail(e.emit_to_string(&source)))?;
    naga::back::spv::write_vec(&module, &info, &naga::back::spv::Options::default(), None)
        .map_err(|e| fail(e.to_string()))
}
