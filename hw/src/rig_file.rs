//! [`RigFile`]: the TOML file that says where the real devices are and how the sensors are
//! mounted (hand-eye calibration). The scene still says what the sensors are (ranges,
//! field of view, resolution) and what the workcell holds; the rig file only says how to
//! reach this particular rig.
//!
//! ```toml
//! [arm]                      # Comau C4G running hw/pdl2/nbv_server.pdl
//! address = "192.168.1.10:12345"
//! timeout_s = 2.0            # optional
//! sample_timeout_s = 0.5     # longest gap between motion samples (optional; timeout_s)
//!
//! [laser]                    # SICK LMS400
//! address = "192.168.0.1:2111"
//! clock_offset_s = 0.0       # scanner clock → controller clock, seconds (optional)
//! hand_eye = { parent = "tool0", xyz = [0.0, -0.1, 0.05], rpy = [0.0, 0.0, 0.0] }
//!
//! [camera]                   # Dinast IPA-1110
//! usb = "0"                  # the n-th IPA-1110 on the bus, or "BUS:ADDRESS" (optional)
//! ```
//!
//! `hand_eye` (optional) replaces the URDF's nominal mount of the sensor frame: the sensor
//! frame's pose in `parent` (a frame on the flange, `tool0` by default), metres and
//! roll-pitch-yaw radians. Unknown keys are errors, and every error names the file.

use crate::comau::C4gConfig;
use crate::config_error::{ConfigError, check_address, check_timeout};
use crate::dinast::UsbSelection;
use nalgebra::{Translation3, UnitQuaternion};
use nbv_core::kinematics::Robot;
use nbv_core::math::Pose;
use serde::Deserialize;
use std::path::{Path, PathBuf};

/// Why a rig file could not be used.
#[derive(Debug, thiserror::Error)]
pub enum RigFileError {
    /// The file could not be read.
    #[error("{path}: {source}")]
    Read {
        /// The file.
        path: PathBuf,
        /// The I/O error.
        source: std::io::Error,
    },
    /// The TOML is malformed or has a wrong key or value.
    #[error("{path}: {message}")]
    Parse {
        /// The file.
        path: PathBuf,
        /// The parser's message (with line and column).
        message: String,
    },
    /// A value is out of its range.
    #[error("{path}: {key}: {message}")]
    Invalid {
        /// The file.
        path: PathBuf,
        /// The key, dotted.
        key: String,
        /// What is wrong.
        message: String,
    },
    /// The robot model (URDF) could not be loaded.
    #[error("robot model {urdf}: {message}")]
    Robot {
        /// The URDF.
        urdf: PathBuf,
        /// What is wrong.
        message: String,
    },
    /// A hand-eye transform names a frame the robot model cannot mount it on.
    #[error("{path}: {key}: {message}")]
    HandEye {
        /// The file.
        path: PathBuf,
        /// The key, dotted.
        key: String,
        /// What is wrong.
        message: String,
    },
}

/// A sensor mount: the sensor frame's pose in a frame on the flange.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct HandEye {
    /// Flange frame the pose is expressed in.
    #[serde(default = "default_parent")]
    pub parent: String,
    /// Translation, metres.
    pub xyz: [f64; 3],
    /// Roll, pitch, yaw, radians.
    #[serde(default)]
    pub rpy: [f64; 3],
}

fn default_parent() -> String {
    "tool0".into()
}

impl HandEye {
    /// The mount as a pose of the sensor in `parent`.
    pub fn pose(&self) -> Pose {
        Pose::from_parts(
            Translation3::new(self.xyz[0], self.xyz[1], self.xyz[2]),
            UnitQuaternion::from_euler_angles(self.rpy[0], self.rpy[1], self.rpy[2]),
        )
    }
}

/// `[laser]`: the LMS400.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LaserSection {
    /// `host:port` (the LMS400 listens on 2111).
    pub address: String,
    /// Longest wait for a reply or a telegram, seconds.
    #[serde(default = "default_sensor_timeout")]
    pub timeout_s: f64,
    /// Connection attempts when the connection is found lost.
    #[serde(default = "default_attempts")]
    pub connect_attempts: u32,
    /// Added to the scanner's clock to get the controller's (the rig's), seconds.
    #[serde(default)]
    pub clock_offset_s: f64,
    /// Mount of the scanner (default: the URDF's).
    #[serde(default)]
    pub hand_eye: Option<HandEye>,
}

/// `[camera]`: the Dinast.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CameraSection {
    /// Which IPA-1110: `"N"` for the n-th on the bus (default `"0"`), or `"BUS:ADDRESS"`.
    #[serde(default)]
    pub usb: UsbSelection,
    /// Longest wait for a frame, seconds.
    #[serde(default = "default_sensor_timeout")]
    pub timeout_s: f64,
    /// Added to the host clock of a frame to get the rig's, seconds.
    #[serde(default)]
    pub clock_offset_s: f64,
    /// Mount of the camera (default: the URDF's).
    #[serde(default)]
    pub hand_eye: Option<HandEye>,
}

