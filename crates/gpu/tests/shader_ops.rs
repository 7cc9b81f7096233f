//! The GPU cost model's instruction counts against shaders counted by hand from each lobe's
//! formula and the exported wrapper (`if !(t > 0) { return 0 }`, `min(t, 1)`).

use specula::gpu_cost::{modelled, ShaderOps};
use specula::gpus::Gpu;
use specula::{Exponent, Lobe, LobeKind};
use specula_gpu::shader_ops::{ggx_microfacet_ops, lobe_shader_ops, microfacet_shader_ops};

fn ops(kind: LobeKind, n: f64) -> ShaderOps {
    lobe_shader_ops(&Lobe::new(kind, Exponent::new(n))).unwrap()
}

/// The wrapper: `t > 0`, its negation, `min(t, 1)`.
const WRAPPER_COMPARES: u32 = 3;

#[test]
fn hand_counted_shaders() {
    // pow(t, n): log2, multiply, exp2.
    assert_eq!(
        ops(LobeKind::Pow, 64.0),
        ShaderOps {
            arithmetic: 1,
            transcendental: 2,
            compare: WRAPPER_COMPARES,
            ..ShaderOps::default()
        }
    );
    // t / (n (1 - t) + t): subtract, multiply, add, and a divide (reciprocal and multiply).
    assert_eq!(
        ops(LobeKind::Schlick, 64.0),
        ShaderOps {
            arithmetic: 4,
            transcendental: 1,
            compare: WRAPPER_COMPARES,
            ..ShaderOps::default()
        }
    );
    // max(a (t - 1) + 1, 0), then v = 4 squarings, a multiply each (written out).
    assert_eq!(
        ops(LobeKind::CosQuad { v: 4 }, 64.0),
        ShaderOps {
            arithmetic: 3 + 4,
            compare: 1 + WRAPPER_COMPARES,
            ..ShaderOps::default()
        }
    );
    // exp2(r (t - 1)): subtract, multiply, exp2.
    assert_eq!(
        ops(LobeKind::Sg, 64.0),
        ShaderOps {
            arithmetic: 2,
            transcendental: 1,
            compare: WRAPPER_COMPARES,
            ..ShaderOps::default()
        }
    );
    // The angle lobes call acos once.
    assert_eq!(ops(LobeKind::Cheb2, 64.0).acos, 1);
}

/// The modelled rates follow from those counts and the published rates by hand.
#[test]
fn modelled_rates_follow_from_the_counts() {
    let rate = |gpu: &str, kind| {
        modelled(&ops(kind, 64.0), &Gpu::find(gpu).unwrap().rates).evals_per_clock
    };
    // pow: 2 special functions at 16 per clock on an Ada SM and an RDNA 3 CU.
    assert_eq!(rate("sm_89", LobeKind::Pow), 8.0);
    assert_eq!(rate("gfx1100", LobeKind::Pow), 8.0);
    // schlick: 1 special function (16 per clock) and 8 instructions (128 issued per clock on
    // an SM, 64 on a CU).
    assert_eq!(rate("sm_89", LobeKind::Schlick), 16.0);
    assert_eq!(rate("gfx1100", LobeKind::Schlick), 8.0);
    // cosquad: 11 instructions, none special: issue-bound.
    assert_eq!(rate("sm_89", LobeKind::CosQuad { v: 4 }), 128.0 / 11.0);
    assert_eq!(rate("gfx1100", LobeKind::CosQuad { v: 4 }), 64.0 / 11.0);
    // On Xe's 8-lane EU, pow's 2 special functions at 2 lanes a clock: 1 per clock.
    assert_eq!(rate("tgllp", LobeKind::Pow), 1.0);
}

/// A lobe's microfacet BRDF adds `brdf.wgsl`'s `microfacet_factor` to the lobe, counted by
/// hand (vector operations one instruction a lane); GGX's term (`ggx_cost.wgsl`, as three.js
/// writes it) likewise.
#[test]
fn hand_counted_microfacet_terms() {
    // G1 from the table: clamp, sqrt, * 63; u32(), min; f32(), -; + 1u, two shifts and two
    // masks; the interpolation's -, *, +.
    let g1 = ShaderOps {
        arithmetic: 5,
        compare: 2,
        transcendental: 1,
        conversion: 2,
        integer: 5,
        ..ShaderOps::default()
    };
    // G2: two G1s; a + b - a b (3), a b again, a divide, `> 0` and the select.
    let g2 = g1 * 2
        + ShaderOps {
            arithmetic: 3 + 1 + 1,
            compare: 2,
            transcendental: 1,
            ..ShaderOps::default()
        };
    // C lobe G2 / (4 N.wo): three multiplies and a divide; 1 - clamp(); four multiplies for
    // the fifth power; (F0 (1 - S) + ks S) base: 1 - S, then three vec3 operations of three
    // lanes and the scaling by base, three lanes.
    let factor = g2
        + ShaderOps {
            arithmetic: 4 + 1 + 4 + 1 + 3 * 3 + 3,
            compare: 1,
            transcendental: 1,
            ..ShaderOps::default()
        };
    let pow = Lobe::new(LobeKind::Pow, Exponent::new(64.0));
    assert_eq!(
        microfacet_shader_ops(&pow).unwrap(),
        ops(LobeKind::Pow, 64.0) + factor
    );
    // GGX: a2; each of the two visibility roots 1 - a2, two multiplies, +, sqrt, the outer
    // multiply; their sum, max, 0.5 / x; D's denominator (4) and a2 / pi / d^2 (two
    // multiplies and a divide); Fresnel as above; V D N.wi (2).
    assert_eq!(
        ggx_microfacet_ops().unwrap(),
        ShaderOps {
            arithmetic: 1 + 2 * 5 + 1 + 1 + 4 + 3 + 1 + 4 + 1 + 3 * 3 + 2 + 3,
            compare: 1 + 1,
            transcendental: 2 + 1 + 1,
            ..ShaderOps::default()
        }
    );
}
