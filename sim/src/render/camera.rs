//! [`Camera`]: a perspective look-at camera, the framings of the workspace from the front
//! and from the back, and projection of world points to pixels.

use nalgebra::{Isometry3, Matrix4, Point2, Point3, Vector3, Vector4};

/// A perspective look-at camera in world coordinates.
///
/// Pixel coordinates have their origin at the top-left corner of the image, x to the
/// right and y down; pixel `(i, j)` covers `[i, i+1) × [j, j+1)`.
///
/// ```
/// use nbv_sim::render::Camera;
/// use nalgebra::Point3;
/// let cam = Camera::look_at(Point3::new(-1.0, 0.0, 0.0), Point3::origin());
/// // The target projects to the image centre.
/// let p = cam.project(&Point3::origin(), 640, 480).unwrap();
/// assert!((p.x - 320.0).abs() < 1e-9 && (p.y - 240.0).abs() < 1e-9);
/// // A point behind the camera has no projection.
/// assert!(cam.project(&Point3::new(-2.0, 0.0, 0.0), 640, 480).is_none());
/// ```
#[derive(Debug, Clone, PartialEq)]
pub struct Camera {
    /// Where the camera is.
    pub eye: Point3<f64>,
    /// The point it looks at (the image centre).
    pub target: Point3<f64>,
    /// The world direction that appears upward in the image.
    pub up: Vector3<f64>,
    /// Vertical field of view, radians.
    pub fov_y: f64,
    /// Near clipping distance, metres.
    pub near: f64,
    /// Far clipping distance, metres.
    pub far: f64,
}

/// Default vertical field of view: 35°.
const DEFAULT_FOV_Y: f64 = 35.0 * std::f64::consts::PI / 180.0;
/// Azimuth offset of the front and back framings from the x axis, so that the side faces
/// of boxes show as well as the front ones.
const FRAMING_AZIMUTH_OFFSET: f64 = 0.45;
/// Elevation of the front and back framings above the horizontal.
const FRAMING_ELEVATION: f64 = 0.55;
/// Fraction of the image the framed box may fill at most.
const FRAMING_FILL: f64 = 0.92;

impl Camera {
    /// A camera at `eye` looking at `target` with z up and default field of view and
    /// clipping distances (35°, 0.02 m … 100 m).
    pub fn look_at(eye: Point3<f64>, target: Point3<f64>) -> Self {
        Self {
            eye,
            target,
            up: Vector3::z(),
            fov_y: DEFAULT_FOV_Y,
            near: 0.02,
            far: 100.0,
        }
    }

    /// A camera on a sphere around `target`: `azimuth` (radians) is measured in the
    /// horizontal plane from the +x axis towards +y to the direction of the eye, and
    /// `elevation` (radians) upwards from the horizontal.
    ///
    /// ```
    /// use nbv_sim::render::Camera;
    /// use nalgebra::Point3;
    /// let cam = Camera::orbit(Point3::origin(), 2.0, 0.0, 0.0);
    /// assert!((cam.eye - Point3::new(2.0, 0.0, 0.0)).norm() < 1e-12);
    /// ```
    pub fn orbit(target: Point3<f64>, distance: f64, azimuth: f64, elevation: f64) -> Self {
        let dir = Vector3::new(
            elevation.cos() * azimuth.cos(),
            elevation.cos() * azimuth.sin(),
            elevation.sin(),
        );
        Self::look_at(target + dir * distance, target)
    }

    /// Frames the axis-aligned box `[min, max]` seen from the robot's side (the eye on the
    /// −x side, above and a little to the left), for images of aspect `width / height`.
    ///
    /// ```
    /// use nbv_sim::render::Camera;
    /// use nalgebra::Point3;
    /// let (lo, hi) = (Point3::new(0.30, -0.70, 0.23), Point3::new(1.50, 0.70, 0.83));
    /// let cam = Camera::front_of(lo, hi, 4.0 / 3.0);
    /// assert!(cam.eye.x < lo.x && cam.eye.z > hi.z);
    /// // Every corner of the box is inside the 1280x960 image.
    /// for i in 0..8 {
    ///     let c = Point3::new(
    ///         if i & 1 == 0 { lo.x } else { hi.x },
    ///         if i & 2 == 0 { lo.y } else { hi.y },
    ///         if i & 4 == 0 { lo.z } else { hi.z },
    ///     );
    ///     let p = cam.project(&c, 1280, 960).unwrap();
    ///     assert!(p.x > 0.0 && p.x < 1280.0 && p.y > 0.0 && p.y < 960.0);
    /// }
    /// ```
    pub fn front_of(min: Point3<f64>, max: Point3<f64>, aspect: f64) -> Self {
        Self::framing(
            min,
            max,
            std::f64::consts::PI - FRAMING_AZIMUTH_OFFSET,
            FRAMING_ELEVATION,
            aspect,
        )
    }

