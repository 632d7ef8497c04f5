//! The engine behind the model harness: [`EngineSimulator`] connects
//! `frictionid_models::testing::motion` (energy never increases, mirror symmetry, integrators
//! agree) to this crate's simulator, so a model crate checks its laws in motion with one line
//! (see docs/writing-a-model.md).
//!
//! And the records the integration tests share: Dahl's force along a stroke in closed form,
//! runs at constant velocity, and the real tribometer record where the developers keep it.

use crate::axis::{NoRestoring, Restoring};
use crate::oscillator::Oscillator;
use crate::record::{Channel, Record, TimeBase};
use crate::simulate::{simulate, Initial, Integrator, SimOptions};
use crate::synthetic::{add_gaussian_noise, uniform_times};
use frictionid_models::testing::motion::{Integration, Motion, Release, Simulator};
use frictionid_models::testing::Model;
use std::path::{Path, PathBuf};

/// Releases of an oscillator simulated by the engine, sampled at 1 kHz.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EngineSimulator(pub Oscillator);

impl EngineSimulator {
    /// The options of one release: the default adaptive method, or the paper's Euler.
    fn options(integration: Integration) -> SimOptions {
        let integrator = match integration {
            Integration::Adaptive => SimOptions::default().integrator,
            Integration::Euler { steps_per_period } => Integrator::Euler { steps_per_period },
        };
        SimOptions {
            integrator,
            ..SimOptions::default()
        }
    }
}

impl Simulator for EngineSimulator {
    fn stiffness(&self) -> f64 {
        self.0.stiffness
    }

    fn normal_force(&self) -> f64 {
        self.0.normal_force
    }

    fn release(&self, model: &Model, release: Release) -> Result<Motion, String> {
        let Release {
            x0,
            t_end,
            integration,
        } = release;
        let times = uniform_times(t_end, 1000.0);
        let opts = Self::options(integration);
        let sim = simulate(&self.0, model, &Initial::at_rest(x0), t_end, &times, &opts)
            .map_err(|e| e.to_string())?;
        Ok(Motion {
            total_energy: sim.total_energy(),
            rest_displacement: sim.rest.map(|r| r.displacement),
            events: sim.events.len(),
            time: sim.time,
            x: sim.x,
            v: sim.v,
            friction: sim.friction,
        })
    }
}

/// Dahl's force (alpha 1) after a travel `dx` from the force `f`, at rest stiffness `sigma0`
/// \[N/m\] and level `level` \[N\]: F = s level + (f - s level) exp(-sigma0 |dx| / level) in
/// the direction s of the travel (no travel, no change).
pub fn dahl_step(f: f64, dx: f64, sigma0: f64, level: f64) -> f64 {
    if dx == 0.0 {
        return f;
    }
    let s = dx.signum();
    s * level + (f - s * level) * (-sigma0 * dx.abs() / level).exp()
}

/// Dahl's force (alpha 1) in closed form along the sampled path `x` \[m\], linear between
/// samples, from F = 0 at the first sample.
pub fn dahl_force_along(x: &[f64], sigma0: f64, level: f64) -> Vec<f64> {
    let mut f = 0.0;
    let mut previous = x.first().copied().unwrap_or(0.0);
    x.iter()
        .map(|&xi| {
            f = dahl_step(f, xi - previous, sigma0, level);
            previous = xi;
            f
        })
        .collect()
}

/// A friction damper's sinusoidal stroke sampled at 1 kHz, with Dahl's force (alpha 1) along
/// the sampled path plus Gaussian noise: a force-domain record whose truth is known.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DamperStroke {
    /// Stroke amplitude \[m\].
    pub amplitude: f64,
    /// Stroke frequency \[Hz\].
    pub frequency: f64,
    /// Dahl's rest stiffness \[N/m\].
    pub sigma0: f64,
    /// Dahl's level \[N\].
    pub level: f64,
    /// Standard deviation of the force noise \[N\].
    pub noise: f64,
    /// The noise's seed.
    pub seed: u64,
}

