//! The vendor's raw-to-distance model of the IPA-1110: how an 8-bit raw value at a raw
//! pixel becomes a range and a 3-D point, its exact inverse ([`raw_from_range`], used by the
//! emulator) and the size of its 8-bit quantisation step.
//!
//! Raw pixel `(x, y)` (x the column, 0..320; y the row, 0..240) lies at
//! `r = |(x, y) − (160, 120)|` pixels from the image centre. With
//!
//! ```text
//! A(r) = −2e-5·r³ + 0.004·r² + 0.1719·r + 350.03
//! B(r) = −2e-9·r³ + 3e-7·r² − 1e-5·r − 0.01
//! K(r) = 7e-7·r³ − 1e-4·r² + 0.004·r + 0.9985
//! dist = (ln(min(p, A)/A)/B − 0.1·y)·K·1.5          (units of 2 mm)
//! θ    = 64°·r/160                                  (equidistant, f-θ lens)
//! ```
//!
//! the point is `dist/500 · (sin θ·(x−160)/r, sin θ·(y−120)/r, cos θ)` metres in the optical
//! frame (z forward, x right, y down), so `dist/500` is the range along the pixel's ray.
//! Points with z outside [`VALID_Z`] are invalid.
//!
//! Decisions where the vendor driver is not usable as is:
//! - `r = 0` (the centre pixel): the direction in the image plane is undefined but
//!   `sin θ = 0`, so x = y = 0; no division by zero.
//! - No `+0.5` is added to x and y: it is applied after the scaling to metres, so it would
//!   move every point half a metre off the optical axis while z stays put, which no lens
//!   does; it is a display offset of the vendor's viewer, not part of the optics.
//! - `p = 0` is invalid (no return; `ln 0` is undefined). The emulator writes 0 where it
//!   has no valid depth.

use nalgebra::{Point3, Vector3};

/// Raw image width, pixels.
pub const RAW_WIDTH: usize = 320;
/// Raw image height, pixels.
pub const RAW_HEIGHT: usize = 240;
/// Raw image centre (column, row), pixels.
pub const RAW_CENTRE: [f64; 2] = [160.0, 120.0];
/// Model units per metre (`dist` is in units of 2 mm).
pub const UNITS_PER_METRE: f64 = 500.0;
/// Valid band of z (metres) of a decoded point.
pub const VALID_Z: [f64; 2] = [0.02, 0.8];

/// Ray angle per pixel of radius, radians (64° per 160 px).
pub fn radians_per_pixel() -> f64 {
    64f64.to_radians() / 160.0
}

fn coefficient_a(r: f64) -> f64 {
    ((-2e-5 * r + 0.004) * r + 0.1719) * r + 350.03
}

fn coefficient_b(r: f64) -> f64 {
    ((-2e-9 * r + 3e-7) * r - 1e-5) * r - 0.01
}

fn range_factor(r: f64) -> f64 {
    ((7e-7 * r - 1e-4) * r + 0.004) * r + 0.9985
}

/// Distance of raw pixel `(x, y)` from the image centre, pixels.
fn pixel_radius(x: f64, y: f64) -> f64 {
    (x - RAW_CENTRE[0]).hypot(y - RAW_CENTRE[1])
}

/// Unit direction (optical frame) of the ray through raw image position `(x, y)` (pixels,
/// may be fractional).
///
/// ```
/// use nbv_hw::dinast::raw_direction;
/// let centre = raw_direction(160.0, 120.0);
/// assert_eq!((centre.x, centre.y, centre.z), (0.0, 0.0, 1.0));
/// // 160 px to the right is 64° off axis.
/// let right = raw_direction(320.0, 120.0);
/// assert!((right.x.atan2(right.z).to_degrees() - 64.0).abs() < 1e-9);
/// ```
pub fn raw_direction(x: f64, y: f64) -> Vector3<f64> {
    let r = pixel_radius(x, y);
    if r == 0.0 {
        return Vector3::z();
    }
    let theta = radians_per_pixel() * r;
    let s = theta.sin() / r;
    Vector3::new(
        s * (x - RAW_CENTRE[0]),
        s * (y - RAW_CENTRE[1]),
        theta.cos(),
    )
}

