//! Phong shading of a tile's visible samples, as structure-of-arrays loops compiled for the
//! widest SIMD the CPU has.
//!
//! The samples are grouped by material (a counting sort), so that within a group every
//! constant (the lobe, the geometry, the illumination model, the coefficients) is uniform and
//! each step is one straight loop over plain `f32` slices: the interpolated surface, the view
//! direction, then per light the cosines, the lobe (the core's batch path) and the sum. The
//! loops run inside `pulp`'s dispatch, so they are compiled for AVX-512, AVX2+FMA or the
//! baseline and chosen at run time; what is not uniform across lanes (a light below the
//! horizon, a point light at the sample) becomes a select rather than a branch.
//!
//! The arithmetic is [`Shader::shade`]'s, term for term, so both agree to rounding (tested).

mod kernels;

use glam::Vec3;
use kernels::{Accumulate, Cosines, Surfaces, ViewDirections};

use crate::camera::Camera;
use crate::material::{Light, Shader};

/// Three component slices of a structure-of-arrays vector field.
type Field = [Vec<f32>; 3];

/// Reusable buffers for one tile's shading; a thread keeps one for all its tiles.
#[derive(Default)]
pub(crate) struct Scratch {
    order: Vec<u32>,
    starts: Vec<usize>,
    weight_sum: Vec<f32>,
    face_normal: Field,
    position: Field,
    normal: Field,
    wo: Field,
    radiance: Field,
    t: Vec<f32>,
    lobe: Vec<f32>,
    diffuse_weight: Vec<f32>,
    specular_weight: Vec<f32>,
    /// The microfacet model's `N.wo`, `N.wi`, `wo.h` and the lobe's share at grazing.
    cos_out: Vec<f32>,
    cos_in: Vec<f32>,
    cos_half: Vec<f32>,
    grazing_lobe: Vec<f32>,
}

/// What one visible sample brings from the rasterizer: its slot in the tile, its material,
/// and its surface as perspective-weighted sums `sum_k e_k / w_k (1, p_k, n_k)` over the
/// triangle's vertices, with `e_k` the edge weights. The divide by the weight sum and the
/// normal's normalisation happen here, vectorised: they are the dependent divisions that
/// made the scalar interpolation latency-bound (measured: 60 % of a Phong frame's sample
/// work), and the normalisation cancels the weights' common scale.
pub(crate) struct Sample {
    pub slot: u32,
    pub shader: u32,
    pub weight_sum: f32,
    pub weighted_position: Vec3,
    pub weighted_normal: Vec3,
    /// The triangle's normal: the fallback where the interpolated one vanishes.
    pub face_normal: Vec3,
}

