//! The batch (SIMD) path against the scalar `f32` path, lobe by lobe, within
//! `Lobe::batch_ulp_bound`, over random and edge-case cosines.

use proptest::prelude::*;
use specula::{Exponent, Lobe, LobeKind};

const ULP: f64 = 1.0 / (1u32 << 23) as f64;

fn check(lobe: &Lobe, ts: &[f32]) -> Result<(), TestCaseError> {
    let mut batch = vec![0.0; ts.len()];
    lobe.eval_batch(ts, &mut batch);
    let bound = lobe.batch_ulp_bound() * ULP;
    for (&t, &value) in ts.iter().zip(&batch) {
        let scalar = lobe.eval(t);
        let error = f64::from((value - scalar).abs());
        prop_assert!(
            error <= bound,
            "{} n = {} t = {t:e}: batch {value:e}, scalar {scalar:e} ({:.1} ULP > {:.1})",
            lobe.kind(),
            lobe.exponent(),
            error / ULP,
            bound / ULP
        );
        prop_assert!((0.0..=1.0).contains(&value));
    }
    Ok(())
}

fn kinds() -> impl Strategy<Value = LobeKind> {
    prop_oneof![
        proptest::sample::select(LobeKind::ALL.to_vec()),
        (0_u8..=10).prop_map(|v| LobeKind::CosQuad { v }),
    ]
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(200))]
    #[test]
    fn batch_matches_scalar_within_its_bound(
        kind in kinds(),
        n in 1.0_f64..=1000.0,
        ts in proptest::collection::vec(
            prop_oneof![0.0_f32..=1.0, 0.99_f32..=1.0, -1.0_f32..=1.5],
            1..300,
        ),
    ) {
        check(&Lobe::new(kind, Exponent::new(n)), &ts)?;
    }
}

#[test]
fn edge_cases_follow_the_shared_rules() {
    let ts = [
        0.0,
        -0.0,
        -0.5,
        f32::NAN,
        f32::NEG_INFINITY,
        1.0,
        1.5,
        f32::INFINITY,
        f32::MIN_POSITIVE,
        1e-30,
    ];
    for kind in LobeKind::ALL {
        for n in [1.0, 64.0, 1000.0] {
            let lobe = Lobe::new(kind, Exponent::new(n));
            let mut out = [9.0; 10];
            lobe.eval_batch(&ts, &mut out);
            assert_eq!(&out[..5], &[0.0; 5], "{kind}");
            assert_eq!(out[5], out[6], "{kind}: t > 1 counts as 1");
            assert_eq!(out[6], out[7], "{kind}");
            check(&lobe, &ts).unwrap();
        }
    }
}
