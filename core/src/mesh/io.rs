//! Reading and writing [`TriMesh`] files: binary/ASCII STL (via `stl_io`) and Wavefront OBJ
//! (via `tobj`), with typed errors.
//!
//! Readers merge vertices with bit-identical coordinates (STL stores every triangle's
//! corners separately), so a watertight mesh written by [`write_stl_file`] reads back watertight.
//! Writers are deterministic: the same mesh gives the same bytes. [`write_stl_file`] writes
//! atomically (a temporary file in the destination directory, then a rename).

use super::TriMesh;
use nalgebra::Point3;
use std::io::Cursor;
use std::path::{Path, PathBuf};
use thiserror::Error;

/// Errors of mesh reading and writing.
#[derive(Debug, Error)]
pub enum MeshIoError {
    /// The file could not be opened, read or written.
    #[error("{path}: {source}")]
    Io {
        /// The file.
        path: PathBuf,
        /// The underlying I/O error.
        source: std::io::Error,
    },
    /// The file's extension is neither `.stl` nor `.obj`.
    #[error("{path}: unsupported mesh format (expected .stl or .obj)")]
    UnsupportedFormat {
        /// The file.
        path: PathBuf,
    },
    /// The STL data is malformed (truncated binary file, bad ASCII syntax, ...).
    #[error("{path}: malformed STL: {message}")]
    Stl {
        /// The file.
        path: PathBuf,
        /// What the STL reader reported.
        message: String,
    },
    /// The OBJ data is malformed.
    #[error("{path}: malformed OBJ: {message}")]
    Obj {
        /// The file.
        path: PathBuf,
        /// What the OBJ reader reported.
        message: String,
    },
    /// The file holds no triangle.
    #[error("{path}: the mesh has no triangle")]
    Empty {
        /// The file.
        path: PathBuf,
    },
    /// A vertex coordinate is NaN or infinite.
    #[error("{path}: vertex {index} is not finite")]
    NotFinite {
        /// The file.
        path: PathBuf,
        /// Index of the offending vertex.
        index: usize,
    },
    /// A triangle refers to a vertex that does not exist.
    #[error("{path}: triangle {index} refers to a missing vertex")]
    BadIndex {
        /// The file.
        path: PathBuf,
        /// Index of the offending triangle.
        index: usize,
    },
}

/// Reads a mesh, choosing the format by the file extension (`stl` or `obj`, any case).
pub fn read_mesh(path: &Path) -> Result<TriMesh, MeshIoError> {
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase);
    match ext.as_deref() {
        Some("stl") => read_stl(path),
        Some("obj") => read_obj(path),
        _ => Err(MeshIoError::UnsupportedFormat {
            path: path.to_path_buf(),
        }),
    }
}

/// Reads a binary or ASCII STL file.
pub fn read_stl(path: &Path) -> Result<TriMesh, MeshIoError> {
    let bytes = std::fs::read(path).map_err(|source| MeshIoError::Io {
        path: path.to_path_buf(),
        source,
    })?;
    stl_from_bytes(&bytes, path)
}

/// Parses STL data held in memory; `path` only names the data in errors.
///
/// ```
/// use nbv_core::mesh::{TriMesh, io::{stl_from_bytes, stl_to_bytes}};
/// let cube = TriMesh::cuboid([0.5, 0.5, 0.5]);
/// let back = stl_from_bytes(&stl_to_bytes(&cube), "cube.stl".as_ref()).unwrap();
/// assert!(back.is_watertight());
/// assert!((back.volume() - 1.0).abs() < 1e-6);
/// ```
pub fn stl_from_bytes(bytes: &[u8], path: &Path) -> Result<TriMesh, MeshIoError> {
    let stl_err = |e: std::io::Error| MeshIoError::Stl {
        path: path.to_path_buf(),
        message: e.to_string(),
    };
    let indexed = stl_io::read_stl(&mut Cursor::new(bytes)).map_err(stl_err)?;
    let vertices: Vec<Point3<f64>> = indexed
        .vertices
        .iter()
        .map(|v| Point3::new(f64::from(v[0]), f64::from(v[1]), f64::from(v[2])))
        .collect();
    let mut triangles = Vec::with_capacity(indexed.faces.len());
    for (index, f) in indexed.faces.iter().enumerate() {
        let t: Option<Vec<u32>> = f.vertices.iter().map(|&i| u32::try_from(i).ok()).collect();
        match t.as_deref() {
            Some(&[a, b, c]) => triangles.push([a, b, c]),
            _ => {
                return Err(MeshIoError::BadIndex {
                    path: path.to_path_buf(),
                    index,
                });
            }
        }
    }
    checked(
        TriMesh {
            vertices,
            triangles,
        },
        path,
    )
}

