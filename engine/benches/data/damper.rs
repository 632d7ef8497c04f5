//! The friction-damper benchmark's records: 30 sinusoidal strokes of a friction damper, as a
//! damper test rig sweeps them (five amplitudes by six frequencies), 28 672 samples at 1 kHz
//! each, with the friction force of Dahl's law at alpha = 1 along the displacement.
//!
//! The force is exact: at alpha = 1 Dahl's law along a path that moves one way is
//! dF/dx = sigma0 (1 - s F / F_c) with s the direction, so over a displacement dx in that
//! direction F goes to s F_c + (F - s F_c) exp(-sigma0 |dx| / F_c). The true displacement
//! A sin(2 pi f t) is followed through every reversal between samples, from F = 0 at t = 0.
//! Each record then gets a load-cell offset and Gaussian noise on the force, and encoder-like
//! noise on the displacement. The files are written once to `target/bench-data/damper/`
//! (CSV per record, the `runs.csv` manifest, `campaign.toml`, and the truth in `truth.csv`), where `frictionid campaign`,
//! the `damper` criterion bench and `benches/scipy_damper.py` all read them.

use frictionid_engine::synthetic::add_gaussian_noise;
use std::f64::consts::TAU;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

/// Samples per record (28 s at 1 kHz).
pub const SAMPLES: usize = 28_672;
/// Sample rate [Hz].
pub const RATE: f64 = 1000.0;
/// Stroke amplitudes [m].
pub const AMPLITUDES: [f64; 5] = [0.001, 0.002, 0.004, 0.006, 0.008];
/// Stroke frequencies [Hz].
pub const FREQUENCIES: [f64; 6] = [0.5, 1.0, 2.0, 3.0, 5.0, 8.0];
/// The contact's rest stiffness [N/m]: 0.15 mm of presliding at 75 N.
pub const SIGMA0: f64 = 5.0e5;
/// Force noise [N] (one standard deviation).
pub const FORCE_NOISE: f64 = 0.5;
/// Displacement noise [m] (one standard deviation).
pub const DISPLACEMENT_NOISE: f64 = 0.1e-6;
/// Written into `VERSION` beside the files: data of another version is written again.
const VERSION: &str = "damper-2";

/// One record's stroke and truth.
#[derive(Debug, Clone, Copy)]
pub struct DamperCase {
    /// Its place in the sweep (0..30), also its noise seed.
    pub index: usize,
    /// Stroke amplitude [m].
    pub amplitude: f64,
    /// Stroke frequency [Hz].
    pub frequency: f64,
    /// The Coulomb level F_c [N]: it rises with the peak speed, a trend for the campaign.
    pub level: f64,
    /// The load cell's offset [N].
    pub offset: f64,
}

impl DamperCase {
    /// The record's file name.
    pub fn file(&self) -> String {
        format!("damper-{:02}.csv", self.index)
    }

    /// The true displacement at time `t` [m].
    fn displacement(&self, t: f64) -> f64 {
        self.amplitude * (TAU * self.frequency * t).sin()
    }
}

/// The 30 strokes of the sweep.
pub fn damper_cases() -> Vec<DamperCase> {
    let mut cases = Vec::new();
    for &amplitude in &AMPLITUDES {
        for &frequency in &FREQUENCIES {
            let index = cases.len();
            let peak_speed = TAU * frequency * amplitude;
            cases.push(DamperCase {
                index,
                amplitude,
                frequency,
                level: 60.0 + 50.0 * peak_speed,
                // Offsets spread over [-4, 4] N, deterministic and unsorted.
                offset: 4.0 * ((index as f64 * 2.399_963).sin()),
            });
        }
    }
    cases
}

/// Dahl's force (alpha = 1) after moving `dx` from force `f`, at rest stiffness `sigma0` and
/// level `level`.
pub use frictionid_engine::testing::dahl_step;

