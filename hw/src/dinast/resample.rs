//! Between the vendor's raw image and the spec's pinhole image: [`PinholeResampler`]
//! (raw frame → pinhole depth, the driver side) and [`RawEncoder`] (pinhole depth → raw
//! frame, the emulator side).
//!
//! The pipeline works with the pinhole model of [`DepthCameraSpec`] (pixel `(u, v)` looks
//! along `pixel_ray(u, v)`), while the vendor model is an equidistant (f-θ) lens: the ray
//! angle grows linearly with the distance from the image centre, 64° per 160 px. The two
//! images therefore sample different directions, and each side maps a pixel to the
//! *nearest* pixel of the other model (no interpolation, so no mixed depths across edges).
//! Ranges along the ray are what both models share: depth z = range · cos(ray angle).

use super::frame::{IMAGE_LEN, RawFrame};
use super::raw_model::{
    RAW_HEIGHT, RAW_WIDTH, point_from_raw, raw_direction, raw_from_range, raw_position,
};
use nbv_core::rig::{DepthCameraSpec, DepthFrame};

/// For each pinhole pixel, the raw pixel it reads (driver side).
#[derive(Debug, Clone)]
pub struct PinholeResampler {
    spec: DepthCameraSpec,
    /// Per pinhole pixel (row-major): the nearest raw pixel `(x, y)`, and cos of the
    /// pinhole ray's angle to the optical axis.
    sources: Vec<Option<([usize; 2], f64)>>,
}

/// The raw pixel `(x, y)` nearest to the direction of pinhole pixel `(u, v)`.
fn nearest_raw_pixel(spec: &DepthCameraSpec, u: usize, v: usize) -> Option<[usize; 2]> {
    let [x, y] = raw_position(&spec.pixel_ray(u, v))?;
    let (x, y) = (x.round(), y.round());
    let inside = (0.0..RAW_WIDTH as f64).contains(&x) && (0.0..RAW_HEIGHT as f64).contains(&y);
    inside.then_some([x as usize, y as usize])
}

impl PinholeResampler {
    /// The mapping for `spec`'s pinhole grid.
    pub fn new(spec: &DepthCameraSpec) -> Self {
        let mut sources = Vec::with_capacity(spec.width * spec.height);
        for v in 0..spec.height {
            for u in 0..spec.width {
                let cos_angle = 1.0 / spec.pixel_ray(u, v).norm();
                sources.push(nearest_raw_pixel(spec, u, v).map(|raw| (raw, cos_angle)));
            }
        }
        Self {
            spec: spec.clone(),
            sources,
        }
    }

    /// The pinhole spec this maps to.
    pub fn spec(&self) -> &DepthCameraSpec {
        &self.spec
    }

    /// Pinhole depths (row-major, metres, NaN where invalid) of a raw frame: each pinhole
    /// pixel takes the range of its nearest raw pixel (vendor model, z band applied), keeps
    /// it if inside the spec's range, and converts it to z along its own ray.
    pub fn depth(&self, raw: &RawFrame) -> Vec<f32> {
        let [min_range, max_range] = self.spec.range;
        self.sources
            .iter()
            .map(|source| {
                let Some(([x, y], cos_angle)) = *source else {
                    return f32::NAN;
                };
                let point = raw
                    .depth_code_at(x, y)
                    .and_then(|p| point_from_raw(x, y, p));
                match point.map(|p| p.coords.norm()) {
                    Some(range) if (min_range..=max_range).contains(&range) => {
                        (range * cos_angle) as f32
                    }
                    _ => f32::NAN,
                }
            })
            .collect()
    }
}

/// For each raw pixel, the pinhole pixel it shows (emulator side).
#[derive(Debug, Clone)]
pub struct RawEncoder {
    spec: DepthCameraSpec,
    /// Per raw pixel (row-major): the nearest pinhole pixel's index and the length of its
    /// unnormalised ray (range = z · length).
    sources: Vec<Option<(usize, f64)>>,
}

/// How far (pinhole pixels) outside the pinhole image a raw pixel's direction may fall and
/// still take the nearest edge pixel's depth. The driver reads, for each pinhole pixel,
/// the raw pixel nearest to it, whose direction is within half a raw pixel diagonal
/// (0.28°) of it; at the corners of an 80° image that is up to 2 pinhole pixels outside
/// the image. Without this margin the image's border would decode as invalid.
pub const EDGE_MARGIN_PX: f64 = 2.5;

