//! Realistic records through the configuration file: `[record_defaults]`, `release = "auto"`
//! and unit mistakes caught before any fit, on a synthetic record whose release is
//! known.

use frictionid_cli::config::Config;
use frictionid_engine::synthetic::{defective_record, Defects};
use frictionid_engine::Oscillator;
use frictionid_models::Coulomb;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

const OSC: &str =
    "[oscillator]\nmass = 10.391\ndamping = 0.275\nstiffness = 1982.0\nnormal_force = 14.5\n";

/// A scratch directory holding `rest.csv`: 0.37 s of noisy rest, then the FMM Coulomb release
/// from 14 mm, 5 kHz, exported in mm/s with the lab's own column names.
fn lab_export(name: &str) -> PathBuf {
    let dir =
        std::env::temp_dir().join(format!("frictionid-recconf-{}-{name}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("scratch");
    let defects = Defects {
        rest: 0.37,
        offset: 2e-4,
        noise: 2e-4,
        correlation: 0.5,
    };
    let r = defective_record(
        &Oscillator::fmm(),
        &Coulomb { mu: 0.24 },
        0.014,
        1.5,
        5000.0,
        &defects,
        7,
    )
    .expect("synthetic record");
    let mut text = String::from("Zeit [s],Geschwindigkeit [mm/s]\n");
    for (t, v) in r.time().iter().zip(r.velocity()) {
        let _ = writeln!(text, "{t:.6},{:.9}", v * 1e3);
    }
    std::fs::write(dir.join("rest.csv"), text).expect("write");
    dir
}

/// `[record_defaults]` naming the lab export's columns (velocity in mm/s).
const LAB_COLUMNS: &str = "[record_defaults]\ntime_column = \"Zeit [s]\"\n\
                           velocity_column = \"Geschwindigkeit [mm/s]\"\n";

fn config(dir: &Path, text: &str) -> Result<Config, String> {
    Config::parse(&dir.join("c.toml"), &format!("{OSC}{text}")).map_err(|e| e.to_string())
}

#[test]
fn record_defaults_and_auto_release_read_a_lab_export() {
    let dir = lab_export("ok");
    let cfg = config(
        &dir,
        &format!(
            "{LAB_COLUMNS}velocity_scale = 1e-3\nrelease = \"auto\"\nweight = 3.0\n\
             [[records]]\nfile = \"rest.csv\"\nx0 = 0.014\nweight = 2.0\n"
        ),
    )
    .unwrap();
    let records = cfg.load_records("fit").unwrap();
    let r = &records[0];
    // The record's own weight wins over the default.
    assert_eq!(r.weight, 2.0);
    let release = r.release_time.expect("release found");
    assert!((release - 0.37).abs() < 2e-4, "release at {release} s");
    assert!(r.time()[0] <= release && release - r.time()[0] < 2e-4);
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn an_export_in_mm_per_s_without_its_scale_is_an_error_naming_the_key() {
    let dir = lab_export("mm");
    let records = format!("{LAB_COLUMNS}[[records]]\nfile = \"rest.csv\"\nx0 = 0.014\n");
    let cfg = config(&dir, &records).unwrap();
    let e = cfg.load_records("fit").unwrap_err().to_string();
    assert!(e.starts_with("rest.csv: peak speed"), "{e}");
    assert!(
        e.ends_with("is the velocity in mm/s? set velocity_scale = 1e-3"),
        "{e}"
    );
    assert!(!e.contains('\n'));
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn record_defaults_reject_unknown_keys_with_a_suggestion() {
    let e = config(
        Path::new("dir"),
        "[record_defaults]\nvelocity_colum = \"v\"\n[[records]]\nfile = \"a.csv\"\nx0 = 0.01\n",
    )
    .unwrap_err();
    assert!(
        e.contains(
            "unknown key `velocity_colum` in [record_defaults] (did you mean `velocity_column`?)"
        ),
        "{e}"
    );
    let e = config(
        Path::new("dir"),
        "[[records]]\nfile = \"a.csv\"\nx0 = 0.01\nrelease = \"later\"\n",
    )
    .unwrap_err();
    assert!(e.contains("\"auto\" or the release time in seconds"), "{e}");
}
