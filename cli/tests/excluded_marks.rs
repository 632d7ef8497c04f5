//! The fit plot marks the samples the fit left out: an inverse-dynamics fit of a drive whose
//! position is quantised to 1 um (`units.rs`'s record) leaves out the samples whose
//! acceleration is differentiated across a reversal; its force-balance plot draws one
//! marker per sample left out, as many as report.json's finding counts.

use crate::units::{drive_config, drive_csv, filled, force_balance_svg, run_quiet};
use frictionid_cli::testing::scratch_dir;

/// The fill of a marked sample's circle in the SVG (the plots' colour of marked samples).
const MARK_FILL: &str = "#E60078";

/// Filled circles in `svg` in the marked samples' colour.
fn marks(svg: &str) -> usize {
    filled(svg, "circle", MARK_FILL)
}

#[test]
fn the_force_balance_plot_marks_each_sample_left_out() {
    let dir = scratch_dir("marks", "drive");
    std::fs::write(dir.join("drive.csv"), drive_csv(&dir, 1.0)).unwrap();
    std::fs::write(dir.join("fit.toml"), drive_config("force", "mass = 10.0\n")).unwrap();
    let out = dir.join("fit");
    run_quiet("fit", &dir.join("fit.toml"), &out);
    let report: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("report.json")).unwrap()).unwrap();
    let count = report["records"][0]["unreliable_target"]["count"]
        .as_u64()
        .unwrap_or_else(|| panic!("no samples left out: {}", report["records"][0]));
    let svg = force_balance_svg(&out);
    eprintln!("{count} samples left out, {} marked", marks(&svg));
    assert!(count > 0);
    assert_eq!(marks(&svg) as u64, count);
    assert!(svg.contains("left out: unreliable target"));
    let _ = std::fs::remove_dir_all(&dir);
}
