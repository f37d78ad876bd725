//! Ground truth attached by the twin to each return: what was hit, and where, noise-free;
//! and a cloud's points counted by what they hit ([`LabelCounts`]).

use crate::cloud::PointCloud;
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

/// A cloud's labelled points counted by the kind of surface they hit.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct LabelCounts {
    /// On the table.
    pub table: usize,
    /// On the scene's objects.
    pub objects: usize,
    /// On the obstacles.
    pub obstacles: usize,
    /// On the robot, or with a code that is no [`TruthLabel`].
    pub robot: usize,
}

impl LabelCounts {
    /// The counts of `cloud`'s labels (none without labels).
    ///
    /// ```
    /// use nbv_core::cloud::PointCloud;
    /// use nbv_core::rig::{LabelCounts, TruthLabel};
    /// let mut cloud = PointCloud::from_points(vec![nalgebra::Point3::origin(); 4]);
    /// let labels = [TruthLabel::Table, TruthLabel::Object(2), TruthLabel::Object(0), TruthLabel::Robot];
    /// cloud.labels = Some(labels.map(TruthLabel::code).to_vec());
    /// let n = LabelCounts::of(&cloud);
    /// assert_eq!((n.table, n.objects, n.obstacles, n.robot), (1, 2, 0, 1));
    /// ```
    pub fn of(cloud: &PointCloud) -> Self {
        let mut n = Self::default();
        for code in cloud.labels.iter().flatten() {
            match TruthLabel::from_code(*code) {
                Some(TruthLabel::Table) => n.table += 1,
                Some(TruthLabel::Object(_)) => n.objects += 1,
                Some(TruthLabel::Obstacle(_)) => n.obstacles += 1,
                Some(TruthLabel::Robot) | None => n.robot += 1,
            }
        }
        n
    }
}
