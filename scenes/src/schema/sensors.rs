//! [`Sensors`]: the mid-range line scanner (SICK LMS400) and the short-range depth camera
//! (Dinast IPA-1110), with their noise models.

use super::Check;
use crate::error::SceneError;
use nbv_core::rig::{DepthCameraSpec, LineScannerSpec};
use serde::{Deserialize, Serialize};

/// Both eye-in-hand sensors (`[sensors.mid_range]`, `[sensors.short_range]`).
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct Sensors {
    /// The mid-range 2-D laser line scanner.
    pub mid_range: MidRangeSensor,
    /// The short-range depth camera.
    pub short_range: ShortRangeSensor,
}

/// The mid-range planar laser scanner (SICK LMS400). Its rays fan out in the sensor
/// frame's x–z plane, symmetric about +z (the viewing direction).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct MidRangeSensor {
    /// URDF frame of the sensor (z forward). Default `"lms400"`.
    pub frame: String,
    /// Valid range `[min, max]` (m). Default `[0.7, 3.0]` (paper).
    pub range: [f64; 2],
    /// Fan opening angle (degrees). Default 70 (paper).
    pub fov_deg: f64,
    /// Angle between neighbouring rays (degrees). Default 0.25 (281 rays per line).
    pub resolution_deg: f64,
    /// Scan lines per second. Default 190 (paper).
    pub line_rate_hz: f64,
    /// Range noise.
    pub noise: LaserNoise,
}

impl Default for MidRangeSensor {
    fn default() -> Self {
        Self {
            frame: "lms400".into(),
            range: [0.7, 3.0],
            fov_deg: 70.0,
            resolution_deg: 0.25,
            line_rate_hz: 190.0,
            noise: LaserNoise::default(),
        }
    }
}

impl MidRangeSensor {
    /// The rig-level spec (angles in radians) the pipeline and the twin use.
    ///
    /// ```
    /// let spec = nbv_scenes::schema::MidRangeSensor::default().spec();
    /// assert_eq!(spec.beams(), 281);
    /// assert_eq!(spec.range, [0.7, 3.0]);
    /// ```
    pub fn spec(&self) -> LineScannerSpec {
        LineScannerSpec {
            frame: self.frame.clone(),
            range: self.range,
            fov: self.fov_deg.to_radians(),
            resolution: self.resolution_deg.to_radians(),
            line_rate_hz: self.line_rate_hz,
        }
    }
}

/// Gaussian range noise of the laser, independent of range.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct LaserNoise {
    /// Standard deviation (m) along the ray. Default 0.002: the paper's ±4 mm read as a
    /// 2σ bound.
    pub range_sigma: f64,
}

impl Default for LaserNoise {
    fn default() -> Self {
        Self { range_sigma: 0.002 }
    }
}

/// The short-range depth camera (Dinast IPA-1110): a pinhole ray set, z forward, x right,
/// y down in the image.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct ShortRangeSensor {
    /// URDF frame of the camera (z forward). Default `"dinast"`.
    pub frame: String,
    /// Valid range `[min, max]` (m, along the ray). Default `[0.1, 0.8]` (paper).
    pub range: [f64; 2],
    /// Horizontal field of view (degrees) across `width`; the vertical one follows from the
    /// aspect ratio (square pixels). Default 80 (paper).
    pub fov_deg: f64,
    /// Image width (pixels). Default 320 (paper).
    pub width: u32,
    /// Image height (pixels). Default 240 (paper).
    pub height: u32,
    /// Frames per second. Default 30 (assumed: the frame rate is not documented).
    pub frame_rate_hz: f64,
    /// Range noise and dropouts.
    pub noise: CameraNoise,
}

impl Default for ShortRangeSensor {
    fn default() -> Self {
        Self {
            frame: "dinast".into(),
            range: [0.1, 0.8],
            fov_deg: 80.0,
            width: 320,
            height: 240,
            frame_rate_hz: 30.0,
            noise: CameraNoise::default(),
        }
    }
}

impl ShortRangeSensor {
    /// The rig-level spec (pinhole, horizontal field of view in radians) the pipeline and
    /// the twin use.
    ///
    /// ```
    /// let spec = nbv_scenes::schema::ShortRangeSensor::default().spec();
    /// assert_eq!((spec.width, spec.height), (320, 240));
    /// // 80° across 320 pixels: f = 160 / tan(40°).
    /// assert!((spec.focal() - 160.0 / 40f64.to_radians().tan()).abs() < 1e-9);
    /// ```
    pub fn spec(&self) -> DepthCameraSpec {
        DepthCameraSpec {
            frame: self.frame.clone(),
            range: self.range,
            width: self.width as usize,
            height: self.height as usize,
            hfov: self.fov_deg.to_radians(),
        }
    }
}

