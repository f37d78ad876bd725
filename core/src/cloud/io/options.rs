//! Reader and writer options ([`ReadOptions`], [`WriteOptions`]) and what a reader returns
//! besides the points ([`CloudFile`]).

use nalgebra::Isometry3;

use crate::cloud::PointCloud;

/// What a reader does with points whose position, origin or normal is NaN or infinite
/// (PCL writes NaN for the invalid pixels of organised clouds, and NaN normals where
/// normal estimation failed).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum NonFinite {
    /// Remove such points, keeping every column in step (the default: the cloud then
    /// passes [`PointCloud::validate`] and the count is reported in
    /// [`CloudFile::dropped_non_finite`]).
    #[default]
    Drop,
    /// Keep them (an organised cloud keeps `width × height` points in row-major order).
    Keep,
    /// Fail with [`CloudIoErrorKind::NonFinite`](super::CloudIoErrorKind::NonFinite) at the
    /// first such point.
    Reject,
}

/// Options of the readers.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct ReadOptions {
    /// Policy for non-finite points.
    pub non_finite: NonFinite,
}

/// Text or binary body.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Encoding {
    /// One record per line, values separated by one space (`format ascii 1.0`,
    /// `DATA ascii`).
    Ascii,
    /// Little-endian binary records (`format binary_little_endian 1.0`, `DATA binary`).
    #[default]
    Binary,
    /// PCD only: LZF-compressed field-major binary (`DATA binary_compressed`, as PCL
    /// writes it). Writing a PLY file with it is an
    /// [`Unsupported`](super::CloudIoErrorKind::Unsupported) error.
    BinaryCompressed,
}

/// Floating-point type of the written coordinates (points, normals, origins, truth).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum FloatType {
    /// 32-bit `float` (PLY) / `F 4` (PCD), as PCL and most tools write: about 7 significant
    /// digits, i.e. 0.1 µm at 1 m.
    #[default]
    F32,
    /// 64-bit `double` / `F 8`, lossless.
    F64,
}

/// Options of the writers. The default is binary little-endian with 32-bit floats.
///
/// ```
/// use nbv_core::cloud::io::{Encoding, FloatType, WriteOptions};
/// let o = WriteOptions { encoding: Encoding::Ascii, float: FloatType::F64 };
/// assert_ne!(o, WriteOptions::default());
/// ```
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct WriteOptions {
    /// Text or binary body.
    pub encoding: Encoding,
    /// Type of coordinate values. Labels and views are always `uint` / `U 4`.
    pub float: FloatType,
}

/// A cloud as read from a file, with the file's metadata.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct CloudFile {
    /// The points and the columns the file has.
    pub cloud: PointCloud,
    /// Columns per row as declared in the file (PCD `WIDTH`; the vertex count for PLY).
    /// Describes the file: after non-finite points are dropped, `cloud.len()` is smaller.
    pub width: usize,
    /// Rows as declared in the file (PCD `HEIGHT`, > 1 for organised clouds; 1 for PLY).
    pub height: usize,
    /// The PCD `VIEWPOINT` (sensor pose of the whole cloud, in the cloud's frame), if the
    /// header has one. Points are *not* transformed by it.
    pub viewpoint: Option<Isometry3<f64>>,
    /// Points removed by [`NonFinite::Drop`].
    pub dropped_non_finite: usize,
    /// Names of the point fields (PCD) or vertex properties (PLY) that were skipped because
    /// no column takes them (colours, intensity, curvature, `_` padding, ...), in file
    /// order. Other PLY elements (faces, PCL's `camera`) are skipped and not listed.
    pub ignored_fields: Vec<String>,
}
