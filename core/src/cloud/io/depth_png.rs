//! 16-bit depth images as PNG, as Kinect-style tools store them: grey value =
//! `round(depth / scale)` with 0 meaning "no measurement"; the default scale is 1 mm per
//! unit (Open3D's and PCL's `depth_scale` 1000).

use std::io::Cursor;
use std::path::Path;

use image::{DynamicImage, ImageBuffer, ImageFormat, ImageReader, Luma};

use super::atomic_file::write_atomically;
use super::error::{CloudIoError, CloudIoErrorKind};

/// Metres per grey level of [`write_depth_png`] by default: 1 mm.
pub const DEFAULT_DEPTH_SCALE: f64 = 0.001;

/// A decoded depth image: row-major depths in metres, NaN where the pixel is 0 (invalid).
#[derive(Debug, Clone, PartialEq)]
pub struct DepthImage {
    /// Pixels per row.
    pub width: u32,
    /// Rows.
    pub height: u32,
    /// `width × height` depths in metres, row by row; NaN for invalid pixels.
    pub depth_m: Vec<f64>,
}

fn depth_error(msg: String) -> CloudIoError {
    CloudIoError::file(CloudIoErrorKind::Depth(msg))
}

fn check_scale(scale: f64) -> Result<(), CloudIoError> {
    if scale.is_finite() && scale > 0.0 {
        Ok(())
    } else {
        Err(depth_error(format!(
            "scale {scale} must be a positive number of metres per unit"
        )))
    }
}

/// Encodes row-major depths in metres as a 16-bit greyscale PNG.
///
/// Each pixel becomes `round(depth / scale)`. NaN and infinite depths (no measurement)
/// become 0, as do depths below `scale / 2`. A negative depth, or one above
/// `65535 × scale` (65.535 m at the default scale), is an error rather than a silently
/// wrong pixel: choose a coarser scale for far ranges.
///
/// ```
/// use nbv_core::cloud::io::{encode_depth_png, decode_depth_png, DEFAULT_DEPTH_SCALE};
/// let png = encode_depth_png(2, 1, &[0.5f32, f32::NAN], DEFAULT_DEPTH_SCALE).unwrap();
/// let img = decode_depth_png(&png, DEFAULT_DEPTH_SCALE).unwrap();
/// assert!((img.depth_m[0] - 0.5).abs() < 1e-9 && img.depth_m[1].is_nan());
/// ```
pub fn encode_depth_png<T: Copy + Into<f64>>(
    width: u32,
    height: u32,
    depth_m: &[T],
    scale: f64,
) -> Result<Vec<u8>, CloudIoError> {
    check_scale(scale)?;
    if width == 0 || height == 0 {
        return Err(depth_error(format!(
            "a {width} × {height} image has no pixel"
        )));
    }
    if depth_m.len() as u64 != u64::from(width) * u64::from(height) {
        return Err(depth_error(format!(
            "{} depths for a {width} × {height} image",
            depth_m.len()
        )));
    }
    let mut pixels = Vec::with_capacity(depth_m.len());
    for (i, &d) in depth_m.iter().enumerate() {
        let d: f64 = d.into();
        let (u, v) = (i % width as usize, i / width as usize);
        let units = if d.is_finite() {
            (d / scale).round()
        } else {
            0.0
        };
        if units < 0.0 {
            return Err(depth_error(format!(
                "pixel ({u}, {v}) has negative depth {d} m"
            )));
        }
        if units > f64::from(u16::MAX) {
            return Err(depth_error(format!(
                "pixel ({u}, {v}) depth {d} m exceeds 65535 × scale = {} m",
                65535.0 * scale
            )));
        }
        pixels.push(units as u16);
    }
    let img: ImageBuffer<Luma<u16>, Vec<u16>> = ImageBuffer::from_raw(width, height, pixels)
        .ok_or_else(|| depth_error("pixel buffer does not match the image size".into()))?;
    let mut out = Cursor::new(Vec::new());
    DynamicImage::ImageLuma16(img)
        .write_to(&mut out, ImageFormat::Png)
        .map_err(|e| CloudIoError::file(CloudIoErrorKind::Png(e)))?;
    Ok(out.into_inner())
}

/// Decodes a 16-bit greyscale PNG into depths in metres (`value × scale`, NaN for 0).
/// Other pixel formats (8-bit, colour) are an error: their scale is ambiguous.
pub fn decode_depth_png(bytes: &[u8], scale: f64) -> Result<DepthImage, CloudIoError> {
    check_scale(scale)?;
    let mut reader = ImageReader::with_format(Cursor::new(bytes), ImageFormat::Png);
    // image's default limits cap decoder allocations (512 MiB) whatever the header claims.
    reader.limits(image::Limits::default());
    let img = reader
        .decode()
        .map_err(|e| CloudIoError::file(CloudIoErrorKind::Png(e)))?;
    let DynamicImage::ImageLuma16(buf) = img else {
        return Err(depth_error(format!(
            "expected a 16-bit greyscale PNG, found {:?}",
            img.color()
        )));
    };
    let (width, height) = buf.dimensions();
    let depth_m = buf
        .into_raw()
        .into_iter()
        .map(|v| {
            if v == 0 {
                f64::NAN
            } else {
                f64::from(v) * scale
            }
        })
        .collect();
    Ok(DepthImage {
        width,
        height,
        depth_m,
    })
}

/// Writes a depth image as a 16-bit PNG file, atomically (see [`encode_depth_png`]).
pub fn write_depth_png<T: Copy + Into<f64>>(
    path: impl AsRef<Path>,
    width: u32,
    height: u32,
    depth_m: &[T],
    scale: f64,
) -> Result<(), CloudIoError> {
    let path = path.as_ref();
    let png = encode_depth_png(width, height, depth_m, scale).map_err(|e| e.with_path(path))?;
    write_atomically(path, |w| w.write_all(&png).map_err(CloudIoError::io))
}

/// Reads a 16-bit PNG depth image (see [`decode_depth_png`]).
pub fn read_depth_png(path: impl AsRef<Path>, scale: f64) -> Result<DepthImage, CloudIoError> {
    let path = path.as_ref();
    let bytes = std::fs::read(path).map_err(|e| CloudIoError::io(e).with_path(path))?;
    decode_depth_png(&bytes, scale).map_err(|e| e.with_path(path))
}
