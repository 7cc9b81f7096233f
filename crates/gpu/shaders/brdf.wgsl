// Geometry, lights and the two illumination models: a transcription of crates/render's
// `Shader::shade` (see crates/render/src/material.rs for the formulas). Needs the generated
// lobe library (wgsl::lobes) and geometry.wgsl, and a `lights` array declared by the entry
// points' module.

struct Material {
    // ka colour.
    ambient: vec3<f32>,
    // 0: Phong (t = R.V), 1: Blinn (t = N.H).
    geometry: u32,
    // kd colour (over pi in the physical model).
    diffuse: vec3<f32>,
    // 0: classic, 1: physical.
    model: u32,
    // ks specular colour N(n).
    specular: vec3<f32>,
    padding: u32,
    lobe: Lobe,
}

struct Light {
    // A point light's position, or the unit direction towards a directional light.
    position: vec3<f32>,
    // 0: directional, 1: point.
    kind: u32,
    intensity: vec3<f32>,
    padding: u32,
}

// Radiance leaving `position` towards `wo` for a unit `normal`, under `light_count` lights.
fn shade(
    material: Material,
    position: vec3<f32>,
    normal: vec3<f32>,
    wo: vec3<f32>,
    ambient: vec3<f32>,
    light_count: u32,
) -> vec3<f32> {
    var radiance = material.ambient * ambient;
    if dot(normal, wo) <= 0.0 {
        return radiance;
    }
    for (var i = 0u; i < light_count; i++) {
        let light = lights[i];
        var wi = light.position;
        var intensity = light.intensity;
        if light.kind == 1u {
            let offset = light.position - position;
            let distance_squared = dot(offset, offset);
            if distance_squared <= 0.0 {
                continue;
            }
            if material.model == 1u {
                // The inverse square stops growing inside 1e-4 units (Rust's MIN_DISTANCE_SQUARED).
                intensity = intensity / max(distance_squared, 1e-8);
            }
            wi = offset / sqrt(distance_squared);
        }
        let cos_in = dot(normal, wi);
        if cos_in <= 0.0 {
            continue;
        }
        let lobe = lobe_eval(material.lobe, cos_lobe(material.geometry, normal, wo, wi));
        if material.model == 0u {
            radiance += intensity * (material.diffuse * cos_in + material.specular * lobe);
        } else {
            radiance += intensity * (material.diffuse + material.specular * lobe) * cos_in;
        }
    }
    return radiance;
}
