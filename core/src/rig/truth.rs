//! Ground truth attached by the twin to each return: what was hit, and where, noise-free.

use nalgebra::Point3;

/// What a ray hit.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum TruthLabel {
    /// The table.
    Table,
    /// Scene object by index in the scene's object list.
    Object(u32),
    /// Obstacle by index in the scene's obstacle list.
    Obstacle(u32),
    /// A link of the robot itself.
    Robot,
}

impl TruthLabel {
    /// A `u32` code for point-cloud label columns: 0 table, 1 robot, 1000 + i obstacle
    /// `i`, 2000 + i object `i`.
    pub fn code(self) -> u32 {
        match self {
            Self::Table => 0,
            Self::Robot => 1,
            Self::Obstacle(i) => 1000 + i,
            Self::Object(i) => 2000 + i,
        }
    }

    /// Inverse of [`TruthLabel::code`].
    pub fn from_code(code: u32) -> Option<Self> {
        match code {
            0 => Some(Self::Table),
            1 => Some(Self::Robot),
            1000..2000 => Some(Self::Obstacle(code - 1000)),
            2000.. => Some(Self::Object(code - 2000)),
            _ => None,
        }
    }
}

/// The ground truth of one return.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TruthHit {
    /// What the ray hit.
    pub label: TruthLabel,
    /// The noise-free hit point in the world frame.
    pub point: Point3<f64>,
}
