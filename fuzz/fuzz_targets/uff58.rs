//! Fuzzes the UFF dataset 58 (ASCII) record reader.
#![no_main]

use frictionid_engine::data::{read_uff58, ReadOptions};
use libfuzzer_sys::fuzz_target;
use std::path::Path;

fuzz_target!(|data: &[u8]| {
    let text = String::from_utf8_lossy(data);
    let opts = ReadOptions {
        min_samples: 2,
        ..ReadOptions::default()
    };
    let _ = read_uff58(Path::new("fuzz.uff"), &text, &opts);
});
