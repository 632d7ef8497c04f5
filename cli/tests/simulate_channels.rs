//! `simulate` of a law that reads a record channel: the FMM rig held at 5 mm by
//! `coulomb_load` while the load named in `[simulation] input` falls linearly from 20 N to 0
//! over a second (a record of the run: its velocity and load, no input force) breaks away
//! where mu N + mu_load |load(t)| meets k x0, in closed form
//! t = 1 - (k x0 - mu N) / (20 mu_load); without the channel the one-line error names it.

use frictionid_cli::testing::{runs_ok, scratch_dir, FMM_OSCILLATOR};
use std::path::Path;
use std::process::{Command, Output};

fn run(dir: &Path, channels: &str) -> std::io::Result<Output> {
    // A record of the run (its velocity beside the load), no input force: it drives nothing.
    let mut csv = String::from("time,velocity,load\n");
    for i in 0..=100 {
        let t = i as f64 * 0.01;
        csv.push_str(&format!("{t},0,{}\n", 20.0 * (1.0 - t)));
    }
    std::fs::write(dir.join("load.csv"), csv).unwrap();
    let cfg = dir.join("c.toml");
    std::fs::write(
        &cfg,
        format!(
            "{FMM_OSCILLATOR}[model]\ntype = \"coulomb_load\"\nmu = 0.2\nmu_load = 0.5\n\
             viscous = 0.0\n[simulation]\nx0 = 0.005\nduration = 0.5\n\
             input = {{ file = \"load.csv\"{channels} }}\n"
        ),
    )
    .unwrap();
    Command::new(env!("CARGO_BIN_EXE_frictionid"))
        .arg("simulate")
        .arg(&cfg)
        .arg("--quiet")
        .arg("--out")
        .arg(dir.join("out"))
        .output()
}

#[test]
fn a_simulation_reads_its_load_from_the_input_file_and_breaks_away_on_time() {
    let dir = scratch_dir("simulate-channels", "load");
    let (report, _) = runs_ok(
        run(&dir, ", channels = { load = \"load\" }"),
        &dir.join("out"),
    );
    let events = report["events"].as_array().cloned().unwrap_or_default();
    let breakaway = events
        .iter()
        .find(|e| e["kind"] == "breakaway")
        .and_then(|e| e["time"].as_f64())
        .unwrap_or_else(|| panic!("no breakaway among {events:?}"));
    let t_b = 1.0 - (1982.0 * 0.005 - 0.2 * 14.5) / (20.0 * 0.5);
    assert!((breakaway - t_b).abs() < 1e-6, "{breakaway} against {t_b}");
    let bare = run(&dir, "").expect("runs");
    let stderr = String::from_utf8_lossy(&bare.stderr);
    assert!(!bare.status.success(), "{stderr}");
    assert!(stderr.contains("`load`"), "{stderr}");
    let _ = std::fs::remove_dir_all(&dir);
}