/// Inverse of [`raw_direction`]: the raw image position `(x, y)` whose ray points along
/// `direction` (any length), or `None` for a zero or non-finite direction.
///
/// ```
/// use nbv_hw::dinast::{raw_direction, raw_position};
/// let [x, y] = raw_position(&raw_direction(37.0, 201.0)).unwrap();
/// assert!((x - 37.0).abs() < 1e-9 && (y - 201.0).abs() < 1e-9);
/// ```
pub fn raw_position(direction: &Vector3<f64>) -> Option<[f64; 2]> {
    let lateral = direction.x.hypot(direction.y);
    let theta = lateral.atan2(direction.z);
    if !theta.is_finite() || direction.norm() == 0.0 {
        return None;
    }
    if lateral == 0.0 {
        return (direction.z > 0.0).then_some(RAW_CENTRE);
    }
    let r = theta / radians_per_pixel();
    Some([
        RAW_CENTRE[0] + r * direction.x / lateral,
        RAW_CENTRE[1] + r * direction.y / lateral,
    ])
}

/// The model's range (metres, along the ray) of raw value `p` at raw pixel `(x, y)`,
/// without the validity band; `None` for `p = 0` or a non-positive range.
///
/// ```
/// use nbv_hw::dinast::range_from_raw;
/// assert_eq!(range_from_raw(160, 120, 0), None);
/// // Larger raw values are nearer.
/// assert!(range_from_raw(160, 120, 200).unwrap() < range_from_raw(160, 120, 50).unwrap());
/// ```
pub fn range_from_raw(x: usize, y: usize, p: u8) -> Option<f64> {
    if p == 0 {
        return None;
    }
    let (xf, yf) = (x as f64, y as f64);
    let r = pixel_radius(xf, yf);
    let a = coefficient_a(r);
    let b = coefficient_b(r);
    let p = f64::from(p).min(a);
    let dist = ((p / a).ln() / b - 0.1 * yf) * range_factor(r) * 1.5;
    let range = dist / UNITS_PER_METRE;
    (range.is_finite() && range > 0.0).then_some(range)
}

/// The 3-D point (optical frame, metres) of raw value `p` at raw pixel `(x, y)`, or `None`
/// if invalid (`p = 0`, or z outside [`VALID_Z`]).
///
/// ```
/// use nbv_hw::dinast::{point_from_raw, range_from_raw};
/// let p = point_from_raw(200, 150, 80).unwrap();
/// assert!((p.coords.norm() - range_from_raw(200, 150, 80).unwrap()).abs() < 1e-12);
/// ```
pub fn point_from_raw(x: usize, y: usize, p: u8) -> Option<Point3<f64>> {
    let range = range_from_raw(x, y, p)?;
    let point = Point3::from(raw_direction(x as f64, y as f64) * range);
    (VALID_Z[0]..=VALID_Z[1])
        .contains(&point.z)
        .then_some(point)
}

/// The continuous raw value of `range_m` at `(x, y)`: `A·exp(B·(dist/(1.5·K) + 0.1·y))`.
fn continuous_raw(x: usize, y: usize, range_m: f64) -> Option<f64> {
    let (xf, yf) = (x as f64, y as f64);
    let r = pixel_radius(xf, yf);
    let k = range_factor(r);
    if !(range_m.is_finite() && range_m > 0.0 && k > 0.0) {
        return None;
    }
    let dist = range_m * UNITS_PER_METRE;
    let p = coefficient_a(r) * (coefficient_b(r) * (dist / (1.5 * k) + 0.1 * yf)).exp();
    p.is_finite().then_some(p)
}

/// Exact inverse of [`range_from_raw`]: the raw value (rounded) that encodes `range_m`
/// (metres along the ray) at raw pixel `(x, y)`, or `None` if it is not representable in
/// `1..=255` (too near or too far for that pixel) or not a positive finite range. The
/// validity band is not applied: the device encodes what it sees.
///
/// ```
/// use nbv_hw::dinast::{range_from_raw, raw_from_range};
/// let p = raw_from_range(100, 80, 0.5).unwrap();
/// assert!((range_from_raw(100, 80, p).unwrap() - 0.5).abs() < 0.01);
/// assert_eq!(raw_from_range(100, 80, 0.001), None);
/// ```
pub fn raw_from_range(x: usize, y: usize, range_m: f64) -> Option<u8> {
    let p = continuous_raw(x, y, range_m)?.round();
    (1.0..=255.0).contains(&p).then_some(p as u8)
}