    /// Frames the axis-aligned box `[min, max]` seen from behind (the eye on the +x side,
    /// above and a little to the right), for images of aspect `width / height`.
    pub fn back_of(min: Point3<f64>, max: Point3<f64>, aspect: f64) -> Self {
        Self::framing(min, max, -FRAMING_AZIMUTH_OFFSET, FRAMING_ELEVATION, aspect)
    }

    /// Frames the axis-aligned box `[min, max]` from the direction given by `azimuth` and
    /// `elevation` (as in [`Camera::orbit`]): the camera looks at the box centre from the
    /// nearest distance at which all eight corners fit in an image of aspect
    /// `width / height`, with a small margin.
    pub fn framing(
        min: Point3<f64>,
        max: Point3<f64>,
        azimuth: f64,
        elevation: f64,
        aspect: f64,
    ) -> Self {
        let (lo, hi) = (min.inf(&max), min.sup(&max));
        let centre = nalgebra::center(&lo, &hi);
        let mut cam = Self::orbit(centre, 1.0, azimuth, elevation);
        let aspect = if aspect.is_finite() && aspect > 0.0 {
            aspect
        } else {
            4.0 / 3.0
        };
        let (right, up, forward) = cam.basis();
        let tan_y = (cam.fov_y / 2.0).tan() * FRAMING_FILL;
        let tan_x = tan_y * aspect;
        // A corner at offset o from the centre, seen from distance d along `forward`, sits at
        // depth d + o·f; it fits when |o·r| <= depth·tan_x and |o·u| <= depth·tan_y.
        let mut distance: f64 = 1e-3;
        for i in 0..8 {
            let corner = Point3::new(
                if i & 1 == 0 { lo.x } else { hi.x },
                if i & 2 == 0 { lo.y } else { hi.y },
                if i & 4 == 0 { lo.z } else { hi.z },
            );
            let o = corner - centre;
            let along = o.dot(&forward);
            distance = distance
                .max(o.dot(&right).abs() / tan_x - along)
                .max(o.dot(&up).abs() / tan_y - along);
        }
        let radius = (hi - lo).norm() / 2.0;
        cam.eye = centre - forward * distance;
        cam.near = (distance - 4.0 * radius).max(distance * 0.01).max(0.01);
        cam.far = distance + 8.0 * radius + 1.0;
        cam
    }

