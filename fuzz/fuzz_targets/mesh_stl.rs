//! `stl_from_bytes` on arbitrary bytes (binary or ASCII STL; the binary triangle count may
//! lie): never panics; a mesh that parses has triangles, finite vertices and indices in
//! range, and writes back (binary STL) to bytes that re-read to the same mesh.
#![no_main]

use std::path::Path;

use libfuzzer_sys::fuzz_target;
use nbv_core::mesh::io::{stl_from_bytes, stl_to_bytes};

fuzz_target!(|data: &[u8]| {
    let Ok(mesh) = stl_from_bytes(data, Path::new("fuzz.stl")) else {
        return;
    };
    let n = mesh.vertices.len();
    assert!(!mesh.triangles.is_empty());
    assert!(mesh.triangles.iter().flatten().all(|&i| (i as usize) < n));
    assert!(
        mesh.vertices
            .iter()
            .all(|p| p.coords.iter().all(|c| c.is_finite()))
    );
    let bytes = stl_to_bytes(&mesh);
    let again = stl_from_bytes(&bytes, Path::new("again.stl")).expect("a written mesh reads");
    assert_eq!(again.triangles.len(), mesh.triangles.len());
    assert_eq!(
        stl_to_bytes(&again),
        bytes,
        "write → read → write changed the file"
    );
});
