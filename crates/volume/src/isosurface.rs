//! Isosurfaces by marching cubes, rendered with the rasterizer like any mesh.
//!
//! The case table (which cube edges each of the 256 inside/outside patterns joins into
//! polygons) is built here on first use rather than typed in, by the construction the
//! published tables come from: on each of the cube's six faces, walked counter-clockwise as
//! seen from outside, every run of inside corners contributes one segment from the edge where
//! the walk enters it to the edge where it leaves; the segments chain into closed polygons,
//! which are fanned into triangles. A face with two diagonal inside corners (the ambiguous
//! case) cuts each corner off on its own. Because that choice depends on the face's four
//! corners alone, the two cubes sharing a face agree on it, so the surface has no holes
//! (the cracks of the original 1987 table), and every polygon winds with the outside
//! (values below the isovalue) on its front.
//!
//! "Inside" is a value at or above the isovalue: bone in CT, the object in a phantom.
//! Vertices lie on cube edges by linear interpolation, are shared between the cubes around an
//! edge, and take their normals from the volume's gradient (pointing down it, out of the
//! surface).

use std::collections::HashMap;
use std::sync::OnceLock;

use glam::Vec3;
use specula_render::{
    render, Display, IlluminationModel, Image, Light, Material, Mesh, Object, Scene, Settings,
};

use crate::dvr::{surface_camera, View};
use crate::lighting::Shading;
use crate::volume::{Units, Volume, VolumeError};

/// The most triangles an isosurface may have (about 1.5 GiB of mesh).
pub const MAX_TRIANGLES: usize = 1 << 25;

/// Corner `c` of the unit cube sits at `(c & 1, c >> 1 & 1, c >> 2 & 1)`.
fn corner_offset(corner: usize) -> [usize; 3] {
    [corner & 1, corner >> 1 & 1, corner >> 2 & 1]
}

/// The twelve edges as (lower corner, axis).
fn edges() -> [(usize, usize); 12] {
    core::array::from_fn(|e| {
        let axis = e / 4;
        let others = e % 4;
        // Spread the two bits of `others` over the corner bits that are not `axis`.
        let (u, w) = ((axis + 1) % 3, (axis + 2) % 3);
        ((others & 1) << u | (others >> 1 & 1) << w, axis)
    })
}

/// Each case's triangles, as triples of cube edges.
fn case_table() -> &'static [Vec<[u8; 3]>; 256] {
    static TABLE: OnceLock<[Vec<[u8; 3]>; 256]> = OnceLock::new();
    TABLE.get_or_init(|| core::array::from_fn(triangulate_case))
}

fn triangulate_case(case: usize) -> Vec<[u8; 3]> {
    let edges = edges();
    let edge_between = |a: usize, b: usize| -> u8 {
        let (low, high) = (a.min(b), a.max(b));
        let axis = (high ^ low).trailing_zeros() as usize;
        edges
            .iter()
            .position(|&(corner, along)| corner == low && along == axis)
            .expect("corners of one face edge differ in one bit") as u8
    };
    let inside = |corner: usize| case >> corner & 1 == 1;
    let mut next: [Option<u8>; 12] = [None; 12];
    for axis in 0..3 {
        let (u, w) = ((axis + 1) % 3, (axis + 2) % 3);
        for side in 0..2 {
            // (u, w) = (0,0), (1,0), (1,1), (0,1) turns counter-clockwise about +axis since
            // u x w = axis; the face at side 0 is seen from -axis, so it is walked backwards.
            let mut cycle =
                [(0, 0), (1, 0), (1, 1), (0, 1)].map(|(a, b)| side << axis | a << u | b << w);
            if side == 0 {
                cycle.reverse();
            }
            let crossing = |i: usize| edge_between(cycle[i], cycle[(i + 1) % 4]);
            for i in 0..4 {
                let entering = !inside(cycle[i]) && inside(cycle[(i + 1) % 4]);
                if !entering {
                    continue;
                }
                let leaving = (1..4)
                    .map(|step| (i + step) % 4)
                    .find(|&j| inside(cycle[j]) && !inside(cycle[(j + 1) % 4]))
                    .expect("a walk that enters the inside leaves it");
                next[usize::from(crossing(i))] = Some(crossing(leaving));
            }
        }
    }
    let mut triangles = Vec::new();
    let mut visited = [false; 12];
    for start in 0..12 {
        if next[start].is_none() || visited[start] {
            continue;
        }
        let mut polygon = vec![start as u8];
        visited[start] = true;
        let mut edge = next[start].expect("checked above");
        while usize::from(edge) != start {
            visited[usize::from(edge)] = true;
            polygon.push(edge);
            edge = next[usize::from(edge)].expect("every entered edge is left on another face");
        }
        for pair in polygon[1..].windows(2) {
            triangles.push([polygon[0], pair[0], pair[1]]);
        }
    }
    triangles
}

