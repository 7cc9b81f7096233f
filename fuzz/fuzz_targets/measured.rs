//! The measured-material reader (RGL `.bsdf` tensor files): see `checks/measured.rs`.
#![no_main]

#[path = "checks/measured.rs"]
mod checks;

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| checks::check_measured(data));
