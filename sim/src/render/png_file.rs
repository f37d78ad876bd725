//! [`save_png`]: writes a picture as PNG atomically (temporary file in the destination
//! directory, then rename), so a reader never sees half a file.

use super::RenderError;
use image::RgbaImage;
use std::io::{BufWriter, Write};
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
    let fail = |detail: String| RenderError::Write {
        path: path.to_path_buf(),
        detail,
    };
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    };
    let tmp = tempfile::Builder::new()
        .prefix(".nbv-png-")
        .suffix(".tmp")
        .tempfile_in(dir)
        .map_err(|e| {
            fail(format!(
                "cannot create a temporary file in {}: {e}",
                dir.display()
            ))
        })?;
    {
        let mut out = BufWriter::new(tmp.as_file());
        image
            .write_to(&mut out, image::ImageFormat::Png)
            .map_err(|e| fail(e.to_string()))?;
        out.flush().map_err(|e| fail(e.to_string()))?;
    }
    tmp.as_file().sync_all().map_err(|e| fail(e.to_string()))?;
    tmp.persist(path).map_err(|e| fail(e.error.to_string()))?;
    Ok(())
}
