//! The analysis of any formula: see `checks/analysis.rs`.
#![no_main]

#[path = "checks/formula.rs"]
mod formula;
#[path = "checks/analysis.rs"]
mod analysis;

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| analysis::check_analysis(data));
