//! [`UnseenCauses`]: where the surface no reachable view sees lies, by cause — against the
//! table, hidden by the object itself (its inside, a concavity), facing another object or an
//! obstacle, or open to the outside but seen from no pose the arm reaches.

use nalgebra::{Point3, Rotation3, Unit, Vector3};
use nbv_core::rig::TruthLabel;
use nbv_sim::world::TwinWorld;
use serde::{Deserialize, Serialize};

/// Height (m) above the table top under which an unseen sample counts as against the table.
pub const TABLE_BAND: f64 = 0.015;
/// How far (m) a probe ray looks for what blocks a sample's view.
const PROBE_REACH: f64 = 1.0;
/// Tilt (degrees) of the eight outer probe rays from the surface normal.
const PROBE_TILT_DEG: f64 = 40.0;
/// Offset (m) of the probe rays' origin along the normal, off the surface.
const PROBE_OFFSET: f64 = 0.002;

/// The unseen share of an object's surface samples, by cause (each a share of all the
/// samples; they sum to `1 − ceiling`).
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
pub struct UnseenCauses {
    /// Within [`TABLE_BAND`] of the table top, or every probe ray from it meets the table.
    pub table: f64,
    /// Every probe ray from it meets the object itself (its inside, a concavity).
    pub self_occluded: f64,
    /// Every probe ray meets something, most often another object or an obstacle.
    pub obstacle: f64,
    /// Some probe ray leaves freely: the sample could be seen from a direction no
    /// reachable pose takes (under an overhang, behind, beyond the arm's reach).
    pub out_of_reach: f64,
}

/// Why one sample is unseen.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum UnseenCause {
    /// See [`UnseenCauses::table`].
    Table,
    /// See [`UnseenCauses::self_occluded`].
    SelfOccluded,
    /// See [`UnseenCauses::obstacle`].
    Obstacle,
    /// See [`UnseenCauses::out_of_reach`].
    OutOfReach,
}

/// The cause for the sample at `point` with outward `normal` on object `object`, in
/// `world` (the robot ignored) with the table top at `table_top`: nine probe rays, along
/// the normal and tilted 40° around it.
pub fn unseen_cause(
    world: &TwinWorld,
    object: u32,
    point: &Point3<f64>,
    normal: &Vector3<f64>,
    table_top: f64,
) -> UnseenCause {
    if point.z - table_top < TABLE_BAND {
        return UnseenCause::Table;
    }
    let Some(n) = normal.try_normalize(1e-12) else {
        return UnseenCause::OutOfReach;
    };
    let caster = world.ray_caster();
    let origin = point + n * PROBE_OFFSET;
    let side = if n.x.abs() < 0.9 {
        Vector3::x()
    } else {
        Vector3::y()
    };
    let axis = Unit::new_normalize(n.cross(&side));
    let tilted = Rotation3::from_axis_angle(&axis, PROBE_TILT_DEG.to_radians()) * n;
    let mut counts = [0usize; 3]; // table, self, other
    for k in 0..9 {
        let dir = if k == 0 {
            n
        } else {
            let turn = Rotation3::from_axis_angle(
                &Unit::new_normalize(n),
                std::f64::consts::TAU * (k - 1) as f64 / 8.0,
            );
            turn * tilted
        };
        match caster
            .cast(&origin, &dir, PROBE_REACH, None)
            .map(|h| h.label)
        {
            None | Some(TruthLabel::Robot) => return UnseenCause::OutOfReach,
            Some(TruthLabel::Table) => counts[0] += 1,
            Some(TruthLabel::Object(i)) if i == object => counts[1] += 1,
            Some(_) => counts[2] += 1,
        }
    }
    if counts[1] >= counts[0] && counts[1] >= counts[2] {
        UnseenCause::SelfOccluded
    } else if counts[0] >= counts[2] {
        UnseenCause::Table
    } else {
        UnseenCause::Obstacle
    }
}

impl UnseenCauses {
    /// The shares of `causes` among `samples` samples.
    pub fn of(causes: &[UnseenCause], samples: usize) -> Self {
        let share = |c: UnseenCause| {
            if samples == 0 {
                0.0
            } else {
                causes.iter().filter(|&&x| x == c).count() as f64 / samples as f64
            }
        };
        Self {
            table: share(UnseenCause::Table),
            self_occluded: share(UnseenCause::SelfOccluded),
            obstacle: share(UnseenCause::Obstacle),
            out_of_reach: share(UnseenCause::OutOfReach),
        }
    }
}