/// Shades `count` samples, `sample(i)` giving the `i`th, and writes each one's radiance to
/// `out[slot]`.
pub(crate) fn shade(
    shaders: &[Shader],
    lights: &[Light],
    ambient: Vec3,
    camera: &Camera,
    samples: &[Sample],
    out: &mut [Vec3],
    scratch: &mut Scratch,
) {
    let count = samples.len();
    group_by_shader(samples, shaders.len(), scratch);
    let Scratch {
        order,
        starts,
        weight_sum,
        face_normal,
        position,
        normal,
        wo,
        radiance,
        t,
        lobe,
        diffuse_weight,
        specular_weight,
        cos_out,
        cos_in,
        cos_half,
        grazing_lobe,
    } = scratch;
    for field in [
        &mut *face_normal,
        &mut *position,
        &mut *normal,
        &mut *wo,
        &mut *radiance,
    ] {
        for component in field.iter_mut() {
            component.resize(count, 0.0);
        }
    }
    for buffer in [
        &mut *weight_sum,
        &mut *t,
        &mut *lobe,
        &mut *diffuse_weight,
        &mut *specular_weight,
        &mut *cos_out,
        &mut *cos_in,
        &mut *cos_half,
        &mut *grazing_lobe,
    ] {
        buffer.resize(count, 0.0);
    }
    for (i, &k) in order.iter().enumerate() {
        let sample = &samples[k as usize];
        weight_sum[i] = sample.weight_sum;
        for c in 0..3 {
            position[c][i] = sample.weighted_position[c];
            normal[c][i] = sample.weighted_normal[c];
            face_normal[c][i] = sample.face_normal[c];
        }
    }
    let arch = pulp::Arch::new();
    arch.dispatch(Surfaces {
        weight_sum,
        face_normal: view(face_normal, 0..count),
        position: view_mut(position, 0..count),
        normal: view_mut(normal, 0..count),
    });
    arch.dispatch(ViewDirections {
        camera,
        position: view(position, 0..count),
        wo: view_mut(wo, 0..count),
    });
    for (s, shader) in shaders.iter().enumerate() {
        let range = starts[s]..starts[s + 1];
        if range.is_empty() {
            continue;
        }
        let (ambient_term, diffuse, specular) = shader.coefficients();
        let ambient_term = ambient_term * ambient;
        for c in 0..3 {
            radiance[c][range.clone()].fill(ambient_term[c]);
        }
        let (geometry, model) = shader.geometry_and_model();
        for light in lights {
            arch.dispatch(Cosines {
                light,
                geometry,
                model,
                position: view(position, range.clone()),
                normal: view(normal, range.clone()),
                wo: view(wo, range.clone()),
                t: &mut t[range.clone()],
                diffuse_weight: &mut diffuse_weight[range.clone()],
                specular_weight: &mut specular_weight[range.clone()],
                cosines: [
                    &mut cos_out[range.clone()],
                    &mut cos_in[range.clone()],
                    &mut cos_half[range.clone()],
                ],
            });
            let lobe = &mut lobe[range.clone()];
            if shader.has_specular() {
                shader.lobe().eval_batch(&t[range.clone()], lobe);
            } else {
                lobe.fill(0.0);
            }
            let intensity = match *light {
                Light::Directional { intensity, .. } | Light::Point { intensity, .. } => intensity,
            };
            if let Some(terms) = shader.microfacet() {
                let grazing_lobe = &mut grazing_lobe[range.clone()];
                terms.factors(
                    [
                        &cos_out[range.clone()],
                        &cos_in[range.clone()],
                        &cos_half[range.clone()],
                    ],
                    lobe,
                    grazing_lobe,
                );
                // Fresnel's grazing part, `ks (1 - F0) (1 - wo.h)^5`, as a second specular
                // term on its own share of the lobe.
                arch.dispatch(Accumulate {
                    diffuse: Vec3::ZERO,
                    specular: terms.grazing() * intensity,
                    diffuse_weight: &diffuse_weight[range.clone()],
                    specular_weight: &specular_weight[range.clone()],
                    lobe: grazing_lobe,
                    radiance: view_mut(radiance, range.clone()),
                });
            }
            arch.dispatch(Accumulate {
                diffuse: diffuse * intensity,
                specular: specular * intensity,
                diffuse_weight: &diffuse_weight[range.clone()],
                specular_weight: &specular_weight[range.clone()],
                lobe,
                radiance: view_mut(radiance, range.clone()),
            });
        }
    }
    for (i, &k) in order.iter().enumerate() {
        let slot = samples[k as usize].slot as usize;
        out[slot] = Vec3::new(radiance[0][i], radiance[1][i], radiance[2][i]);
    }
}

/// Fills `scratch.order` with sample indices sorted by shader (stable) and `scratch.starts`
/// with each shader's first position in it (plus the end).
fn group_by_shader(samples: &[Sample], shader_count: usize, scratch: &mut Scratch) {
    let starts = &mut scratch.starts;
    starts.clear();
    starts.resize(shader_count + 1, 0);
    for sample in samples {
        starts[sample.shader as usize + 1] += 1;
    }
    for s in 0..shader_count {
        starts[s + 1] += starts[s];
    }
    let mut next = starts.clone();
    scratch.order.clear();
    scratch.order.resize(samples.len(), 0);
    for (k, sample) in samples.iter().enumerate() {
        let shader = sample.shader as usize;
        scratch.order[next[shader]] = k as u32;
        next[shader] += 1;
    }
}

fn view(field: &Field, range: core::ops::Range<usize>) -> [&[f32]; 3] {
    let [x, y, z] = field;
    [&x[range.clone()], &y[range.clone()], &z[range]]
}

