//! `nbv fuse`: a dataset in Open3D's layout, written here from a sphere's depth views,
//! fused into a mesh with normals; bad input fails with the file named and no output.

mod common;

use common::{nbv, text};
use nalgebra::Point3;
use nbv_core::rig::DepthCameraSpec;
use nbv_core::surface::{DepthView, PinholeIntrinsics, RgbdDataset};
use nbv_fixtures::sphere_views::{around, sphere_depth};

/// Eight views of a 5 cm sphere at (0.8, 0, 0.3) from 0.35 m around it.
fn sphere_dataset() -> RgbdDataset {
    let k = PinholeIntrinsics::of_camera(&DepthCameraSpec::ipa1110());
    let centre = Point3::new(0.8, 0.0, 0.3);
    let views = around(centre, 8, 0.35, 0.5)
        .into_iter()
        .map(|pose| DepthView {
            intrinsics: k,
            depth: sphere_depth(k.width, k.height, k.fx, &pose, centre, 0.05),
            pose,
        })
        .collect();
    RgbdDataset::new(k, views, None)
}

#[test]
fn fuses_a_written_dataset_into_a_mesh_with_normals() {
    let dir = tempfile::tempdir().unwrap();
    let rgbd = dir.path().join("rgbd");
    sphere_dataset().write(&rgbd).unwrap();
    let mesh = dir.path().join("sphere.ply");
    let run = nbv(&["fuse", rgbd.to_str().unwrap(), "-o", mesh.to_str().unwrap()]);
    assert!(run.status.success(), "{}", text(&run.stderr));
    assert!(
        text(&run.stdout).contains("8 view(s) fused"),
        "{}",
        text(&run.stdout)
    );
    let bytes = std::fs::read(&mesh).unwrap();
    let header = String::from_utf8_lossy(&bytes[..bytes.len().min(400)]).to_string();
    assert!(
        header.contains("property float nx") && header.contains("element face"),
        "{header}"
    );
}

#[test]
fn bad_datasets_name_the_file_and_write_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let rgbd = dir.path().join("rgbd");
    sphere_dataset().write(&rgbd).unwrap();
    let mesh = dir.path().join("out.ply");
    let fuse = || nbv(&["fuse", rgbd.to_str().unwrap(), "-o", mesh.to_str().unwrap()]);
    // A frame too many in the trajectory.
    let log = rgbd.join("trajectory.log");
    let good = std::fs::read_to_string(&log).unwrap();
    std::fs::write(
        &log,
        format!("{good}8 8 9\n1 0 0 0\n0 1 0 0\n0 0 1 0\n0 0 0 1\n"),
    )
    .unwrap();
    let run = fuse();
    assert!(!run.status.success());
    assert!(
        text(&run.stderr).contains("8 depth image(s) but 9 frame(s)"),
        "{}",
        text(&run.stderr)
    );
    // A malformed matrix row: the file and the line.
    std::fs::write(&log, good.replacen("0.", "x.", 1)).unwrap();
    let run = fuse();
    assert!(!run.status.success());
    let err = text(&run.stderr);
    assert!(err.contains("trajectory.log line 2"), "{err}");
    std::fs::write(&log, &good).unwrap();
    // An 8-bit depth image.
    std::fs::copy(rgbd.join("color/000003.png"), rgbd.join("depth/000003.png")).unwrap();
    let run = fuse();
    assert!(!run.status.success());
    let err = text(&run.stderr);
    assert!(
        err.contains("000003.png") && err.contains("16-bit"),
        "{err}"
    );
    // A missing intrinsics file.
    std::fs::remove_file(rgbd.join("camera_intrinsic.json")).unwrap();
    let run = fuse();
    assert!(!run.status.success());
    assert!(
        text(&run.stderr).contains("camera_intrinsic.json"),
        "{}",
        text(&run.stderr)
    );
    assert!(!mesh.exists(), "no output on failure");
}
