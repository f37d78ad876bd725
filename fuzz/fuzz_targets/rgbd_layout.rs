//! `parse_trajectory` and `parse_intrinsics` (the reconstruction-system layout `nbv fuse`
//! reads: Redwood trajectory.log, Open3D's camera_intrinsic.json) on arbitrary text: never
//! panic; what parses is rigid, finite poses and a valid camera; errors name the file.
#![no_main]

use std::path::Path;

use libfuzzer_sys::fuzz_target;
use nbv_core::surface::{parse_intrinsics, parse_trajectory};

fuzz_target!(|data: &[u8]| {
    let text = String::from_utf8_lossy(data);
    match parse_trajectory(&text, Path::new("fuzz.log")) {
        Ok(poses) => {
            for p in poses {
                assert!(p.to_homogeneous().iter().all(|x| x.is_finite()));
            }
        }
        Err(e) => assert!(e.to_string().starts_with("fuzz.log line "), "{e}"),
    }
    match parse_intrinsics(&text, Path::new("fuzz.json")) {
        Ok(k) => assert!(k.is_valid()),
        Err(e) => assert!(e.to_string().starts_with("fuzz.json"), "{e}"),
    }
});
