//! The GPU cost model's instruction counts against shaders counted by hand from each lobe's
//! formula and the exported wrapper (`if !(t > 0) { return 0 }`, `min(t, 1)`).

use specula::gpu_cost::{GpuFamily, ShaderOps};
use specula::{Exponent, Lobe, LobeKind};
use specula_gpu::shader_ops::lobe_shader_ops;

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
    let rate = |family: &str, kind| {
        GpuFamily::find(family)
            .unwrap()
            .cost(&ops(kind, 64.0))
            .evals_per_clock
    };
    // pow: 2 special functions at 16 per clock on both families.
    assert_eq!(rate("gpu-nvidia", LobeKind::Pow), 8.0);
    assert_eq!(rate("gpu-amd", LobeKind::Pow), 8.0);
    // schlick: 1 special function (16 per clock) and 8 instructions (128 issued per clock on
    // an SM, 64 on a CU).
    assert_eq!(rate("gpu-nvidia", LobeKind::Schlick), 16.0);
    assert_eq!(rate("gpu-amd", LobeKind::Schlick), 8.0);
    // cosquad: 11 instructions, none special: issue-bound.
    assert_eq!(rate("gpu-nvidia", LobeKind::CosQuad { v: 4 }), 128.0 / 11.0);
    assert_eq!(rate("gpu-amd", LobeKind::CosQuad { v: 4 }), 64.0 / 11.0);
}
