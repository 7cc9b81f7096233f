// The render pipeline: flat, Gouraud and Phong shading of crates/render, on the GPU.
// Needs the generated lobe library (wgsl::lobes) and brdf.wgsl. Flat shading draws unindexed
// triangles whose three vertices carry the face normal and the centroid (`anchor`), so each
// face gets one colour, lit at its centroid as on the CPU.

struct Frame {
    view_projection: mat4x4<f32>,
    eye: vec3<f32>,
    orthographic: u32,
    // Unit direction from the target to the eye: the orthographic camera's `wo`.
    backwards: vec3<f32>,
    light_count: u32,
    ambient: vec3<f32>,
    // 0: flat, 1: Gouraud, 2: Phong.
    shading: u32,
}

@group(0) @binding(0) var<uniform> frame: Frame;
@group(0) @binding(1) var<storage, read> lights: array<Light>;
@group(1) @binding(0) var<uniform> material: Material;

struct VertexIn {
    @location(0) position: vec3<f32>,
    @location(1) normal: vec3<f32>,
    @location(2) anchor: vec3<f32>,
}

struct VertexOut {
    @builtin(position) clip: vec4<f32>,
    @location(0) position: vec3<f32>,
    @location(1) normal: vec3<f32>,
    @location(2) colour: vec3<f32>,
}

fn towards_viewer(position: vec3<f32>) -> vec3<f32> {
    if frame.orthographic != 0u {
        return frame.backwards;
    }
    let offset = frame.eye - position;
    let length_squared = dot(offset, offset);
    if length_squared > 0.0 {
        return offset / sqrt(length_squared);
    }
    return frame.backwards;
}

fn shade_at(position: vec3<f32>, normal: vec3<f32>) -> vec3<f32> {
    return shade(material, position, normal, towards_viewer(position), frame.ambient, frame.light_count);
}

@vertex
fn vs_main(vertex: VertexIn) -> VertexOut {
    var out: VertexOut;
    out.clip = frame.view_projection * vec4<f32>(vertex.position, 1.0);
    out.position = vertex.position;
    out.normal = vertex.normal;
    out.colour = vec3<f32>(0.0);
    if frame.shading == 0u {
        out.colour = shade_at(vertex.anchor, vertex.normal);
    } else if frame.shading == 1u {
        out.colour = shade_at(vertex.position, vertex.normal);
    }
    return out;
}

@fragment
fn fs_main(in: VertexOut) -> @location(0) vec4<f32> {
    // The geometric normal, for an interpolated normal that vanishes (opposite vertex normals).
    let face = cross(dpdx(in.position), dpdy(in.position));
    if frame.shading != 2u {
        return vec4<f32>(in.colour, 1.0);
    }
    var normal = in.normal;
    let length_squared = dot(normal, normal);
    if length_squared > 0.0 {
        normal = normal / sqrt(length_squared);
    } else {
        normal = normalize(face);
        if dot(normal, towards_viewer(in.position)) < 0.0 {
            normal = -normal;
        }
    }
    return vec4<f32>(shade_at(in.position, normal), 1.0);
}
