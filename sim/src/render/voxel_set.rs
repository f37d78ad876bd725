//! [`VoxelSet`]: voxels drawn as instanced, shaded, outlined cubes — occupancy maps
//! (occupied red, unknown grey, as in the paper's Figures 7–8).

use super::point_set::check_colors;
use super::{Color, RenderError};
use nalgebra::Point3;

/// Axis-aligned cubes of one edge length, given by their centres.
///
/// `colors` holds either one colour for every cube or one per cube. Each face is lit by
/// the scene's [`Lighting`](super::Lighting) and, when `outline` is above zero, its edges
/// are darkened by that fraction (about a pixel wide) so that neighbouring cubes stay
/// distinct.
///
/// ```
/// use nbv_sim::render::{Color, VoxelSet};
/// use nalgebra::Point3;
/// let occupied = VoxelSet::uniform(vec![Point3::new(1.0, 0.0, 0.5)], 0.01, Color::OCCUPIED);
/// assert_eq!(occupied.centers.len(), 1);
/// ```
#[derive(Debug, Clone, PartialEq)]
pub struct VoxelSet {
    /// Cube centres, world coordinates.
    pub centers: Vec<Point3<f64>>,
    /// Edge length of every cube, metres.
    pub size: f64,
    /// One colour for all cubes, or one per cube.
    pub colors: Vec<Color>,
    /// How much the cube edges are darkened, in `[0, 1]` (0: no outline).
    pub outline: f32,
}

impl VoxelSet {
    /// Cubes of one colour with the default outline.
    pub fn uniform(centers: Vec<Point3<f64>>, size: f64, color: Color) -> Self {
        Self {
            centers,
            size,
            colors: vec![color],
            outline: 0.45,
        }
    }

    /// Cubes with one colour each and the default outline; fails if the lengths differ.
    pub fn per_voxel(
        centers: Vec<Point3<f64>>,
        size: f64,
        colors: Vec<Color>,
    ) -> Result<Self, RenderError> {
        if colors.len() != centers.len() {
            return Err(RenderError::LengthMismatch {
                what: "voxel set",
                expected: centers.len(),
                got: colors.len(),
            });
        }
        Ok(Self {
            centers,
            size,
            colors,
            outline: 0.45,
        })
    }

    /// The colour of cube `i` (the single colour if there is one), if any.
    pub fn color_of(&self, i: usize) -> Option<Color> {
        match self.colors.as_slice() {
            [one] => Some(*one),
            many => many.get(i).copied(),
        }
    }

    /// Checks that `colors` holds one colour, or one per cube.
    pub(crate) fn check(&self) -> Result<(), RenderError> {
        check_colors("voxel set", self.centers.len(), self.colors.len())
    }
}
