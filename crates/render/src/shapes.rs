//! The built-in shapes: a UV sphere, a torus and a square plane, with exact normals.

use core::f32::consts::{PI, TAU};

use glam::Vec3;

use crate::mesh::Mesh;

/// A grid of `(rows + 1) x (columns + 1)` vertices from `point(row, column) -> (position,
/// normal)`, triangulated counter-clockwise when `d/drow x d/dcolumn` points outwards.
pub(crate) fn grid(rows: u32, columns: u32, point: impl Fn(u32, u32) -> (Vec3, Vec3)) -> Mesh {
    let mut positions = Vec::with_capacity(((rows + 1) * (columns + 1)) as usize);
    let mut normals = Vec::with_capacity(positions.capacity());
    for row in 0..=rows {
        for column in 0..=columns {
            let (p, n) = point(row, column);
            positions.push(p);
            normals.push(n);
        }
    }
    let index = |row: u32, column: u32| row * (columns + 1) + column;
    let mut triangles = Vec::with_capacity((2 * rows * columns) as usize);
    for row in 0..rows {
        for column in 0..columns {
            let (a, b) = (index(row, column), index(row + 1, column));
            let (c, d) = (index(row + 1, column + 1), index(row, column + 1));
            triangles.push([a, b, c]);
            triangles.push([a, c, d]);
        }
    }
    // Triangles at a pole (a sphere's, the teapot lid's) have no area, or only rounding
    // noise's, and no meaningful orientation: they are dropped.
    triangles.retain(|t| {
        let [pa, pb, pc] = t.map(|i| positions[i as usize]);
        let longest = (pb - pa).length_squared().max((pc - pa).length_squared());
        (pb - pa).cross(pc - pa).length() > 1e-5 * longest
    });
    Mesh::try_new(positions, normals, triangles).unwrap_or_default()
}

/// A sphere of `radius` centred at the origin, `rings` bands from pole to pole (`+z` to
/// `-z`) and `segments` around.
#[must_use]
pub fn sphere(radius: f32, segments: u32, rings: u32) -> Mesh {
    let (segments, rings) = (segments.max(3), rings.max(2));
    grid(rings, segments, |ring, segment| {
        // The poles exactly (sin(PI) is not 0 in f32), so their slivers are dropped as
        // degenerate instead of surviving with a random orientation.
        let (sin_theta, cos_theta) = match ring {
            0 => (0.0, 1.0),
            r if r == rings => (0.0, -1.0),
            _ => (PI * ring as f32 / rings as f32).sin_cos(),
        };
        let phi = TAU * segment as f32 / segments as f32;
        let normal = Vec3::new(sin_theta * phi.cos(), sin_theta * phi.sin(), cos_theta);
        (radius * normal, normal)
    })
}

/// A torus around the `z` axis: tube centre at distance `major` from the axis, tube radius
/// `minor`, `segments` around the axis and `sides` around the tube.
#[must_use]
pub fn torus(major: f32, minor: f32, segments: u32, sides: u32) -> Mesh {
    let (segments, sides) = (segments.max(3), sides.max(3));
    grid(segments, sides, |segment, side| {
        let u = TAU * segment as f32 / segments as f32;
        let v = TAU * side as f32 / sides as f32;
        let normal = Vec3::new(v.cos() * u.cos(), v.cos() * u.sin(), v.sin());
        let centre = Vec3::new(major * u.cos(), major * u.sin(), 0.0);
        (centre + minor * normal, normal)
    })
}

/// A square of side `size` in the `xy` plane, centred at the origin, facing `+z`.
#[must_use]
pub fn plane(size: f32) -> Mesh {
    let h = 0.5 * size;
    grid(1, 1, |row, column| {
        let x = if column == 0 { -h } else { h };
        let y = if row == 0 { h } else { -h };
        (Vec3::new(x, y, 0.0), Vec3::Z)
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn outward(mesh: &Mesh, centre_of: impl Fn(Vec3) -> Vec3) -> bool {
        mesh.triangles().iter().all(|t| {
            let [a, b, c] = t.map(|i| mesh.positions()[i as usize]);
            let centroid = (a + b + c) / 3.0;
            (b - a).cross(c - a).dot(centroid - centre_of(centroid)) > 0.0
        })
    }

    #[test]
    fn sphere_area_converges_to_four_pi_r_squared_and_faces_point_out() {
        let mesh = sphere(2.0, 256, 128);
        let exact = 4.0 * PI * 4.0;
        assert!(
            (mesh.area() - exact).abs() < 2e-3 * exact,
            "{}",
            mesh.area()
        );
        assert!(outward(&mesh, |_| Vec3::ZERO));
        for (p, n) in mesh.positions().iter().zip(mesh.normals()) {
            assert!((*p / 2.0 - *n).length() < 1e-6);
        }
    }

    #[test]
    fn torus_area_converges_to_four_pi_squared_r_r_and_faces_point_out() {
        let mesh = torus(2.0, 0.5, 256, 128);
        let exact = 4.0 * PI * PI * 2.0 * 0.5;
        assert!(
            (mesh.area() - exact).abs() < 2e-3 * exact,
            "{}",
            mesh.area()
        );
        assert!(outward(&mesh, |p| 2.0 * Vec3::new(p.x, p.y, 0.0).normalize()));
    }

    #[test]
    fn plane_faces_up() {
        let mesh = plane(3.0);
        assert_eq!(mesh.triangles().len(), 2);
        assert!((mesh.area() - 9.0).abs() < 1e-6);
        assert!(outward(&mesh, |p| p - Vec3::Z));
    }
}
