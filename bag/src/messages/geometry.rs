//! `geometry_msgs`: [`Vector3`], [`Point`], [`Quaternion`], [`Pose`], [`Transform`],
//! [`PoseWithCovariance`], [`PoseWithCovarianceStamped`] and
//! [`TransformStamped`], with conversions to and from nalgebra.

use nalgebra::{Isometry3, Quaternion as NaQuaternion, Translation3, UnitQuaternion};

use super::{CdrStruct, Header, ros_message};
use crate::cdr::{CdrReader, CdrWriter};
use crate::error::CdrError;

/// Three `float64` fields `x`, `y`, `z` (shared by `Vector3` and `Point`).
macro_rules! xyz_struct {
    ($t:ident, $doc:literal, $name:literal, $hash:literal) => {
        #[doc = $doc]
        #[derive(Debug, Clone, Copy, Default, PartialEq)]
        pub struct $t {
            /// x.
            pub x: f64,
            /// y.
            pub y: f64,
            /// z.
            pub z: f64,
        }

        impl CdrStruct for $t {
            fn write_cdr(&self, w: &mut CdrWriter) {
                w.f64(self.x);
                w.f64(self.y);
                w.f64(self.z);
            }
            fn read_cdr(r: &mut CdrReader<'_>) -> Result<Self, CdrError> {
                Ok(Self {
                    x: r.f64()?,
                    y: r.f64()?,
                    z: r.f64()?,
                })
            }
        }

        ros_message!($t, $name, $hash, "float64 x\nfloat64 y\nfloat64 z\n", []);
    };
}

xyz_struct!(
    Vector3,
    "`geometry_msgs/msg/Vector3`: a free vector.",
    "geometry_msgs/msg/Vector3",
    "RIHS01_cc12fe83e4c02719f1ce8070bfd14aecd40f75a96696a67a2a1f37f7dbb0765d"
);
xyz_struct!(
    Point,
    "`geometry_msgs/msg/Point`: a position.",
    "geometry_msgs/msg/Point",
    "RIHS01_6963084842a9b04494d6b2941d11444708d892da2f4b09843b9c43f42a7f6881"
);

/// `geometry_msgs/msg/Quaternion`: a rotation, `w` last on the wire. The default is the
/// identity (`w = 1`), as in ROS.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Quaternion {
    /// i component.
    pub x: f64,
    /// j component.
    pub y: f64,
    /// k component.
    pub z: f64,
    /// Real part.
    pub w: f64,
}

impl Default for Quaternion {
    fn default() -> Self {
        Self {
            x: 0.0,
            y: 0.0,
            z: 0.0,
            w: 1.0,
        }
    }
}

impl Quaternion {
    /// As a unit quaternion (normalised; nalgebra's order is `w, i, j, k`).
    pub fn to_unit(self) -> UnitQuaternion<f64> {
        UnitQuaternion::from_quaternion(NaQuaternion::new(self.w, self.x, self.y, self.z))
    }

    /// From a unit quaternion.
    pub fn from_unit(q: &UnitQuaternion<f64>) -> Self {
        Self {
            x: q.i,
            y: q.j,
            z: q.k,
            w: q.w,
        }
    }
}

impl CdrStruct for Quaternion {
    fn write_cdr(&self, w: &mut CdrWriter) {
        w.f64(self.x);
        w.f64(self.y);
        w.f64(self.z);
        w.f64(self.w);
    }
    fn read_cdr(r: &mut CdrReader<'_>) -> Result<Self, CdrError> {
        Ok(Self {
            x: r.f64()?,
            y: r.f64()?,
            z: r.f64()?,
            w: r.f64()?,
        })
    }
}

ros_message!(
    Quaternion,
    "geometry_msgs/msg/Quaternion",
    "RIHS01_8a765f66778c8ff7c8ab94afcc590a2ed5325a1d9a076ffff38fbce36f458684",
    "float64 x\nfloat64 y\nfloat64 z\nfloat64 w\n",
    []
);

/// `geometry_msgs/msg/Pose`: a position and an orientation.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Pose {
    /// Position.
    pub position: Point,
    /// Orientation.
    pub orientation: Quaternion,
}

impl CdrStruct for Pose {
    fn write_cdr(&self, w: &mut CdrWriter) {
        self.position.write_cdr(w);
        self.orientation.write_cdr(w);
    }
    fn read_cdr(r: &mut CdrReader<'_>) -> Result<Self, CdrError> {
        Ok(Self {
            position: Point::read_cdr(r)?,
            orientation: Quaternion::read_cdr(r)?,
        })
    }
}

ros_message!(
    Pose,
    "geometry_msgs/msg/Pose",
    "RIHS01_d501954e9476cea2996984e812054b68026ae0bfae789d9a10b23daf35cc90fa",
    "geometry_msgs/Point position\ngeometry_msgs/Quaternion orientation\n",
    [Point, Quaternion]
);

/// `geometry_msgs/msg/Transform`: the child frame's pose in the parent
/// (`p_parent = R·p_child + t`).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Transform {
    /// Translation, metres.
    pub translation: Vector3,
    /// Rotation.
    pub rotation: Quaternion,
}

