//! `read_ply` on arbitrary bytes: never panics, never allocates more than the bytes can
//! hold (a header may declare 2^64 vertices), and a cloud that parses writes back (ASCII
//! and binary, doubles) to a file that re-reads to the same cloud and the same bytes.
#![no_main]

use libfuzzer_sys::fuzz_target;
use nbv_core::cloud::io::{Encoding, FloatType, ReadOptions, WriteOptions, read_ply, write_ply};

fuzz_target!(|data: &[u8]| {
    let Ok(file) = read_ply(data, &ReadOptions::default()) else {
        return;
    };
    assert_eq!(file.cloud.validate(), Ok(()));
    for encoding in [Encoding::Ascii, Encoding::Binary] {
        let options = WriteOptions {
            encoding,
            float: FloatType::F64,
        };
        let mut first = Vec::new();
        write_ply(&mut first, &file.cloud, &options).expect("a parsed cloud writes");
        let again = read_ply(&first[..], &ReadOptions::default()).expect("a written cloud reads");
        assert_eq!(again.cloud.len(), file.cloud.len());
        let mut second = Vec::new();
        write_ply(&mut second, &again.cloud, &options).unwrap();
        assert!(first == second, "write → read → write changed the file");
    }
});
