//! [`SceneError`]: every way a scene can fail to load, validate, save or generate. Its
//! message names the file, the key path (`objects[2].pose.xyz`) and the problem.

use nbv_core::mesh::io::MeshIoError;
use std::path::PathBuf;
use thiserror::Error;

/// An error about a scene file.
#[derive(Debug, Error)]
pub enum SceneError {
    /// The file could not be read or written.
    #[error("{file}: {source}")]
    Io {
        /// The scene file.
        file: PathBuf,
        /// The I/O error.
        source: std::io::Error,
    },
    /// TOML syntax error, unknown key, missing key or wrong type (the message from the TOML
    /// parser, with line, column and key).
    #[error("{file}: {message}")]
    Parse {
        /// The scene file.
        file: PathBuf,
        /// The parser's message.
        message: String,
    },
    /// A value is not acceptable.
    #[error("{file}: `{key}`: {problem}")]
    Invalid {
        /// The scene file.
        file: PathBuf,
        /// Key path of the offending value, e.g. `objects[2].pose.xyz`.
        key: String,
        /// What is wrong (boxed to keep the error small).
        problem: Box<Problem>,
    },
    /// A mesh file referenced by the scene could not be loaded.
    #[error("{file}: `{key}`: {source}")]
    Mesh {
        /// The scene file.
        file: PathBuf,
        /// Key path of the mesh reference.
        key: String,
        /// The mesh reader's error.
        source: MeshIoError,
    },
    /// The scene could not be written as TOML.
    #[error("{file}: cannot serialise the scene: {message}")]
    Serialize {
        /// The destination.
        file: PathBuf,
        /// The serialiser's message.
        message: String,
    },
    /// No built-in scene has this name.
    #[error("no built-in scene named `{name}` (built-in: {available})")]
    UnknownBuiltin {
        /// The requested name.
        name: String,
        /// The names that exist, comma separated.
        available: String,
    },
    /// The random generator could not build a valid scene.
    #[error("scene generator (seed {seed}): {message}")]
    Generate {
        /// The generator's seed.
        seed: u64,
        /// Why it failed.
        message: String,
    },
}

/// What is wrong with a value (the `problem` of [`SceneError::Invalid`]).
#[derive(Debug, Clone, PartialEq, Error)]
pub enum Problem {
    /// NaN or infinite.
    #[error("must be finite (got {0})")]
    NotFinite(String),
    /// Zero or negative where a positive value is needed.
    #[error("must be positive (got {0})")]
    NotPositive(String),
    /// Outside the accepted interval.
    #[error("{value} is out of range: {expected}")]
    OutOfRange {
        /// The value as written.
        value: String,
        /// The accepted interval, in words.
        expected: String,
    },
    /// An interval whose lower end is not below its upper end.
    #[error("the lower end must be below the upper end (got {0})")]
    EmptyRange(String),
    /// The workspace side is not a whole number of voxels.
    #[error("resolution {resolution} does not divide the workspace side {side} (axis {axis})")]
    ResolutionNotDividing {
        /// Voxel size.
        resolution: f64,
        /// Side length.
        side: f64,
        /// Axis name.
        axis: char,
    },
    /// A referenced file does not exist.
    #[error("file {0} does not exist")]
    MissingFile(PathBuf),
    /// A mesh is not closed and consistently oriented, or has no positive volume.
    #[error("mesh {path} is not watertight with positive volume ({detail})")]
    NotWatertight {
        /// The mesh file.
        path: PathBuf,
        /// What failed.
        detail: String,
    },
    /// The name is used twice.
    #[error("duplicate name `{0}`")]
    Duplicate(String),
    /// An empty string or list where content is needed.
    #[error("must not be empty")]
    Empty,
    /// An obstacle gives both or neither of `box` and `mesh`.
    #[error("give exactly one of `box` and `mesh`")]
    ShapeChoice,
    /// Part of an object lies outside the workspace.
    #[error("object `{name}` extends outside the workspace (bounds {bounds})")]
    OutsideWorkspace {
        /// Object name.
        name: String,
        /// Its placed bounds, formatted.
        bounds: String,
    },
    /// An object does not rest on the table top.
    #[error("object `{name}` does not rest on the table: {detail}")]
    NotOnTable {
        /// Object name.
        name: String,
        /// What is off.
        detail: String,
    },
    /// Two shapes are closer than allowed, touch, or interpenetrate.
    #[error("`{a}` and `{b}` are {distance:.4} m apart, less than the minimum {min} m{note}")]
    TooClose {
        /// First name.
        a: String,
        /// Second name.
        b: String,
        /// Their distance (0 when they touch or intersect).
        distance: f64,
        /// The required minimum.
        min: f64,
        /// ` (they intersect)`, ` (one is inside the other)` or empty.
        note: String,
    },
    /// An obstacle cuts into the table.
    #[error("obstacle `{0}` penetrates the table")]
    IntoTable(String),
    /// The grid would be unreasonably large.
    #[error("the grid has {0} voxels, more than the limit of 100 million")]
    GridTooLarge(usize),
    /// The robot model cannot be used: malformed URDF, no closed-form IK, a missing sensor
    /// frame, a home configuration outside the joint limits.
    #[error("robot model: {0}")]
    Robot(String),
    /// A seed too large for TOML's signed 64-bit integers.
    #[error("seed {0} exceeds 2^63 - 1")]
    SeedTooLarge(u64),
}