/// The exact Dahl force at every sample time along the true stroke of `case`, from F = 0:
/// each interval is split at the reversals of the sine that fall inside it.
pub fn true_force(case: &DamperCase, time: &[f64]) -> Vec<f64> {
    let half_period = 0.5 / case.frequency;
    let mut f = 0.0;
    let mut out = Vec::with_capacity(time.len());
    let mut previous = time.first().copied().unwrap_or(0.0);
    for &t in time {
        // Reversals at t = (k + 1/2) half periods; k starts at the first one after `from`.
        let mut from = previous;
        let mut k = (from / half_period - 0.5).floor() + 1.0;
        loop {
            let reversal = (k + 0.5) * half_period;
            if reversal >= t {
                break;
            }
            f = dahl_step(
                f,
                case.displacement(reversal) - case.displacement(from),
                SIGMA0,
                case.level,
            );
            from = reversal;
            k += 1.0;
        }
        f = dahl_step(
            f,
            case.displacement(t) - case.displacement(from),
            SIGMA0,
            case.level,
        );
        out.push(f);
        previous = t;
    }
    out
}

/// The measured columns of `case`: time, displacement and force (offset and noise added).
pub fn damper_columns(case: &DamperCase) -> [Vec<f64>; 3] {
    let time: Vec<f64> = (0..SAMPLES).map(|i| i as f64 / RATE).collect();
    let mut x: Vec<f64> = time.iter().map(|&t| case.displacement(t)).collect();
    let mut force: Vec<f64> = true_force(case, &time)
        .into_iter()
        .map(|f| f + case.offset)
        .collect();
    add_gaussian_noise(&mut x, DISPLACEMENT_NOISE, 7_000 + case.index as u64);
    add_gaussian_noise(&mut force, FORCE_NOISE, 9_000 + case.index as u64);
    [time, x, force]
}

/// The campaign config: Coulomb and Dahl (alpha fixed at 1) fitted to each record in the
/// force domain with a load-cell offset, no normal force (the levels are forces in N).
const CAMPAIGN: &str = "\
# The friction-damper benchmark (engine/benches/data/damper.rs): Coulomb and Dahl with
# alpha = 1 fitted to each of 30 strokes in the force domain, with a load-cell offset.
[oscillator]

[fit]
free = [\"mu\", \"sigma0\", \"mu_c\"]

[fit.options]
domain = \"force\"
force_offset = true

[campaign]
manifest = \"runs.csv\"
models = [\"coulomb\", \"dahl\"]
";

/// Where the damper data lives: `target/bench-data/damper` of the workspace.
pub fn damper_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../target/bench-data/damper")
}

/// Writes the records, the manifest and the campaign config into `dir` unless this
/// version's data is already there; returns the campaign config's path.
pub fn write_damper_data(dir: &Path) -> std::io::Result<PathBuf> {
    let config = dir.join("campaign.toml");
    let stamp = dir.join("VERSION");
    if std::fs::read_to_string(&stamp).is_ok_and(|v| v.trim() == VERSION) && config.exists() {
        return Ok(config);
    }
    std::fs::create_dir_all(dir)?;
    let mut manifest = String::from("file,amplitude_mm,frequency_hz\n");
    let mut truth = String::from("file,sigma0,level,offset\n");
    for case in damper_cases() {
        let [time, x, force] = damper_columns(&case);
        let mut csv = String::with_capacity(SAMPLES * 48);
        csv.push_str("time,displacement,force\n");
        for ((t, x), f) in time.iter().zip(&x).zip(&force) {
            let _ = writeln!(csv, "{t:.3},{x:.9e},{f:.6e}");
        }
        std::fs::write(dir.join(case.file()), csv)?;
        let file = case.file();
        let _ = writeln!(
            manifest,
            "{file},{},{}",
            case.amplitude * 1e3,
            case.frequency
        );
        let _ = writeln!(truth, "{file},{SIGMA0},{},{}", case.level, case.offset);
    }
    std::fs::write(dir.join("runs.csv"), manifest)?;
    std::fs::write(dir.join("truth.csv"), truth)?;
    std::fs::write(&config, CAMPAIGN)?;
    std::fs::write(&stamp, VERSION)?;
    Ok(config)
}
