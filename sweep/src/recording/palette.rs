//! Colours of a recording: the scene's categorical palette as bytes, and a score ramp
//! for the candidate viewpoints.

use nbv_sim::render::Color;

/// A render colour as RGBA bytes.
pub fn rgba(c: Color) -> [u8; 4] {
    [c.r, c.g, c.b, c.a].map(|v| (v.clamp(0.0, 1.0) * 255.0).round() as u8)
}

/// Categorical colour `i` (views, objects) as RGBA bytes.
pub fn categorical(i: usize) -> [u8; 4] {
    rgba(Color::categorical(i))
}

/// `t` in [0, 1] on a blue → yellow → red ramp (low to high score).
pub fn ramp(t: f64) -> [u8; 4] {
    let t = if t.is_finite() {
        t.clamp(0.0, 1.0)
    } else {
        0.0
    };
    let (r, g, b) = if t < 0.5 {
        let s = t * 2.0;
        (s, s, 1.0 - s)
    } else {
        let s = (t - 0.5) * 2.0;
        (1.0, 1.0 - s, 0.0)
    };
    let [r, g, b] = [r, g, b].map(|v| (v * 255.0).round() as u8);
    [r, g, b, 255]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ramp_runs_from_blue_to_red() {
        assert_eq!(ramp(0.0), [0, 0, 255, 255]);
        assert_eq!(ramp(1.0), [255, 0, 0, 255]);
        assert_eq!(ramp(f64::NAN), ramp(0.0));
    }
}
