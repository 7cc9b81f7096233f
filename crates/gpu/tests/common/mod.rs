//! The GPU every test uses: skipped with a note where none exists, but a failure under CI
//! (`CI=true`), where `.ci/run` installs Mesa's lavapipe. And the CPU/GPU agreement check
//! the parity tests share.

// Each test binary uses part of this module.
#![allow(dead_code)]

use specula_gpu::Gpu;
use specula_render::metrics::compare;
use specula_render::{Display, Image};

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

/// Bounds on how far a GPU image may be from the CPU's, and the worst case seen.
pub struct Parity {
    max_mean_flip: f64,
    min_psnr_db: f64,
    worst: (f64, f64),
}

impl Parity {
    pub fn new(max_mean_flip: f64, min_psnr_db: f64) -> Self {
        Self {
            max_mean_flip,
            min_psnr_db,
            worst: (f64::INFINITY, 0.0),
        }
    }

    /// Prints the case's PSNR and mean FLIP and fails it when outside the bounds.
    pub fn check(&mut self, what: &str, gpu: &Gpu, cpu: &Image, on_gpu: &Image, display: Display) {
        let difference = compare(cpu, on_gpu, display).unwrap();
        let (psnr, flip) = (difference.psnr_db, difference.mean_flip);
        eprintln!("{what:>24}: PSNR {psnr:.1} dB, mean FLIP {flip:.2e}");
        assert!(
            flip <= self.max_mean_flip && psnr >= self.min_psnr_db,
            "{what} on {}: PSNR {psnr:.1} dB, mean FLIP {flip:.2e}",
            gpu.adapter_name()
        );
        self.worst = (self.worst.0.min(psnr), self.worst.1.max(flip));
    }

    /// Whether `a` and `b` are further apart than the bounds allow: the bounds can fail.
    pub fn exceeded(&self, a: &Image, b: &Image, display: Display) -> bool {
        let difference = compare(a, b, display).unwrap();
        difference.mean_flip > self.max_mean_flip || difference.psnr_db < self.min_psnr_db
    }

    /// Prints the worst case.
    pub fn report(&self) {
        eprintln!(
            "worst: PSNR {:.1} dB, mean FLIP {:.2e}",
            self.worst.0, self.worst.1
        );
    }
}
