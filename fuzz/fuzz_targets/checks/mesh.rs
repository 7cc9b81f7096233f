//! The mesh targets' check, also run by `crates/render/tests/fuzz_regressions.rs` on the seeds
//! and every crash input kept in `fuzz/regressions/`.

use specula_render::{parse_mesh, MeshFormat};

/// A loader must answer any bytes with a mesh or an error, never a panic; a mesh it accepts
/// has only finite positions and in-range indices.
pub fn check_mesh(data: &[u8], format: MeshFormat) {
    if let Ok(loaded) = parse_mesh(std::io::Cursor::new(data), format) {
        let mesh = loaded.mesh;
        assert!(mesh.positions().iter().all(|p| p.is_finite()));
        assert!(mesh
            .triangles()
            .iter()
            .flatten()
            .all(|&i| (i as usize) < mesh.positions().len()));
    }
}