/// A rig file.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RigFile {
    /// The arm (`[arm]`).
    pub arm: C4gConfig,
    /// The mid-range scanner.
    pub laser: LaserSection,
    /// The short-range camera.
    #[serde(default = "default_camera")]
    pub camera: CameraSection,
    /// Where it was read from (errors name it).
    #[serde(skip)]
    pub path: PathBuf,
}

impl LaserSection {
    /// Checks the values a file may get wrong (keys relative to `[laser]`).
    pub fn validate(&self) -> Result<(), ConfigError> {
        check_address("address", &self.address)?;
        check_timeout("timeout_s", self.timeout_s)?;
        if self.connect_attempts == 0 {
            return Err(ConfigError::new("connect_attempts", "must be at least 1"));
        }
        if !self.clock_offset_s.is_finite() {
            return Err(ConfigError::new("clock_offset_s", "must be finite"));
        }
        check_hand_eye(self.hand_eye.as_ref())
    }
}

impl CameraSection {
    /// Checks the values a file may get wrong (keys relative to `[camera]`).
    pub fn validate(&self) -> Result<(), ConfigError> {
        check_timeout("timeout_s", self.timeout_s)?;
        if !self.clock_offset_s.is_finite() {
            return Err(ConfigError::new("clock_offset_s", "must be finite"));
        }
        check_hand_eye(self.hand_eye.as_ref())
    }
}

fn check_hand_eye(he: Option<&HandEye>) -> Result<(), ConfigError> {
    let Some(he) = he else { return Ok(()) };
    if he.xyz.iter().chain(&he.rpy).any(|x| !x.is_finite()) {
        return Err(ConfigError::new("hand_eye", "xyz and rpy must be finite"));
    }
    if he.xyz.iter().any(|x| x.abs() > 1.0) {
        return Err(ConfigError::new(
            "hand_eye",
            "a sensor more than 1 m from the flange",
        ));
    }
    Ok(())
}

fn default_sensor_timeout() -> f64 {
    1.0
}

fn default_attempts() -> u32 {
    3
}

fn default_camera() -> CameraSection {
    CameraSection {
        usb: UsbSelection::default(),
        timeout_s: default_sensor_timeout(),
        clock_offset_s: 0.0,
        hand_eye: None,
    }
}

impl RigFile {
    /// Reads and validates a rig file.
    pub fn load(path: impl AsRef<Path>) -> Result<Self, RigFileError> {
        let path = path.as_ref();
        let text = std::fs::read_to_string(path).map_err(|source| RigFileError::Read {
            path: path.to_owned(),
            source,
        })?;
        Self::parse(&text, path)
    }

    /// Parses and validates rig-file text; `path` is what errors name.
    ///
    /// ```
    /// use nbv_hw::rig_file::RigFile;
    /// let rig = RigFile::parse(
    ///     "[arm]\naddress = \"127.0.0.1:12345\"\n[laser]\naddress = \"127.0.0.1:2111\"\n",
    ///     "rig.toml".as_ref(),
    /// )?;
    /// assert_eq!(rig.arm.timeout_s, 2.0);
    /// let err = RigFile::parse("[arm]\naddress = \"x:1\"\ntimeout_s = -1\n[laser]\naddress = \"y:2\"\n", "rig.toml".as_ref())
    ///     .unwrap_err();
    /// assert_eq!(err.to_string(), "rig.toml: arm.timeout_s: must be a positive number of seconds, got -1");
    /// # Ok::<(), nbv_hw::rig_file::RigFileError>(())
    /// ```
    pub fn parse(text: &str, path: &Path) -> Result<Self, RigFileError> {
        let mut rig: Self = toml::from_str(text).map_err(|e| RigFileError::Parse {
            path: path.to_owned(),
            message: e.to_string().trim_end().to_owned(),
        })?;
        rig.path = path.to_owned();
        rig.validate()?;
        Ok(rig)
    }

    fn invalid(&self, key: &str, message: impl Into<String>) -> RigFileError {
        RigFileError::Invalid {
            path: self.path.clone(),
            key: key.into(),
            message: message.into(),
        }
    }

    fn validate(&self) -> Result<(), RigFileError> {
        let sections = [
            ("arm", self.arm.validate()),
            ("laser", self.laser.validate()),
            ("camera", self.camera.validate()),
        ];
        for (section, result) in sections {
            if let Err(e) = result {
                return Err(self.invalid(&format!("{section}.{}", e.key), e.message));
            }
        }
        Ok(())
    }

    /// The kinematic model the pipeline plans with on this rig: the robot of `urdf` with
    /// the sensors mounted as the file says ([`mount_sensors`](Self::mount_sensors)).
    pub fn robot(
        &self,
        urdf: &std::path::Path,
        laser_frame: &str,
        camera_frame: &str,
    ) -> Result<Robot, RigFileError> {
        let mut robot = Robot::from_urdf_file(urdf).map_err(|e| RigFileError::Robot {
            urdf: urdf.to_path_buf(),
            message: e.to_string(),
        })?;
        self.mount_sensors(&mut robot, laser_frame, camera_frame)?;
        Ok(robot)
    }

