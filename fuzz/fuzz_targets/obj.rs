//! The obj loader: see `common::check_mesh`.
#![no_main]

mod common;

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| common::check_mesh(data, specula_render::MeshFormat::Obj));
