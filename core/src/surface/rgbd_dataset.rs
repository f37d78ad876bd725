//! [`RgbdDataset`]: depth views in Open3D's reconstruction-system layout, so that Open3D
//! (or any tool reading that layout) fuses exactly the views the rig took, and
//! `nbv fuse` fuses other datasets:
//!
//! ```text
//! DIR/depth/000000.png        16-bit depth, millimetres (depth_scale 1000), 0 = no return
//! DIR/color/000000.png        a grey image per frame (the layout requires a colour folder)
//! DIR/camera_intrinsic.json   {"width", "height", "intrinsic_matrix": K column-major}
//! DIR/trajectory.log          per frame "i i i+1" then the camera-to-world 4×4, row by row
//! DIR/noise.json              (nbv's own) the depth noise σ(d) = sigma_at_1m · d^exponent
//! ```

use std::path::{Path, PathBuf};

use nalgebra::Matrix4;

use crate::cloud::io::{decode_depth_png, encode_depth_png};
use crate::math::Pose;

use super::{DepthView, PinholeIntrinsics, SurfaceError, SurfaceMesh, TsdfParams, TsdfVolume};

/// Metres per unit of the depth PNGs: 1 mm.
pub const DEPTH_SCALE: f64 = 0.001;

/// Views of one camera, each with its camera-to-world pose, and the camera's noise.
#[derive(Debug, Clone, PartialEq)]
pub struct RgbdDataset {
    /// The camera.
    pub intrinsics: PinholeIntrinsics,
    /// The views (their intrinsics are `intrinsics`).
    pub views: Vec<DepthView>,
    /// Depth noise σ(d) = `noise.0 · d^noise.1` (m), `None` when unknown (equal weights).
    pub noise: Option<(f64, f64)>,
}

impl RgbdDataset {
    /// A dataset of `views` of one camera, their depths rounded to the layout's
    /// millimetre ([`DEPTH_SCALE`]) as the files hold them, so that fusing it and fusing
    /// what [`write`](Self::write) leaves give the same surface.
    pub fn new(
        intrinsics: PinholeIntrinsics,
        views: Vec<DepthView>,
        noise: Option<(f64, f64)>,
    ) -> Self {
        let views = views
            .into_iter()
            .map(|mut v| {
                v.intrinsics = intrinsics;
                for d in &mut v.depth {
                    *d = if d.is_finite() && f64::from(*d) >= 0.5 * DEPTH_SCALE {
                        ((f64::from(*d) / DEPTH_SCALE).round() * DEPTH_SCALE) as f32
                    } else {
                        f32::NAN
                    };
                }
                v
            })
            .collect();
        Self {
            intrinsics,
            views,
            noise,
        }
    }

    /// The views fused into a surface ([`TsdfVolume`]), each return weighted by the
    /// inverse square of [`noise`](Self::noise) at its depth (equal weights without one).
    pub fn fuse(&self, params: TsdfParams) -> Result<SurfaceMesh, SurfaceError> {
        let mut volume = TsdfVolume::new(params)?;
        let (sigma_at_1m, exponent) = self.noise.unwrap_or((1.0, 0.0));
        for view in &self.views {
            volume.integrate(view, |d| sigma_at_1m * d.max(1e-3).powf(exponent))?;
        }
        Ok(volume.extract_mesh())
    }

