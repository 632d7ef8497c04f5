//! Response fits over every response channel a record holds, against the exact piecewise
//! Coulomb solution (engine/src/exact.rs) with seeded noise: the paper's FMM case seen by an
//! interferometer alone, and by a vibrometer + accelerometer pair.

use frictionid_engine::exact::coulomb_free_vibration;
use frictionid_engine::identify::{fit, FitOptions, FitResult, ParamOptions};
use frictionid_engine::record::{Channel, TimeBase};
use frictionid_engine::synthetic::{add_gaussian_noise, uniform_times};
use frictionid_engine::{Oscillator, Record};
use frictionid_models::Coulomb;

const MU: f64 = 0.24;
const RELEASES: [f64; 3] = [0.010, 0.014, 0.022];
/// Interferometer: 5e-7 m white noise, 1 nm quantisation.
const X_NOISE: f64 = 5e-7;
const X_QUANTUM: f64 = 1e-9;
/// Laser vibrometer.
const V_NOISE: f64 = 2e-4;
/// Piezoelectric accelerometer: 5e-3 m/s^2 broadband (about 0.5 mg).
const A_NOISE: f64 = 5e-3;

/// The FMM records (2 s at 1 kHz) with the `channels` asked for, each from the exact
/// solution with its own seeded noise.
fn fmm_records(channels: &[(Channel, f64)], seed: u64) -> Vec<Record> {
    let osc = Oscillator::fmm();
    let time = uniform_times(2.0, 1000.0);
    RELEASES
        .iter()
        .enumerate()
        .map(|(i, &x0)| {
            let exact = coulomb_free_vibration(&osc, MU * osc.normal_force, x0, &time).unwrap();
            let mut record = Record::from_time_base(
                format!("x{}mm", (x0 * 1e3).round()),
                TimeBase::new(time.clone()).unwrap(),
            );
            for (k, &(channel, sigma)) in channels.iter().enumerate() {
                let mut values = match channel {
                    Channel::Displacement => exact.x.clone(),
                    Channel::Acceleration => exact.a.clone(),
                    _ => exact.v.clone(),
                };
                add_gaussian_noise(&mut values, sigma, seed + 10 * i as u64 + k as u64);
                if channel == Channel::Displacement {
                    for x in &mut values {
                        *x = (*x / X_QUANTUM).round() * X_QUANTUM;
                    }
                }
                record = record.with_channel(channel, values);
            }
            record.x0 = x0;
            record
        })
        .collect()
}

fn coulomb_fit(records: &[Record]) -> FitResult {
    fit(
        &Oscillator::fmm(),
        &Coulomb { mu: 0.2 },
        records,
        &FitOptions::default(),
    )
    .unwrap()
}

fn mu_of(result: &FitResult) -> (f64, [f64; 2]) {
    let p = result.parameters.iter().find(|p| p.name == "mu").unwrap();
    (p.value, p.ci95.unwrap())
}

/// An interferometer alone (no velocity channel) identifies mu within 0.1 %; the report
/// names the displacement channel and the noise it estimated (close to the true 5e-7 m).
#[test]
fn an_interferometer_alone_identifies_mu_within_a_tenth_of_a_percent() {
    let records = fmm_records(&[(Channel::Displacement, X_NOISE)], 11);
    let result = coulomb_fit(&records);
    let (mu, [lo, hi]) = mu_of(&result);
    assert!(((mu - MU) / MU).abs() < 1e-3, "mu = {mu}");
    assert!(lo < MU && MU < hi, "ci95 [{lo}, {hi}]");
    assert!(result.converged, "{}", result.termination);
    // White noise plus the quantisation's uniform error.
    let noise = (X_NOISE * X_NOISE + X_QUANTUM * X_QUANTUM / 12.0).sqrt();
    assert!(
        (result.rms_residual / noise - 1.0).abs() < 0.05,
        "rms {}",
        result.rms_residual
    );
    assert_eq!(
        (result.compared.as_str(), result.residual_unit.as_str()),
        ("displacement", "m")
    );
    for r in &result.records {
        let channel = &r.channels[0];
        assert_eq!(channel.channel, "displacement");
        let noise = channel.noise.unwrap();
        assert!((noise / X_NOISE - 1.0).abs() < 0.1, "noise {noise}");
        // The fit leaves the noise: the RMS residual is the noise level.
        assert!(
            (channel.rms_residual / X_NOISE - 1.0).abs() < 0.1,
            "{channel:?}"
        );
    }
}

