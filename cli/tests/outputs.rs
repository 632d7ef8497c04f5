//! Where the commands write: per config and command by default, `--out` when given, and
//! distinct plot files when record file names collide.

use frictionid_cli::testing::{fixtures_dir, read_report, run_ok, scratch_dir, FMM_OSCILLATOR};
use std::path::Path;
use std::process::Command;

fn frictionid() -> Command {
    Command::new(env!("CARGO_BIN_EXE_frictionid"))
}

fn run_in(dir: &Path, args: &[&str]) {
    run_ok(frictionid().current_dir(dir).args(args).arg("--quiet"));
}

fn files_in(dir: &Path) -> Vec<String> {
    let mut names: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    names
}

#[test]
fn default_output_directories_of_the_commands_are_disjoint() {
    let dir = scratch_dir("out", "layout");
    let cfg = format!(
        "{FMM_OSCILLATOR}[model]\ntype = \"coulomb\"\nmu = 0.2\n[simulation]\nx0 = 0.014\nduration = 1.0\n\
         [[records]]\nfile = \"{}\"\nx0 = 0.014\n",
        fixtures_dir().join("x14mm.csv").display()
    );
    std::fs::write(dir.join("rig.toml"), cfg).unwrap();
    for cmd in ["simulate", "fit", "energy"] {
        run_in(&dir, &[cmd, "rig.toml"]);
    }
    let base = dir.join("frictionid-out").join("rig");
    assert_eq!(files_in(&base), ["energy", "fit", "simulate"]);
    let sim = files_in(&base.join("simulate"));
    let fit = files_in(&base.join("fit"));
    let energy = files_in(&base.join("energy"));
    for (name, files) in [("simulate", &sim), ("fit", &fit), ("energy", &energy)] {
        assert!(
            files.contains(&"report.json".to_string()),
            "{name}: {files:?}"
        );
    }
    assert!(sim.contains(&"trajectory.csv".to_string()));
    assert!(!fit.contains(&"trajectory.csv".to_string()), "{fit:?}");
    assert!(
        fit.contains(&"x14mm_friction_force.svg".to_string()),
        "{fit:?}"
    );
    assert!(
        energy.contains(&"x14mm_friction_force.svg".to_string()),
        "{energy:?}"
    );
    // --out still wins.
    run_in(&dir, &["energy", "rig.toml", "--out", "mine"]);
    assert!(dir.join("mine").join("report.json").is_file());
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn records_with_the_same_file_name_get_distinct_plots() {
    let dir = scratch_dir("out", "same-name");
    for sub in ["a", "b"] {
        std::fs::create_dir_all(dir.join(sub)).unwrap();
        std::fs::copy(
            fixtures_dir().join("x14mm.csv"),
            dir.join(sub).join("data.csv"),
        )
        .unwrap();
    }
    let cfg = format!(
        "{FMM_OSCILLATOR}[[records]]\nfile = \"a/data.csv\"\nx0 = 0.014\n[[records]]\nfile = \"b/data.csv\"\nx0 = 0.014\n\
         [energy]\nreference_force = 3.48\n"
    );
    std::fs::write(dir.join("two.toml"), cfg).unwrap();
    run_in(&dir, &["energy", "two.toml", "--out", "out"]);
    let out = dir.join("out");
    for stem in ["a_data", "b_data"] {
        assert!(
            out.join(format!("{stem}_friction_force.svg")).is_file(),
            "{stem}"
        );
    }
    let r: serde_json::Value = read_report(&out);
    let files: Vec<&str> = r["files"]
        .as_array()
        .unwrap()
        .iter()
        .map(|f| f.as_str().unwrap())
        .collect();
    let mut unique = files.clone();
    unique.sort();
    unique.dedup();
    assert_eq!(unique.len(), files.len(), "{files:?}");
    let _ = std::fs::remove_dir_all(&dir);
}
