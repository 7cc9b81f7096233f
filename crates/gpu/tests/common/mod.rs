//! The GPU every test uses: skipped with a note where none exists, but a failure under CI
//! (`CI=true`), where `.ci/run` installs Mesa's lavapipe.

use specula_gpu::Gpu;

/// The GPU, or `None` (outside CI only) when wgpu finds no adapter.
pub fn gpu() -> Option<Gpu> {
    match Gpu::new() {
        Ok(gpu) => Some(gpu),
        Err(error) if std::env::var("CI").as_deref() == Ok("true") => {
            panic!("CI=true but no GPU: {error}")
        }
        Err(error) => {
            eprintln!("skipped: {error}");
            None
        }
    }
}
