//! Fuzzes the delimited-text (CSV, semicolon, tab, whitespace) record reader.
#![no_main]

use frictionid_engine::data::{read_delimited, DataFormat, ReadOptions};
use libfuzzer_sys::fuzz_target;
use std::path::Path;

fuzz_target!(|data: &[u8]| {
    // The first byte picks the format; the rest is the file (decoded like the reader does).
    let Some((&first, rest)) = data.split_first() else {
        return;
    };
    let format = match first % 3 {
        0 => DataFormat::Auto,
        1 => DataFormat::Csv,
        _ => DataFormat::Whitespace,
    };
    let text = String::from_utf8_lossy(rest);
    let opts = ReadOptions {
        min_samples: 2,
        ..ReadOptions::default()
    };
    let _ = read_delimited(Path::new("fuzz.csv"), &text, format, &opts);
});