    /// Mounts the sensors on `robot` as the file's hand-eye transforms say (`laser_frame`
    /// and `camera_frame` are the sensor frames the scene names); frames without a
    /// `hand_eye` keep the URDF's mount.
    pub fn mount_sensors(
        &self,
        robot: &mut Robot,
        laser_frame: &str,
        camera_frame: &str,
    ) -> Result<(), RigFileError> {
        for (key, frame, he) in [
            ("laser.hand_eye", laser_frame, &self.laser.hand_eye),
            ("camera.hand_eye", camera_frame, &self.camera.hand_eye),
        ] {
            let Some(he) = he else { continue };
            let mount = robot
                .frame_in_tip(&he.parent)
                .and_then(|parent| robot.set_frame_in_tip(frame, parent * he.pose()))
                .map_err(|e| RigFileError::HandEye {
                    path: self.path.clone(),
                    key: key.into(),
                    message: e.to_string(),
                });
            mount?;
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const MINIMAL: &str = "[arm]\naddress = \"127.0.0.1:1\"\n[laser]\naddress = \"127.0.0.1:2\"\n";

    fn parse(text: &str) -> Result<RigFile, RigFileError> {
        RigFile::parse(text, Path::new("r.toml"))
    }

    #[test]
    fn errors_name_the_file_and_the_key() {
        let cases = [
            ("[arm]\naddress = \"h:1\"\n", "missing field `laser`"),
            (
                &format!("{MINIMAL}[camera]\ntimeout = 1\n"),
                "unknown field `timeout`",
            ),
            (
                "[arm]\naddress = \"h\"\n[laser]\naddress = \"h:2\"\n",
                "arm.address: `h` is not host:port",
            ),
            (
                &format!("{MINIMAL}[camera]\nhand_eye = {{ xyz = [0, 0, 5] }}\n"),
                "camera.hand_eye: a sensor more than 1 m",
            ),
            (
                "[arm]\naddress = \"h:1\"\njoint_sign = [1, 1, 2, 1, 1, 1]\n[laser]\naddress = \"h:2\"\n",
                "arm.joint_sign[2]: must be 1 or -1",
            ),
            (
                &format!("{MINIMAL}[camera]\nusb = \"one\"\n"),
                "USB selection \"one\" is neither N nor BUS:ADDRESS",
            ),
        ];
        for (text, expected) in cases {
            let message = parse(text).unwrap_err().to_string();
            assert!(message.starts_with("r.toml: "), "{message}");
            assert!(message.contains(expected), "{message} lacks {expected}");
        }
    }

    #[test]
    fn the_example_rig_files_are_valid() {
        let dir = concat!(env!("CARGO_MANIFEST_DIR"), "/../examples/rigs");
        let lab = RigFile::load(format!("{dir}/lab.toml")).unwrap();
        assert_eq!(lab.laser.address, "192.168.0.1:2111");
        assert_eq!(lab.camera.usb, UsbSelection::Nth(0));
        let emulated = RigFile::load(format!("{dir}/emulated.toml")).unwrap();
        assert!(emulated.arm.address.ends_with(":0"));
        let missing = RigFile::load(format!("{dir}/nope.toml")).unwrap_err();
        assert!(missing.to_string().contains("nope.toml"), "{missing}");
    }

    #[test]
    fn hand_eye_moves_the_sensor_frame_on_the_flange() {
        let mut robot = nbv_core::kinematics::comau_smart_six().unwrap();
        let text = format!(
            "{MINIMAL}[camera]\nhand_eye = {{ xyz = [0.01, 0.02, 0.15], rpy = [0.0, 0.1, 0.0] }}\n"
        );
        let rig = parse(&text).unwrap();
        let laser_before = robot.frame_in_tip("lms400").unwrap();
        rig.mount_sensors(&mut robot, "lms400", "dinast").unwrap();
        assert_eq!(robot.frame_in_tip("lms400").unwrap(), laser_before);
        let tool0 = robot.frame_in_tip("tool0").unwrap();
        let camera = tool0.inverse() * robot.frame_in_tip("dinast").unwrap();
        assert!(
            (camera.translation.vector - nalgebra::Vector3::new(0.01, 0.02, 0.15)).norm() < 1e-12
        );
        assert!((camera.rotation.euler_angles().1 - 0.1).abs() < 1e-12);

        let bad =
            format!("{MINIMAL}[camera]\nhand_eye = {{ parent = \"link_2\", xyz = [0, 0, 0] }}\n");
        let err = parse(&bad)
            .unwrap()
            .mount_sensors(&mut robot, "lms400", "dinast")
            .unwrap_err();
        assert!(err.to_string().contains("camera.hand_eye"), "{err}");
    }
}
