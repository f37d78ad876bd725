//! `read_pcd` on arbitrary bytes: never panics, never allocates more than the bytes can
//! hold (`POINTS`, `COUNT` and the compressed block sizes may lie), and a cloud that
//! parses writes back (ASCII, binary and binary_compressed, doubles) to a file that
//! re-reads to the same cloud and the same bytes.
#![no_main]

use libfuzzer_sys::fuzz_target;
use nbv_core::cloud::io::{Encoding, FloatType, ReadOptions, WriteOptions, read_pcd, write_pcd};

fuzz_target!(|data: &[u8]| {
    let Ok(file) = read_pcd(data, &ReadOptions::default()) else {
        return;
    };
    assert_eq!(file.cloud.validate(), Ok(()));
    for encoding in [
        Encoding::Ascii,
        Encoding::Binary,
        Encoding::BinaryCompressed,
    ] {
        let options = WriteOptions {
            encoding,
            float: FloatType::F64,
        };
        let mut first = Vec::new();
        write_pcd(&mut first, &file.cloud, &options).expect("a parsed cloud writes");
        let again = read_pcd(&first[..], &ReadOptions::default()).expect("a written cloud reads");
        assert_eq!(again.cloud.len(), file.cloud.len());
        let mut second = Vec::new();
        write_pcd(&mut second, &again.cloud, &options).unwrap();
        assert!(first == second, "write → read → write changed the file");
    }
});