/// Reads a Wavefront OBJ file (all objects merged; polygons are triangulated). Material
/// libraries (`mtllib`) are looked up next to the file; materials are not used.
pub fn read_obj(path: &Path) -> Result<TriMesh, MeshIoError> {
    let bytes = std::fs::read(path).map_err(|source| MeshIoError::Io {
        path: path.to_path_buf(),
        source,
    })?;
    let dir = path.parent().map(Path::to_path_buf).unwrap_or_default();
    obj_from_reader(&mut Cursor::new(bytes), path, |mtl| {
        tobj::load_mtl(dir.join(mtl))
    })
}

/// Parses OBJ data held in memory; `path` only names the data in errors. Material
/// libraries are not loaded (they do not change the mesh).
///
/// ```
/// use nbv_core::mesh::io::obj_from_bytes;
/// let tet = b"v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n";
/// let m = obj_from_bytes(tet, "tet.obj".as_ref()).unwrap();
/// assert!(m.is_watertight());
/// let err = obj_from_bytes(b"f 1 2 3\n", "bad.obj".as_ref()).unwrap_err();
/// assert!(err.to_string().starts_with("bad.obj: "), "{err}");
/// ```
pub fn obj_from_bytes(bytes: &[u8], path: &Path) -> Result<TriMesh, MeshIoError> {
    obj_from_reader(&mut Cursor::new(bytes), path, |_| {
        Err(tobj::LoadError::OpenFileFailed)
    })
}

fn obj_from_reader(
    reader: &mut impl std::io::BufRead,
    path: &Path,
    materials: impl Fn(&Path) -> tobj::MTLLoadResult,
) -> Result<TriMesh, MeshIoError> {
    let options = tobj::LoadOptions {
        triangulate: true,
        single_index: false,
        ..Default::default()
    };
    let (models, _materials) =
        tobj::load_obj_buf(reader, &options, materials).map_err(|e| MeshIoError::Obj {
            path: path.to_path_buf(),
            message: e.to_string(),
        })?;
    let mut mesh = TriMesh::default();
    for model in &models {
        let m = &model.mesh;
        let base = mesh.vertices.len();
        mesh.vertices.extend(
            m.positions
                .chunks_exact(3)
                .map(|c| Point3::new(f64::from(c[0]), f64::from(c[1]), f64::from(c[2]))),
        );
        let count = mesh.vertices.len() - base;
        for (index, t) in m.indices.chunks_exact(3).enumerate() {
            if t.iter().any(|&i| i as usize >= count) {
                return Err(MeshIoError::BadIndex {
                    path: path.to_path_buf(),
                    index,
                });
            }
            let shift = |i: u32| u32::try_from(base + i as usize).ok();
            match (shift(t[0]), shift(t[1]), shift(t[2])) {
                (Some(a), Some(b), Some(c)) => mesh.triangles.push([a, b, c]),
                _ => {
                    return Err(MeshIoError::BadIndex {
                        path: path.to_path_buf(),
                        index,
                    });
                }
            }
        }
    }
    checked(mesh, path)
}

