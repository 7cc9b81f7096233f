//! Homogeneous clipping of triangles against the near and far planes and a guard band.
//!
//! Only the near plane is needed for correctness (it keeps `w > 0`); the far plane keeps depth
//! in `[0, 1]`, and the guard band (far outside the image) keeps screen coordinates small enough
//! for the rasterizer's exact fixed point. Triangles inside the guard band are never cut at the
//! image border: the rasterizer's bounds do that for free and without new vertices.
//!
//! A cut edge's new vertex is always computed from its inside end towards its outside end, so
//! the two triangles sharing an edge produce the bit-identical vertex and stay watertight.

use glam::{Vec3, Vec4};

use crate::raster::MAX_COORDINATE;

/// What the pipeline interpolates across a triangle: world position, normal and colour
/// (the vertex colour of Gouraud shading).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub(crate) struct Varyings {
    pub position: Vec3,
    pub normal: Vec3,
    pub colour: Vec3,
}

impl Varyings {
    fn lerp(&self, other: &Varyings, t: f32) -> Varyings {
        Varyings {
            position: self.position.lerp(other.position, t),
            normal: self.normal.lerp(other.normal, t),
            colour: self.colour.lerp(other.colour, t),
        }
    }
}

/// A vertex in clip space with its varyings.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct ClipVertex {
    pub clip: Vec4,
    pub varyings: Varyings,
}

/// How far outside the image (in multiples of its half-size) triangles may reach before they
/// are cut. The rasterizer's coordinate bound allows `(GUARD_BAND + 1) / 2 * size` pixels.
pub(crate) const GUARD_BAND: f32 = 64.0;

/// The largest image side (in samples) the guard band keeps within the rasterizer's range.
pub(crate) const MAX_SIDE: u32 = (2.0 * MAX_COORDINATE / (GUARD_BAND + 1.0)) as u32;

/// Signed distances to the clipping planes, non-negative inside: near (`z >= 0`), far
/// (`z <= w`) and the guard band's four sides (`|x|, |y| <= G w`).
fn plane_distance(plane: usize, v: Vec4) -> f32 {
    match plane {
        0 => v.z,
        1 => v.w - v.z,
        2 => GUARD_BAND * v.w + v.x,
        3 => GUARD_BAND * v.w - v.x,
        4 => GUARD_BAND * v.w + v.y,
        _ => GUARD_BAND * v.w - v.y,
    }
}

/// Clips a triangle and writes the result, a convex polygon of 0 or 3 to 9 vertices, to
/// `polygon` (cleared first). `scratch` is reused storage.
pub(crate) fn clip_triangle(
    triangle: [ClipVertex; 3],
    polygon: &mut Vec<ClipVertex>,
    scratch: &mut Vec<ClipVertex>,
) {
    polygon.clear();
    polygon.extend_from_slice(&triangle);
    let all_inside = |polygon: &[ClipVertex]| {
        polygon
            .iter()
            .all(|v| (0..6).all(|plane| plane_distance(plane, v.clip) >= 0.0))
    };
    if all_inside(polygon) {
        return;
    }
    for plane in 0..6 {
        scratch.clear();
        for (k, current) in polygon.iter().enumerate() {
            let next = &polygon[(k + 1) % polygon.len()];
            let (d_current, d_next) = (
                plane_distance(plane, current.clip),
                plane_distance(plane, next.clip),
            );
            if d_current >= 0.0 {
                scratch.push(*current);
            }
            if (d_current >= 0.0) != (d_next >= 0.0) {
                let (inside, outside, d_in, d_out) = if d_current >= 0.0 {
                    (current, next, d_current, d_next)
                } else {
                    (next, current, d_next, d_current)
                };
                let t = d_in / (d_in - d_out);
                scratch.push(ClipVertex {
                    clip: inside.clip.lerp(outside.clip, t),
                    varyings: inside.varyings.lerp(&outside.varyings, t),
                });
            }
        }
        core::mem::swap(polygon, scratch);
        if polygon.len() < 3 {
            polygon.clear();
            return;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn vertex(x: f32, y: f32, z: f32, w: f32) -> ClipVertex {
        ClipVertex {
            clip: Vec4::new(x, y, z, w),
            varyings: Varyings {
                colour: Vec3::new(z, w, 0.0),
                ..Varyings::default()
            },
        }
    }

    #[test]
    fn inside_triangles_pass_unchanged_and_outside_ones_vanish() {
        let (mut polygon, mut scratch) = (Vec::new(), Vec::new());
        let inside = [
            vertex(0.0, 0.0, 0.5, 1.0),
            vertex(1.0, 0.0, 0.5, 1.0),
            vertex(0.0, 1.0, 0.5, 1.0),
        ];
        clip_triangle(inside, &mut polygon, &mut scratch);
        assert_eq!(polygon, inside.to_vec());
        let behind = [
            vertex(0.0, 0.0, -0.5, 1.0),
            vertex(1.0, 0.0, -0.5, 1.0),
            vertex(0.0, 1.0, -0.1, 1.0),
        ];
        clip_triangle(behind, &mut polygon, &mut scratch);
        assert!(polygon.is_empty());
    }

    #[test]
    fn near_plane_cut_puts_new_vertices_on_the_plane_with_interpolated_varyings() {
        let (mut polygon, mut scratch) = (Vec::new(), Vec::new());
        let crossing = [
            vertex(0.0, 0.0, -1.0, 1.0),
            vertex(1.0, 0.0, 1.0, 3.0),
            vertex(0.0, 1.0, 1.0, 3.0),
        ];
        clip_triangle(crossing, &mut polygon, &mut scratch);
        assert_eq!(polygon.len(), 4);
        for v in &polygon {
            assert!(v.clip.z >= -1e-6);
            // colour carries (z, w): interpolated exactly like the position.
            assert!((v.varyings.colour.x - v.clip.z).abs() < 1e-6);
            assert!((v.varyings.colour.y - v.clip.w).abs() < 1e-6);
        }
        let new = polygon.iter().filter(|v| !crossing.contains(v));
        assert!(new.clone().all(|v| v.clip.z.abs() < 1e-6));
        assert_eq!(new.count(), 2);
    }

    #[test]
    fn a_shared_edge_is_cut_at_the_same_point_from_both_sides() {
        let (a, b) = (vertex(0.3, 0.1, -0.7, 1.0), vertex(0.9, 0.4, 0.8, 2.7));
        let (mut first, mut second, mut scratch) = (Vec::new(), Vec::new(), Vec::new());
        clip_triangle(
            [a, b, vertex(-1.0, 1.0, 0.5, 1.5)],
            &mut first,
            &mut scratch,
        );
        clip_triangle(
            [b, a, vertex(1.0, -1.0, 0.5, 1.5)],
            &mut second,
            &mut scratch,
        );
        let on_plane = |p: &Vec<ClipVertex>| {
            p.iter()
                .filter(|v| v.clip.z.abs() < 1e-6)
                .map(|v| v.clip)
                .collect::<Vec<_>>()
        };
        let shared: Vec<_> = on_plane(&first)
            .into_iter()
            .filter(|v| on_plane(&second).contains(v))
            .collect();
        assert_eq!(shared.len(), 1, "{first:?} {second:?}");
    }
}
