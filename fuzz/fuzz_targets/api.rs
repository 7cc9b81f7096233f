//! The explorer's API: see `checks/api.rs`.
#![no_main]

#[path = "checks/api.rs"]
mod checks;

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| checks::check_api(data));