fn view_mut(field: &mut Field, range: core::ops::Range<usize>) -> [&mut [f32]; 3] {
    let [x, y, z] = field;
    [&mut x[range.clone()], &mut y[range.clone()], &mut z[range]]
}

#[cfg(test)]
mod tests {
    use rand::{RngExt, SeedableRng};
    use specula::{Exponent, Geometry, Lobe, LobeKind, Normalisation};

    use super::*;
    use crate::camera::Projection;
    use crate::material::{IlluminationModel, Material};

    /// Every branch of the vectorised path (both light kinds, geometries and models, lights
    /// below the horizon, hidden normals, a vanishing normal, a sample at a point light)
    /// against the scalar [`Shader::shade`] on the same, already divided, surface.
    #[test]
    fn vectorised_shading_matches_the_scalar_shader() {
        let mut rng = rand_pcg::Pcg64::seed_from_u64(11);
        let unit = |rng: &mut rand_pcg::Pcg64| {
            Vec3::new(
                rng.random_range(-1.0..1.0),
                rng.random_range(-1.0..1.0),
                rng.random_range(-1.0..1.0),
            )
        };
        let point_at = Vec3::new(0.5, -0.25, 2.0);
        let lights = [
            Light::Directional {
                towards: Vec3::new(-0.3, -0.5, 0.8).normalize(),
                intensity: Vec3::new(0.9, 0.8, 0.7),
            },
            Light::Point {
                position: point_at,
                intensity: Vec3::new(0.3, 0.4, 0.5),
            },
        ];
        let mut shaders = Vec::new();
        for model in IlluminationModel::ALL {
            for geometry in Geometry::ALL {
                for (kind, ks) in [(LobeKind::Pow, 0.5), (LobeKind::SchlickMod, 0.0)] {
                    let material = Material {
                        ka: 0.2,
                        kd: 0.6,
                        ks,
                        colour: Vec3::new(0.8, 0.4, 0.2),
                        specular_colour: Vec3::ONE,
                        lobe: Lobe::new(kind, Exponent::new(24.0)),
                        geometry,
                        normalisation: Normalisation::Lobe,
                    };
                    shaders.push(Shader::new(&material, model));
                }
            }
        }
        let for_orthographic = |orthographic: bool| {
            let projection = if orthographic {
                Projection::Orthographic { height: 4.0 }
            } else {
                Projection::Perspective {
                    fov_y_degrees: 40.0,
                }
            };
            Camera::try_new(
                Vec3::new(0.0, -6.0, 2.0),
                Vec3::ZERO,
                Vec3::Z,
                projection,
                0.1,
                50.0,
            )
            .expect("valid camera")
        };
        let ambient = Vec3::splat(0.1);
        for orthographic in [false, true] {
            let camera = for_orthographic(orthographic);
            let samples: Vec<Sample> = (0..500)
                .map(|k| {
                    let weight_sum = rng.random_range(0.01..100.0);
                    let position = match k {
                        0 => point_at,
                        _ => unit(&mut rng) * 2.0,
                    };
                    let normal = match k {
                        1 => Vec3::ZERO,
                        _ => unit(&mut rng) * weight_sum,
                    };
                    Sample {
                        slot: (499 - k) as u32,
                        shader: rng.random_range(0..shaders.len() as u32),
                        weight_sum,
                        weighted_position: position * weight_sum,
                        weighted_normal: normal,
                        face_normal: Vec3::new(0.0, -1.0, 0.0),
                    }
                })
                .collect();
            let mut out = vec![Vec3::NAN; samples.len()];
            shade(
                &shaders,
                &lights,
                ambient,
                &camera,
                &samples,
                &mut out,
                &mut Scratch::default(),
            );
            for sample in &samples {
                let position = sample.weighted_position / sample.weight_sum;
                let normal = sample
                    .weighted_normal
                    .try_normalize()
                    .unwrap_or(sample.face_normal);
                let wo = camera.towards_viewer(position);
                let expected =
                    shaders[sample.shader as usize].shade(position, normal, wo, &lights, ambient);
                let got = out[sample.slot as usize];
                assert!(
                    (got - expected).abs().max_element() <= 1e-4 * expected.max_element().max(1.0),
                    "sample {}: {got} against {expected}",
                    sample.slot
                );
            }
        }
    }
}