fn checked(mesh: TriMesh, path: &Path) -> Result<TriMesh, MeshIoError> {
    if mesh.triangles.is_empty() {
        return Err(MeshIoError::Empty {
            path: path.to_path_buf(),
        });
    }
    if let Some(index) = mesh
        .vertices
        .iter()
        .position(|p| !p.coords.iter().all(|c| c.is_finite()))
    {
        return Err(MeshIoError::NotFinite {
            path: path.to_path_buf(),
            index,
        });
    }
    let n = mesh.vertices.len();
    if let Some(index) = mesh
        .triangles
        .iter()
        .position(|t| t.iter().any(|&i| i as usize >= n))
    {
        return Err(MeshIoError::BadIndex {
            path: path.to_path_buf(),
            index,
        });
    }
    Ok(mesh)
}

/// Encodes a mesh as binary STL (80-byte zero header, f32 coordinates, facet normals).
///
/// Coordinates are rounded to `f32`; `-0.0` is written as `0.0` so that vertices shared by
/// several triangles stay bit-identical. Triangles with an out-of-range index are skipped.
pub fn stl_to_bytes(mesh: &TriMesh) -> Vec<u8> {
    let f = |x: f64| (x as f32) + 0.0;
    let n = mesh.vertices.len();
    let triangles: Vec<stl_io::Triangle> = mesh
        .triangles
        .iter()
        .enumerate()
        .filter(|(_, t)| t.iter().all(|&i| (i as usize) < n))
        .map(|(i, _)| {
            let [a, b, c] = mesh.triangle(i);
            let nrm = mesh.triangle_normal(i);
            let v = |p: Point3<f64>| stl_io::Vertex::new([f(p.x), f(p.y), f(p.z)]);
            stl_io::Triangle {
                normal: stl_io::Normal::new([f(nrm.x), f(nrm.y), f(nrm.z)]),
                vertices: [v(a), v(b), v(c)],
            }
        })
        .collect();
    let mut out = Vec::with_capacity(84 + 50 * triangles.len());
    // Writing into a Vec cannot fail.
    let _ = stl_io::write_stl(&mut out, triangles.iter());
    out
}

/// Writes a mesh as binary STL, atomically (temporary file in the same directory, then
/// rename).
pub fn write_stl_file(mesh: &TriMesh, path: &Path) -> Result<(), MeshIoError> {
    write_atomic(path, &stl_to_bytes(mesh))
}

/// Encodes a mesh as binary little-endian PLY: per vertex `float x, y, z` and, when
/// `normals` holds one per vertex, `float nx, ny, nz`; per face a `uchar` count and `int`
/// indices (the layout Open3D, MeshLab and Blender read).
///
/// ```
/// use nbv_core::mesh::{TriMesh, io::ply_mesh_to_bytes};
/// let bytes = ply_mesh_to_bytes(&TriMesh::cuboid([0.5; 3]), &[]);
/// let text = String::from_utf8_lossy(&bytes);
/// assert!(text.contains("element vertex 8\n") && text.contains("element face 12\n"));
/// ```
pub fn ply_mesh_to_bytes(mesh: &TriMesh, normals: &[nalgebra::Vector3<f64>]) -> Vec<u8> {
    let with_normals = !normals.is_empty() && normals.len() == mesh.vertices.len();
    let mut out = Vec::with_capacity(64 + 24 * mesh.vertices.len() + 13 * mesh.triangles.len());
    let mut header = format!(
        "ply\nformat binary_little_endian 1.0\ncomment generated by nbv-twin\nelement vertex {}\nproperty float x\nproperty float y\nproperty float z\n",
        mesh.vertices.len()
    );
    if with_normals {
        header.push_str("property float nx\nproperty float ny\nproperty float nz\n");
    }
    header.push_str(&format!(
        "element face {}\nproperty list uchar int vertex_indices\nend_header\n",
        mesh.triangles.len()
    ));
    out.extend_from_slice(header.as_bytes());
    for (k, p) in mesh.vertices.iter().enumerate() {
        for c in p.iter() {
            out.extend_from_slice(&(*c as f32).to_le_bytes());
        }
        if with_normals {
            for c in normals[k].iter() {
                out.extend_from_slice(&(*c as f32).to_le_bytes());
            }
        }
    }
    for t in &mesh.triangles {
        out.push(3);
        for &i in t {
            out.extend_from_slice(&(i as i32).to_le_bytes());
        }
    }
    out
}