impl DamperStroke {
    /// A short stroke: 3 mm at 2 Hz, Dahl at sigma0 4e5 N/m and 50 N, 0.2 N of noise (seed 17).
    pub fn short() -> Self {
        Self {
            amplitude: 0.003,
            frequency: 2.0,
            sigma0: 4e5,
            level: 50.0,
            noise: 0.2,
            seed: 17,
        }
    }

    /// `samples` samples from t = 0 of x = amplitude sin(2 pi frequency t), as a record
    /// `stroke` with a displacement and a force channel.
    ///
    /// # Panics
    /// Never for a finite stroke (its time base is uniform).
    pub fn record(&self, samples: usize) -> Record {
        let time: Vec<f64> = (0..samples).map(|i| i as f64 * 1e-3).collect();
        let x: Vec<f64> = time
            .iter()
            .map(|&t| self.amplitude * (std::f64::consts::TAU * self.frequency * t).sin())
            .collect();
        let mut force = dahl_force_along(&x, self.sigma0, self.level);
        add_gaussian_noise(&mut force, self.noise, self.seed);
        let base = TimeBase::new(time).expect("a uniform time base");
        Record::from_time_base("stroke", base)
            .with_channel(Channel::Displacement, x)
            .with_channel(Channel::Force, force)
    }
}

/// A slide of mass `mass` with no spring, unit stiffness and normal force (friction levels in
/// N) and an input offset of `offset` N: the driven axis of the inverse-dynamics tests.
pub fn driven_slide(mass: f64, offset: f64) -> Oscillator {
    Oscillator {
        mass,
        damping: 0.0,
        stiffness: 1.0,
        normal_force: 1.0,
        restoring: Restoring::None(NoRestoring),
        input_offset: offset,
        ..Oscillator::fmm()
    }
}

/// A run at the constant velocity `v` over `time`: displacement v t, velocity v and the force
/// `force(t)` plus Gaussian noise of `noise` (seed `seed`); the record is named `run{seed}`.
///
/// # Panics
/// When `time` is not a valid time base (empty, not increasing).
pub fn constant_velocity_run(
    time: Vec<f64>,
    v: f64,
    (noise, seed): (f64, u64),
    force: impl Fn(f64) -> f64,
) -> Record {
    let n = time.len();
    let x: Vec<f64> = time.iter().map(|t| v * t).collect();
    let mut f: Vec<f64> = time.iter().map(|&t| force(t)).collect();
    add_gaussian_noise(&mut f, noise, seed);
    let base = TimeBase::new(time).expect("a valid time base");
    Record::from_time_base(format!("run{seed}"), base)
        .with_channel(Channel::Displacement, x)
        .with_channel(Channel::Velocity, vec![v; n])
        .with_channel(Channel::Force, f)
}

/// Where every developer and CI keep the real reciprocating tribometer record published with
/// FrictionModels.jl (MIT, `examples/test_data_2.txt` there): `shared/data/tribometer/`
/// beside the repository.
pub fn real_tribometer_record() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../shared/data/tribometer/test_data_2.txt")
}

/// The evenly sampled six seconds of the real tribometer record (its header, then data rows
/// 1401 to 2600: t = 7.894 ... 13.889 s, 1200 samples at 200 Hz) written as
/// `real-tribometer.txt` in `dir`; or, where the record is absent (a user's clone), the line
/// a test prints as it skips: `skipped: ... not found`.
///
/// # Panics
/// When the record is shorter than that, or the slice cannot be written.
pub fn real_tribometer_slice(dir: &Path) -> Result<PathBuf, String> {
    let record = real_tribometer_record();
    let Ok(text) = std::fs::read_to_string(&record) else {
        return Err(format!(
            "skipped: the real tribometer record {} not found",
            record.display()
        ));
    };
    let lines: Vec<&str> = text.lines().collect();
    let (Some(header), Some(rows)) = (lines.first(), lines.get(1401..=2600)) else {
        panic!("{}: fewer than 2600 data rows", record.display());
    };
    let slice = std::iter::once(header).chain(rows);
    let mut out = String::new();
    for line in slice {
        out.push_str(line);
        out.push('\n');
    }
    let path = dir.join("real-tribometer.txt");
    if let Err(e) = std::fs::write(&path, out) {
        panic!("cannot write {}: {e}", path.display());
    }
    Ok(path)
}
