// Evaluates one lobe over a batch of cosines. Needs the generated lobe library (wgsl::lobes).

@group(0) @binding(0) var<uniform> lobe: Lobe;
@group(0) @binding(1) var<storage, read> cosines: array<f32>;
@group(0) @binding(2) var<storage, read_write> values: array<f32>;

@compute @workgroup_size(64)
fn evaluate(@builtin(global_invocation_id) id: vec3<u32>) {
    let i = id.x + id.y * 65535u * 64u;
    if i < arrayLength(&cosines) {
        values[i] = lobe_eval(lobe, cosines[i]);
    }
}