/// Writes a mesh as binary PLY ([`ply_mesh_to_bytes`]), atomically.
pub fn write_ply_mesh(
    mesh: &TriMesh,
    normals: &[nalgebra::Vector3<f64>],
    path: &Path,
) -> Result<(), MeshIoError> {
    write_atomic(path, &ply_mesh_to_bytes(mesh, normals))
}

/// Writes bytes to `path` atomically ([`crate::atomic_file::write_atomic`]).
fn write_atomic(path: &Path, bytes: &[u8]) -> Result<(), MeshIoError> {
    crate::atomic_file::write_atomic(path, bytes).map_err(|source| MeshIoError::Io {
        path: path.to_path_buf(),
        source,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::{Isometry3, Vector3};

    #[test]
    fn stl_round_trip_keeps_topology_and_volume() {
        let m = TriMesh::cuboid([0.1, 0.2, 0.3]).transformed(&Isometry3::new(
            Vector3::new(0.5, -0.25, 1.0),
            Vector3::new(0.1, 0.2, 0.3),
        ));
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("box.STL");
        write_stl_file(&m, &p).unwrap();
        let back = read_mesh(&p).unwrap();
        assert_eq!(back.triangles.len(), 12);
        assert_eq!(back.vertices.len(), 8);
        assert!(back.is_watertight());
        assert!((back.volume() - m.volume()).abs() < 1e-6);
        // Deterministic bytes.
        assert_eq!(std::fs::read(&p).unwrap(), stl_to_bytes(&m));
        assert_eq!(std::fs::read(&p).unwrap().len(), 84 + 50 * 12);
    }

    #[test]
    fn negative_zero_does_not_split_vertices() {
        let mut m = TriMesh::cuboid([0.5, 0.5, 0.5]);
        m.vertices.iter_mut().for_each(|p| p.x += 0.5); // some x become exactly 0.0
        m.vertices[0].x = -0.0;
        let back = stl_from_bytes(&stl_to_bytes(&m), Path::new("m.stl")).unwrap();
        assert!(back.is_watertight());
    }

    #[test]
    fn obj_is_read_and_polygons_triangulated() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("tet.obj");
        std::fs::write(
            &p,
            "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n",
        )
        .unwrap();
        let m = read_mesh(&p).unwrap();
        assert_eq!(m.triangles.len(), 4);
        assert!(m.is_watertight());
        assert!((m.volume() - 1.0 / 6.0).abs() < 1e-9);
    }

    #[test]
    fn bad_inputs_give_typed_errors() {
        let dir = tempfile::tempdir().unwrap();
        let missing = dir.path().join("missing.stl");
        assert!(matches!(read_mesh(&missing), Err(MeshIoError::Io { .. })));
        assert!(matches!(
            read_mesh(Path::new("x.ply")),
            Err(MeshIoError::UnsupportedFormat { .. })
        ));
        let truncated = &stl_to_bytes(&TriMesh::cuboid([1.0; 3]))[..300];
        assert!(matches!(
            stl_from_bytes(truncated, Path::new("t.stl")),
            Err(MeshIoError::Stl { .. })
        ));
        let empty = stl_to_bytes(&TriMesh::default());
        assert!(matches!(
            stl_from_bytes(&empty, Path::new("e.stl")),
            Err(MeshIoError::Empty { .. })
        ));
        let mut nan = TriMesh::cuboid([1.0; 3]);
        nan.vertices[3].y = f64::NAN;
        assert!(matches!(
            stl_from_bytes(&stl_to_bytes(&nan), Path::new("n.stl")),
            Err(MeshIoError::NotFinite { .. })
        ));
        let garbage = dir.path().join("g.obj");
        std::fs::write(&garbage, "f 1 2 3\n").unwrap();
        assert!(read_mesh(&garbage).is_err());
    }
}
