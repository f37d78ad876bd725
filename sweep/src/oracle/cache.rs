//! [`OracleCache`]: oracles kept on disk and shared by the episodes whose ceiling is the
//! same. The oracle depends on the true world (objects and their meshes, table, obstacles,
//! robot), the sensors, the laser sweep and its errors, the seed, phase 1's segmentation
//! and workcell alignment (its base) and Algorithm 2's sphere and rolls — not on what a
//! sweep usually varies: the score's weights, the thresholds and stop rules, the map, the
//! planner, the rest of registration and the model. A sweep of k such settings on one
//! scene and seed computes its oracle once instead of k times (about a minute each on two
//! cores); each episode still casts its own views ([`OracleObject::views_noise_free`]).
//!
//! [`OracleObject::views_noise_free`]: super::OracleObject::views_noise_free

use std::path::{Path, PathBuf};

use nbv_scenes::Scene;

use super::{DensePoses, OracleReport};
use crate::error::{Context, Result};

/// The scene's top-level sections the oracle does not read.
const IGNORED_SECTIONS: [&str; 4] = ["description", "mapping", "planner", "model"];

/// The `[registration]` keys the oracle reads: phase 1's workcell alignment.
const REGISTRATION_KEYS: [&str; 1] = ["align_to_workcell"];

/// The `[nbv]` keys the oracle reads: Algorithm 2's sphere and rolls.
const NBV_KEYS: [&str; 6] = [
    "preset",
    "radius",
    "dtheta_deg",
    "theta_max_deg",
    "dphi_deg",
    "rolls",
];

/// A directory of oracles, `<key>.json` each.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct OracleCache {
    dir: PathBuf,
}

impl OracleCache {
    /// The cache in `dir` (created when the first oracle is stored).
    pub fn new(dir: impl Into<PathBuf>) -> Self {
        Self { dir: dir.into() }
    }

    /// Its directory.
    pub fn dir(&self) -> &Path {
        &self.dir
    }

    /// What identifies the oracle of `scene` with the `dense` pose set: a 64-bit FNV-1a
    /// hash of the scene without the sections and keys the oracle does not read, the
    /// dense set, and the bytes of the object meshes and the robot's URDF, in hex.
    pub fn key(scene: &Scene, dense: &DensePoses) -> Result<String> {
        let mut value = serde_json::to_value(scene)?;
        if let Some(map) = value.as_object_mut() {
            for section in IGNORED_SECTIONS {
                map.remove(section);
            }
            for (section, kept) in [("nbv", &NBV_KEYS[..]), ("registration", &REGISTRATION_KEYS)] {
                if let Some(keys) = map.get_mut(section).and_then(|n| n.as_object_mut()) {
                    keys.retain(|k, _| kept.contains(&k.as_str()));
                }
            }
        }
        let mut h = Fnv64::default();
        h.write(serde_json::to_string(&value)?.as_bytes());
        h.write(serde_json::to_string(dense)?.as_bytes());
        let files = scene
            .objects
            .iter()
            .map(|o| o.mesh.as_path())
            .chain(std::iter::once(scene.robot.urdf.as_path()));
        for path in files {
            let bytes =
                std::fs::read(path).with_context(|| format!("reading {}", path.display()))?;
            h.write(&(bytes.len() as u64).to_le_bytes());
            h.write(&bytes);
        }
        Ok(format!("{:016x}", h.0))
    }

    /// The stored oracle of `key`, if there is a readable one.
    pub fn load(&self, key: &str) -> Option<OracleReport> {
        let text = std::fs::read_to_string(self.path(key)).ok()?;
        serde_json::from_str(&text).ok()
    }

    /// Stores `report` under `key` (atomically: a reader sees the whole file or none).
    pub fn store(&self, key: &str, report: &OracleReport) -> Result<()> {
        std::fs::create_dir_all(&self.dir)
            .with_context(|| format!("creating {}", self.dir.display()))?;
        crate::layout::write_json(&self.path(key), report)
    }

    fn path(&self, key: &str) -> PathBuf {
        self.dir.join(format!("{key}.json"))
    }
}

/// 64-bit FNV-1a.
struct Fnv64(u64);

impl Default for Fnv64 {
    fn default() -> Self {
        Self(0xcbf2_9ce4_8422_2325)
    }
}

impl Fnv64 {
    fn write(&mut self, bytes: &[u8]) {
        for &b in bytes {
            self.0 ^= u64::from(b);
            self.0 = self.0.wrapping_mul(0x0000_0100_0000_01b3);
        }
    }
}