    /// Frames a set of points (for example every vertex a picture draws) from the direction
    /// given by `azimuth` and `elevation` (as in [`Camera::orbit`]): the view direction is
    /// fixed, the target is moved so that the points' picture is centred, and the distance
    /// is the smallest at which every point fits in an image of aspect `width / height`
    /// with a small margin. Tighter than [`Camera::framing`] of the points' bounding box,
    /// which leaves the box's empty corners in the picture. Non-finite points are ignored;
    /// without a finite point it frames the unit cube at the origin.
    ///
    /// ```
    /// use nbv_sim::render::Camera;
    /// use nalgebra::Point3;
    /// let pts: Vec<_> = (0..20).map(|i| Point3::new(1.0, i as f64 * 0.1, (i % 3) as f64 * 0.2)).collect();
    /// let cam = Camera::fit(&pts, 3.0, 0.4, 4.0 / 3.0);
    /// let (mut lo, mut hi) = ([f64::MAX; 2], [f64::MIN; 2]);
    /// for p in &pts {
    ///     let q = cam.project(p, 1280, 960).unwrap();
    ///     assert!(q.x > 0.0 && q.x < 1280.0 && q.y > 0.0 && q.y < 960.0);
    ///     lo = [lo[0].min(q.x), lo[1].min(q.y)];
    ///     hi = [hi[0].max(q.x), hi[1].max(q.y)];
    /// }
    /// // Centred, and filling the image along at least one axis.
    /// assert!(((lo[0] + hi[0]) / 2.0 - 640.0).abs() < 8.0 && ((lo[1] + hi[1]) / 2.0 - 480.0).abs() < 8.0);
    /// assert!(hi[0] - lo[0] > 1100.0 || hi[1] - lo[1] > 820.0);
    /// ```
    pub fn fit(points: &[Point3<f64>], azimuth: f64, elevation: f64, aspect: f64) -> Self {
        let finite: Vec<Point3<f64>> = points
            .iter()
            .filter(|p| p.coords.iter().all(|v| v.is_finite()))
            .copied()
            .collect();
        let Some(first) = finite.first() else {
            return Self::framing(
                Point3::origin(),
                Point3::new(1.0, 1.0, 1.0),
                azimuth,
                elevation,
                aspect,
            );
        };
        let (lo, hi) = finite
            .iter()
            .fold((*first, *first), |(lo, hi), p| (lo.inf(p), hi.sup(p)));
        let aspect = if aspect.is_finite() && aspect > 0.0 {
            aspect
        } else {
            4.0 / 3.0
        };
        let mut cam = Self::orbit(nalgebra::center(&lo, &hi), 1.0, azimuth, elevation);
        let (right, up, forward) = cam.basis();
        let tan_y = (cam.fov_y / 2.0).tan() * FRAMING_FILL;
        let tan_x = tan_y * aspect;
        let radius = ((hi - lo).norm() / 2.0).max(1e-6);
        // The nearest distance at which every point fits, for a given target.
        let fit_distance = |target: Point3<f64>| {
            finite.iter().fold(1e-3f64, |d, p| {
                let o = p - target;
                let along = o.dot(&forward);
                d.max(o.dot(&right).abs() / tan_x - along)
                    .max(o.dot(&up).abs() / tan_y - along)
            })
        };
        for _ in 0..6 {
            // Centre the picture: move the target sideways by the middle of the points'
            // extent in normalised image coordinates, scaled to the target's depth.
            let distance = fit_distance(cam.target);
            let (mut x0, mut x1, mut y0, mut y1) = (f64::MAX, f64::MIN, f64::MAX, f64::MIN);
            for p in &finite {
                let o = p - cam.target;
                let depth = (distance + o.dot(&forward)).max(1e-9);
                let (x, y) = (o.dot(&right) / depth, o.dot(&up) / depth);
                (x0, x1, y0, y1) = (x0.min(x), x1.max(x), y0.min(y), y1.max(y));
            }
            cam.target += right * ((x0 + x1) / 2.0 * distance) + up * ((y0 + y1) / 2.0 * distance);
        }
        let distance = fit_distance(cam.target);
        cam.eye = cam.target - forward * distance;
        cam.near = (distance - 4.0 * radius).max(distance * 0.01).max(0.01);
        cam.far = distance + 8.0 * radius + 1.0;
        cam
    }

    /// The camera's right, up and forward unit vectors in world coordinates. A degenerate
    /// `up` (zero, or parallel to the viewing direction) is replaced by another axis.
    pub fn basis(&self) -> (Vector3<f64>, Vector3<f64>, Vector3<f64>) {
        let forward = (self.target - self.eye)
            .try_normalize(1e-12)
            .unwrap_or_else(|| -Vector3::z());
        let mut right = forward.cross(&self.up).try_normalize(1e-9);
        for alt in [Vector3::z(), Vector3::y(), Vector3::x()] {
            if right.is_some() {
                break;
            }
            right = forward.cross(&alt).try_normalize(1e-9);
        }
        let right = right.unwrap_or_else(Vector3::x);
        let up = right.cross(&forward);
        (right, up, forward)
    }

    /// The world-to-camera transform (camera looking along its −z, y up).
    pub fn view(&self) -> Isometry3<f64> {
        let (_, up, forward) = self.basis();
        Isometry3::look_at_rh(&self.eye, &(self.eye + forward), &up)
    }

    /// The perspective projection for an image of aspect `width / height`, mapping view
    /// depth `near` to 0 and `far` to 1 (wgpu clip space).
    pub fn projection(&self, aspect: f64) -> Matrix4<f64> {
        let f = 1.0 / (self.fov_y.clamp(1e-3, 3.1) / 2.0).tan();
        let near = self.near.max(1e-6);
        let far = self.far.max(near * (1.0 + 1e-6));
        let aspect = if aspect.is_finite() && aspect > 0.0 {
            aspect
        } else {
            1.0
        };
        let mut m = Matrix4::zeros();
        m[(0, 0)] = f / aspect;
        m[(1, 1)] = f;
        m[(2, 2)] = far / (near - far);
        m[(2, 3)] = near * far / (near - far);
        m[(3, 2)] = -1.0;
        m
    }