/// Noise of the depth camera: Gaussian along the ray, growing with range, and dropouts.
///
/// `σ(d) = range_sigma_at_1m · d^range_sigma_exponent` (d in m). A pixel drops out with
/// probability `max(dropout_probability, grazing(a), near_limit(d))`, where `grazing` ramps
/// linearly from 0 at `grazing_start_deg` to 1 at `grazing_cutoff_deg` (angle between the ray
/// and the surface normal) and `near_limit` ramps from 0 to 1 over the last `range_margin`
/// metres before either range limit.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct CameraNoise {
    /// σ at 1 m (m). Default 0.04: σ(0.3 m) = 12 mm, σ(0.5 m) = 20 mm, one order of
    /// magnitude above the laser's 2 mm (paper), an assumption.
    pub range_sigma_at_1m: f64,
    /// Exponent of the range dependence. Default 1.0.
    pub range_sigma_exponent: f64,
    /// Dropout probability of any valid pixel. Default 0.01.
    pub dropout_probability: f64,
    /// Incidence angle (degrees) where grazing dropouts start. Default 60.
    pub grazing_start_deg: f64,
    /// Incidence angle (degrees) beyond which every pixel drops out. Default 80.
    pub grazing_cutoff_deg: f64,
    /// Width (m) of the dropout ramp inside each range limit. Default 0.05.
    pub range_margin: f64,
}

impl Default for CameraNoise {
    fn default() -> Self {
        Self {
            range_sigma_at_1m: 0.04,
            range_sigma_exponent: 1.0,
            dropout_probability: 0.01,
            grazing_start_deg: 60.0,
            grazing_cutoff_deg: 80.0,
            range_margin: 0.05,
        }
    }
}

impl MidRangeSensor {
    /// Checks every value of `[sensors.mid_range]`; the error names the key.
    pub(crate) fn check(&self, c: &Check) -> Result<(), SceneError> {
        c.name("sensors.mid_range.frame", &self.frame)?;
        c.interval("sensors.mid_range.range", self.range, true)?;
        c.within(
            "sensors.mid_range.fov_deg",
            self.fov_deg,
            f64::MIN_POSITIVE,
            360.0,
            "(0, 360] degrees",
        )?;
        c.within(
            "sensors.mid_range.resolution_deg",
            self.resolution_deg,
            1e-4,
            self.fov_deg,
            "[0.0001, fov_deg] degrees",
        )?;
        c.positive("sensors.mid_range.line_rate_hz", self.line_rate_hz)?;
        c.within(
            "sensors.mid_range.noise.range_sigma",
            self.noise.range_sigma,
            0.0,
            1.0,
            "[0, 1] m",
        )?;
        Ok(())
    }
}

impl ShortRangeSensor {
    /// Checks every value of `[sensors.short_range]`; the error names the key.
    pub(crate) fn check(&self, c: &Check) -> Result<(), SceneError> {
        c.name("sensors.short_range.frame", &self.frame)?;
        c.interval("sensors.short_range.range", self.range, true)?;
        c.within(
            "sensors.short_range.fov_deg",
            self.fov_deg,
            f64::MIN_POSITIVE,
            179.0,
            "(0, 179] degrees",
        )?;
        c.within(
            "sensors.short_range.width",
            f64::from(self.width),
            1.0,
            10_000.0,
            "1..=10000 pixels",
        )?;
        c.within(
            "sensors.short_range.height",
            f64::from(self.height),
            1.0,
            10_000.0,
            "1..=10000 pixels",
        )?;
        c.positive("sensors.short_range.frame_rate_hz", self.frame_rate_hz)?;
        let n = &self.noise;
        let k = "sensors.short_range.noise";
        c.within(
            &format!("{k}.range_sigma_at_1m"),
            n.range_sigma_at_1m,
            0.0,
            1.0,
            "[0, 1] m",
        )?;
        c.within(
            &format!("{k}.range_sigma_exponent"),
            n.range_sigma_exponent,
            0.0,
            4.0,
            "[0, 4]",
        )?;
        c.within(
            &format!("{k}.dropout_probability"),
            n.dropout_probability,
            0.0,
            1.0,
            "[0, 1]",
        )?;
        c.within(
            &format!("{k}.grazing_start_deg"),
            n.grazing_start_deg,
            0.0,
            90.0,
            "[0, 90] degrees",
        )?;
        c.within(
            &format!("{k}.grazing_cutoff_deg"),
            n.grazing_cutoff_deg,
            n.grazing_start_deg,
            90.0,
            "[grazing_start_deg, 90] degrees",
        )?;
        c.within(
            &format!("{k}.range_margin"),
            n.range_margin,
            0.0,
            1.0,
            "[0, 1] m",
        )
    }
}

impl Sensors {
    /// Checks every value of `[sensors]`; the error names the key.
    pub(crate) fn check(&self, c: &Check) -> Result<(), SceneError> {
        self.mid_range.check(c)?;
        self.short_range.check(c)
    }
}
