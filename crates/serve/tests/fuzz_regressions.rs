//! Replays the API, formula and analysis fuzzers' seeds and every crash input they found
//! (`fuzz/regressions/{api,formula,analysis}/`) through the fuzz targets' own checks, so that CI
//! needs
//! no fuzzer.

use std::path::Path;

#[path = "../../../fuzz/fuzz_targets/checks/analysis.rs"]
mod analysis;
#[path = "../../../fuzz/fuzz_targets/checks/api.rs"]
mod api;
#[path = "../../../fuzz/fuzz_targets/checks/formula.rs"]
mod formula;

/// Every seed and regression input of `target`, run through `check`; how many there were.
fn replay(target: &str, check: fn(&[u8])) -> usize {
    let fuzz = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../fuzz");
    let mut count = 0;
    for kind in ["seeds", "regressions"] {
        for entry in std::fs::read_dir(fuzz.join(kind).join(target))
            .into_iter()
            .flatten()
        {
            let path = entry.expect("entry").path();
            if path.file_name().is_some_and(|name| name == ".gitkeep") {
                continue;
            }
            check(&std::fs::read(&path).expect("read"));
            count += 1;
        }
    }
    count
}

#[test]
fn fuzz_inputs_get_200_or_a_json_400() {
    assert!(
        replay("api", api::check_api) >= 2,
        "the API seeds are missing"
    );
}

#[test]
fn fuzz_formulas_are_lobes_in_range_or_one_line_refusals() {
    assert!(
        replay("formula", formula::check_formula) >= 5,
        "the formula seeds are missing"
    );
}

#[test]
fn fuzz_formulas_are_analysed_in_bounded_time() {
    assert!(
        replay("analysis", analysis::check_analysis) >= 3,
        "the analysis seeds are missing"
    );
}