    /// World to clip space for an image of aspect `width / height`.
    pub fn view_projection(&self, aspect: f64) -> Matrix4<f64> {
        self.projection(aspect) * self.view().to_homogeneous()
    }

    /// The pixel position of a world point in a `width × height` image, or `None` if the
    /// point is behind the camera (at or behind the eye plane). Points outside the image
    /// still project (to coordinates outside `[0, width] × [0, height]`).
    pub fn project(&self, p: &Point3<f64>, width: u32, height: u32) -> Option<Point2<f64>> {
        let (w, h) = (f64::from(width), f64::from(height));
        let clip = self.view_projection(w / h) * Vector4::new(p.x, p.y, p.z, 1.0);
        if clip.w <= 1e-12 || !clip.iter().all(|v| v.is_finite()) {
            return None;
        }
        let (nx, ny) = (clip.x / clip.w, clip.y / clip.w);
        Some(Point2::new((nx + 1.0) / 2.0 * w, (1.0 - ny) / 2.0 * h))
    }

    /// Distance of a world point in front of the eye, along the viewing direction
    /// (negative behind the camera). Nearer points have smaller depth.
    pub fn depth(&self, p: &Point3<f64>) -> f64 {
        let (_, _, forward) = self.basis();
        (p - self.eye).dot(&forward)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn near_and_far_map_to_depth_range() {
        let cam = Camera::look_at(Point3::new(0.0, 0.0, 5.0), Point3::origin());
        let vp = cam.view_projection(1.0);
        for (d, want) in [(cam.near, 0.0), (cam.far, 1.0)] {
            let c = vp * Vector4::new(0.0, 0.0, 5.0 - d, 1.0);
            assert!((c.z / c.w - want).abs() < 1e-9, "depth {d}");
        }
    }

    #[test]
    fn up_appears_up_and_right_appears_right() {
        // Looking along +x with z up: +z is up in the image, -y is right.
        let cam = Camera::look_at(Point3::origin(), Point3::new(1.0, 0.0, 0.0));
        let up = cam.project(&Point3::new(1.0, 0.0, 0.1), 100, 100).unwrap();
        let right = cam.project(&Point3::new(1.0, -0.1, 0.0), 100, 100).unwrap();
        assert!(up.y < 50.0 && (up.x - 50.0).abs() < 1e-9);
        assert!(right.x > 50.0 && (right.y - 50.0).abs() < 1e-9);
    }

    #[test]
    fn degenerate_up_still_gives_an_orthonormal_basis() {
        let cam = Camera::look_at(Point3::new(0.0, 0.0, 3.0), Point3::origin());
        let (r, u, f) = cam.basis();
        assert!((r.norm() - 1.0).abs() < 1e-12 && (u.norm() - 1.0).abs() < 1e-12);
        assert!(r.dot(&u).abs() < 1e-12 && r.dot(&f).abs() < 1e-12 && u.dot(&f).abs() < 1e-12);
        assert!(cam.project(&Point3::origin(), 10, 10).is_some());
    }

    #[test]
    fn back_framing_looks_from_behind() {
        let (lo, hi) = (Point3::new(0.3, -0.7, 0.23), Point3::new(1.5, 0.7, 0.83));
        let cam = Camera::back_of(lo, hi, 4.0 / 3.0);
        assert!(cam.eye.x > hi.x && cam.eye.z > hi.z);
        let (_, _, f) = cam.basis();
        assert!(f.x < 0.0 && f.z < 0.0);
        assert!(cam.near > 0.0 && cam.near < cam.depth(&nalgebra::center(&lo, &hi)));
    }

    #[test]
    fn depth_orders_points_along_the_view() {
        let cam = Camera::look_at(Point3::origin(), Point3::new(1.0, 0.0, 0.0));
        assert!(cam.depth(&Point3::new(1.0, 0.3, 0.0)) < cam.depth(&Point3::new(2.0, 0.0, 0.0)));
        assert!(cam.depth(&Point3::new(-1.0, 0.0, 0.0)) < 0.0);
    }
}
