//! [`UrdfError`]: why a URDF could not be turned into a kinematic chain.

/// A URDF that cannot be loaded as a six-joint serial arm. Every variant names the file (or
/// `<string>` for in-memory text) and says what is wrong.
#[derive(Debug, thiserror::Error)]
pub enum UrdfError {
    /// The file could not be read.
    #[error("{file}: cannot read the URDF: {source}")]
    Read {
        /// File name.
        file: String,
        /// The I/O error.
        #[source]
        source: std::io::Error,
    },
    /// The XML is malformed or does not follow the URDF schema.
    #[error("{file}: not a valid URDF: {message}")]
    Parse {
        /// File name.
        file: String,
        /// The parser's message.
        message: String,
    },
    /// Two links or two joints share a name.
    #[error("{file}: {kind} `{name}` is defined more than once")]
    Duplicate {
        /// File name.
        file: String,
        /// `"link"` or `"joint"`.
        kind: &'static str,
        /// The repeated name.
        name: String,
    },
    /// A joint refers to a link that is not defined.
    #[error("{file}: joint `{joint}` names {role} link `{link}`, which is not defined")]
    MissingLink {
        /// File name.
        file: String,
        /// The joint.
        joint: String,
        /// `"parent"` or `"child"`.
        role: &'static str,
        /// The missing link.
        link: String,
    },
    /// The links do not form a tree whose movable joints lie on one path from the root.
    #[error("{file}: not a serial chain: {detail}")]
    NotSerialChain {
        /// File name.
        file: String,
        /// What is wrong.
        detail: String,
    },
    /// A joint type other than `revolute` or `fixed`.
    #[error(
        "{file}: joint `{joint}` is of type `{kind}`; only revolute and fixed joints are supported"
    )]
    UnsupportedJointType {
        /// File name.
        file: String,
        /// The joint.
        joint: String,
        /// Its type as written in the URDF.
        kind: String,
    },
    /// A revolute joint without `<limit lower upper velocity>`.
    #[error("{file}: revolute joint `{joint}` has no <limit> with lower, upper and velocity")]
    MissingLimits {
        /// File name.
        file: String,
        /// The joint.
        joint: String,
    },
    /// Limits present but unusable (lower > upper, velocity ≤ 0).
    #[error("{file}: joint `{joint}` has invalid limits: {detail}")]
    InvalidLimits {
        /// File name.
        file: String,
        /// The joint.
        joint: String,
        /// What is wrong.
        detail: String,
    },
    /// A revolute joint whose axis has zero length.
    #[error("{file}: joint `{joint}` has a zero-length axis")]
    ZeroAxis {
        /// File name.
        file: String,
        /// The joint.
        joint: String,
    },
    /// The chain does not have exactly six revolute joints.
    #[error("{file}: expected {expected} revolute joints from `{root}` to the tip, found {found}")]
    JointCount {
        /// File name.
        file: String,
        /// The root link.
        root: String,
        /// Joints required.
        expected: usize,
        /// Joints found.
        found: usize,
    },
    /// A NaN or infinite number.
    #[error("{file}: {item}: non-finite number in {field}")]
    NonFinite {
        /// File name.
        file: String,
        /// The link or joint.
        item: String,
        /// The attribute.
        field: &'static str,
    },
    /// A collision or visual primitive with a non-positive or non-finite size.
    #[error("{file}: link `{link}`: invalid geometry: {detail}")]
    InvalidGeometry {
        /// File name.
        file: String,
        /// The link.
        link: String,
        /// What is wrong.
        detail: String,
    },
}
