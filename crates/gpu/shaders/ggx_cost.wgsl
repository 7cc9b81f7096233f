// GGX's microfacet specular term, written as three.js writes it (`D_GGX` and
// `V_GGX_SmithCorrelated` in its `bsdfs` shader chunk), with the same Schlick Fresnel as
// brdf.wgsl's `microfacet_factor`: the GPU cost model counts this function as a GGX
// microfacet BRDF beside each lobe's (`microfacet_factor` and the lobe). It computes what
// `microfacet_factor` computes, F D G2 / (4 N.wo) per unit intensity, from the same inputs
// (N.h in place of the lobe's value). Costed, not drawn.
fn ggx_factor(alpha: f32, f0: vec3<f32>, grazing: vec3<f32>, n_dot_h: f32, cos_out: f32,
    cos_in: f32, cos_half: f32) -> vec3<f32> {
    let a2 = alpha * alpha;
    let gv = cos_in * sqrt(a2 + (1.0 - a2) * cos_out * cos_out);
    let gl = cos_out * sqrt(a2 + (1.0 - a2) * cos_in * cos_in);
    let v = 0.5 / max(gv + gl, 1e-6);
    let denominator = n_dot_h * n_dot_h * (a2 - 1.0) + 1.0;
    let d = 0.31830988618 * a2 / (denominator * denominator);
    let m = 1.0 - clamp(cos_half, 0.0, 1.0);
    let s = m * m * m * m * m;
    return (f0 * (1.0 - s) + grazing * s) * (v * d * cos_in);
}
