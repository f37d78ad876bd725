//! The last stage of an object: its registered camera views fused into a surface
//! ([`RgbdDataset::fuse`]), each view's returns weighted by the averaged burst's noise.

use crate::rig::DepthCameraSpec;
use crate::surface::{PinholeIntrinsics, RgbdDataset, SurfaceError, SurfaceMesh, TsdfParams};

use super::{ExploreConfig, ObjectExploration};

/// The dataset of `object`'s registered camera views (`objects/<name>/rgbd/`), depths
/// at the layout's millimetre; `None` without a camera view.
pub fn object_views(
    object: &ObjectExploration,
    camera: &DepthCameraSpec,
    config: &ExploreConfig,
) -> Option<RgbdDataset> {
    let intrinsics = PinholeIntrinsics::of_camera(camera);
    let views = object.depth_views(intrinsics);
    if views.is_empty() {
        return None;
    }
    let noise = config
        .uncertainty
        .camera_noise
        .averaged(config.frames_per_view.max(1));
    Some(RgbdDataset::new(
        intrinsics,
        views,
        Some((noise.sigma_at_1m, noise.exponent)),
    ))
}

/// The fused surface of `object`'s registered camera views; `None` without one.
pub(super) fn fuse_surface(
    object: &ObjectExploration,
    camera: &DepthCameraSpec,
    params: TsdfParams,
    config: &ExploreConfig,
) -> Result<Option<SurfaceMesh>, SurfaceError> {
    object_views(object, camera, config)
        .map(|d| d.fuse(params))
        .transpose()
}
