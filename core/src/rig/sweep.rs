//! [`acquire_sweep`]: the phase-1 mid-range observation on any rig — move to the sweep's
//! first waypoint (not scanned), then stream lines while the arm follows the rest.

use super::{Arm, JointPath, LineScanner, Motion, RigError, ScanLine};
use crate::kinematics::Joints;

/// The lines and the reported motion of a sweep (feed them to
/// [`lines_to_cloud`](super::lines_to_cloud)).
#[derive(Debug, Clone, PartialEq)]
pub struct SweepData {
    /// The scan lines, in time order.
    pub lines: Vec<ScanLine>,
    /// The arm's reported motion while scanning.
    pub motion: Motion,
}

/// Runs a sweep: from the arm's current configuration straight (in joint space) to
/// `waypoints[0]`, then, with the scanner streaming, through the remaining waypoints, all
/// at `speed_fraction`. If the scanned motion fails the stream is stopped and the error
/// returned.
///
/// ```no_run
/// # fn demo(arm: &mut impl nbv_core::rig::Arm, scanner: &mut impl nbv_core::rig::LineScanner,
/// #         waypoints: &[nbv_core::kinematics::Joints]) -> Result<(), nbv_core::rig::RigError> {
/// let sweep = nbv_core::rig::acquire_sweep(arm, scanner, waypoints, 0.1)?;
/// println!("{} lines", sweep.lines.len());
/// # Ok(()) }
/// ```
pub fn acquire_sweep<A: Arm + ?Sized, L: LineScanner + ?Sized>(
    arm: &mut A,
    scanner: &mut L,
    waypoints: &[Joints],
    speed_fraction: f64,
) -> Result<SweepData, RigError> {
    let Some(first) = waypoints.first() else {
        return Err(RigError::InvalidPath("a sweep needs waypoints".into()));
    };
    let here = arm.joints()?;
    arm.execute(&JointPath {
        waypoints: vec![here, *first],
        speed_fraction,
    })?;
    let mut scanned = vec![arm.joints()?];
    scanned.extend_from_slice(&waypoints[1..]);
    scanner.start()?;
    let motion = arm.execute(&JointPath {
        waypoints: scanned,
        speed_fraction,
    });
    let lines = scanner.stop();
    let motion = motion?;
    Ok(SweepData {
        lines: lines?,
        motion,
    })
}
