//! [`Lighting`]: the light rig that shades meshes, voxels and point sprites.

use nalgebra::Vector3;

/// A camera-relative light rig: a key light from the upper left behind the viewer, a
/// weaker fill light from the right, an ambient term and a Blinn-Phong highlight of the key
/// light. Because the lights move with the camera, every view (front or back) is lit alike
/// and the faces of a box get three different brightnesses.
///
/// Directions point from the surface towards the light, in camera coordinates (x right,
/// y up, z towards the viewer).
#[derive(Debug, Clone, PartialEq)]
pub struct Lighting {
    /// Direction towards the key light, camera coordinates.
    pub key_direction: Vector3<f64>,
    /// Diffuse intensity of the key light.
    pub key: f64,
    /// Direction towards the fill light, camera coordinates.
    pub fill_direction: Vector3<f64>,
    /// Diffuse intensity of the fill light.
    pub fill: f64,
    /// Ambient intensity.
    pub ambient: f64,
    /// Strength of the key light's specular highlight (0 for none).
    pub specular: f64,
    /// Blinn-Phong exponent of the highlight.
    pub shininess: f64,
}

impl Default for Lighting {
    fn default() -> Self {
        Self {
            key_direction: Vector3::new(-0.35, 0.8, 0.5),
            key: 0.65,
            fill_direction: Vector3::new(0.7, -0.2, 0.7),
            fill: 0.3,
            ambient: 0.25,
            specular: 0.12,
            shininess: 32.0,
        }
    }
}

impl Lighting {
    /// Flat, unshaded colour: every surface shows its own colour.
    pub fn unlit() -> Self {
        Self {
            key: 0.0,
            fill: 0.0,
            ambient: 1.0,
            specular: 0.0,
            ..Self::default()
        }
    }
}
