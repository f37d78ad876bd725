//! Pose files: a JSON object mapping each view's file name to its pose, the 4×4
//! homogeneous view-to-world transform as 4 rows, row-major —
//! `{ "scan_a.ply": [[r00, r01, r02, tx], …, [0, 0, 0, 1]], … }` — as `nbv register`
//! reads (`--init`) and writes (`--poses`).

use super::Pose;
use nalgebra::{Isometry3, Matrix3, Matrix4, Rotation3, Translation3, UnitQuaternion};
use std::collections::BTreeMap;

/// Largest deviation of a pose matrix from a rigid transform that is accepted (and then
/// re-orthonormalised): 1e-6 on any entry.
pub const RIGID_TOLERANCE: f64 = 1e-6;

/// Why a pose file could not be read.
#[derive(Debug, thiserror::Error)]
pub enum PoseFileError {
    /// Not a JSON object of name → matrix.
    #[error("expected a JSON object of file name -> 4x4 matrix")]
    NotAnObject(#[source] serde_json::Error),
    /// A view has no entry.
    #[error("no pose for view {0}")]
    Missing(String),
    /// A view's matrix is not a rigid transform.
    #[error("pose of {name}")]
    Matrix {
        /// The view.
        name: String,
        /// What is wrong with its matrix.
        #[source]
        source: MatrixError,
    },
}

/// Why a 4×4 matrix is not a rigid transform.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum MatrixError {
    /// Not 4 rows of 4 numbers.
    #[error("expected 4 rows of 4 numbers")]
    Shape,
    /// NaN or infinite.
    #[error("the matrix has a non-finite entry")]
    NonFinite,
    /// The last row is not `0 0 0 1`.
    #[error("the last row must be 0 0 0 1, got {0:?}")]
    LastRow([f64; 4]),
    /// The rotation block is not a rotation.
    #[error("the upper-left 3x3 block is not a rotation")]
    NotRotation,
}

/// `{ name: [[row 0], …, [row 3]], … }` of the views in order, pretty-printed, with a
/// final newline.
pub fn poses_json(names: &[String], poses: &[Pose]) -> Vec<u8> {
    let mut map = serde_json::Map::new();
    for (name, pose) in names.iter().zip(poses) {
        let m = pose.to_homogeneous();
        let rows: Vec<Vec<f64>> = (0..4)
            .map(|r| (0..4).map(|c| m[(r, c)]).collect())
            .collect();
        map.insert(name.clone(), serde_json::json!(rows));
    }
    let mut bytes = serde_json::to_vec_pretty(&serde_json::Value::Object(map)).unwrap_or_default();
    bytes.push(b'\n');
    bytes
}

/// The pose of every name in `names` from a pose file's text (other names are ignored).
pub fn parse_poses(text: &str, names: &[String]) -> Result<Vec<Pose>, PoseFileError> {
    let map: BTreeMap<String, serde_json::Value> =
        serde_json::from_str(text).map_err(PoseFileError::NotAnObject)?;
    names
        .iter()
        .map(|name| {
            let value = map
                .get(name)
                .ok_or_else(|| PoseFileError::Missing(name.clone()))?;
            parse_matrix(value).map_err(|source| PoseFileError::Matrix {
                name: name.clone(),
                source,
            })
        })
        .collect()
}

/// A rigid transform from a 4×4 row-major JSON matrix.
pub fn parse_matrix(value: &serde_json::Value) -> Result<Pose, MatrixError> {
    let rows: Vec<Vec<f64>> =
        serde_json::from_value(value.clone()).map_err(|_| MatrixError::Shape)?;
    if rows.len() != 4 || rows.iter().any(|r| r.len() != 4) {
        return Err(MatrixError::Shape);
    }
    let m = Matrix4::from_fn(|r, c| rows[r][c]);
    if !m.iter().all(|v| v.is_finite()) {
        return Err(MatrixError::NonFinite);
    }
    let bottom = [m[(3, 0)], m[(3, 1)], m[(3, 2)], m[(3, 3)]];
    if bottom
        .iter()
        .zip([0.0, 0.0, 0.0, 1.0])
        .any(|(v, want)| (v - want).abs() > RIGID_TOLERANCE)
    {
        return Err(MatrixError::LastRow(bottom));
    }
    let r: Matrix3<f64> = m.fixed_view::<3, 3>(0, 0).into_owned();
    if (r.transpose() * r - Matrix3::identity()).amax() > RIGID_TOLERANCE
        || (r.determinant() - 1.0).abs() > RIGID_TOLERANCE
    {
        return Err(MatrixError::NotRotation);
    }
    let rotation = UnitQuaternion::from_rotation_matrix(&Rotation3::from_matrix(&r));
    let t = Translation3::new(m[(0, 3)], m[(1, 3)], m[(2, 3)]);
    Ok(Isometry3::from_parts(t, rotation))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::pose_from_xyz_rpy;

    #[test]
    fn written_poses_read_back() {
        let names = vec!["a.ply".to_string(), "b.ply".to_string()];
        let poses = vec![
            Pose::identity(),
            pose_from_xyz_rpy([0.1, -0.2, 0.3], [0.2, -0.1, 1.0]),
        ];
        let bytes = poses_json(&names, &poses);
        assert_eq!(bytes.last(), Some(&b'\n'));
        let text = String::from_utf8(bytes).unwrap();
        let back = parse_poses(&text, &names).unwrap();
        for (a, b) in back.iter().zip(&poses) {
            assert!((a.to_homogeneous() - b.to_homogeneous()).amax() < 1e-12);
        }
        // Only the names asked for; a missing one is named.
        assert_eq!(parse_poses(&text, &names[1..]).unwrap().len(), 1);
        let e = parse_poses(&text, &["c.ply".to_string()]).unwrap_err();
        assert_eq!(e.to_string(), "no pose for view c.ply");
    }

    #[test]
    fn matrices_must_be_rigid() {
        let m = |v: serde_json::Value| parse_matrix(&v);
        assert_eq!(m(serde_json::json!([[1, 0, 0]])), Err(MatrixError::Shape));
        assert_eq!(
            m(serde_json::json!([
                [1, 0, 0, 0],
                [0, 1, 0, 0],
                [0, 0, 1, 0],
                [0, 0, 1, 1]
            ])),
            Err(MatrixError::LastRow([0.0, 0.0, 1.0, 1.0]))
        );
        assert_eq!(
            m(serde_json::json!([
                [2, 0, 0, 0],
                [0, 1, 0, 0],
                [0, 0, 1, 0],
                [0, 0, 0, 1]
            ])),
            Err(MatrixError::NotRotation)
        );
        // A reflection has an orthonormal block but determinant -1.
        assert_eq!(
            m(serde_json::json!([
                [-1, 0, 0, 0],
                [0, 1, 0, 0],
                [0, 0, 1, 0],
                [0, 0, 0, 1]
            ])),
            Err(MatrixError::NotRotation)
        );
        let p = m(serde_json::json!([
            [0, -1, 0, 1],
            [1, 0, 0, 2],
            [0, 0, 1, 3],
            [0, 0, 0, 1]
        ]))
        .unwrap();
        assert!((p.translation.vector - nalgebra::Vector3::new(1.0, 2.0, 3.0)).norm() < 1e-12);
        assert!((p.rotation.angle() - std::f64::consts::FRAC_PI_2).abs() < 1e-12);
    }
}