/// The surface where `volume` crosses `iso`, in world millimetres.
pub fn marching_cubes(volume: &Volume, iso: f32) -> Result<Mesh, VolumeError> {
    if !iso.is_finite() {
        return Err(VolumeError(format!("the isovalue {iso} must be finite")));
    }
    let table = case_table();
    let edges = edges();
    let [nx, ny, nz] = volume.dims();
    let value = |p: [usize; 3]| volume.samples().get(p[0] + nx * (p[1] + ny * p[2]));
    let mut vertex_of_edge: HashMap<(usize, usize), u32> = HashMap::new();
    let mut positions = Vec::new();
    let mut triangles = Vec::new();
    for k in 0..nz - 1 {
        for j in 0..ny - 1 {
            for i in 0..nx - 1 {
                let corner = |c: usize| {
                    let [x, y, z] = corner_offset(c);
                    [i + x, j + y, k + z]
                };
                let case = (0..8).fold(0, |case, c| {
                    case | usize::from(value(corner(c)) >= iso) << c
                });
                for triangle in &table[case] {
                    let mut ids = [0_u32; 3];
                    for (id, &edge) in ids.iter_mut().zip(triangle) {
                        let (low, axis) = edges[usize::from(edge)];
                        let a = corner(low);
                        let key = (a[0] + nx * (a[1] + ny * a[2]), axis);
                        *id = *vertex_of_edge.entry(key).or_insert_with(|| {
                            let mut b = a;
                            b[axis] += 1;
                            let (va, vb) = (value(a), value(b));
                            let t = ((iso - va) / (vb - va)).clamp(0.0, 1.0);
                            let index = Vec3::new(a[0] as f32, a[1] as f32, a[2] as f32)
                                + t * Vec3::new(
                                    (b[0] - a[0]) as f32,
                                    (b[1] - a[1]) as f32,
                                    (b[2] - a[2]) as f32,
                                );
                            positions.push(index);
                            (positions.len() - 1) as u32
                        });
                    }
                    triangles.push(ids);
                }
                if triangles.len() > MAX_TRIANGLES {
                    return Err(VolumeError(format!(
                        "the isosurface at {iso} has more than {MAX_TRIANGLES} triangles; choose \
                            another value or a smaller volume"
                    )));
                }
            }
        }
    }
    let normals = positions
        .iter()
        .map(|&index| -volume.gradient(index).normalize_or_zero())
        .collect();
    let world = positions.iter().map(|&index| volume.world(index)).collect();
    let mesh = Mesh::try_new(world, normals, triangles).map_err(|e| VolumeError(e.to_string()))?;
    // A world map that mirrors (negative determinant) turns the index-space winding over.
    Ok(if volume.to_world().determinant() < 0.0 {
        mesh.flipped()
    } else {
        mesh
    })
}

/// The default isovalue: 300 HU (bone) for CT, else the middle of the volume's range.
#[must_use]
pub fn default_isovalue(volume: &Volume) -> f32 {
    match volume.units() {
        Units::Hounsfield => 300.0,
        Units::Arbitrary => {
            let (lo, hi) = volume.range();
            0.5 * (lo + hi)
        }
    }
}

/// An isosurface to draw: the value, the view and how it is lit.
#[derive(Clone, Copy, Debug)]
pub struct IsoSettings {
    /// Image width in pixels.
    pub width: u32,
    /// Image height in pixels.
    pub height: u32,
    /// The view, framed as direct volume rendering frames it.
    pub view: View,
    /// The isovalue.
    pub iso: f32,
    /// The material's lobe and weights (the light is the ray marcher's).
    pub shading: Shading,
    /// Flat, Gouraud or Phong interpolation.
    pub method: specula_render::Shading,
    /// Supersampling per axis.
    pub samples: u32,
}

/// The colour of an isosurface: ivory, as bone is usually drawn.
const IVORY: Vec3 = Vec3::new(0.9, 0.82, 0.68);

/// The scene that draws `mesh` (an isosurface of `volume`) as `settings` asks, for the CPU
/// rasterizer or the GPU.
pub fn iso_scene(
    volume: &Volume,
    mesh: Mesh,
    settings: &IsoSettings,
) -> Result<Scene, VolumeError> {
    let (camera, towards) = surface_camera(settings.view, volume)?;
    let shading = settings.shading;
    let material = Material {
        ka: shading.ka,
        kd: shading.kd,
        ks: shading.ks,
        colour: IVORY,
        specular_colour: Vec3::ONE,
        lobe: shading.lobe,
        geometry: shading.geometry,
        normalisation: shading.normalisation,
    };
    let scene = Scene {
        camera,
        lights: vec![Light::Directional {
            towards,
            intensity: Vec3::ONE,
        }],
        ambient: Vec3::ONE,
        objects: vec![Object {
            mesh,
            analytic: None,
            material,
        }],
        settings: Settings {
            width: settings.width,
            height: settings.height,
            samples: settings.samples,
            shading: settings.method,
            model: IlluminationModel::Classic,
            // Where the grid's boundary cuts the surface open, its inside shows.
            cull_back_faces: false,
            background: Vec3::ZERO,
        },
        display: Display::default(),
    };
    scene
        .settings
        .validate()
        .map_err(|e| VolumeError(e.to_string()))?;
    Ok(scene)
}

