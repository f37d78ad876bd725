//! [`RenderError`]: everything that can stop a picture from being made.

use std::path::PathBuf;

/// Why rendering or writing a picture failed.
#[derive(Debug, thiserror::Error)]
pub enum RenderError {
    /// wgpu found no adapter at all: no GPU driver and no software driver.
    #[error(
        "no GPU adapter (backends tried: {backends}): install Mesa's lavapipe \
         (Debian packages mesa-vulkan-drivers libvulkan1) or llvmpipe \
         (libegl1 libegl-mesa0 libgl1-mesa-dri), or set WGPU_BACKEND to a backend this \
         machine has (vulkan, gl); wgpu said: {detail}"
    )]
    NoAdapter {
        /// The backends that were asked for.
        backends: String,
        /// wgpu's own explanation.
        detail: String,
    },
    /// An adapter exists but refused to open a device.
    #[error("the GPU adapter {adapter} refused a device: {detail}")]
    NoDevice {
        /// The adapter's name and backend.
        adapter: String,
        /// wgpu's own explanation.
        detail: String,
    },
    /// The requested picture size is zero or larger than the device allows.
    #[error("image size {width}x{height} is not allowed: each side must be in 1..={max}")]
    BadSize {
        /// Requested width in pixels.
        width: u32,
        /// Requested height in pixels.
        height: u32,
        /// The device's largest texture side.
        max: u32,
    },
    /// The scene has more data than one GPU buffer of this device may hold.
    #[error("the scene's {what} need {bytes} bytes, more than the device's buffer limit {max}")]
    TooLarge {
        /// Which drawables.
        what: &'static str,
        /// Bytes needed.
        bytes: u64,
        /// The device limit.
        max: u64,
    },
    /// Two per-item arrays of one drawable have different lengths.
    #[error("{what}: {expected} items but {got} colours")]
    LengthMismatch {
        /// Which drawable.
        what: &'static str,
        /// Number of items.
        expected: usize,
        /// Number of colours given.
        got: usize,
    },
    /// A point cloud lacks the column it was asked to be coloured by.
    #[error("the point cloud has no `{0}` column to colour by")]
    MissingColumn(&'static str),
    /// The GPU reported an error while rendering or reading back.
    #[error("GPU error while rendering: {0}")]
    Gpu(String),
    /// Writing the PNG failed.
    #[error("cannot write PNG {path}: {detail}")]
    Write {
        /// Destination.
        path: PathBuf,
        /// What went wrong.
        detail: String,
    },
}
