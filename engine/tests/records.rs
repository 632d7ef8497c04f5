//! Records as a laboratory writes them, read through the engine's record source: the real
//! tribometer record (where the developers keep it) and the simulated one in its export
//! format, with their own column names and units, pre-trigger rests found by
//! `release = "auto"` against the known release of synthetic records, `[record_defaults]`, and
//! unit mistakes caught before any fit.

use frictionid_engine::data::DataError;
use frictionid_engine::data::RecordSource;
use frictionid_engine::record::{Channel, NormalForce, Release, ScaleError};
use frictionid_engine::synthetic::{defective_record, Defects};
use frictionid_engine::testing::real_tribometer_slice;
use frictionid_engine::{Oscillator, Record};
use frictionid_models::Coulomb;
use std::fmt::Write;
use std::path::{Path, PathBuf};

fn fixtures() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../fixtures")
}

fn scratch(name: &str) -> PathBuf {
    let dir =
        std::env::temp_dir().join(format!("frictionid-records-{}-{name}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("scratch dir");
    dir
}

fn tribometer_source() -> RecordSource {
    RecordSource {
        file: Some("tribometer/tribometer-sim.txt".into()),
        x0: Some(0.0),
        time_column: Some("Time [s]".into()),
        displacement_column: Some("Position [mm]".into()),
        displacement_scale: Some(1e-3),
        force_column: Some("Friction [uN]".into()),
        force_scale: Some(-1e-6),
        normal_force_column: Some("Normal [uN]".into()),
        normal_force_scale: Some(1e-6),
        ..RecordSource::default()
    }
}

fn mean(v: &[f64]) -> f64 {
    v.iter().sum::<f64>() / v.len() as f64
}

fn close(a: f64, b: f64, rel: f64) -> bool {
    (a - b).abs() <= rel * b.abs()
}

/// Oracle: Python's `csv` module on the same six seconds of the real record
/// (`frictionid_engine::testing::real_tribometer_slice`): 1200 rows, t = 7.894 ... 13.889 s;
/// means N = 5.00018268916667 N, x = -0.10992864041666539 m, F (negated) = 0.35316973424999976 N; x in
/// [-0.1100356, -0.1097962] m, F in [-2.509324, 2.5265442] N; row 500 is
/// (10.394, 5000010.3, -109.7965, -2315632.4).
#[test]
fn the_tribometer_record_reads_with_its_own_columns_and_units() {
    let dir = scratch("real-tribometer");
    let slice = match real_tribometer_slice(&dir) {
        Ok(slice) => slice,
        Err(skipped) => return eprintln!("{skipped}"),
    };
    let source = RecordSource {
        file: Some(slice.display().to_string()),
        ..tribometer_source()
    };
    let r = source.load(&dir).expect("tribometer slice");
    assert_eq!(r.len(), 1200);
    assert_eq!(
        r.channels(),
        vec![Channel::Displacement, Channel::Force, Channel::NormalForce]
    );
    assert_eq!((r.time()[0], r.time()[1199]), (7.894, 13.889));
    let x = r.channel(Channel::Displacement).unwrap();
    let f = r.channel(Channel::Force).unwrap();
    let n = r.channel(Channel::NormalForce).unwrap();
    assert!(close(mean(n), 5.00018268916667, 1e-12), "{}", mean(n));
    assert!(close(mean(x), -0.10992864041666539, 1e-12), "{}", mean(x));
    assert!(close(mean(f), 0.35316973424999976, 1e-12), "{}", mean(f));
    let (xmin, xmax) = x
        .iter()
        .fold((f64::MAX, f64::MIN), |(a, b), &v| (a.min(v), b.max(v)));
    assert!(close(xmin, -0.1100356, 1e-12) && close(xmax, -0.1097962, 1e-12));
    let (fmin, fmax) = f
        .iter()
        .fold((f64::MAX, f64::MIN), |(a, b), &v| (a.min(v), b.max(v)));
    assert!(close(fmin, -2.509324, 1e-12) && close(fmax, 2.5265442, 1e-12));
    assert_eq!(r.time()[500], 10.394);
    assert!(close(n[500], 5.0000103, 1e-12) && close(x[500], -0.1097965, 1e-12));
    assert!(close(f[500], 2.3156324, 1e-12));
    assert!(matches!(r.normal_force(), Some(NormalForce::Sampled(_))));
    // No velocity: the velocity analyses refuse it with a clear error.
    let e = r.validate(10).unwrap_err().to_string();
    assert!(
        e.contains("no velocity channel (the record has: displacement, force, normal_force)"),
        "{e}"
    );
}

#[test]
fn a_constant_normal_force_key_replaces_the_channel_and_names_clash() {
    let source = RecordSource {
        normal_force_column: None,
        normal_force_scale: None,
        normal_force: Some(4.8),
        ..tribometer_source()
    };
    let r = source.load(&fixtures()).unwrap();
    assert_eq!(r.normal_force(), Some(&NormalForce::Constant(4.8)));
    assert_eq!(r.channel(Channel::NormalForce), None);
    let both = RecordSource {
        normal_force: Some(4.8),
        ..tribometer_source()
    };
    let e = both.load(&fixtures()).unwrap_err().to_string();
    assert_eq!(
        e,
        "[[records]] entry 1 (`tribometer/tribometer-sim.txt`): give either `normal_force` \
         (a constant) or `normal_force_column`, not both"
    );
}

#[test]
fn a_named_column_missing_from_the_header_names_file_and_column() {
    let source = RecordSource {
        force_column: Some("Friction [N]".into()),
        ..tribometer_source()
    };
    let e = source.load(&fixtures()).unwrap_err().to_string();
    assert!(
        e.ends_with(
            "tribometer-sim.txt: line 1: no column `Friction [N]` (did you mean `Friction [uN]`?); \
             the header has: Time [s], Normal [uN], Position [mm], Friction [uN]"
        ),
        "{e}"
    );
}

/// Writes `record` as `file` with the lab's own column names, velocity in mm/s.
fn write_mm_per_s(record: &Record, dir: &Path, file: &str) {
    let mut text = String::from("# exported by the vibrometer\nt_s;v_mm_s\n");
    for (t, v) in record.time().iter().zip(record.velocity()) {
        let _ = writeln!(text, "{t:.6};{:.9}", v * 1e3);
    }
    std::fs::write(dir.join(file), text).expect("write record");
}

/// A Coulomb release (mu 0.24) from `x0` on the FMM rig with the lab's defects after
/// `rest` s of pre-trigger rest, `duration` s at `rate` Hz after the release, written by
/// [`write_mm_per_s`] as `file` in `dir`; returns the record written (in SI units).
fn lab_export(
    dir: &Path,
    file: &str,
    x0: f64,
    duration: f64,
    rate: f64,
    rest: f64,
    seed: u64,
) -> Record {
    let truth = defective_record(
        &Oscillator::fmm(),
        &Coulomb { mu: 0.24 },
        x0,
        duration,
        rate,
        &defects(rest),
        seed,
    )
    .expect("synthetic record");
    write_mm_per_s(&truth, dir, file);
    truth
}

/// The `[[records]]` entry of the lab export `file` released from 14 mm: its column names,
/// read as they are (no unit scales).
fn lab_entry(file: &str) -> RecordSource {
    RecordSource {
        file: Some(file.into()),
        x0: Some(0.014),
        time_column: Some("t_s".into()),
        velocity_column: Some("v_mm_s".into()),
        ..RecordSource::default()
    }
}

fn defects(rest: f64) -> Defects {
    Defects {
        rest,
        offset: 3e-4,
        noise: 2e-4,
        correlation: 0.7,
    }
}

#[test]
fn auto_release_finds_the_known_release_after_a_noisy_pre_trigger_rest() {
    let osc = Oscillator::fmm();
    let dir = scratch("release");
    let defaults = RecordSource {
        time_column: Some("t_s".into()),
        velocity_column: Some("v_mm_s".into()),
        velocity_scale: Some(1e-3),
        release: Some(Release::Auto),
        ..RecordSource::default()
    };
    for (i, (rest, x0)) in [(0.2, 0.010), (0.3712, 0.014), (0.5, 0.022), (0.4433, 0.014)]
        .into_iter()
        .enumerate()
    {
        let file = format!("r{i}.csv");
        let truth = lab_export(&dir, &file, x0, 1.0, 5000.0, rest, i as u64);
        let entry = RecordSource {
            file: Some(file.clone()),
            x0: Some(x0),
            ..RecordSource::default()
        };
        let r = entry
            .with_defaults(&defaults)
            .load_checked(&dir, &osc)
            .unwrap_or_else(|e| panic!("{file}: {e}"));
        let found = r.release_time.expect("a release time");
        // Within one sample (0.2 ms) of the truth; the record starts at the last sample at or
        // before the found release.
        assert!(
            (found - rest).abs() < 2e-4,
            "{file}: release {found} s, truth {rest} s"
        );
        assert!(r.time()[0] <= found && found - r.time()[0] < 2e-4, "{file}");
        assert_eq!(
            r.len(),
            truth.len() - truth.time().partition_point(|&t| t < r.time()[0])
        );
        assert_eq!(r.x0, x0);
    }
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn a_release_time_in_seconds_cuts_there_and_a_record_without_rest_is_kept_whole() {
    let osc = Oscillator::fmm();
    let dir = scratch("given");
    lab_export(&dir, "r.csv", 0.014, 1.0, 1000.0, 0.3, 9);
    let entry = RecordSource {
        velocity_scale: Some(1e-3),
        release: Some(Release::At(0.3)),
        ..lab_entry("r.csv")
    };
    let r = entry.load_checked(&dir, &osc).unwrap();
    assert_eq!(
        (r.release_time, r.time()[0], r.len()),
        (Some(0.3), 0.3, 1001)
    );
    let late = RecordSource {
        release: Some(Release::At(5.0)),
        ..entry.clone()
    };
    let e = late.load(&dir).unwrap_err().to_string();
    assert!(
        e.ends_with("r.csv: release = 5 s is not before the last sample (1.3 s)"),
        "{e}"
    );
    // No rest: "auto" keeps every sample.
    let moving = lab_export(&dir, "m.csv", 0.014, 1.0, 1000.0, 0.0, 3);
    let auto = RecordSource {
        file: Some("m.csv".into()),
        release: Some(Release::Auto),
        ..entry
    };
    let r = auto.load_checked(&dir, &osc).unwrap();
    assert_eq!(r.len(), moving.len());
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn record_defaults_give_keys_once_and_a_record_s_own_key_wins() {
    let defaults = RecordSource {
        velocity_scale: Some(1e-3),
        weight: Some(2.0),
        release: Some(Release::Auto),
        ..RecordSource::default()
    };
    let own = RecordSource {
        file: Some("a.csv".into()),
        x0: Some(0.01),
        weight: Some(0.5),
        ..RecordSource::default()
    };
    let merged = own.with_defaults(&defaults);
    assert_eq!(merged.weight, Some(0.5));
    assert_eq!(merged.velocity_scale, Some(1e-3));
    assert_eq!(merged.release, Some(Release::Auto));
    assert_eq!(merged.file.as_deref(), Some("a.csv"));
    let resolved = merged.resolve(1, Path::new(".")).unwrap();
    assert_eq!(resolved.read.scale(Channel::Velocity), 1e-3);
}

#[test]
fn unit_mistakes_are_errors_naming_the_record_the_ratio_and_the_key() {
    let osc = Oscillator::fmm();
    let dir = scratch("units");
    lab_export(&dir, "x14.csv", 0.014, 2.0, 1000.0, 0.0, 5);
    let entry = lab_entry("x14.csv");
    // The mm/s export read as m/s.
    let e = entry.load_checked(&dir, &osc).unwrap_err();
    let msg = e.to_string();
    assert!(msg.starts_with("x14.csv: peak speed"), "{msg}");
    assert!(
        msg.contains("larger than x0 = 0.014 m and k/m allow"),
        "{msg}"
    );
    assert!(
        msg.ends_with("is the velocity in mm/s? set velocity_scale = 1e-3"),
        "{msg}"
    );
    let DataError::Scale(ScaleError::Speed { ratio, .. }) = e else {
        panic!("{e:?}")
    };
    // Peak speed (x0 - mu N / k) w of the Coulomb solution against x0 w, times 1000.
    let expected = 1e3 * (0.014 - 0.24 * 14.5 / osc.stiffness) / 0.014;
    assert!(close(ratio, expected, 0.02), "{ratio} vs {expected}");
    // Time stamps in milliseconds.
    let ms = RecordSource {
        velocity_scale: Some(1e-3),
        time_scale: Some(1e3),
        ..entry.clone()
    };
    let msg = ms.load_checked(&dir, &osc).unwrap_err().to_string();
    assert!(msg.contains("1000x larger than 2 pi sqrt(m/k)"), "{msg}");
    assert!(
        msg.ends_with("are the time stamps in milliseconds? set time_scale = 1e-3"),
        "{msg}"
    );
    // Right units: accepted.
    let right = RecordSource {
        velocity_scale: Some(1e-3),
        ..entry
    };
    right.load_checked(&dir, &osc).unwrap();
    let _ = std::fs::remove_dir_all(&dir);
}
