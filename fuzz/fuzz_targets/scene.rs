//! The scene parser must answer any text with a scene or an error, never a panic.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    if let Ok(text) = std::str::from_utf8(data) {
        let _ = specula_render::Scene::from_toml(text, "fuzz.toml", None);
    }
});
