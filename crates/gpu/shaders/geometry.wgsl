// Lobe geometry: the cosine t a lobe is a function of (crates/specula/src/geometry.rs).
// Geometry ids: 0 Phong (t = R.V), 1 Blinn (t = N.H).

// The lobe's cosine t from a unit normal and unit directions pointing away from the surface.
fn cos_lobe(geometry: u32, normal: vec3<f32>, wo: vec3<f32>, wi: vec3<f32>) -> f32 {
    if geometry == 0u {
        // 2 (N.wi)(N.wo) - wi.wo: symmetric in wi and wo by construction.
        return 2.0 * dot(normal, wi) * dot(normal, wo) - dot(wi, wo);
    }
    let sum = wi + wo;
    let length_squared = dot(sum, sum);
    if length_squared > 0.0 {
        return dot(normal, sum) / sqrt(length_squared);
    }
    return 0.0;
}
