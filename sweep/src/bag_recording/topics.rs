//! The bag's topic and frame names, and [`model_topic`]: an object's name made a valid
//! ROS topic name.

/// Every moving robot link (parent→child), as robot_state_publisher publishes them.
pub const TF: &str = "/tf";
/// The fixed transforms (latched).
pub const TF_STATIC: &str = "/tf_static";
/// The six joints' positions.
pub const JOINT_STATES: &str = "/joint_states";
/// The URDF text (latched).
pub const ROBOT_DESCRIPTION: &str = "/robot_description";
/// The laser sweep cloud, world frame.
pub const SWEEP_POINTS: &str = "/nbv/sweep/points";
/// Each view's object points, camera optical frame.
pub const CAMERA_POINTS: &str = "/nbv/camera/points";
/// Each view's depth image.
pub const CAMERA_DEPTH: &str = "/nbv/camera/depth";
/// The camera's intrinsics, with each depth image.
pub const CAMERA_INFO: &str = "/nbv/camera/camera_info";
/// The reduced map's occupied voxels.
pub const GRID_OCCUPIED: &str = "/nbv/grid/occupied";
/// The reduced map's unknown voxels.
pub const GRID_UNKNOWN: &str = "/nbv/grid/unknown";
/// The candidate viewpoints.
pub const CANDIDATES: &str = "/nbv/candidates";
/// The pipeline's events as JSON.
pub const EVENTS: &str = "/nbv/events";
/// Prefix of the models' topics ([`model_topic`]).
pub const MODELS: &str = "/nbv/models/";
/// The fixed frame.
pub const WORLD: &str = "world";
/// The table's frame: the centre of its top face, axes as the world's.
pub const TABLE: &str = "table";

/// `/nbv/models/<name>` with every character outside `[A-Za-z0-9_]` made `_`, and a `_`
/// before a leading digit (a ROS name token starts with a letter or `_`); an empty name is
/// `object_<index>`.
///
/// ```
/// use nbv_sweep::bag_recording::topics::model_topic;
/// assert_eq!(model_topic("jug", 0), "/nbv/models/jug");
/// assert_eq!(model_topic("bottle-a.2", 1), "/nbv/models/bottle_a_2");
/// assert_eq!(model_topic("3d box", 2), "/nbv/models/_3d_box");
/// assert_eq!(model_topic("", 4), "/nbv/models/object_4");
/// ```
pub fn model_topic(name: &str, index: usize) -> String {
    let mut token: String = name
        .chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || c == '_' {
                c
            } else {
                '_'
            }
        })
        .collect();
    if token.is_empty() {
        token = format!("object_{index}");
    } else if token.starts_with(|c: char| c.is_ascii_digit()) {
        token.insert(0, '_');
    }
    format!("{MODELS}{token}")
}
