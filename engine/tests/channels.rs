//! Response fits in other sensor channels (issue 15), against the exact piecewise Coulomb
//! solution of the FMM case.

use frictionid_engine::exact::coulomb_free_vibration;
use frictionid_engine::identify::{fit, FitOptions};
use frictionid_engine::record::{Channel, TimeBase};
use frictionid_engine::synthetic::{add_gaussian_noise, uniform_times};
use frictionid_engine::{Oscillator, Record};
use frictionid_models::Coulomb;

const MU: f64 = 0.24;
/// Interferometer noise [m] and resolution [m].
const X_NOISE: f64 = 5e-7;
const X_STEP: f64 = 1e-9;

/// The FMM releases of 10, 14 and 22 mm (2 s at 1 kHz) seen by an interferometer only: the
/// exact displacement with Gaussian noise, quantised to the resolution.
fn interferometer_records(seed: u64) -> Vec<Record> {
    let osc = Oscillator::fmm();
    let times = uniform_times(2.0, 1000.0);
    [0.010, 0.014, 0.022]
        .into_iter()
        .enumerate()
        .map(|(i, x0)| {
            let ex = coulomb_free_vibration(&osc, MU * osc.normal_force, x0, &times)
                .expect("exact solution");
            let mut x = ex.x;
            add_gaussian_noise(&mut x, X_NOISE, seed + i as u64);
            for xi in &mut x {
                *xi = (*xi / X_STEP).round() * X_STEP;
            }
            let time = TimeBase::new(ex.time).expect("time base");
            let mut record = Record::from_time_base(format!("x{:.0}mm", x0 * 1e3), time)
                .with_channel(Channel::Displacement, x);
            record.x0 = x0;
            record
        })
        .collect()
}

/// Issue 15's acceptance: the FMM Coulomb case seen by an interferometer only gives mu within
/// 0.1 %; the fit compares displacement (in m) and its residuals are the sensor's noise.
#[test]
fn an_interferometer_alone_identifies_coulomb_friction() {
    let records = interferometer_records(71);
    let r = fit(
        &Oscillator::fmm(),
        &Coulomb::default(),
        &records,
        &FitOptions::default(),
    )
    .expect("fit");
    let mu = r.value("mu").expect("mu");
    eprintln!(
        "interferometer only: mu = {mu:.7}, rms {:.3e} m",
        r.rms_residual
    );
    assert!((mu / MU - 1.0).abs() < 1e-3, "mu = {mu}");
    assert!(r.converged, "{}", r.termination);
    let noise = (X_NOISE * X_NOISE + X_STEP * X_STEP / 12.0).sqrt();
    assert!(
        (r.rms_residual / noise - 1.0).abs() < 0.05,
        "rms {}",
        r.rms_residual
    );
    let [lo, hi] = r.param("mu").expect("mu").ci95.expect("interval");
    assert!(lo < MU && MU < hi, "ci95 [{lo}, {hi}]");
}

/// A velocity offset is a velocity-sensor nuisance: asked of displacement records it is an
/// error naming the option.
#[test]
fn a_velocity_offset_on_displacement_records_is_named() {
    let opts = FitOptions {
        velocity_offset: true,
        ..FitOptions::default()
    };
    let e = fit(
        &Oscillator::fmm(),
        &Coulomb::default(),
        &interferometer_records(3),
        &opts,
    )
    .expect_err("refused");
    assert!(e.to_string().contains("velocity_offset"), "{e}");
}
