//! Newell's teapot (1975, public domain): 32 bicubic Bezier patches, `z` up, height 3.15.
//!
//! The patch data is embedded (`data/teapot.bpt`: the patch count, then per patch `3 3` and
//! 16 control points, row by row). Tessellation evaluates the Bernstein form; normals come from
//! the cross product of the partial derivatives. At the lid's and the bottom's poles one
//! derivative vanishes, so there the normal is taken a small step into the patch, where the
//! surface is regular.

use glam::Vec3;

use crate::mesh::Mesh;

const TEAPOT_BPT: &str = include_str!("../data/teapot.bpt");

/// How many patches the embedded teapot has.
pub const TEAPOT_PATCHES: usize = 32;

/// A bicubic Bezier patch: `points[row][column]`, `u` along rows, `v` along columns.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BezierPatch {
    /// The 4 x 4 control points.
    pub points: [[Vec3; 4]; 4],
}

/// The cubic Bernstein basis and its derivative at `t`.
fn bernstein(t: f32) -> ([f32; 4], [f32; 4]) {
    let s = 1.0 - t;
    (
        [s * s * s, 3.0 * t * s * s, 3.0 * t * t * s, t * t * t],
        [
            -3.0 * s * s,
            3.0 * s * s - 6.0 * t * s,
            6.0 * t * s - 3.0 * t * t,
            3.0 * t * t,
        ],
    )
}

impl BezierPatch {
    /// The point and its partial derivatives `(P, dP/du, dP/dv)` at `(u, v)` in `[0, 1]^2`.
    #[must_use]
    pub fn eval(&self, u: f32, v: f32) -> (Vec3, Vec3, Vec3) {
        let ((bu, du), (bv, dv)) = (bernstein(u), bernstein(v));
        let mut result = (Vec3::ZERO, Vec3::ZERO, Vec3::ZERO);
        for (row, points) in self.points.iter().enumerate() {
            for (column, &p) in points.iter().enumerate() {
                result.0 += bu[row] * bv[column] * p;
                result.1 += du[row] * bv[column] * p;
                result.2 += bu[row] * dv[column] * p;
            }
        }
        result
    }

    /// The outward unit normal `dP/dv x dP/du` at `(u, v)` (Newell's patches turn clockwise
    /// seen from outside), stepping into the patch where the surface is degenerate (a pole).
    #[must_use]
    pub fn normal(&self, u: f32, v: f32) -> Vec3 {
        const STEP: f32 = 1e-3;
        let (_, du, dv) = self.eval(u, v);
        dv.cross(du).try_normalize().unwrap_or_else(|| {
            let inward = |x: f32| if x < 0.5 { x + STEP } else { x - STEP };
            let (_, du, dv) = self.eval(inward(u), inward(v));
            dv.cross(du).normalize_or(Vec3::Z)
        })
    }

    /// The patch as a grid of `(level + 1)^2` vertices, counter-clockwise seen from outside.
    #[must_use]
    pub fn tessellate(&self, level: u32) -> Mesh {
        let level = level.max(1);
        let steps = level as f32;
        // Rows along v and columns along u, so that d/drow x d/dcolumn is the outward normal.
        crate::shapes::grid(level, level, |row, column| {
            let (u, v) = (column as f32 / steps, row as f32 / steps);
            (self.eval(u, v).0, self.normal(u, v))
        })
    }
}

/// Parses the embedded patch file.
fn patches() -> Vec<BezierPatch> {
    let numbers: Vec<f32> = TEAPOT_BPT
        .split_whitespace()
        .filter_map(|word| word.parse().ok())
        .collect();
    // Layout: count, then per patch: 3 3, then 16 x (x y z).
    numbers[1..]
        .chunks_exact(2 + 48)
        .map(|chunk| {
            let coords = &chunk[2..];
            let point = |k: usize| Vec3::new(coords[3 * k], coords[3 * k + 1], coords[3 * k + 2]);
            BezierPatch {
                points: core::array::from_fn(|row| {
                    core::array::from_fn(|column| point(4 * row + column))
                }),
            }
        })
        .collect()
}

/// The teapot, each patch tessellated into `level x level` quads.
#[must_use]
pub fn teapot(level: u32) -> Mesh {
    let mut mesh = Mesh::default();
    for patch in patches() {
        mesh.append(&patch.tessellate(level));
    }
    mesh
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn embedded_data_has_every_patch_and_corners_interpolate_control_points() {
        let all = patches();
        assert_eq!(all.len(), TEAPOT_PATCHES);
        for patch in &all {
            assert_eq!(patch.eval(0.0, 0.0).0, patch.points[0][0]);
            assert!((patch.eval(1.0, 1.0).0 - patch.points[3][3]).length() < 1e-6);
        }
    }

    #[test]
    fn teapot_is_the_documented_size_with_unit_finite_normals() {
        let mesh = teapot(8);
        let (lo, hi) = mesh.bounds().expect("not empty");
        assert!(lo.z.abs() < 1e-4 && (hi.z - 3.15).abs() < 1e-3, "{lo} {hi}");
        assert!(mesh
            .normals()
            .iter()
            .all(|n| n.is_finite() && (n.length() - 1.0).abs() < 1e-5));
    }

    /// Finite differences of the Bernstein form agree with the analytic derivatives.
    #[test]
    fn derivatives_match_finite_differences() {
        let patch = patches()[5];
        let (u, v, h) = (0.37, 0.61, 1e-3);
        let (_, du, dv) = patch.eval(u, v);
        let fd_u = (patch.eval(u + h, v).0 - patch.eval(u - h, v).0) / (2.0 * h);
        let fd_v = (patch.eval(u, v + h).0 - patch.eval(u, v - h).0) / (2.0 * h);
        assert!((du - fd_u).length() < 1e-2 * du.length().max(1.0));
        assert!((dv - fd_v).length() < 1e-2 * dv.length().max(1.0));
    }

    /// Outward faces: the body's normals point away from the axis, the lid's (not its knob's)
    /// and the rim's upwards, the bottom's downwards; each triangle's winding agrees with its
    /// normals.
    #[test]
    fn faces_and_normals_point_outwards() {
        let all = patches();
        let away_from_axis = |patch: &BezierPatch| {
            let p = patch.eval(0.5, 0.5).0;
            patch
                .normal(0.5, 0.5)
                .dot(Vec3::new(p.x, p.y, 0.0).normalize())
        };
        for (range, expected) in [(0..4, Vec3::Z), (24..28, Vec3::Z), (28..32, -Vec3::Z)] {
            for patch in &all[range] {
                assert!(patch.normal(0.5, 0.5).dot(expected) > 0.5);
            }
        }
        assert!(all[4..12].iter().all(|patch| away_from_axis(patch) > 0.5));
        let mesh = teapot(6);
        for t in mesh.triangles() {
            let [a, b, c] = t.map(|i| mesh.positions()[i as usize]);
            let mean_normal: Vec3 = t.iter().map(|&i| mesh.normals()[i as usize]).sum();
            let face = (b - a).cross(c - a);
            assert!(
                face.dot(mean_normal) > 0.0,
                "{t:?} {a} {b} {c} face {face} normals {mean_normal}"
            );
        }
    }
}
