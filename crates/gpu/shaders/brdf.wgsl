// Geometry, lights and the three illumination models: a transcription of crates/render's
// `Shader::shade` (see crates/render/src/material.rs for the formulas). Needs the generated
// lobe library (wgsl::lobes) and geometry.wgsl, and a `lights` array declared by the entry
// points' module.

struct Material {
    // ka colour.
    ambient: vec3<f32>,
    // 0: Phong (t = R.V), 1: Blinn (t = N.H).
    geometry: u32,
    // kd colour (over pi in the physical and microfacet models).
    diffuse: vec3<f32>,
    // 0: classic, 1: physical, 2: microfacet.
    model: u32,
    // ks specular colour N(n) (ks F0 in the microfacet model).
    specular: vec3<f32>,
    // The microfacet model's normaliser C(n).
    normaliser: f32,
    // ks: the scale of Fresnel's grazing part (microfacet model).
    grazing: vec3<f32>,
    padding: u32,
    lobe: Lobe,
    // G1 at the cosines (k / 63)^2, four to an element (microfacet model).
    masking: array<vec4<f32>, 16>,
}

// G1 from the material's table, linear in sqrt(cos): `MicrofacetTerms::g1`.
fn masking_g1(material: Material, cos: f32) -> f32 {
    let x = sqrt(clamp(cos, 0.0, 1.0)) * 63.0;
    let at = min(u32(x), 62u);
    let fraction = x - f32(at);
    let next = at + 1u;
    let low = material.masking[at >> 2u][at & 3u];
    let high = material.masking[next >> 2u][next & 3u];
    return low + fraction * (high - low);
}

// The height-correlated G2 from the two G1s: `MicrofacetTerms::g2`.
fn masking_g2(material: Material, cos_o: f32, cos_i: f32) -> f32 {
    let a = masking_g1(material, cos_o);
    let b = masking_g1(material, cos_i);
    let denominator = a + b - a * b;
    return select(0.0, a * b / denominator, denominator > 0.0);
}

struct Light {
    // A point light's position, or the unit direction towards a directional light.
    position: vec3<f32>,
    // 0: directional, 1: point.
    kind: u32,
    intensity: vec3<f32>,
    padding: u32,
}

// The microfacet model's specular term times N.wi, per unit intensity, from the lobe's value at
// N.h and the cosines N.wo, N.wi, wo.h: F C(n) lobe G2 / (4 N.wo) with Schlick's F, its F0 the
// `specular` colour (`Shader::microfacet_contribution`). The GPU cost model counts this
// function as what a lobe's microfacet BRDF adds to the lobe.
fn microfacet_factor(material: Material, lobe: f32, cos_out: f32, cos_in: f32, cos_half: f32)
    -> vec3<f32> {
    let base = material.normaliser * lobe * masking_g2(material, cos_out, cos_in) / (4.0 * cos_out);
    let m = 1.0 - clamp(cos_half, 0.0, 1.0);
    let s = m * m * m * m * m;
    return (material.specular * (1.0 - s) + material.grazing * s) * base;
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
            if material.model != 0u {
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
        } else if material.model == 2u {
            let cos_out = dot(normal, wo);
            let sum = wo + wi;
            let length_squared = dot(sum, sum);
            let cos_half = select(0.0, dot(wo, sum) / sqrt(length_squared), length_squared > 0.0);
            radiance += intensity * (material.diffuse * cos_in
                + microfacet_factor(material, lobe, cos_out, cos_in, cos_half));
        } else {
            radiance += intensity * (material.diffuse + material.specular * lobe) * cos_in;
        }
    }
    return radiance;
}