    /// Writes the layout into `dir` (created; an existing one is replaced whole). The
    /// files are written into a temporary folder beside it first, so `dir` is complete or
    /// untouched.
    pub fn write(&self, dir: &Path) -> Result<(), SurfaceError> {
        let io = |path: &Path, e: std::io::Error| SurfaceError::file(path, None, e.to_string());
        let parent = match dir.parent() {
            Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
            _ => PathBuf::from("."),
        };
        std::fs::create_dir_all(&parent).map_err(|e| io(&parent, e))?;
        let tmp = tempfile::Builder::new()
            .prefix(".rgbd.")
            .tempdir_in(&parent)
            .map_err(|e| io(&parent, e))?;
        let root = tmp.path();
        for sub in ["depth", "color"] {
            std::fs::create_dir(root.join(sub)).map_err(|e| io(&root.join(sub), e))?;
        }
        let k = &self.intrinsics;
        let grey = grey_png(k.width as u32, k.height as u32).map_err(|e| io(root, e))?;
        let mut log = String::new();
        for (i, view) in self.views.iter().enumerate() {
            let path = root.join(format!("depth/{i:06}.png"));
            let png = encode_depth_png(k.width as u32, k.height as u32, &view.depth, DEPTH_SCALE)
                .map_err(|e| SurfaceError::file(&path, None, e.to_string()))?;
            std::fs::write(&path, png).map_err(|e| io(&path, e))?;
            let path = root.join(format!("color/{i:06}.png"));
            std::fs::write(&path, &grey).map_err(|e| io(&path, e))?;
            let m = view.pose.to_homogeneous();
            log.push_str(&format!("{i} {i} {}\n", i + 1));
            for r in 0..4 {
                let row: Vec<String> = (0..4).map(|c| format!("{:.8}", m[(r, c)])).collect();
                log.push_str(&row.join(" "));
                log.push('\n');
            }
        }
        let path = root.join("trajectory.log");
        std::fs::write(&path, log).map_err(|e| io(&path, e))?;
        let json = serde_json::json!({
            "width": k.width,
            "height": k.height,
            "intrinsic_matrix": [k.fx, 0.0, 0.0, 0.0, k.fy, 0.0, k.cx, k.cy, 1.0],
        });
        let path = root.join("camera_intrinsic.json");
        std::fs::write(
            &path,
            serde_json::to_string_pretty(&json).unwrap_or_default(),
        )
        .map_err(|e| io(&path, e))?;
        if let Some((sigma_at_1m, exponent)) = self.noise {
            let path = root.join("noise.json");
            let json = serde_json::json!({ "sigma_at_1m": sigma_at_1m, "exponent": exponent });
            std::fs::write(&path, json.to_string()).map_err(|e| io(&path, e))?;
        }
        if dir.exists() {
            std::fs::remove_dir_all(dir).map_err(|e| io(dir, e))?;
        }
        let kept = tmp.keep();
        std::fs::rename(&kept, dir).map_err(|e| io(dir, e))?;
        Ok(())
    }

    /// Reads the layout from `dir`: the depth PNGs in name order, paired with the
    /// trajectory's frames in file order. Errors name the file (and line) at fault: a
    /// missing file, a count of frames other than of depth images, a depth image that is
    /// not 16-bit or not of the intrinsics' size, a malformed trajectory or intrinsics.
    pub fn read(dir: &Path) -> Result<Self, SurfaceError> {
        let path = dir.join("camera_intrinsic.json");
        let intrinsics = parse_intrinsics(&read_text(&path)?, &path)?;
        let path = dir.join("trajectory.log");
        let poses = parse_trajectory(&read_text(&path)?, &path)?;
        let depth_dir = dir.join("depth");
        let mut files: Vec<PathBuf> = std::fs::read_dir(&depth_dir)
            .map_err(|e| SurfaceError::file(&depth_dir, None, e.to_string()))?
            .filter_map(|e| e.ok().map(|e| e.path()))
            .filter(|p| p.extension().is_some_and(|x| x.eq_ignore_ascii_case("png")))
            .collect();
        files.sort();
        if files.len() != poses.len() {
            return Err(SurfaceError::file(
                &depth_dir,
                None,
                format!(
                    "{} depth image(s) but {} frame(s) in {}",
                    files.len(),
                    poses.len(),
                    path.display()
                ),
            ));
        }
        let mut views = Vec::with_capacity(files.len());
        for (file, pose) in files.iter().zip(poses) {
            let bytes =
                std::fs::read(file).map_err(|e| SurfaceError::file(file, None, e.to_string()))?;
            let image = decode_depth_png(&bytes, DEPTH_SCALE)
                .map_err(|e| SurfaceError::file(file, None, e.kind.to_string()))?;
            if (image.width as usize, image.height as usize)
                != (intrinsics.width, intrinsics.height)
            {
                return Err(SurfaceError::file(
                    file,
                    None,
                    format!(
                        "{}x{} pixels, but camera_intrinsic.json says {}x{}",
                        image.width, image.height, intrinsics.width, intrinsics.height
                    ),
                ));
            }
            views.push(DepthView {
                intrinsics,
                depth: image.depth_m.iter().map(|&d| d as f32).collect(),
                pose,
            });
        }
        let path = dir.join("noise.json");
        let noise = if path.exists() {
            let v: serde_json::Value = serde_json::from_str(&read_text(&path)?)
                .map_err(|e| SurfaceError::file(&path, Some(e.line()), e.to_string()))?;
            let num = |key: &str| {
                v[key]
                    .as_f64()
                    .filter(|x| x.is_finite() && *x >= 0.0)
                    .ok_or_else(|| {
                        SurfaceError::file(&path, None, format!("`{key}` must be a number ≥ 0"))
                    })
            };
            Some((num("sigma_at_1m")?, num("exponent")?))
        } else {
            None
        };
        Ok(Self {
            intrinsics,
            views,
            noise,
        })
    }
}

