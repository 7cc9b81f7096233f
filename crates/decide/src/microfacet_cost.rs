//! What a lobe's whole microfacet BRDF costs on a target, beside GGX's: the figure that turns
//! "this lobe as the distribution saves its `pow`" into a share of the specular term's cost.
//!
//! The work costed is the specular term per light from the cosines a renderer has computed
//! (`N.h`, `N.wo`, `N.wi`, `wo.h`): for a lobe, the lobe at `N.h` and what the microfacet model
//! adds (its normaliser, `G2` from the masking table's two lookups, Schlick's Fresnel per
//! channel, the division by `4 N.wo`); for GGX, its `D` and Smith's correlated visibility in
//! closed form as three.js writes them, with the same Fresnel. Both write the same outputs.
//!
//! - **GPU** (`gpu-nvidia`, `gpu-amd`): modelled, as the lobes are, from the instructions of
//!   the shader functions the renderer runs (`specula_gpu::shader_ops`).
//! - **CPU**: measured, as the lobes are: evaluations per second over an L1-sized batch, one
//!   thread, best of three: the lobe's SIMD kernel then the renderer's own microfacet loop
//!   (`MicrofacetTerms::factors`, scalar: the table lookups), against GGX's loop written here
//!   in plain Rust `f32`, which the compiler vectorises (the peer at its best).
//! - **FPGA**: refused, as for every material verdict (the datapaths take no masking table).

use std::sync::Mutex;

use specula::Lobe;
use specula_render::MicrofacetTerms;

use crate::choice::Target;
use crate::costing::material_target;
use crate::rates::{l1_rate, L1_SIZE};

/// The directions' cosines the CPU kernels are timed over: `N.wo`, `N.wi` and `wo.h`, spread
/// over the hemisphere's working range, fixed.
fn timed_cosines() -> [Vec<f32>; 3] {
    let spread = |offset: usize, low: f32| -> Vec<f32> {
        (0..L1_SIZE)
            .map(|i| low + (1.0 - low) * (((i * 7 + offset) % 1021) as f32 / 1021.0))
            .collect()
    };
    [spread(0, 0.05), spread(331, 0.05), spread(617, 0.3)]
}

/// Evaluations per second of `lobe`'s microfacet specular term on this CPU.
fn measured_lobe_rate(lobe: &Lobe) -> f64 {
    let terms = MicrofacetTerms::new(lobe, 1.0);
    let [cos_out, cos_in, cos_half] = timed_cosines();
    let grazing = Mutex::new(vec![0.0_f32; L1_SIZE]);
    l1_rate(&|n_dot_h: &[f32], out: &mut [f32]| {
        lobe.eval_batch(n_dot_h, out);
        let mut grazing = grazing
            .lock()
            .unwrap_or_else(std::sync::PoisonError::into_inner);
        terms.factors([&cos_out, &cos_in, &cos_half], out, &mut grazing);
    })
}

/// GGX's specular term over a batch, split as [`MicrofacetTerms::factors`] splits a lobe's:
/// `out` gets `D V 4 N.wi N.wo / (4 N.wo) (1 - S)`, written with three.js's `D_GGX` and
/// `V_GGX_SmithCorrelated`, and `grazing` the same times `S`.
fn ggx_factors(
    alpha: f32,
    n_dot_h: &[f32],
    [cos_out, cos_in, cos_half]: [&[f32]; 3],
    out: &mut [f32],
    grazing: &mut [f32],
) {
    let a2 = alpha * alpha;
    for i in 0..out.len().min(n_dot_h.len()) {
        let (o, l) = (cos_out[i], cos_in[i]);
        let gv = l * (a2 + (1.0 - a2) * o * o).sqrt();
        let gl = o * (a2 + (1.0 - a2) * l * l).sqrt();
        let visibility = 0.5 / (gv + gl).max(1e-6);
        let denominator = n_dot_h[i] * n_dot_h[i] * (a2 - 1.0) + 1.0;
        let d = core::f32::consts::FRAC_1_PI * a2 / (denominator * denominator);
        let m = 1.0 - cos_half[i].clamp(0.0, 1.0);
        let s = m * m * m * m * m;
        let base = visibility * d * l;
        (out[i], grazing[i]) = (base * (1.0 - s), base * s);
    }
}

