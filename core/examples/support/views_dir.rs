//! The views directory the registration examples write and `benches/peers/` reads:
//! `truth.json` and `initial.json` (pose files, the format `nbv register --init` reads) and
//! `spec.json`, each written atomically.

use std::path::Path;

use nbv_core::cloud::io::{CloudIoError, write_atomically};
use nbv_core::math::Pose;
use nbv_core::math::pose_file::poses_json;

/// Writes the pose file of the views ([`nbv_core::math::pose_file::poses_json`]).
pub fn write_poses(path: &Path, names: &[String], poses: &[Pose]) -> Result<(), String> {
    write_bytes(path, &poses_json(names, poses))
}

/// Writes `value` as pretty JSON with a final newline.
pub fn write_json(path: &Path, value: &serde_json::Value) -> Result<(), String> {
    let mut bytes = serde_json::to_vec_pretty(value).map_err(|e| e.to_string())?;
    bytes.push(b'\n');
    write_bytes(path, &bytes)
}

fn write_bytes(path: &Path, bytes: &[u8]) -> Result<(), String> {
    write_atomically(path, |w| w.write_all(bytes).map_err(CloudIoError::from))
        .map_err(|e| format!("{}: {e}", path.display()))
}
