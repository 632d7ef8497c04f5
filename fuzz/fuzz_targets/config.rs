//! Fuzzes the configuration loader and the expression model's formula parser.
//!
//! An input whose first byte is even is a whole configuration file (TOML: oscillator, model
//! with the registry and the expression model, fit, simulation, energy, records); an odd first
//! byte makes the rest a force formula, which is parsed, compiled over its own variables and
//! evaluated.
#![no_main]

use frictionid_cli::config::Config;
use frictionid_models::formula;
use libfuzzer_sys::fuzz_target;
use std::path::Path;

fuzz_target!(|data: &[u8]| {
    let Some((&first, rest)) = data.split_first() else {
        return;
    };
    let Ok(text) = std::str::from_utf8(rest) else {
        return;
    };
    if first % 2 == 0 {
        let _ = Config::parse(Path::new("fuzz/config.toml"), text);
    } else if let Ok(parsed) = formula::parse(text) {
        let names: Vec<&str> = parsed.variables().iter().map(|(n, _)| n.as_str()).collect();
        if let Ok(f) = parsed.compile(&names) {
            for x in [0.0, -1.0, 1e-3, 1e300, f64::MIN_POSITIVE] {
                let _ = f.eval_by(|_| x);
            }
        }
    }
});
