//! Indexed triangle meshes with per-vertex normals.

use glam::Vec3;
use thiserror::Error;

/// Why mesh data was refused.
#[derive(Clone, Debug, Error, PartialEq)]
#[non_exhaustive]
pub enum MeshError {
    /// A position or normal with a NaN or infinite coordinate.
    #[error(
        "vertex {index} has a non-finite {what} ({value}); every coordinate must be a finite \
        number"
    )]
    NonFinite {
        /// The vertex.
        index: usize,
        /// `position` or `normal`.
        what: &'static str,
        /// The offending vector, formatted.
        value: String,
    },
    /// A triangle that names a vertex the mesh does not have.
    #[error("triangle {triangle} refers to vertex {vertex}, but the mesh has {count} vertices")]
    IndexOutOfRange {
        /// The triangle.
        triangle: usize,
        /// The vertex index it names.
        vertex: u32,
        /// How many vertices there are.
        count: usize,
    },
    /// Positions and normals of different lengths.
    #[error("{positions} positions but {normals} normals; each vertex needs one of each")]
    LengthMismatch {
        /// Number of positions.
        positions: usize,
        /// Number of normals.
        normals: usize,
    },
}

/// An indexed triangle mesh: counter-clockwise triangles seen from outside, unit normals.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Mesh {
    positions: Vec<Vec3>,
    normals: Vec<Vec3>,
    triangles: Vec<[u32; 3]>,
}

impl Mesh {
    /// A mesh from its parts, validated: finite coordinates, indices in range, one normal per
    /// position. Normals are renormalised; a zero normal is replaced by the average of the
    /// face normals around the vertex (or `+z` for an isolated vertex).
    pub fn try_new(
        positions: Vec<Vec3>,
        normals: Vec<Vec3>,
        triangles: Vec<[u32; 3]>,
    ) -> Result<Self, MeshError> {
        if positions.len() != normals.len() {
            return Err(MeshError::LengthMismatch {
                positions: positions.len(),
                normals: normals.len(),
            });
        }
        for (index, (p, n)) in positions.iter().zip(&normals).enumerate() {
            for (what, v) in [("position", p), ("normal", n)] {
                if !v.is_finite() {
                    return Err(MeshError::NonFinite {
                        index,
                        what,
                        value: format!("{v}"),
                    });
                }
            }
        }
        for (triangle, corners) in triangles.iter().enumerate() {
            if let Some(&vertex) = corners.iter().find(|&&v| v as usize >= positions.len()) {
                return Err(MeshError::IndexOutOfRange {
                    triangle,
                    vertex,
                    count: positions.len(),
                });
            }
        }
        let mut mesh = Self {
            positions,
            normals,
            triangles,
        };
        mesh.repair_normals();
        Ok(mesh)
    }

    fn repair_normals(&mut self) {
        let mut face_sums = vec![Vec3::ZERO; self.positions.len()];
        for &[a, b, c] in &self.triangles {
            let [pa, pb, pc] = [a, b, c].map(|i| self.positions[i as usize]);
            let face = (pb - pa).cross(pc - pa);
            for i in [a, b, c] {
                face_sums[i as usize] += face;
            }
        }
        for (normal, sum) in self.normals.iter_mut().zip(face_sums) {
            *normal = normal
                .try_normalize()
                .or_else(|| sum.try_normalize())
                .unwrap_or(Vec3::Z);
        }
    }

    /// Vertex positions.
    #[must_use]
    pub fn positions(&self) -> &[Vec3] {
        &self.positions
    }

    /// Unit vertex normals.
    #[must_use]
    pub fn normals(&self) -> &[Vec3] {
        &self.normals
    }

    /// Triangles as vertex indices.
    #[must_use]
    pub fn triangles(&self) -> &[[u32; 3]] {
        &self.triangles
    }

    /// Appends `other` (for meshes built from several parts).
    pub fn append(&mut self, other: &Mesh) {
        let offset = self.positions.len() as u32;
        self.positions.extend_from_slice(&other.positions);
        self.normals.extend_from_slice(&other.normals);
        self.triangles
            .extend(other.triangles.iter().map(|t| t.map(|i| i + offset)));
    }

    /// The same surface seen from the other side: winding reversed, normals negated (for a
    /// dome or room the camera sits inside).
    #[must_use]
    pub fn flipped(&self) -> Mesh {
        Mesh {
            positions: self.positions.clone(),
            normals: self.normals.iter().map(|&n| -n).collect(),
            triangles: self.triangles.iter().map(|&[a, b, c]| [a, c, b]).collect(),
        }
    }

    /// The axis-aligned bounds `(min, max)`; `None` for an empty mesh.
    #[must_use]
    pub fn bounds(&self) -> Option<(Vec3, Vec3)> {
        let first = *self.positions.first()?;
        Some(
            self.positions
                .iter()
                .fold((first, first), |(lo, hi), &p| (lo.min(p), hi.max(p))),
        )
    }

    /// Total surface area.
    #[must_use]
    pub fn area(&self) -> f32 {
        self.triangles
            .iter()
            .map(|&[a, b, c]| {
                let [pa, pb, pc] = [a, b, c].map(|i| self.positions[i as usize]);
                0.5 * (pb - pa).cross(pc - pa).length()
            })
            .sum()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn refuses_bad_data_with_a_message_naming_it() {
        let p = vec![Vec3::ZERO, Vec3::X, Vec3::Y];
        let n = vec![Vec3::Z; 3];
        let error = Mesh::try_new(
            vec![Vec3::ZERO, Vec3::new(f32::NAN, 0.0, 0.0), Vec3::Y],
            n.clone(),
            vec![[0, 1, 2]],
        )
        .unwrap_err();
        assert!(error.to_string().contains("vertex 1"), "{error}");
        assert!(matches!(
            Mesh::try_new(p.clone(), n.clone(), vec![[0, 1, 3]]),
            Err(MeshError::IndexOutOfRange { vertex: 3, .. })
        ));
        assert!(Mesh::try_new(p, vec![Vec3::Z], vec![]).is_err());
    }

    #[test]
    fn zero_normals_are_replaced_by_the_face_normal() {
        let mesh = Mesh::try_new(
            vec![Vec3::ZERO, Vec3::X, Vec3::Y],
            vec![Vec3::ZERO, Vec3::new(0.0, 0.0, 2.0), Vec3::ZERO],
            vec![[0, 1, 2]],
        )
        .unwrap();
        assert!(mesh
            .normals()
            .iter()
            .all(|&n| (n - Vec3::Z).length() < 1e-7));
        assert!((mesh.area() - 0.5).abs() < 1e-7);
    }
}