/// A vibrometer + accelerometer pair: the joint fit's mu interval is narrower than the
/// velocity-only fit's on the same velocity samples, and both contain the truth.
#[test]
fn an_accelerometer_beside_the_vibrometer_narrows_the_mu_interval() {
    let pair = fmm_records(
        &[
            (Channel::Velocity, V_NOISE),
            (Channel::Acceleration, A_NOISE),
        ],
        21,
    );
    let velocity_only: Vec<Record> = pair
        .iter()
        .map(|r| {
            let mut only = Record::new(
                r.name.clone(),
                r.time().to_vec(),
                r.velocity().to_vec(),
                r.x0,
            );
            only.weight = r.weight;
            only
        })
        .collect();
    let (mu_v, ci_v) = mu_of(&coulomb_fit(&velocity_only));
    let joint = coulomb_fit(&pair);
    let (mu_j, ci_j) = mu_of(&joint);
    assert!(
        ci_v[0] <= MU && MU <= ci_v[1],
        "velocity only: {mu_v} {ci_v:?}"
    );
    assert!(ci_j[0] <= MU && MU <= ci_j[1], "joint: {mu_j} {ci_j:?}");
    let (width_v, width_j) = (ci_v[1] - ci_v[0], ci_j[1] - ci_j[0]);
    assert!(
        width_j < width_v,
        "joint {width_j} vs velocity only {width_v}"
    );
    let channels: Vec<&str> = joint.records[0]
        .channels
        .iter()
        .map(|c| c.channel.as_str())
        .collect();
    assert_eq!(channels, ["velocity", "acceleration"]);
    let a_noise = joint.records[0].channels[1].noise.unwrap();
    assert!((a_noise / A_NOISE - 1.0).abs() < 0.1, "{a_noise}");
    eprintln!("mu 95 % width: velocity only {width_v:.3e}, joint {width_j:.3e}");
}

/// Eq. 7 from measured x, v and a (exact closed form) equals mu N sign(v) to round-off away
/// from v = 0, far better than with the acceleration differentiated from the velocity and
/// the displacement integrated; the analysis says which series were measured.
#[test]
fn eq7_with_measured_displacement_and_acceleration_is_mu_n() {
    use frictionid_engine::energy::{analyze_record, EnergyOptions, SeriesSource};
    let osc = Oscillator::fmm();
    let time = uniform_times(2.0, 1000.0);
    let exact = coulomb_free_vibration(&osc, MU * osc.normal_force, 0.014, &time).unwrap();
    let velocity_only = Record::new("v", time.clone(), exact.v.clone(), 0.014);
    let all = velocity_only
        .clone()
        .with_channel(Channel::Displacement, exact.x.clone())
        .with_channel(Channel::Acceleration, exact.a.clone());
    let mu_n = MU * osc.normal_force;
    let worst = |record: &Record| {
        let a = analyze_record(record, &osc, &EnergyOptions::default()).unwrap();
        a.friction
            .iter()
            .zip(&a.v)
            .filter(|(f, _)| f.is_finite())
            .map(|(f, v)| (f - mu_n * v.signum()).abs() / mu_n)
            .fold(0.0f64, f64::max)
    };
    let (measured, derived) = (worst(&all), worst(&velocity_only));
    assert!(measured < 1e-9, "measured channels: {measured}");
    assert!(
        measured < 1e-3 * derived,
        "measured {measured} vs derived {derived}"
    );
    let sources = |record: &Record| {
        let s = analyze_record(record, &osc, &EnergyOptions::default())
            .unwrap()
            .sources;
        [s.displacement, s.velocity, s.acceleration]
    };
    assert_eq!(sources(&all), [SeriesSource::Measured; 3]);
    assert_eq!(
        sources(&velocity_only),
        [
            SeriesSource::Integrated,
            SeriesSource::Measured,
            SeriesSource::Differentiated
        ]
    );
}

/// A velocity offset is a velocity-sensor nuisance: asked of displacement records it is an
/// error naming the option.
#[test]
fn a_velocity_offset_on_displacement_records_is_named() {
    let opts = FitOptions {
        params: ParamOptions {
            velocity_offset: true,
            ..ParamOptions::default()
        },
        ..FitOptions::default()
    };
    let records = fmm_records(&[(Channel::Displacement, X_NOISE)], 3);
    let e = fit(&Oscillator::fmm(), &Coulomb::default(), &records, &opts).expect_err("refused");
    assert!(
        e.to_string()
            .contains("velocity_offset = true needs a velocity channel"),
        "{e}"
    );
}
