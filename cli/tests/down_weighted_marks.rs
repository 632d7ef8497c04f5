//! The fit plot marks the samples a robust loss down-weighted: the drive of `units.rs` with
//! 0.2 N of Gaussian noise on its input and spikes of 6 N at known samples, fitted by inverse
//! dynamics with `loss = "huber"`. Its force-balance plot draws one triangle per sample
//! report.json counts as down-weighted, the spikes among them, with a legend entry.

use crate::units::{drive_config, drive_csv, filled, force_balance_svg, run_quiet};
use frictionid_cli::testing::scratch_dir;
use frictionid_engine::synthetic::add_gaussian_noise;
use std::fmt::Write;

/// The fill of a down-weighted sample's triangle in the SVG.
const MARK_FILL: &str = "#E67800";
/// Every this many samples the input carries a spike.
const SPIKE_EVERY: usize = 151;

/// Filled polygons in `svg` in the down-weighted samples' colour.
fn triangles(svg: &str) -> usize {
    filled(svg, "polygon", MARK_FILL)
}

/// The drive's rows with noise and spikes on the input, and the spikes' times.
fn spiked(csv: &str) -> (String, Vec<f64>) {
    let rows: Vec<Vec<f64>> = csv
        .lines()
        .skip(1)
        .map(|l| l.split(',').map(|x| x.parse().unwrap()).collect())
        .collect();
    let mut u: Vec<f64> = rows.iter().map(|r| r[2]).collect();
    add_gaussian_noise(&mut u, 0.2, 17);
    let mut spikes = Vec::new();
    for i in (SPIKE_EVERY..u.len()).step_by(SPIKE_EVERY) {
        u[i] += 6.0;
        spikes.push(rows[i][0]);
    }
    let mut out = String::from("time,position,u\n");
    for (r, u) in rows.iter().zip(&u) {
        let _ = writeln!(out, "{},{:.9},{u:.9}", r[0], r[1]);
    }
    (out, spikes)
}

#[test]
fn the_force_balance_plot_marks_each_sample_the_loss_down_weighted() {
    let dir = scratch_dir("marks", "huber");
    let (csv, spikes) = spiked(&drive_csv(&dir, 1.0));
    std::fs::write(dir.join("drive.csv"), csv).unwrap();
    let config = drive_config("force", "mass = 10.0\n")
        .replace("[fit.options]\n", "[fit.options]\nloss = \"huber\"\n");
    std::fs::write(dir.join("fit.toml"), config).unwrap();
    let out = dir.join("fit");
    run_quiet("fit", &dir.join("fit.toml"), &out);
    let report: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("report.json")).unwrap()).unwrap();
    let weights = &report["records"][0]["robust_weights"];
    let count = weights["count"]
        .as_u64()
        .unwrap_or_else(|| panic!("no robust weights: {}", report["records"][0]));
    let ranges: Vec<[f64; 2]> = serde_json::from_value(weights["ranges"].clone()).unwrap();
    let svg = force_balance_svg(&out);
    eprintln!(
        "{count} samples down-weighted, {} marked, {} spikes",
        triangles(&svg),
        spikes.len()
    );
    let within = |t: &f64| ranges.iter().any(|[a, b]| a - 1e-9 <= *t && *t <= b + 1e-9);
    let left_out = report["records"][0]["unreliable_target"]["ranges"].clone();
    let left_out: Vec<[f64; 2]> = serde_json::from_value(left_out).unwrap_or_default();
    let compared = |t: &&f64| !left_out.iter().any(|[a, b]| *a <= **t && **t <= *b);
    assert!(spikes.iter().filter(compared).all(within), "{ranges:?}");
    assert!(count as usize >= spikes.iter().filter(compared).count());
    assert!(count < 2 * spikes.len() as u64, "{count}");
    assert_eq!(triangles(&svg) as u64, count);
    assert!(svg.contains("down-weighted by the robust loss"));
    let findings = report["diagnostics"].as_array().unwrap();
    assert!(findings.iter().any(|f| f["check"] == "down_weighted"));
    let _ = std::fs::remove_dir_all(&dir);
}
