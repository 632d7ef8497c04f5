//! Calibration of the identifier's uncertainty, including the uncertainty budget: over many
//! realisations of the Coulomb FMM case, how often does the total 95 % interval of mu contain
//! the truth, and how does the spread of the estimates compare with the reported standard
//! errors?
//!
//! First with the properties known exactly (only the noise varies), then with the budget:
//! each realisation draws the rig's true mass, stiffness and normal force from their stated
//! uncertainties (the paper's 0.0049 kg and 1.3 N/m; 1 % of N), simulates the three releases
//! with those drawn values and fresh velocity noise, and fits mu with the *nominal* values and
//! the standard deviations stated (`FitOptions::uncertainty`), as a user of the rig would.
//!
//! Then under coloured noise: the nominal rig's three releases from the exact piecewise
//! Coulomb solution (`exact::coulomb_free_vibration`, independent of the fitted simulation)
//! with stationary AR(1) velocity noise of lag-1 correlation 0.6 and 0.9, where the standard
//! errors come from the Newey-West estimate after AR(1) prewhitening.
//!
//! Run: `cargo run --release -p frictionid-engine --example calibration [-- REALISATIONS]`

use frictionid_engine::exact::coulomb_free_vibration;
use frictionid_engine::identify::{fit, FitOptions, PropertyUncertainty};
use frictionid_engine::simulate::{simulate, Initial, SimOptions};
use frictionid_engine::synthetic::{add_coloured_noise, add_gaussian_noise, uniform_times};
use frictionid_engine::{Oscillator, Record};
use frictionid_models::Coulomb;
use rand::rngs::StdRng;
use rand::SeedableRng;
use rand_distr::{Distribution, Normal};

/// The true friction coefficient.
const MU: f64 = 0.24;
/// Velocity noise [m/s].
const NOISE: f64 = 2e-4;
/// The releases [m].
const RELEASES: [f64; 3] = [0.010, 0.014, 0.022];

/// The stated standard deviations: the paper's mass and stiffness, 1 % of the normal force.
fn stated(nominal: &Oscillator) -> PropertyUncertainty {
    PropertyUncertainty {
        mass: 0.0049,
        damping: 0.0,
        stiffness: 1.3,
        normal_force: 0.01 * nominal.normal_force,
    }
}

/// The rig as it really is in one realisation: each property drawn around its nominal value.
fn draw_rig(
    nominal: &Oscillator,
    sigma: &PropertyUncertainty,
    rng: &mut StdRng,
) -> Result<Oscillator, Box<dyn std::error::Error>> {
    let mut draw = |value: f64, sd: f64| -> Result<f64, rand_distr::NormalError> {
        Ok(Normal::new(value, sd)?.sample(rng))
    };
    Ok(Oscillator {
        mass: draw(nominal.mass, sigma.mass)?,
        damping: draw(nominal.damping, sigma.damping)?,
        stiffness: draw(nominal.stiffness, sigma.stiffness)?,
        normal_force: draw(nominal.normal_force, sigma.normal_force)?,
        ..*nominal
    })
}

/// The velocity noise of a calibration run.
#[derive(Debug, Clone, Copy, PartialEq)]
enum NoiseModel {
    /// White Gaussian, on the engine's simulation of the drawn rig.
    White,
    /// Stationary AR(1) of this lag-1 correlation, on the exact Coulomb solution.
    Coloured(f64),
}

/// The three noisy records of `rig` (realisation `k`) with `noise`.
fn records(
    rig: &Oscillator,
    times: &[f64],
    k: usize,
    noise: NoiseModel,
) -> Result<Vec<Record>, Box<dyn std::error::Error>> {
    match noise {
        NoiseModel::White => simulated_records(rig, times, k),
        NoiseModel::Coloured(phi) => exact_records(rig, times, k, phi),
    }
}

/// The exact Coulomb motions of `rig` with AR(1) noise of lag-1 correlation `phi`.
fn exact_records(
    rig: &Oscillator,
    times: &[f64],
    k: usize,
    phi: f64,
) -> Result<Vec<Record>, Box<dyn std::error::Error>> {
    RELEASES
        .iter()
        .enumerate()
        .map(|(i, &x0)| {
            let exact = coulomb_free_vibration(rig, MU * rig.normal_force, x0, times)?;
            let mut v = exact.v;
            add_coloured_noise(&mut v, NOISE, phi, 20_000 + 3 * k as u64 + i as u64);
            Ok(Record::new(format!("r{i}"), times.to_vec(), v, x0))
        })
        .collect()
}