fn read_text(path: &Path) -> Result<String, SurfaceError> {
    std::fs::read_to_string(path).map_err(|e| SurfaceError::file(path, None, e.to_string()))
}

/// A mid-grey 8-bit PNG of the given size.
fn grey_png(width: u32, height: u32) -> std::io::Result<Vec<u8>> {
    let img = image::GrayImage::from_pixel(width, height, image::Luma([128]));
    let mut out = std::io::Cursor::new(Vec::new());
    img.write_to(&mut out, image::ImageFormat::Png)
        .map_err(std::io::Error::other)?;
    Ok(out.into_inner())
}

/// Parses Open3D's `PinholeCameraIntrinsic` JSON (`path` names it in errors): `width`,
/// `height` and `intrinsic_matrix`, K in column-major order.
///
/// ```
/// use nbv_core::surface::parse_intrinsics;
/// let k = parse_intrinsics(
///     r#"{"width": 320, "height": 240, "intrinsic_matrix": [300, 0, 0, 0, 310, 0, 159.5, 119.5, 1]}"#,
///     "camera_intrinsic.json".as_ref(),
/// ).unwrap();
/// assert_eq!((k.fx, k.fy, k.cx, k.cy), (300.0, 310.0, 159.5, 119.5));
/// ```
pub fn parse_intrinsics(text: &str, path: &Path) -> Result<PinholeIntrinsics, SurfaceError> {
    let v: serde_json::Value = serde_json::from_str(text)
        .map_err(|e| SurfaceError::file(path, Some(e.line()), e.to_string()))?;
    let size = |key: &str| {
        v[key]
            .as_u64()
            .filter(|&n| n > 0 && n <= 1 << 16)
            .ok_or_else(|| {
                SurfaceError::file(
                    path,
                    None,
                    format!("`{key}` must be a whole number of pixels in [1, 65536]"),
                )
            })
    };
    let (width, height) = (size("width")? as usize, size("height")? as usize);
    let m: Vec<f64> = v["intrinsic_matrix"]
        .as_array()
        .map(|a| a.iter().filter_map(serde_json::Value::as_f64).collect())
        .unwrap_or_default();
    if m.len() != 9 {
        return Err(SurfaceError::file(
            path,
            None,
            "`intrinsic_matrix` must be 9 numbers (K, column-major)",
        ));
    }
    let k = PinholeIntrinsics {
        width,
        height,
        fx: m[0],
        fy: m[4],
        cx: m[6],
        cy: m[7],
    };
    if !k.is_valid() {
        return Err(SurfaceError::file(
            path,
            None,
            "`intrinsic_matrix` needs positive focal lengths and a finite principal point",
        ));
    }
    Ok(k)
}