/// Extracts the isosurface and draws it with the CPU rasterizer.
pub fn render_isosurface(
    volume: &Volume,
    settings: &IsoSettings,
    progress: &(dyn Fn(usize, usize) + Sync),
) -> Result<Image, VolumeError> {
    let mesh = marching_cubes(volume, settings.iso)?;
    let scene = iso_scene(volume, mesh, settings)?;
    render(&scene, progress).map_err(|e| VolumeError(e.to_string()))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A ball of radius `radius` voxels: values fall through 0 at the sphere.
    fn ball(side: usize, radius: f32, spacing: Vec3) -> Volume {
        let centre = (side - 1) as f32 / 2.0 + 0.137;
        let mut samples = Vec::with_capacity(side * side * side);
        for k in 0..side {
            for j in 0..side {
                for i in 0..side {
                    let d = Vec3::new(i as f32, j as f32, k as f32) - centre;
                    samples.push(radius - (d * spacing).length());
                }
            }
        }
        Volume::centred([side; 3], spacing, samples, Units::Arbitrary).unwrap()
    }

    /// Euler characteristic, and whether every edge is shared by exactly two triangles that
    /// cross it in opposite directions (a closed, consistently oriented surface).
    fn topology(mesh: &Mesh) -> (i64, bool) {
        let mut directed: HashMap<(u32, u32), usize> = HashMap::new();
        for &[a, b, c] in mesh.triangles() {
            for edge in [(a, b), (b, c), (c, a)] {
                *directed.entry(edge).or_default() += 1;
            }
        }
        let closed = directed
            .iter()
            .all(|(&(a, b), &count)| count == 1 && directed.get(&(b, a)) == Some(&1));
        let edges = directed.len() as i64 / 2;
        let euler = mesh.positions().len() as i64 - edges + mesh.triangles().len() as i64;
        (euler, closed)
    }

    fn signed_volume(mesh: &Mesh) -> f32 {
        let p = mesh.positions();
        mesh.triangles()
            .iter()
            .map(|&[a, b, c]| p[a as usize].dot(p[b as usize].cross(p[c as usize])) / 6.0)
            .sum()
    }

    #[test]
    fn every_case_uses_each_crossed_edge_once_as_a_vertex() {
        let table = case_table();
        assert!(table[0].is_empty() && table[255].is_empty());
        for (case, triangles) in table.iter().enumerate() {
            let crossed = edges()
                .iter()
                .filter(|&&(low, axis)| (case >> low & 1) != (case >> (low | 1 << axis) & 1))
                .count();
            let used: std::collections::BTreeSet<u8> =
                triangles.iter().flatten().copied().collect();
            assert_eq!(
                used.len(),
                crossed,
                "case {case}: each crossed edge is a vertex"
            );
        }
    }

    #[test]
    fn a_sphere_is_closed_oriented_of_genus_zero_and_of_the_right_area() {
        let radius = 20.0;
        for spacing in [Vec3::ONE, Vec3::new(0.8, 1.0, 1.25)] {
            let mesh = marching_cubes(&ball(56, radius, spacing), 0.0).unwrap();
            let (euler, closed) = topology(&mesh);
            assert!(closed, "{spacing}: open or inconsistently wound");
            assert_eq!(euler, 2, "{spacing}");
            let area = 4.0 * std::f32::consts::PI * radius * radius;
            assert!(
                (mesh.area() - area).abs() < 0.01 * area,
                "{spacing}: area {} for {area}",
                mesh.area()
            );
            // Outside (lower values) in front: the enclosed volume is positive.
            let volume = 4.0 / 3.0 * std::f32::consts::PI * radius.powi(3);
            assert!((signed_volume(&mesh) - volume).abs() < 0.01 * volume);
            // Normals from the gradient point away from the centre, as the winding does.
            let centre = mesh.positions().iter().sum::<Vec3>() / mesh.positions().len() as f32;
            for (p, n) in mesh.positions().iter().zip(mesh.normals()) {
                assert!((*p - centre).normalize().dot(*n) > 0.95);
            }
        }
    }

    #[test]
    fn two_balls_and_a_ring_have_the_euler_characteristics_of_their_topology() {
        let side = 40;
        let field = |f: &dyn Fn(Vec3) -> f32| {
            let mut samples = Vec::new();
            for k in 0..side {
                for j in 0..side {
                    for i in 0..side {
                        let p = Vec3::new(i as f32, j as f32, k as f32) - 19.63;
                        samples.push(f(p));
                    }
                }
            }
            Volume::centred([side; 3], Vec3::ONE, samples, Units::Arbitrary).unwrap()
        };
        let balls = field(&|p| {
            (7.0 - (p - Vec3::X * 9.0).length()).max(7.0 - (p + Vec3::X * 9.0).length())
        });
        let (euler, closed) = topology(&marching_cubes(&balls, 0.0).unwrap());
        assert!(closed);
        assert_eq!(euler, 4, "two spheres");
        let torus = field(&|p| 4.0 - Vec3::new(p.truncate().length() - 11.0, p.z, 0.0).length());
        let (euler, closed) = topology(&marching_cubes(&torus, 0.0).unwrap());
        assert!(closed);
        assert_eq!(euler, 0, "a torus");
    }
}