/// Evaluations per second of GGX's microfacet specular term on this CPU.
fn measured_ggx_rate() -> f64 {
    let cosines = timed_cosines();
    let grazing = Mutex::new(vec![0.0_f32; L1_SIZE]);
    l1_rate(&|n_dot_h: &[f32], out: &mut [f32]| {
        let mut grazing = grazing
            .lock()
            .unwrap_or_else(std::sync::PoisonError::into_inner);
        let [o, l, h] = &cosines;
        ggx_factors(0.3, n_dot_h, [o, l, h], out, &mut grazing);
    })
}

/// The rate of `lobe`'s microfacet specular term on `target` (higher is cheaper): measured on
/// the CPU; on a GPU, the naga-IR model of `brdf.wgsl`'s term on the vendor's current
/// generation (the term is WGSL alone, with no CUDA C or OpenCL C twin for the vendors'
/// compilers), so compare it with [`ggx_microfacet_rate`] on the same basis.
pub fn microfacet_rate(target: Target, lobe: &Lobe) -> Result<f64, String> {
    match material_target(target)?.gpu(None)? {
        Some(gpu) => Ok(specula::gpu_cost::modelled(
            &specula_gpu::shader_ops::microfacet_shader_ops(lobe)?,
            &gpu.rates,
        )
        .evals_per_clock),
        None => Ok(measured_lobe_rate(lobe)),
    }
}

/// The rate of GGX's microfacet specular term on `target`, the peer of [`microfacet_rate`].
pub fn ggx_microfacet_rate(target: Target) -> Result<f64, String> {
    match material_target(target)?.gpu(None)? {
        Some(gpu) => Ok(specula::gpu_cost::modelled(
            &specula_gpu::shader_ops::ggx_microfacet_ops()?,
            &gpu.rates,
        )
        .evals_per_clock),
        None => Ok(measured_ggx_rate()),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use specula::{Exponent, LobeKind};

    /// The whole term costs more than its lobe alone on every modelled GPU, for every lobe;
    /// the figures are printed (`--nocapture`).
    #[test]
    fn the_whole_term_costs_more_than_its_lobe() {
        for target in Target::GPUS {
            let ggx = ggx_microfacet_rate(target).unwrap();
            let gpu = target.gpu(None).unwrap().unwrap();
            for kind in LobeKind::ALL {
                let lobe = Lobe::new(kind, Exponent::new(64.0));
                let (alone, whole) = (
                    crate::modelled_rate(&gpu, &lobe).unwrap(),
                    microfacet_rate(target, &lobe).unwrap(),
                );
                eprintln!("{target:?} {kind}: lobe {alone:.3}, term {whole:.3}, GGX {ggx:.3}");
                assert!(whole < alone, "{target:?} {kind}: {whole} vs {alone}");
            }
        }
    }

    /// The GGX peer computes GGX's specular term: against the core's `f64` closed forms
    /// (`D`, the exact height-correlated `G2`), split by Schlick's weight as the lobes' is.
    #[test]
    fn the_ggx_peer_is_ggxs_specular_term() {
        let alpha = 0.3_f64;
        let ggx = specula::microfacet::Distribution::Ggx { alpha };
        let (o, l, nh, oh) = (0.8_f32, 0.6_f32, 0.95_f32, 0.9_f32);
        let (mut out, mut grazing) = ([0.0_f32], [0.0_f32]);
        ggx_factors(
            alpha as f32,
            &[nh],
            [&[o], &[l], &[oh]],
            &mut out,
            &mut grazing,
        );
        let expected =
            ggx.d(f64::from(nh)) * ggx.g2(f64::from(o), f64::from(l)) / (4.0 * f64::from(o));
        let total = f64::from(out[0] + grazing[0]);
        assert!(
            (total - expected).abs() < 1e-5 * expected,
            "{total} vs {expected}"
        );
        let s = (1.0 - f64::from(oh)).powi(5);
        assert!((f64::from(grazing[0]) - expected * s).abs() < 1e-5 * expected);
    }
}
