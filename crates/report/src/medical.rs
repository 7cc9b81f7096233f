//! What the medical section's two halves share (the phantom in `volumes.rs`, the real scans
//! in `real_scans.rs`): the lobes' exponent and shading, and how a frame's times are told.

use specula::{Exponent, Geometry, Lobe, LobeKind, Normalisation};
use specula_volume::dvr::Shading;

/// The exponent of every lobe in the section (VTK's specular power in the comparison).
pub(crate) const EXPONENT: f64 = 32.0;

/// The section's shading with `kind` as the specular term.
pub(crate) fn shading(kind: LobeKind) -> Result<Shading, String> {
    let n = Exponent::try_new(EXPONENT).map_err(|e| e.to_string())?;
    Ok(Shading::new(
        Lobe::new(kind, n),
        Geometry::Blinn,
        Normalisation::ThesisPhong,
    ))
}

/// The sentence giving pow's frame alone and every lobe's from one march, `on` the CPU's
/// threads or the GPU.
#[must_use]
pub(crate) fn march_times(on: &str, alone_ms: f64, together_ms: f64, lobes: usize) -> String {
    format!(
        "One frame on {on}: pow alone {alone_ms:.1} ms; all {lobes} lobes' images from one march \
            {together_ms:.1} ms, {:.1} ms a lobe beyond the first (each image bit for bit the one \
            marched for its lobe alone).",
        (together_ms - alone_ms) / (lobes.max(2) - 1) as f64,
    )
}

/// [`march_times`]' `on` for the CPU.
#[must_use]
pub(crate) fn cpu_threads() -> String {
    format!("{} threads", rayon::current_num_threads())
}
