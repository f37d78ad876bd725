//! `sensor_msgs`: [`JointState`], the robot's joint positions (and velocities, efforts).

use super::{CdrStruct, Header, ros_message};
use crate::cdr::{CdrReader, CdrWriter};
use crate::error::CdrError;

/// `sensor_msgs/msg/JointState`: parallel arrays by joint; any may be empty.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct JointState {
    /// Stamp (frame usually empty).
    pub header: Header,
    /// Joint names.
    pub name: Vec<String>,
    /// Positions (rad or m).
    pub position: Vec<f64>,
    /// Velocities.
    pub velocity: Vec<f64>,
    /// Efforts.
    pub effort: Vec<f64>,
}

impl CdrStruct for JointState {
    fn write_cdr(&self, w: &mut CdrWriter) {
        self.header.write_cdr(w);
        w.string_seq(&self.name);
        w.f64_seq(&self.position);
        w.f64_seq(&self.velocity);
        w.f64_seq(&self.effort);
    }
    fn read_cdr(r: &mut CdrReader<'_>) -> Result<Self, CdrError> {
        Ok(Self {
            header: Header::read_cdr(r)?,
            name: r.string_seq()?,
            position: r.f64_seq()?,
            velocity: r.f64_seq()?,
            effort: r.f64_seq()?,
        })
    }
}

ros_message!(
    JointState,
    "sensor_msgs/msg/JointState",
    "RIHS01_a13ee3a330e346c9d87b5aa18d24e11690752bd33a0350f11c5882bc9179260e",
    "std_msgs/Header header\nstring[] name\nfloat64[] position\nfloat64[] velocity\n\
     float64[] effort\n",
    [Header]
);