/// The nearest cell (0-based) of coordinate `c` (0 at the first cell's left edge) among
/// `count` cells, clamped to the grid within [`EDGE_MARGIN_PX`] of it.
fn nearest_cell(c: f64, count: usize) -> Option<usize> {
    let last = count.checked_sub(1)? as f64;
    let cell = (c - 0.5).round();
    let inside = (-EDGE_MARGIN_PX..=last + EDGE_MARGIN_PX).contains(&(c - 0.5));
    (inside && cell.is_finite()).then(|| cell.clamp(0.0, last) as usize)
}

/// Why a pinhole frame cannot be encoded.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("depth frame is {got_width}×{got_height} with {got_len} depths, spec is {width}×{height}")]
pub struct FrameSizeError {
    /// Frame width.
    pub got_width: usize,
    /// Frame height.
    pub got_height: usize,
    /// Number of depths in the frame.
    pub got_len: usize,
    /// Spec width.
    pub width: usize,
    /// Spec height.
    pub height: usize,
}

impl RawEncoder {
    /// The mapping from `spec`'s pinhole grid.
    pub fn new(spec: &DepthCameraSpec) -> Self {
        let focal = spec.focal();
        let mut sources = Vec::with_capacity(IMAGE_LEN);
        for y in 0..RAW_HEIGHT {
            for x in 0..RAW_WIDTH {
                let direction = raw_direction(x as f64, y as f64);
                let source = (direction.z > 0.0)
                    .then(|| {
                        let u = direction.x / direction.z * focal + 0.5 * spec.width as f64;
                        let v = direction.y / direction.z * focal + 0.5 * spec.height as f64;
                        let column = nearest_cell(u, spec.width)?;
                        let row = nearest_cell(v, spec.height)?;
                        Some((
                            row * spec.width + column,
                            spec.pixel_ray(column, row).norm(),
                        ))
                    })
                    .flatten();
                sources.push(source);
            }
        }
        Self {
            spec: spec.clone(),
            sources,
        }
    }

    /// The pinhole spec this maps from.
    pub fn spec(&self) -> &DepthCameraSpec {
        &self.spec
    }

    /// The raw frame the device would send for `frame`: each raw pixel takes the depth of
    /// its nearest pinhole pixel (edge pixels extended by [`EDGE_MARGIN_PX`]), as a range
    /// along that pixel's ray, encoded with
    /// [`raw_from_range`] (0 where invalid, outside the pinhole image or not
    /// representable). The amplitude image is synthetic: `255·(0.2 m / range)²`, clamped
    /// to 1..=255, 0 where the depth is 0.
    pub fn encode(&self, frame: &DepthFrame) -> Result<RawFrame, FrameSizeError> {
        if frame.width != self.spec.width
            || frame.height != self.spec.height
            || frame.depth.len() != frame.width * frame.height
        {
            return Err(FrameSizeError {
                got_width: frame.width,
                got_height: frame.height,
                got_len: frame.depth.len(),
                width: self.spec.width,
                height: self.spec.height,
            });
        }
        let mut raw = RawFrame::empty();
        let pixels = raw.depth_code.iter_mut().zip(raw.amplitude.iter_mut());
        for (i, ((code, amplitude), source)) in pixels.zip(&self.sources).enumerate() {
            let Some((index, ray_length)) = *source else {
                continue;
            };
            let z = frame.depth.get(index).map_or(f64::NAN, |&z| f64::from(z));
            if !(z.is_finite() && z > 0.0) {
                continue;
            }
            let range = z * ray_length;
            let (x, y) = (i % RAW_WIDTH, i / RAW_WIDTH);
            if let Some(p) = raw_from_range(x, y, range) {
                *code = p;
                *amplitude = (255.0 * (0.2 / range).powi(2)).clamp(1.0, 255.0) as u8;
            }
        }
        Ok(raw)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn spec() -> DepthCameraSpec {
        DepthCameraSpec::ipa1110()
    }

    #[test]
    fn every_pinhole_pixel_of_the_80_degree_spec_reads_a_raw_pixel() {
        let resampler = PinholeResampler::new(&spec());
        assert!(resampler.sources.iter().all(Option::is_some));
    }

    #[test]
    fn raw_pixels_outside_the_pinhole_field_of_view_are_not_encoded() {
        let encoder = RawEncoder::new(&spec());
        // Raw column 0 is 64° off axis, beyond the pinhole image's 40°.
        assert!(encoder.sources.get(120 * RAW_WIDTH).unwrap().is_none());
        assert!(
            encoder
                .sources
                .get(120 * RAW_WIDTH + 160)
                .unwrap()
                .is_some()
        );
    }

    #[test]
    fn wrong_frame_size_is_an_error() {
        let frame = DepthFrame {
            time: 0.0,
            width: 2,
            height: 2,
            depth: vec![0.5; 4],
            truth: None,
        };
        assert!(RawEncoder::new(&spec()).encode(&frame).is_err());
    }
}