/// The three records of `rig` simulated by the engine with white noise (realisation `k`).
fn simulated_records(
    rig: &Oscillator,
    times: &[f64],
    k: usize,
) -> Result<Vec<Record>, Box<dyn std::error::Error>> {
    RELEASES
        .iter()
        .enumerate()
        .map(|(i, &x0)| {
            let t_end = times.last().copied().unwrap_or(0.0);
            let traj = simulate(
                rig,
                &Coulomb { mu: MU },
                &Initial::at_rest(x0),
                t_end,
                times,
                &SimOptions::default(),
            )?;
            let mut v = traj.v;
            add_gaussian_noise(&mut v, NOISE, 10_000 + 3 * k as u64 + i as u64);
            Ok(Record::new(format!("r{i}"), times.to_vec(), v, x0))
        })
        .collect()
}

/// Mean and sample standard deviation.
fn mean_sd(x: &[f64]) -> (f64, f64) {
    let n = x.len() as f64;
    let mean = x.iter().sum::<f64>() / n;
    let sd = (x.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / (n - 1.0)).sqrt();
    (mean, sd)
}

/// What one calibration run found.
struct Calibration {
    coverage: f64,
    mean: f64,
    spread: f64,
    mean_std_error: f64,
}

/// `n` realisations with the rig's properties drawn with standard deviations `sigma` (all 0:
/// the nominal rig, only the noise varies) and velocity noise `noise`, each fitted with the
/// nominal values and `sigma` stated.
fn calibrate(
    n: usize,
    sigma: PropertyUncertainty,
    noise: NoiseModel,
) -> Result<Calibration, Box<dyn std::error::Error>> {
    let nominal = Oscillator::fmm();
    let opts = FitOptions {
        uncertainty: sigma,
        ..FitOptions::default()
    };
    let times = uniform_times(2.0, 1000.0);
    let mut rng = StdRng::seed_from_u64(2024);
    let (mut covered, mut estimates, mut errors) = (0usize, Vec::new(), Vec::new());
    for k in 0..n {
        let rig = draw_rig(&nominal, &sigma, &mut rng)?;
        let r = fit(
            &nominal,
            &Coulomb::default(),
            &records(&rig, &times, k, noise)?,
            &opts,
        )?;
        let p = r.param("mu").ok_or("no mu")?;
        let [lo, hi] = p.ci95.ok_or("no interval")?;
        if (lo..=hi).contains(&MU) {
            covered += 1;
        }
        estimates.push(p.value);
        errors.push(p.std_error.ok_or("no standard error")?);
    }
    let (mean, spread) = mean_sd(&estimates);
    Ok(Calibration {
        coverage: 100.0 * covered as f64 / n as f64,
        mean,
        spread,
        mean_std_error: errors.iter().sum::<f64>() / n as f64,
    })
}

fn print(title: &str, c: &Calibration) {
    println!("{title}");
    println!("  total 95 % interval coverage:   {:.1} %", c.coverage);
    println!(
        "  mean estimate of mu:            {:.6} (truth {MU})",
        c.mean
    );
    println!("  spread (sd) of estimates:       {:.3e}", c.spread);
    println!("  mean reported total std error:  {:.3e}", c.mean_std_error);
    println!(
        "  spread / mean std error:        {:.3}",
        c.spread / c.mean_std_error
    );
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let n: usize = match std::env::args().nth(1) {
        Some(s) => s.parse()?,
        None => 200,
    };
    let sigma = stated(&Oscillator::fmm());
    println!("realisations: {n}, velocity noise {NOISE} m/s");
    print(
        "properties known exactly (noise only):",
        &calibrate(n, PropertyUncertainty::default(), NoiseModel::White)?,
    );
    print(
        &format!(
            "m, k, N drawn per realisation (std {} kg, {} N/m, {} N) and stated:",
            sigma.mass, sigma.stiffness, sigma.normal_force
        ),
        &calibrate(n, sigma, NoiseModel::White)?,
    );
    for phi in [0.6, 0.9] {
        print(
            &format!("exact Coulomb motion, AR(1) velocity noise of lag-1 correlation {phi}:"),
            &calibrate(n, PropertyUncertainty::default(), NoiseModel::Coloured(phi))?,
        );
    }
    Ok(())
}
