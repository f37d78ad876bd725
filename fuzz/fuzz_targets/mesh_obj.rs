//! `obj_from_bytes` on arbitrary bytes (Wavefront OBJ; faces may name missing or negative
//! vertices, polygons are triangulated): never panics; a mesh that parses has triangles,
//! finite vertices and indices in range; errors name the data.
#![no_main]

use std::path::Path;

use libfuzzer_sys::fuzz_target;
use nbv_core::mesh::io::obj_from_bytes;

fuzz_target!(|data: &[u8]| {
    match obj_from_bytes(data, Path::new("fuzz.obj")) {
        Ok(mesh) => {
            let n = mesh.vertices.len();
            assert!(!mesh.triangles.is_empty());
            assert!(mesh.triangles.iter().flatten().all(|&i| (i as usize) < n));
            assert!(
                mesh.vertices
                    .iter()
                    .all(|p| p.coords.iter().all(|c| c.is_finite()))
            );
        }
        Err(e) => assert!(e.to_string().starts_with("fuzz.obj: "), "{e}"),
    }
});
