//! Mesh files: Wavefront OBJ (via `tobj`), STL binary and ASCII (via `stl_io`) and PLY ASCII
//! and binary (via `ply-rs-bw`).
//!
//! Polygons are fan-triangulated. Missing normals (always, for STL) are left zero, which
//! [`Mesh::try_new`] replaces with the area-weighted average of the faces around the vertex.
//! Degenerate triangles (repeated corners, zero area) are dropped and counted, so a caller can
//! say so; non-finite coordinates and out-of-range indices refuse the file with the reason.

use std::io::{BufRead, BufReader, Seek};
use std::path::Path;

use glam::Vec3;
use thiserror::Error;

use crate::mesh::{Mesh, MeshError};

/// A mesh file that could not be used, and why.
#[derive(Debug, Error)]
#[error("{path}: {message}")]
pub struct LoadError {
    /// The file.
    pub path: String,
    /// What is wrong with it.
    pub message: String,
}

/// A loaded mesh and how many degenerate triangles were dropped from it.
#[derive(Clone, Debug)]
pub struct LoadedMesh {
    /// The mesh.
    pub mesh: Mesh,
    /// Triangles dropped for having no area.
    pub degenerate_triangles: usize,
}

/// The file extensions [`load_mesh`] reads.
pub const MESH_EXTENSIONS: [&str; 3] = ["obj", "stl", "ply"];

/// A mesh file format.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum MeshFormat {
    /// Wavefront OBJ.
    Obj,
    /// STL, binary or ASCII.
    Stl,
    /// PLY, ASCII or binary.
    Ply,
}

impl MeshFormat {
    /// The format named by `path`'s extension.
    pub fn of_path(path: &Path) -> Result<Self, String> {
        let extension = path
            .extension()
            .and_then(|e| e.to_str())
            .map(str::to_ascii_lowercase)
            .unwrap_or_default();
        match extension.as_str() {
            "obj" => Ok(Self::Obj),
            "stl" => Ok(Self::Stl),
            "ply" => Ok(Self::Ply),
            _ => Err(format!(
                "unknown mesh format; the extension must be one of {}",
                MESH_EXTENSIONS.join(", ")
            )),
        }
    }
}

/// Loads a mesh, choosing the format by the file's extension.
pub fn load_mesh(path: &Path) -> Result<LoadedMesh, LoadError> {
    let fail = |message: String| LoadError {
        path: path.display().to_string(),
        message,
    };
    let format = MeshFormat::of_path(path).map_err(fail)?;
    let file = crate::input::open_regular(path).map_err(fail)?;
    parse_mesh(BufReader::new(file), format).map_err(fail)
}

/// Reads a mesh in `format` from `reader`: what [`load_mesh`] does after opening the file.
pub fn parse_mesh(
    mut reader: impl BufRead + Seek,
    format: MeshFormat,
) -> Result<LoadedMesh, String> {
    let (positions, normals, polygons) = match format {
        MeshFormat::Obj => read_obj(&mut reader),
        MeshFormat::Stl => read_stl(&mut reader),
        MeshFormat::Ply => read_ply(&mut reader),
    }?;
    build(positions, normals, &polygons).map_err(|error| error.to_string())
}

type Parts = (Vec<Vec3>, Vec<Vec3>, Vec<Vec<u32>>);

/// Triangulates, drops degenerate triangles and validates.
fn build(
    positions: Vec<Vec3>,
    normals: Vec<Vec3>,
    polygons: &[Vec<u32>],
) -> Result<LoadedMesh, MeshError> {
    let mut triangles = Vec::new();
    let mut degenerate_triangles = 0;
    for polygon in polygons {
        for k in 1..polygon.len().saturating_sub(1) {
            let triangle = [polygon[0], polygon[k], polygon[k + 1]];
            let corners = triangle.map(|i| positions.get(i as usize).copied());
            let area = match corners {
                [Some(a), Some(b), Some(c)] => (b - a).cross(c - a).length_squared(),
                // Out of range: keep it so that validation names the index.
                _ => f32::INFINITY,
            };
            if area > 0.0 || area.is_nan() {
                triangles.push(triangle);
            } else {
                degenerate_triangles += 1;
            }
        }
    }
    let normals = if normals.len() == positions.len() {
        normals
    } else {
        vec![Vec3::ZERO; positions.len()]
    };
    Ok(LoadedMesh {
        mesh: Mesh::try_new(positions, normals, triangles)?,
        degenerate_triangles,
    })
}