impl Transform {
    /// As an isometry (the rotation normalised).
    ///
    /// ```
    /// use nbv_bag::messages::{Transform, Vector3};
    /// let t = Transform { translation: Vector3 { x: 1.0, y: 2.0, z: 3.0 }, ..Default::default() };
    /// assert_eq!(t.to_isometry().translation.vector.y, 2.0);
    /// assert_eq!(Transform::from_isometry(&t.to_isometry()), t);
    /// ```
    pub fn to_isometry(&self) -> Isometry3<f64> {
        let t = self.translation;
        Isometry3::from_parts(Translation3::new(t.x, t.y, t.z), self.rotation.to_unit())
    }

    /// From an isometry.
    pub fn from_isometry(iso: &Isometry3<f64>) -> Self {
        let v = iso.translation.vector;
        Self {
            translation: Vector3 {
                x: v.x,
                y: v.y,
                z: v.z,
            },
            rotation: Quaternion::from_unit(&iso.rotation),
        }
    }
}

impl CdrStruct for Transform {
    fn write_cdr(&self, w: &mut CdrWriter) {
        self.translation.write_cdr(w);
        self.rotation.write_cdr(w);
    }
    fn read_cdr(r: &mut CdrReader<'_>) -> Result<Self, CdrError> {
        Ok(Self {
            translation: Vector3::read_cdr(r)?,
            rotation: Quaternion::read_cdr(r)?,
        })
    }
}

ros_message!(
    Transform,
    "geometry_msgs/msg/Transform",
    "RIHS01_beb83fbe698636351461f6f35d1abb20010c43d55374d81bd041f1ba2581fddc",
    "geometry_msgs/Vector3 translation\ngeometry_msgs/Quaternion rotation\n",
    [Vector3, Quaternion]
);

/// `geometry_msgs/msg/TransformStamped`: `child_frame_id`'s pose in `header.frame_id` (the
/// parent) at `header.stamp`.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct TransformStamped {
    /// Stamp and parent frame.
    pub header: Header,
    /// The child frame.
    pub child_frame_id: String,
    /// The child's pose in the parent.
    pub transform: Transform,
}

impl CdrStruct for TransformStamped {
    fn write_cdr(&self, w: &mut CdrWriter) {
        self.header.write_cdr(w);
        w.string(&self.child_frame_id);
        self.transform.write_cdr(w);
    }
    fn read_cdr(r: &mut CdrReader<'_>) -> Result<Self, CdrError> {
        Ok(Self {
            header: Header::read_cdr(r)?,
            child_frame_id: r.string()?,
            transform: Transform::read_cdr(r)?,
        })
    }
}

ros_message!(
    TransformStamped,
    "geometry_msgs/msg/TransformStamped",
    "RIHS01_0a241f87d04668d94099cbb5ba11691d5ad32c2f29682e4eb5653424bd275206",
    "std_msgs/Header header\nstring child_frame_id\ngeometry_msgs/Transform transform\n",
    [Header, Transform]
);

/// `geometry_msgs/msg/PoseWithCovariance`: a pose and the 6 × 6 covariance of its error,
/// row-major, in the order x, y, z, then rotations about x, y, z (m², rad²).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PoseWithCovariance {
    /// The pose.
    pub pose: Pose,
    /// Its covariance.
    pub covariance: [f64; 36],
}

impl Default for PoseWithCovariance {
    fn default() -> Self {
        Self {
            pose: Pose::default(),
            covariance: [0.0; 36],
        }
    }
}

impl CdrStruct for PoseWithCovariance {
    fn write_cdr(&self, w: &mut CdrWriter) {
        self.pose.write_cdr(w);
        w.f64_array(&self.covariance);
    }
    fn read_cdr(r: &mut CdrReader<'_>) -> Result<Self, CdrError> {
        Ok(Self {
            pose: Pose::read_cdr(r)?,
            covariance: r.f64_array::<36>()?,
        })
    }
}

ros_message!(
    PoseWithCovariance,
    "geometry_msgs/msg/PoseWithCovariance",
    "RIHS01_9a7c0fd234b7f45c6098745ecccd773ca1085670e64107135397aee31c02e1bb",
    "geometry_msgs/Pose pose\nfloat64[36] covariance\n",
    [Pose]
);

/// `geometry_msgs/msg/PoseWithCovarianceStamped`: a pose with its covariance, in
/// `header.frame_id` at `header.stamp`.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct PoseWithCovarianceStamped {
    /// Stamp and frame.
    pub header: Header,
    /// The pose and its covariance.
    pub pose: PoseWithCovariance,
}

impl CdrStruct for PoseWithCovarianceStamped {
    fn write_cdr(&self, w: &mut CdrWriter) {
        self.header.write_cdr(w);
        self.pose.write_cdr(w);
    }
    fn read_cdr(r: &mut CdrReader<'_>) -> Result<Self, CdrError> {
        Ok(Self {
            header: Header::read_cdr(r)?,
            pose: PoseWithCovariance::read_cdr(r)?,
        })
    }
}

ros_message!(
    PoseWithCovarianceStamped,
    "geometry_msgs/msg/PoseWithCovarianceStamped",
    "RIHS01_26432f9803e43727d3c8f668d1fdb3c630f548af631e2f4e31382371bfea3b6e",
    "std_msgs/Header header\ngeometry_msgs/PoseWithCovariance pose\n",
    [Header, PoseWithCovariance]
);
