//! [`save_png`]: writes a picture as PNG atomically
//! ([`nbv_core::atomic_file`]), so a reader never sees half a file.

use super::RenderError;
use image::RgbaImage;
use std::io::Cursor;
use std::path::Path;

/// Writes `image` to `path` as an 8-bit RGBA PNG, atomically.
///
/// ```
/// let dir = tempfile::tempdir().unwrap();
/// let path = dir.path().join("blank.png");
/// let img = image::RgbaImage::from_pixel(4, 3, image::Rgba([10, 20, 30, 255]));
/// nbv_sim::render::save_png(&img, &path).unwrap();
/// let back = image::open(&path).unwrap().to_rgba8();
/// assert_eq!(back, img);
/// ```
pub fn save_png(image: &RgbaImage, path: impl AsRef<Path>) -> Result<(), RenderError> {
    let path = path.as_ref();
    // PNG encoding needs Seek: encode into memory, then write the bytes atomically.
    let mut bytes = Vec::new();
    image
        .write_to(&mut Cursor::new(&mut bytes), image::ImageFormat::Png)
        .and_then(|()| {
            nbv_core::atomic_file::write_atomic(path, &bytes).map_err(image::ImageError::IoError)
        })
        .map_err(|e| RenderError::Write {
            path: path.to_path_buf(),
            detail: e.to_string(),
        })
}
