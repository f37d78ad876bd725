//! 16-bit PNG depth images: round trips, the invalid-pixel convention and bad input.

use nbv_core::cloud::io::{
    CloudIoErrorKind, DEFAULT_DEPTH_SCALE, decode_depth_png, encode_depth_png, read_depth_png,
    write_depth_png,
};
use proptest::prelude::*;

proptest! {
    #![proptest_config(ProptestConfig::with_cases(48))]

    #[test]
    fn round_trip_within_half_a_unit(
        w in 1u32..24,
        h in 1u32..24,
        seed in proptest::collection::vec(prop_oneof![9 => 0.1..0.8f64, 1 => Just(f64::NAN)], 576),
        scale in prop_oneof![Just(DEFAULT_DEPTH_SCALE), Just(0.0001), Just(0.01)],
    ) {
        let depth: Vec<f64> = seed.into_iter().take((w * h) as usize).collect();
        let png = encode_depth_png(w, h, &depth, scale).unwrap();
        let img = decode_depth_png(&png, scale).unwrap();
        prop_assert_eq!((img.width, img.height), (w, h));
        for (d, r) in depth.iter().zip(&img.depth_m) {
            if d.is_nan() {
                prop_assert!(r.is_nan());
            } else {
                prop_assert!((d - r).abs() <= scale / 2.0 + 1e-12, "{} vs {}", d, r);
                // The stored value is exactly round(d / scale).
                prop_assert_eq!((r / scale).round(), (d / scale).round());
            }
        }
        // Deterministic encoding.
        prop_assert_eq!(encode_depth_png(w, h, &depth, scale).unwrap(), png);
    }
}

#[test]
fn file_round_trip_f32_and_invalid_pixels() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("depth.png");
    let depth = [0.5f32, f32::NAN, f32::INFINITY, 0.0, 0.0004, 65.535];
    write_depth_png(&path, 3, 2, &depth, DEFAULT_DEPTH_SCALE).unwrap();
    let img = read_depth_png(&path, DEFAULT_DEPTH_SCALE).unwrap();
    assert_eq!((img.width, img.height), (3, 2));
    assert!((img.depth_m[0] - 0.5).abs() < 1e-12);
    assert!(img.depth_m[1..5].iter().all(|d| d.is_nan()));
    assert!((img.depth_m[5] - 65.535).abs() < 1e-9);
    // It is a real 16-bit greyscale PNG: bit depth 16, colour type 0 in IHDR.
    let bytes = std::fs::read(&path).unwrap();
    assert_eq!(&bytes[1..4], b"PNG");
    assert_eq!((bytes[24], bytes[25]), (16, 0));
}

#[test]
fn bad_depth_input_is_an_error() {
    let e = encode_depth_png(1, 1, &[65.6f64], DEFAULT_DEPTH_SCALE).unwrap_err();
    assert!(matches!(e.kind, CloudIoErrorKind::Depth(_)), "{e}");
    assert!(e.to_string().contains("exceeds 65535"), "{e}");
    let e = encode_depth_png(1, 1, &[-0.1f64], DEFAULT_DEPTH_SCALE).unwrap_err();
    assert!(e.to_string().contains("negative"), "{e}");
    assert!(encode_depth_png(2, 2, &[0.5f64; 3], DEFAULT_DEPTH_SCALE).is_err());
    assert!(encode_depth_png(0, 0, &[0.5f64; 0], DEFAULT_DEPTH_SCALE).is_err());
    assert!(encode_depth_png(1, 1, &[0.5f64], 0.0).is_err());
    assert!(encode_depth_png(1, 1, &[0.5f64], f64::NAN).is_err());
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("d.png");
    let e = write_depth_png(&path, 1, 1, &[100.0f64], DEFAULT_DEPTH_SCALE).unwrap_err();
    assert!(
        e.to_string().starts_with(&path.display().to_string()),
        "{e}"
    );
    assert!(!path.exists());
}

#[test]
fn eight_bit_and_colour_pngs_are_refused() {
    let mut png = std::io::Cursor::new(Vec::new());
    image::DynamicImage::ImageLuma8(image::GrayImage::new(2, 2))
        .write_to(&mut png, image::ImageFormat::Png)
        .unwrap();
    let e = decode_depth_png(png.get_ref(), DEFAULT_DEPTH_SCALE).unwrap_err();
    assert!(e.to_string().contains("16-bit greyscale"), "{e}");
    let e = decode_depth_png(b"not a png", DEFAULT_DEPTH_SCALE).unwrap_err();
    assert!(matches!(e.kind, CloudIoErrorKind::Png(_)), "{e}");
}
