//! [`Color`]: an sRGB colour with alpha, the colour of every drawable and of the background.

/// An sRGB colour with straight alpha, each component in `[0, 1]`.
///
/// Components are as a picture shows them (gamma-encoded sRGB); the renderer converts to
/// linear light for shading and back for the PNG.
///
/// ```
/// use nbv_sim::render::Color;
/// let c = Color::from_srgb8(255, 128, 0);
/// assert_eq!(c.to_srgb8(), [255, 128, 0, 255]);
/// assert_ne!(Color::categorical(0), Color::categorical(1));
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Color {
    /// Red.
    pub r: f32,
    /// Green.
    pub g: f32,
    /// Blue.
    pub b: f32,
    /// Opacity: 1 opaque, 0 invisible.
    pub a: f32,
}

/// Ten well-separated hues (the Tableau 10 palette), for colouring by view or by label.
const CATEGORICAL: [[u8; 3]; 10] = [
    [78, 121, 167],
    [242, 142, 43],
    [225, 87, 89],
    [118, 183, 178],
    [89, 161, 79],
    [237, 201, 72],
    [176, 122, 161],
    [255, 157, 167],
    [156, 117, 95],
    [186, 176, 172],
];

impl Color {
    /// Opaque white.
    pub const WHITE: Color = Color::rgb(1.0, 1.0, 1.0);
    /// Opaque black.
    pub const BLACK: Color = Color::rgb(0.0, 0.0, 0.0);
    /// The default background: a very light grey.
    pub const BACKGROUND: Color = Color::rgb(0.96, 0.96, 0.96);
    /// Occupied voxels, as in the paper's occupancy figures.
    pub const OCCUPIED: Color = Color::rgb(0.85, 0.12, 0.10);
    /// Unknown voxels, as in the paper's occupancy figures.
    pub const UNKNOWN: Color = Color::rgb(0.62, 0.62, 0.62);

    /// An opaque colour from sRGB components in `[0, 1]`.
    pub const fn rgb(r: f32, g: f32, b: f32) -> Self {
        Self { r, g, b, a: 1.0 }
    }

    /// A colour from sRGB components and alpha in `[0, 1]`.
    pub const fn rgba(r: f32, g: f32, b: f32, a: f32) -> Self {
        Self { r, g, b, a }
    }

    /// An opaque colour from 8-bit sRGB components.
    pub fn from_srgb8(r: u8, g: u8, b: u8) -> Self {
        Self::rgb(r as f32 / 255.0, g as f32 / 255.0, b as f32 / 255.0)
    }

    /// The same colour with another alpha.
    pub const fn with_alpha(self, a: f32) -> Self {
        Self { a, ..self }
    }

    /// The `i`-th colour of a ten-colour categorical palette (cycling), for colouring by
    /// view or by label.
    pub fn categorical(i: usize) -> Self {
        let [r, g, b] = CATEGORICAL[i % CATEGORICAL.len()];
        Self::from_srgb8(r, g, b)
    }

    /// 8-bit sRGB components and alpha, clamped to `[0, 1]` first (NaN becomes 0).
    pub fn to_srgb8(self) -> [u8; 4] {
        let q = |v: f32| {
            if v.is_nan() {
                0
            } else {
                (v.clamp(0.0, 1.0) * 255.0).round() as u8
            }
        };
        [q(self.r), q(self.g), q(self.b), q(self.a)]
    }

    /// The colour in linear light (what the GPU blends and clears with), alpha unchanged.
    pub fn to_linear(self) -> [f64; 4] {
        let lin = |c: f32| {
            let c = f64::from(c.clamp(0.0, 1.0));
            if c <= 0.04045 {
                c / 12.92
            } else {
                ((c + 0.055) / 1.055).powf(2.4)
            }
        };
        [
            lin(self.r),
            lin(self.g),
            lin(self.b),
            f64::from(self.a.clamp(0.0, 1.0)),
        ]
    }
}

impl Default for Color {
    fn default() -> Self {
        Self::UNKNOWN
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn srgb8_round_trips() {
        for v in [0u8, 1, 17, 128, 254, 255] {
            assert_eq!(Color::from_srgb8(v, v, v).to_srgb8(), [v, v, v, 255]);
        }
    }

    #[test]
    fn linear_conversion_endpoints_and_midpoint() {
        let [r, g, b, a] = Color::rgb(0.0, 1.0, 0.5).to_linear();
        assert_eq!(r, 0.0);
        assert!((g - 1.0).abs() < 1e-12);
        assert!((b - 0.214).abs() < 1e-3);
        assert_eq!(a, 1.0);
    }

    #[test]
    fn out_of_range_is_clamped() {
        assert_eq!(
            Color::rgba(-1.0, 2.0, f32::NAN, 0.5).to_srgb8(),
            [0, 255, 0, 128]
        );
    }
}
