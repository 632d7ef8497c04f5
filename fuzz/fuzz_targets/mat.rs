//! Fuzzes the MAT-file (level 5) record reader.
#![no_main]

use frictionid_engine::data::{read_mat, ReadOptions};
use libfuzzer_sys::fuzz_target;
use std::path::Path;

fuzz_target!(|data: &[u8]| {
    let opts = ReadOptions {
        min_samples: 2,
        ..ReadOptions::default()
    };
    let _ = read_mat(Path::new("fuzz.mat"), data, &opts);
});
