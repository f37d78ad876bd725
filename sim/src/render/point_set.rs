//! [`PointSet`]: points drawn as round screen-space sprites of a fixed pixel size,
//! coloured uniformly, per point, per view or per label.

use super::{Color, RenderError};
use nalgebra::Point3;
use nbv_core::cloud::PointCloud;

/// How [`PointSet::from_cloud`] colours a cloud.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum CloudColoring {
    /// Every point the same colour.
    Uniform(Color),
    /// By the cloud's `views` column, one [`Color::categorical`] colour per view.
    ByView,
    /// By the cloud's `labels` column, one [`Color::categorical`] colour per label.
    ByLabel,
}

/// Points in world coordinates, each drawn as a shaded disc `size` pixels across.
///
/// `colors` holds either one colour for every point or one colour per point.
///
/// ```
/// use nbv_sim::render::{CloudColoring, Color, PointSet};
/// use nbv_core::cloud::PointCloud;
/// use nalgebra::Point3;
/// let mut cloud = PointCloud::from_points(vec![Point3::origin(), Point3::new(1.0, 0.0, 0.0)]);
/// cloud.views = Some(vec![0, 1]);
/// let set = PointSet::from_cloud(&cloud, CloudColoring::ByView, 4.0).unwrap();
/// assert_eq!(set.colors, vec![Color::categorical(0), Color::categorical(1)]);
/// assert!(PointSet::from_cloud(&cloud, CloudColoring::ByLabel, 4.0).is_err());
/// ```
#[derive(Debug, Clone, PartialEq)]
pub struct PointSet {
    /// Point positions, world coordinates.
    pub points: Vec<Point3<f64>>,
    /// One colour for all points, or one per point.
    pub colors: Vec<Color>,
    /// Sprite diameter in pixels (clamped to 1..=256 when drawn).
    pub size: f32,
}

impl PointSet {
    /// Points of one colour.
    pub fn uniform(points: Vec<Point3<f64>>, color: Color, size: f32) -> Self {
        Self {
            points,
            colors: vec![color],
            size,
        }
    }

    /// Points with one colour each; fails if the lengths differ.
    pub fn per_point(
        points: Vec<Point3<f64>>,
        colors: Vec<Color>,
        size: f32,
    ) -> Result<Self, RenderError> {
        if colors.len() != points.len() {
            return Err(RenderError::LengthMismatch {
                what: "point set",
                expected: points.len(),
                got: colors.len(),
            });
        }
        Ok(Self {
            points,
            colors,
            size,
        })
    }

    /// The points of a cloud coloured as asked; fails if the column to colour by is
    /// missing or has the wrong length.
    pub fn from_cloud(
        cloud: &PointCloud,
        coloring: CloudColoring,
        size: f32,
    ) -> Result<Self, RenderError> {
        let column = match coloring {
            CloudColoring::Uniform(c) => return Ok(Self::uniform(cloud.points.clone(), c, size)),
            CloudColoring::ByView => cloud
                .views
                .as_ref()
                .ok_or(RenderError::MissingColumn("views"))?,
            CloudColoring::ByLabel => cloud
                .labels
                .as_ref()
                .ok_or(RenderError::MissingColumn("labels"))?,
        };
        let colors = column
            .iter()
            .map(|&k| Color::categorical(k as usize))
            .collect();
        Self::per_point(cloud.points.clone(), colors, size)
    }

    /// The colour of point `i` (the single colour if there is one), if any.
    pub fn color_of(&self, i: usize) -> Option<Color> {
        match self.colors.as_slice() {
            [one] => Some(*one),
            many => many.get(i).copied(),
        }
    }

    /// Checks that `colors` holds one colour, or one per point.
    pub(crate) fn check(&self) -> Result<(), RenderError> {
        check_colors("point set", self.points.len(), self.colors.len())
    }
}

/// One colour for all, or one per item (an empty drawable may have any single colour).
pub(crate) fn check_colors(
    what: &'static str,
    items: usize,
    colors: usize,
) -> Result<(), RenderError> {
    if colors == items || colors == 1 {
        Ok(())
    } else {
        Err(RenderError::LengthMismatch {
            what,
            expected: items,
            got: colors,
        })
    }
}
