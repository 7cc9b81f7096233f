//! A scene described for Mitsuba 3 as its users would write it: a sphere as Mitsuba's own
//! `sphere` shape, every other object's mesh as an OBJ file (its vertices and normals, so both
//! renderers shade the same triangles), and a JSON file with the materials, the camera and
//! the environment, in the layout `mitsuba_check.py render` reads (the harness in
//! `crates/cli/tests/renderers/`, compiled into `specula bench environment`).

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use crate::camera::Projection;
use crate::mesh::Mesh;
use crate::scene::{Analytic, Scene};

/// Writes `scene` into `directory` as `<name>.json` and `<name>-object<i>.obj` (for the
/// objects without an exact shape), lit by the
/// environment file `environment` (relative to `directory`), rendered at `spp` samples per
/// pixel from `seed`; returns the JSON file's path. Mitsuba's film has the scene's pixels
/// (its box filter averages within each, as specula's positions within a pixel do).
///
/// # Errors
/// A file that cannot be written, or a camera that is not a perspective one (Mitsuba's
/// `perspective` sensor is the one matched to specula's).
pub fn write_mitsuba_scene(
    scene: &Scene,
    directory: &Path,
    name: &str,
    environment: &str,
    spp: u32,
    seed: u64,
) -> Result<PathBuf, String> {
    let Projection::Perspective { fov_y_degrees } = scene.camera.projection() else {
        return Err(
            "Mitsuba is given perspective cameras only; this scene's camera is orthographic".into(),
        );
    };
    let mut meshes = Vec::new();
    for (index, object) in scene.objects.iter().enumerate() {
        let m = &object.material;
        let (kd, ks) = (m.kd * m.colour, m.ks * m.specular_colour);
        let mut shape = serde_json::json!({
            "n": m.lobe.exponent().get(),
            "kd": kd.to_array(),
            "ks": ks.to_array(),
            "geometry": m.geometry.id(),
            "normalisation": m.normalisation.id(),
        });
        // A sphere as Mitsuba's own shape, as its users draw one (traced exactly, where
        // specula rasterizes its tessellation); anything else as its triangles.
        match object.analytic {
            Some(Analytic::Sphere { centre, radius }) => {
                shape["sphere"] = serde_json::json!({
                    "centre": centre.to_array(),
                    "radius": radius,
                });
            }
            None => {
                let file = format!("{name}-object{index}.obj");
                write_obj(&object.mesh, &directory.join(&file))?;
                shape["obj"] = file.into();
            }
        }
        meshes.push(shape);
    }
    let camera = scene.camera;
    let json = serde_json::json!({
        "environment": environment,
        "meshes": meshes,
        "camera": {
            "eye": camera.eye().to_array(),
            "target": camera.target().to_array(),
            "up": camera.up().to_array(),
            "fov": fov_y_degrees,
            "width": scene.settings.width,
            "height": scene.settings.height,
        },
        "spp": spp,
        "seed": seed,
    });
    let path = directory.join(format!("{name}.json"));
    std::fs::write(&path, json.to_string()).map_err(|e| format!("{}: {e}", path.display()))?;
    Ok(path)
}

/// `mesh` as an OBJ file: positions, normals, and triangles indexing both.
fn write_obj(mesh: &Mesh, path: &Path) -> Result<(), String> {
    let mut obj = String::new();
    for (p, n) in mesh.positions().iter().zip(mesh.normals()) {
        let _ = writeln!(obj, "v {} {} {}\nvn {} {} {}", p.x, p.y, p.z, n.x, n.y, n.z);
    }
    for [a, b, c] in mesh.triangles() {
        let [a, b, c] = [a + 1, b + 1, c + 1];
        let _ = writeln!(obj, "f {a}//{a} {b}//{b} {c}//{c}");
    }
    std::fs::write(path, obj).map_err(|e| format!("{}: {e}", path.display()))
}
