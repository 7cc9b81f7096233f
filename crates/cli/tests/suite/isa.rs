//! `specula isa` and the GPU targets as users run them: the machine code a vendor's compiler
//! writes, read by facts of its text (the special-function unit's operations are `MUFU.*` in
//! SASS, `v_exp`/`v_log`/`v_rcp`/`v_sqrt`/`v_rsq` in AMD's ISA), not by the classifier that
//! made the counts. Without a compiler these print `skipped: ...`, except under `CI=true`.

use super::common::{have_gpu_compilers, ok, specula};

/// The listing's instructions whose text names a special-function operation.
fn special(listing: &serde_json::Value) -> usize {
    let names = [
        "MUFU.", "v_exp_", "v_log_", "v_rcp_", "v_sqrt_", "v_rsq_", "math.",
    ];
    listing
        .as_array()
        .expect("a listing")
        .iter()
        .filter(|line| {
            let text = line[1].as_str().expect("an instruction's text");
            names.iter().any(|name| text.contains(name))
        })
        .count()
}

#[test]
fn isa_prints_the_compilers_code_and_counts_what_the_code_holds() {
    let dir = tempfile::tempdir().unwrap();
    if !have_gpu_compilers() {
        return;
    }
    let text = ok(
        dir.path(),
        &["isa", "--lobe", "sg", "--n", "64", "--gpu", "sm_89"],
    );
    let text = String::from_utf8_lossy(&text.stdout);
    assert!(text.contains("compiled by nvcc"), "{text}");
    assert!(
        text.contains("MUFU.EX2") && text.contains("MUFU.LG2"),
        "{text}"
    );
    for (lobe, gpu) in [
        ("sg", "sm_89"),
        ("schlick", "gfx1100"),
        ("cosquad", "sm_75"),
        ("pow", "tgllp"),
    ] {
        let output = ok(
            dir.path(),
            &[
                "isa", "--lobe", lobe, "--n", "64", "--gpu", gpu, "--format", "json",
            ],
        );
        let answer: serde_json::Value = serde_json::from_slice(&output.stdout).expect("JSON");
        for side in ["lobe", "pow"] {
            let view = &answer[side];
            let counted = view["counts"]
                .as_array()
                .unwrap()
                .iter()
                .find(|c| c[0] == "transcendental")
                .and_then(|c| c[1].as_i64())
                .expect("a transcendental count") as usize;
            let beyond = special(&view["listing"]) - special(&view["baseline_listing"]);
            assert_eq!(counted, beyond, "{lobe} on {gpu}, {side}: {view}");
            // Every printed count is of the listing: the classes sum to the instructions the
            // kernel has beyond the baseline's, which the listings' lengths bound.
            let total = view["total"].as_i64().unwrap();
            let lines = view["listing"].as_array().unwrap().len() as i64;
            let baseline = view["baseline_listing"].as_array().unwrap().len() as i64;
            assert!(
                total >= lines - baseline && total <= lines,
                "{lobe} on {gpu}: {view}"
            );
        }
    }
    // A formula lobe compiles too, and `t^n` is pow's code.
    let formula = ok(
        dir.path(),
        &[
            "isa", "--lobe", "=t^n", "--n", "64", "--gpu", "gfx1100", "--format", "json",
        ],
    );
    let formula: serde_json::Value = serde_json::from_slice(&formula.stdout).unwrap();
    assert_eq!(formula["throughput_vs_pow"], 1.0, "{formula}");
    // The shading context says what share of the specular term the lobe is.
    let shading = ok(
        dir.path(),
        &[
            "isa",
            "--lobe",
            "sg",
            "--n",
            "64",
            "--gpu",
            "gfx1100",
            "--context",
            "shading",
        ],
    );
    assert!(String::from_utf8_lossy(&shading.stdout).contains("of the specular term's"));
}

#[test]
fn a_gpu_target_names_the_compiler_and_generation_it_ranks_by() {
    let dir = tempfile::tempdir().unwrap();
    if !have_gpu_compilers() {
        return;
    }
    let args = "recommend --target gpu-amd --gpu gfx1100 --n 64 --max-error 2%";
    let output = ok(dir.path(), &args.split_whitespace().collect::<Vec<_>>());
    let text = String::from_utf8_lossy(&output.stdout);
    assert!(
        text.contains("costed on gfx1100") && text.contains("ACO"),
        "{text}"
    );
    assert!(text.contains("ACO's inverse throughput"), "{text}");
    let intel = ok(
        dir.path(),
        &[
            "recommend",
            "--target",
            "gpu-intel",
            "--n",
            "64",
            "--max-error",
            "2%",
        ],
    );
    assert!(String::from_utf8_lossy(&intel.stdout).contains("IGC"));
    // A GPU of another vendor is refused, naming the target's GPUs.
    let refused = specula(
        dir.path(),
        &[
            "recommend",
            "--target",
            "gpu-nvidia",
            "--gpu",
            "gfx1100",
            "--max-error",
            "1%",
        ],
    );
    let error = String::from_utf8_lossy(&refused.stderr);
    assert!(!refused.status.success());
    assert!(
        error.contains("sm_75, sm_86, sm_89, sm_90, sm_120"),
        "{error}"
    );
    assert_eq!(error.trim().lines().count(), 1, "{error}");
}
