//! The obj loader: see `checks/mesh.rs`.
#![no_main]

#[path = "checks/mesh.rs"]
mod checks;

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| checks::check_mesh(data, specula_render::MeshFormat::Obj));