fn read_obj(reader: &mut impl BufRead) -> Result<Parts, String> {
    let options = tobj::LoadOptions {
        triangulate: false,
        single_index: true,
        ..tobj::LoadOptions::default()
    };
    // Materials are not used: a referenced .mtl file is not read.
    let (models, _materials) =
        tobj::load_obj_buf(reader, &options, |_| Err(tobj::LoadError::OpenFileFailed))
            .map_err(|e| e.to_string())?;
    let (mut positions, mut normals, mut polygons) = (Vec::new(), Vec::new(), Vec::new());
    for model in models {
        let mesh = model.mesh;
        let offset = positions.len() as u32;
        let vertex_count = mesh.positions.len() / 3;
        positions.extend(mesh.positions.chunks_exact(3).map(Vec3::from_slice));
        if mesh.normals.len() == mesh.positions.len() {
            normals.extend(mesh.normals.chunks_exact(3).map(Vec3::from_slice));
        } else {
            normals.extend(core::iter::repeat_n(Vec3::ZERO, vertex_count));
        }
        let mut start = 0;
        let arities: Vec<u32> = if mesh.face_arities.is_empty() {
            vec![3; mesh.indices.len() / 3]
        } else {
            mesh.face_arities.clone()
        };
        for arity in arities {
            let end = start + arity as usize;
            polygons.push(
                mesh.indices[start..end]
                    .iter()
                    .map(|i| i + offset)
                    .collect(),
            );
            start = end;
        }
    }
    Ok((positions, normals, polygons))
}

fn read_stl(reader: &mut (impl BufRead + Seek)) -> Result<Parts, String> {
    let mesh = stl_io::read_stl(reader).map_err(|e| format!("not a valid STL file ({e})"))?;
    let positions: Vec<Vec3> = mesh
        .vertices
        .iter()
        .map(|v| Vec3::from_array(v.0))
        .collect();
    let polygons = mesh
        .faces
        .iter()
        .map(|face| face.vertices.iter().map(|&i| i as u32).collect())
        .collect();
    Ok((positions, Vec::new(), polygons))
}

fn read_ply(reader: &mut impl BufRead) -> Result<Parts, String> {
    use ply_rs_bw::parser::Parser;
    use ply_rs_bw::ply::{DefaultElement, Property};
    let ply = Parser::<DefaultElement>::new()
        .read_ply(reader)
        .map_err(|e| {
            // The parser's message repeats itself over several lines ("Line 11: Couldn't read
            // element line.", then the text and the grammar's expectations): its first line
            // names where, the offending text says what.
            let text = e.to_string();
            let mut lines = text.lines().map(str::trim).filter(|l| !l.is_empty());
            let at = lines.next().unwrap_or("unreadable");
            let offending = lines
                .find_map(|l| l.strip_prefix("String: "))
                .map(|s| {
                    format!(
                        ": '{}'",
                        s.trim_matches(|c: char| c == '\'' || c.is_whitespace())
                    )
                })
                .unwrap_or_default();
            format!("not a valid PLY file ({at}{offending})")
        })?;
    let empty = Vec::new();
    let vertices = ply.payload.get("vertex").unwrap_or(&empty);
    let scalar = |element: &DefaultElement, index: usize, key: &str| {
        element
            .get(key)
            .and_then(Property::to_f32_lossy)
            .ok_or_else(|| format!("vertex {index} has no numeric property '{key}'"))
    };
    let mut positions = Vec::with_capacity(vertices.len());
    let mut normals = Vec::with_capacity(vertices.len());
    for (index, vertex) in vertices.iter().enumerate() {
        let read = |keys: [&str; 3]| -> Result<Vec3, String> {
            Ok(Vec3::new(
                scalar(vertex, index, keys[0])?,
                scalar(vertex, index, keys[1])?,
                scalar(vertex, index, keys[2])?,
            ))
        };
        positions.push(read(["x", "y", "z"])?);
        normals.push(read(["nx", "ny", "nz"]).unwrap_or(Vec3::ZERO));
    }
    let faces = ply.payload.get("face").unwrap_or(&empty);
    let polygons = faces
        .iter()
        .enumerate()
        .map(|(index, face)| {
            face.get("vertex_indices")
                .or_else(|| face.get("vertex_index"))
                .and_then(Property::to_u32_list)
                .ok_or_else(|| format!("face {index} has no integer list 'vertex_indices'"))
        })
        .collect::<Result<_, _>>()?;
    Ok((positions, normals, polygons))
}
