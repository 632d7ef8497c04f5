//! Calibration of the identifier's uncertainty: over many noise realisations of the Coulomb
//! FMM case, how often does the 95 % interval contain the truth, and how does the spread of
//! the estimates compare with the reported standard errors?
//!
//! Run: `cargo run --release -p frictionid-engine --example calibration [-- REALISATIONS]`

use frictionid_engine::identify::{fit, FitOptions};
use frictionid_engine::simulate::{simulate, Initial, SimOptions};
use frictionid_engine::synthetic::{add_gaussian_noise, uniform_times};
use frictionid_engine::{Oscillator, Record};
use frictionid_models::Coulomb;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let n: usize = match std::env::args().nth(1) {
        Some(s) => s.parse()?,
        None => 200,
    };
    let osc = Oscillator::fmm();
    let truth = Coulomb { mu: 0.24 };
    let times = uniform_times(2.0, 1000.0);
    let clean: Vec<(f64, Vec<f64>)> = [0.010, 0.014, 0.022]
        .iter()
        .map(|&x0| {
            simulate(
                &osc,
                &truth,
                &Initial::at_rest(x0),
                2.0,
                &times,
                &SimOptions::default(),
            )
            .map(|t| (x0, t.v))
        })
        .collect::<Result<_, _>>()?;
    let (mut covered, mut estimates, mut errors) = (0usize, Vec::new(), Vec::new());
    for k in 0..n {
        let records: Vec<Record> = clean
            .iter()
            .enumerate()
            .map(|(i, (x0, v))| {
                let mut v = v.clone();
                add_gaussian_noise(&mut v, 2e-4, 10_000 + 3 * k as u64 + i as u64);
                Record::new(format!("r{i}"), times.clone(), v, *x0)
            })
            .collect();
        let r = fit(&osc, &Coulomb::default(), &records, &FitOptions::default())?;
        let p = r.param("mu").ok_or("no mu")?;
        let [lo, hi] = p.ci95.ok_or("no interval")?;
        if lo <= truth.mu && truth.mu <= hi {
            covered += 1;
        }
        estimates.push(p.value);
        errors.push(p.std_error.ok_or("no standard error")?);
    }
    let mean = estimates.iter().sum::<f64>() / n as f64;
    let sd = (estimates.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / (n as f64 - 1.0)).sqrt();
    let mean_se = errors.iter().sum::<f64>() / n as f64;
    println!("realisations:               {n}");
    println!(
        "95 % interval coverage:      {:.1} %",
        100.0 * covered as f64 / n as f64
    );
    println!("mean estimate of mu:         {mean:.6} (truth 0.24)");
    println!("spread (sd) of estimates:    {sd:.3e}");
    println!("mean reported std error:     {mean_se:.3e}");
    println!("spread / mean std error:     {:.3}", sd / mean_se);
    Ok(())
}