/// Parses a Redwood `trajectory.log` (`path` names it in errors): per frame a line of
/// three integers, then the camera-to-world 4×4 matrix row by row; blank lines and lines
/// starting with `#` are skipped. The matrix must be rigid (a rotation and a translation).
///
/// ```
/// use nbv_core::surface::parse_trajectory;
/// let log = "0 0 1\n1 0 0 0.5\n0 1 0 0\n0 0 1 0\n0 0 0 1\n";
/// let poses = parse_trajectory(log, "trajectory.log".as_ref()).unwrap();
/// assert_eq!(poses[0].translation.vector.x, 0.5);
/// let bad = parse_trajectory("0 0 1\n1 0 0\n0 1 0 0\n0 0 1 0\n0 0 0 1\n", "t.log".as_ref())
///     .unwrap_err();
/// assert_eq!(bad.to_string(), "t.log line 2: expected 4 numbers, found 3");
/// ```
pub fn parse_trajectory(text: &str, path: &Path) -> Result<Vec<Pose>, SurfaceError> {
    let lines: Vec<(usize, &str)> = text
        .lines()
        .enumerate()
        .map(|(i, l)| (i + 1, l.trim()))
        .filter(|(_, l)| !l.is_empty() && !l.starts_with('#'))
        .collect();
    let mut poses = Vec::new();
    for frame in lines.chunks(5) {
        let (n, header) = frame[0];
        let ints: Vec<&str> = header.split_whitespace().collect();
        if ints.len() != 3 || ints.iter().any(|s| s.parse::<i64>().is_err()) {
            return Err(SurfaceError::file(
                path,
                Some(n),
                "expected a frame's three integers",
            ));
        }
        if frame.len() < 5 {
            let last = frame.last().map_or(n, |l| l.0);
            return Err(SurfaceError::file(
                path,
                Some(last + 1),
                "the file ends inside a frame's matrix",
            ));
        }
        let mut m = Matrix4::zeros();
        for (r, &(n, line)) in frame[1..].iter().enumerate() {
            let row: Vec<f64> = line
                .split_whitespace()
                .map(|s| s.parse::<f64>())
                .collect::<Result<_, _>>()
                .map_err(|e| SurfaceError::file(path, Some(n), format!("not a number: {e}")))?;
            if row.len() != 4 {
                return Err(SurfaceError::file(
                    path,
                    Some(n),
                    format!("expected 4 numbers, found {}", row.len()),
                ));
            }
            if row.iter().any(|x| !x.is_finite()) {
                return Err(SurfaceError::file(path, Some(n), "a number is not finite"));
            }
            for (c, x) in row.into_iter().enumerate() {
                m[(r, c)] = x;
            }
        }
        let rot = m.fixed_view::<3, 3>(0, 0).into_owned();
        let rigid = (rot.transpose() * rot - nalgebra::Matrix3::identity()).norm() < 1e-4
            && rot.determinant() > 0.0
            && (m.fixed_view::<1, 4>(3, 0) - nalgebra::RowVector4::new(0.0, 0.0, 0.0, 1.0)).norm()
                < 1e-9;
        if !rigid {
            return Err(SurfaceError::file(
                path,
                Some(frame[1].0),
                "the frame's matrix is not a rotation and a translation",
            ));
        }
        let r = nalgebra::Rotation3::from_matrix(&rot);
        let t = nalgebra::Translation3::new(m[(0, 3)], m[(1, 3)], m[(2, 3)]);
        poses.push(Pose::from_parts(t, r.into()));
    }
    Ok(poses)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rig::DepthCameraSpec;
    use nalgebra::{Isometry3, Vector3};

    fn dataset() -> RgbdDataset {
        let k = PinholeIntrinsics::of_camera(&DepthCameraSpec::ipa1110());
        let views = (0..3)
            .map(|i| {
                let mut depth = vec![f32::NAN; k.width * k.height];
                for (j, d) in depth.iter_mut().enumerate().filter(|(j, _)| j % 7 == i) {
                    *d = 0.3 + (j % 100) as f32 * 0.001;
                }
                DepthView {
                    intrinsics: k,
                    depth,
                    pose: Isometry3::new(
                        Vector3::new(0.1 * i as f64, 0.2, 0.3),
                        Vector3::new(0.1, -0.2, 0.3 * i as f64),
                    ),
                }
            })
            .collect();
        RgbdDataset {
            intrinsics: k,
            views,
            noise: Some((0.01, 1.5)),
        }
    }

    /// Written and read back: the same camera, poses to 1e-8, depths to the millimetre.
    #[test]
    fn round_trip() {
        let dir = tempfile::tempdir().unwrap();
        let out = dir.path().join("rgbd");
        let d = dataset();
        d.write(&out).unwrap();
        // Written twice: replaced whole, nothing left beside it.
        d.write(&out).unwrap();
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 1);
        let back = RgbdDataset::read(&out).unwrap();
        assert_eq!(back.intrinsics, d.intrinsics);
        assert_eq!(back.noise, d.noise);
        assert_eq!(back.views.len(), 3);
        for (a, b) in back.views.iter().zip(&d.views) {
            assert!((a.pose.to_homogeneous() - b.pose.to_homogeneous()).norm() < 1e-7);
            for (x, y) in a.depth.iter().zip(&b.depth) {
                assert_eq!(x.is_nan(), y.is_nan());
                if x.is_finite() {
                    assert!((x - y).abs() <= 0.0005 + 1e-6);
                }
            }
        }
    }

    /// Bad input names the file and what is wrong.
    #[test]
    fn bad_files_are_named() {
        let dir = tempfile::tempdir().unwrap();
        let out = dir.path().join("rgbd");
        dataset().write(&out).unwrap();
        std::fs::remove_file(out.join("depth/000002.png")).unwrap();
        let e = RgbdDataset::read(&out).unwrap_err().to_string();
        assert!(
            e.contains("depth") && e.contains("2 depth image(s) but 3 frame(s)"),
            "{e}"
        );
        // An 8-bit depth image.
        std::fs::copy(out.join("color/000002.png"), out.join("depth/000002.png")).unwrap();
        let e = RgbdDataset::read(&out).unwrap_err().to_string();
        assert!(e.contains("000002.png") && e.contains("16-bit"), "{e}");
        std::fs::write(out.join("camera_intrinsic.json"), "{\"width\": 320}").unwrap();
        let e = RgbdDataset::read(&out).unwrap_err().to_string();
        assert!(
            e.contains("camera_intrinsic.json") && e.contains("height"),
            "{e}"
        );
        std::fs::remove_file(out.join("trajectory.log")).unwrap();
        let e = RgbdDataset::read(&out).unwrap_err().to_string();
        assert!(
            e.contains("camera_intrinsic.json") || e.contains("trajectory.log"),
            "{e}"
        );
    }

    /// A matrix that is no rigid motion, and one frame cut short.
    #[test]
    fn malformed_trajectories() {
        let p: &Path = "t.log".as_ref();
        let e = parse_trajectory("0 0 1\n2 0 0 0\n0 1 0 0\n0 0 1 0\n0 0 0 1\n", p).unwrap_err();
        assert_eq!(
            e.to_string(),
            "t.log line 2: the frame's matrix is not a rotation and a translation"
        );
        let e = parse_trajectory("0 0 1\n1 0 0 0\n0 1 0 0\n", p).unwrap_err();
        assert_eq!(
            e.to_string(),
            "t.log line 4: the file ends inside a frame's matrix"
        );
        let e = parse_trajectory("x 0 1\n", p).unwrap_err();
        assert_eq!(
            e.to_string(),
            "t.log line 1: expected a frame's three integers"
        );
    }
}
