//! The formula language: see `checks/formula.rs`.
#![no_main]

#[path = "checks/formula.rs"]
mod checks;

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| checks::check_formula(data));
