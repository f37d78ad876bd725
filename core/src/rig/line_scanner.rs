//! [`LineScanner`]: a 2-D scanner (SICK LMS400 class) that streams timestamped lines of
//! ranges in its scan plane.
//!
//! Sensor frame: the fan lies in the sensor's x–z plane, centred on +z; beam `i` of a line
//! points along `(sin a, 0, cos a)` with `a = start_angle + i · angle_step`.

use super::{RigError, TruthHit};
use nalgebra::{Point3, Vector3};

/// What the pipeline needs to know of a line scanner.
#[derive(Debug, Clone, PartialEq)]
pub struct LineScannerSpec {
    /// Name of the sensor frame on the robot model (URDF link), e.g. `lms400`.
    pub frame: String,
    /// Minimum and maximum range of a valid return, metres.
    pub range: [f64; 2],
    /// Field of view of the fan, radians.
    pub fov: f64,
    /// Angular step between beams, radians.
    pub resolution: f64,
    /// Lines per second.
    pub line_rate_hz: f64,
}

impl LineScannerSpec {
    /// The SICK LMS400 as the paper uses it: a 70° fan at 0.25° (281 beams), 190 lines per
    /// second, returns from 0.7 to 3.0 m, URDF frame `lms400`.
    ///
    /// ```
    /// assert_eq!(nbv_core::rig::LineScannerSpec::lms400().beams(), 281);
    /// ```
    pub fn lms400() -> Self {
        Self {
            frame: "lms400".into(),
            range: [0.7, 3.0],
            fov: 70f64.to_radians(),
            resolution: 0.25f64.to_radians(),
            line_rate_hz: 190.0,
        }
    }

    /// Number of beams per line.
    pub fn beams(&self) -> usize {
        (self.fov / self.resolution).round() as usize + 1
    }

    /// Unit direction of beam `i` in the sensor frame.
    pub fn beam_direction(&self, i: usize) -> Vector3<f64> {
        let a = -0.5 * self.fov + i as f64 * self.resolution;
        Vector3::new(a.sin(), 0.0, a.cos())
    }
}

/// One line of a scan.
#[derive(Debug, Clone, PartialEq)]
pub struct ScanLine {
    /// Rig time of the line, seconds.
    pub time: f64,
    /// Angle of the first beam from the sensor's +z axis towards +x, radians.
    pub start_angle: f64,
    /// Angle between consecutive beams, radians.
    pub angle_step: f64,
    /// Range per beam, metres; NaN where there was no valid return.
    pub ranges: Vec<f32>,
    /// Ground truth per beam (the twin only): what the beam really hit.
    pub truth: Option<Vec<Option<TruthHit>>>,
}

impl ScanLine {
    /// Beam `i`'s return as a point in the sensor frame, if valid.
    pub fn point(&self, i: usize) -> Option<Point3<f64>> {
        let r = f64::from(*self.ranges.get(i)?);
        if !r.is_finite() {
            return None;
        }
        let a = self.start_angle + i as f64 * self.angle_step;
        Some(Point3::new(r * a.sin(), 0.0, r * a.cos()))
    }
}

/// A streaming line scanner.
pub trait LineScanner {
    /// The scanner's specification.
    fn spec(&self) -> &LineScannerSpec;

    /// Starts streaming lines (they accumulate until [`LineScanner::stop`]).
    fn start(&mut self) -> Result<(), RigError>;

    /// Stops streaming and returns the lines received since [`LineScanner::start`].
    fn stop(&mut self) -> Result<Vec<ScanLine>, RigError>;
}