/// Bound (metres) of the 8-bit quantisation error of `range_m` at `(x, y)`:
/// `|range_from_raw(raw_from_range(range)) − range|` never exceeds it.
///
/// `d dist/dp = 1.5·K/(B·p)`, and rounding moves the continuous raw value `p` by at most
/// ½, so the range error is at most `½·1.5·K/(|B|·(p − ½))/500` (the derivative's largest
/// magnitude within ½ of `p`). `None` where [`raw_from_range`] is `None`.
///
/// ```
/// use nbv_hw::dinast::range_quantisation_bound;
/// // Half a step: about 0.7 mm at the centre at 0.1 m, about 7 mm at 0.8 m.
/// let near = range_quantisation_bound(160, 120, 0.1).unwrap();
/// let far = range_quantisation_bound(160, 120, 0.8).unwrap();
/// assert!(near > 0.0006 && near < 0.0008, "{near}");
/// assert!(far > 0.006 && far < 0.008, "{far}");
/// ```
pub fn range_quantisation_bound(x: usize, y: usize, range_m: f64) -> Option<f64> {
    raw_from_range(x, y, range_m)?;
    let p = continuous_raw(x, y, range_m)?;
    let r = pixel_radius(x as f64, y as f64);
    let bound =
        0.5 * 1.5 * range_factor(r) / (coefficient_b(r).abs() * (p - 0.5)) / UNITS_PER_METRE;
    (bound.is_finite() && bound > 0.0).then_some(bound)
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    #[test]
    fn centre_pixel_has_no_lateral_offset() {
        let p = point_from_raw(160, 120, 100).unwrap();
        assert_eq!((p.x, p.y), (0.0, 0.0));
        assert!(p.z > 0.0);
    }

    #[test]
    fn zero_raw_value_is_invalid_everywhere() {
        for (x, y) in [(0, 0), (160, 120), (319, 239)] {
            assert_eq!(point_from_raw(x, y, 0), None);
        }
    }

    #[test]
    fn points_outside_the_z_band_are_invalid() {
        // p = 1 at the centre is about 1.7 m: beyond 0.8 m.
        assert!(range_from_raw(160, 120, 1).unwrap() > VALID_Z[1]);
        assert_eq!(point_from_raw(160, 120, 1), None);
        // p = 255 at the centre is about 6 cm: inside the band.
        let near = point_from_raw(160, 120, 255).unwrap();
        assert!(near.z > 0.05 && near.z < 0.07, "{near}");
    }

    #[test]
    fn off_axis_point_lies_along_the_pixel_direction() {
        let p = point_from_raw(260, 120, 120).unwrap();
        // 100 px right of centre: 40° off axis, no vertical component.
        assert!((p.x.atan2(p.z).to_degrees() - 40.0).abs() < 1e-9);
        assert_eq!(p.y, 0.0);
    }

    #[test]
    fn working_ranges_are_representable_inside_the_pinhole_field_of_view() {
        // Raw pixels seen by the 80° × 320 px pinhole image (f = 160 / tan 40°). Near the
        // top of that image the −0.1·y term and K(r) push the nearest representable range
        // (p = 255) up to about 0.134 m; the farthest (p = 1) is at least about 1.7 m.
        let focal = 160.0 / 40f64.to_radians().tan();
        let mut seen = 0;
        for y in (0..RAW_HEIGHT).step_by(3) {
            for x in (0..RAW_WIDTH).step_by(3) {
                let ray = raw_direction(x as f64, y as f64);
                let (u, v) = (ray.x / ray.z * focal, ray.y / ray.z * focal);
                if ray.z <= 0.0 || u.abs() > 160.0 || v.abs() > 120.0 {
                    continue;
                }
                seen += 1;
                assert!(range_from_raw(x, y, 255).unwrap() < 0.135, "({x}, {y})");
                assert!(range_from_raw(x, y, 1).unwrap() > 1.7, "({x}, {y})");
                for range in [0.135, 0.3, 0.8, 1.0] {
                    assert!(raw_from_range(x, y, range).is_some(), "({x}, {y}) {range}");
                }
            }
        }
        assert!(seen > 3000, "{seen}");
    }

    proptest! {
        #[test]
        fn decode_of_encode_is_within_the_quantisation_bound(
            x in 0..RAW_WIDTH,
            y in 0..RAW_HEIGHT,
            z in VALID_Z[0]..VALID_Z[1],
        ) {
            let range = z / raw_direction(x as f64, y as f64).z;
            let Some(p) = raw_from_range(x, y, range) else {
                // Only ranges the pixel cannot represent may fail to encode.
                let nearest = range_from_raw(x, y, 255).unwrap();
                let farthest = range_from_raw(x, y, 1).unwrap();
                prop_assert!(range < nearest || range > farthest);
                return Ok(());
            };
            let decoded = range_from_raw(x, y, p).unwrap();
            let bound = range_quantisation_bound(x, y, range).unwrap();
            prop_assert!((decoded - range).abs() <= bound * (1.0 + 1e-9),
                "range {range} decoded {decoded} bound {bound}");
        }

        #[test]
        fn raw_position_inverts_raw_direction(x in -40.0..360.0f64, y in -40.0..280.0f64) {
            let [u, v] = raw_position(&raw_direction(x, y)).unwrap();
            prop_assert!((u - x).abs() < 1e-9 && (v - y).abs() < 1e-9);
        }
    }
}
