//! [`LineSet`]: thick line segments — viewpoints and sensor frusta, coordinate axes,
//! bounding boxes — drawn as screen-space quads a fixed number of pixels wide.

use super::point_set::check_colors;
use super::{Color, RenderError};
use nalgebra::{Isometry3, Point3, Vector3};

/// Line segments in world coordinates, `width` pixels wide.
///
/// `colors` holds either one colour for every segment or one per segment; [`LineSet::push`]
/// keeps one per segment.
///
/// ```
/// use nbv_sim::render::{Color, LineSet};
/// use nalgebra::{Isometry3, Point3};
/// let mut lines = LineSet::new(3.0);
/// lines.push(Point3::origin(), Point3::new(1.0, 0.0, 0.0), Color::BLACK);
/// lines.append(&LineSet::frustum(&Isometry3::identity(), 0.8, 0.6, 0.1, 0.5, Color::BLACK, 2.0));
/// // 4 edges from the apex to the far corners, 4 near and 4 far rectangle edges.
/// assert_eq!(lines.segments.len(), 1 + 12);
/// ```
#[derive(Debug, Clone, PartialEq)]
pub struct LineSet {
    /// Segment end points, world coordinates.
    pub segments: Vec<[Point3<f64>; 2]>,
    /// One colour for all segments, or one per segment.
    pub colors: Vec<Color>,
    /// Line width in pixels (clamped to 1..=64 when drawn).
    pub width: f32,
}

impl LineSet {
    /// An empty set of lines `width` pixels wide.
    pub fn new(width: f32) -> Self {
        Self {
            segments: Vec::new(),
            colors: Vec::new(),
            width,
        }
    }

    /// Adds a segment of its own colour.
    pub fn push(&mut self, a: Point3<f64>, b: Point3<f64>, color: Color) {
        if self.colors.len() == 1 && self.segments.len() != 1 {
            // One colour shared by all: spell it out per segment first.
            let shared = self.colors[0];
            self.colors = vec![shared; self.segments.len()];
        }
        self.segments.push([a, b]);
        self.colors.push(color);
    }

    /// Adds every segment of `other` (with its colours; `other`'s width is ignored).
    pub fn append(&mut self, other: &LineSet) {
        for (i, s) in other.segments.iter().enumerate() {
            let c = match other.colors.as_slice() {
                [one] => *one,
                many => many.get(i).copied().unwrap_or(Color::BLACK),
            };
            self.push(s[0], s[1], c);
        }
    }

    /// The viewing frustum of a sensor at `pose` looking along its +z axis (optical frame:
    /// x right, y down), with full fields of view `fov_x`, `fov_y` (radians) between the
    /// `near` and `far` distances: the apex edges to the far corners and the near and far
    /// rectangles.
    pub fn frustum(
        pose: &Isometry3<f64>,
        fov_x: f64,
        fov_y: f64,
        near: f64,
        far: f64,
        color: Color,
        width: f32,
    ) -> Self {
        let (tx, ty) = ((fov_x / 2.0).tan(), (fov_y / 2.0).tan());
        let rect = |d: f64| -> [Point3<f64>; 4] {
            [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)]
                .map(|(sx, sy)| pose * Point3::new(sx * tx * d, sy * ty * d, d))
        };
        let (n, f) = (rect(near), rect(far));
        let apex = pose * Point3::origin();
        let mut lines = Self::new(width);
        for i in 0..4 {
            let j = (i + 1) % 4;
            lines.push(apex, f[i], color);
            lines.push(n[i], n[j], color);
            lines.push(f[i], f[j], color);
        }
        lines
    }

    /// The x, y and z axes of a frame at `pose`, `length` metres long, in red, green and
    /// blue.
    pub fn axes(pose: &Isometry3<f64>, length: f64, width: f32) -> Self {
        let o = pose * Point3::origin();
        let mut lines = Self::new(width);
        for (axis, color) in [
            (Vector3::x(), Color::rgb(0.85, 0.1, 0.1)),
            (Vector3::y(), Color::rgb(0.1, 0.7, 0.1)),
            (Vector3::z(), Color::rgb(0.1, 0.2, 0.9)),
        ] {
            lines.push(o, o + pose.rotation * axis * length, color);
        }
        lines
    }

    /// The twelve edges of the axis-aligned box `[min, max]` (for example the workspace).
    pub fn aabb(min: Point3<f64>, max: Point3<f64>, color: Color, width: f32) -> Self {
        let corner = |i: usize| {
            Point3::new(
                if i & 1 == 0 { min.x } else { max.x },
                if i & 2 == 0 { min.y } else { max.y },
                if i & 4 == 0 { min.z } else { max.z },
            )
        };
        let mut lines = Self::new(width);
        for i in 0..8usize {
            for bit in [1usize, 2, 4] {
                if i & bit == 0 {
                    lines.push(corner(i), corner(i | bit), color);
                }
            }
        }
        lines
    }

    /// The colour of segment `i` (the single colour if there is one), if any.
    pub fn color_of(&self, i: usize) -> Option<Color> {
        match self.colors.as_slice() {
            [one] => Some(*one),
            many => many.get(i).copied(),
        }
    }

    /// Checks that `colors` holds one colour, or one per segment.
    pub(crate) fn check(&self) -> Result<(), RenderError> {
        check_colors("line set", self.segments.len(), self.colors.len())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn box_has_twelve_unit_edges() {
        let b = LineSet::aabb(
            Point3::origin(),
            Point3::new(1.0, 1.0, 1.0),
            Color::BLACK,
            1.0,
        );
        assert_eq!(b.segments.len(), 12);
        assert!(
            b.segments
                .iter()
                .all(|[a, b]| ((a - b).norm() - 1.0).abs() < 1e-12)
        );
        b.check().unwrap();
    }

    #[test]
    fn push_after_a_shared_colour_keeps_colours_aligned() {
        let mut l = LineSet {
            segments: vec![[Point3::origin(), Point3::new(1.0, 0.0, 0.0)]; 3],
            colors: vec![Color::WHITE],
            width: 1.0,
        };
        l.push(Point3::origin(), Point3::new(0.0, 1.0, 0.0), Color::BLACK);
        assert_eq!(l.colors.len(), 4);
        assert_eq!(l.color_of(0), Some(Color::WHITE));
        assert_eq!(l.color_of(3), Some(Color::BLACK));
    }

    #[test]
    fn frustum_far_corners_subtend_the_field_of_view() {
        let f = LineSet::frustum(
            &Isometry3::identity(),
            1.0,
            0.5,
            0.1,
            2.0,
            Color::BLACK,
            1.0,
        );
        let far_corner = f.segments[0][1];
        assert!((far_corner.z - 2.0).abs() < 1e-12);
        assert!((far_corner.x.abs() - 2.0 * 0.5f64.tan()).abs() < 1e-12);
        assert!((far_corner.y.abs() - 2.0 * 0.25f64.tan()).abs() < 1e-12);
    }
}
