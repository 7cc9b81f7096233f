//! Replays the API fuzzer's seeds and every crash input it found (`fuzz/regressions/api/`)
//! through the fuzz target's own check, so that CI needs no fuzzer.

use std::path::Path;

#[path = "../../../fuzz/fuzz_targets/checks/api.rs"]
mod checks;

#[test]
fn fuzz_inputs_get_200_or_a_json_400() {
    let fuzz = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../fuzz");
    let mut count = 0;
    for kind in ["seeds", "regressions"] {
        for entry in std::fs::read_dir(fuzz.join(kind).join("api"))
            .into_iter()
            .flatten()
        {
            let path = entry.expect("entry").path();
            if path.file_name().is_some_and(|name| name == ".gitkeep") {
                continue;
            }
            checks::check_api(&std::fs::read(&path).expect("read"));
            count += 1;
        }
    }
    assert!(count >= 2, "the API seeds are missing");
}
