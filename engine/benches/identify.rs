//! Identifier benchmarks: the Coulomb mu fit on the three FMM records, the
//! five-model comparison, and LuGre fits from the default start (the default search, and one
//! local start as SciPy's `benches/scipy_lugre_velocity.py` runs it) and from the truth of
//! stiff (sigma0 = 1e7) records. Records: the acceptance set-up of the tests (releases of 10, 14
//! and 22 mm, 2 s at 1 kHz, 0.2 mm/s noise). And the inverse-dynamics fit of a driven axis
//! (25 000 samples; `benches/scipy_inverse_dynamics.py` is SciPy's counterpart), and five
//! models compared in the force domain along a driven axis's measured motion and friction
//! force (25 000 samples), and GMS fitted along 20 000 of those samples.

/// The allocator of the `frictionid` binary and the Python module.
#[path = "../../cli/src/allocator.rs"]
mod allocator;

#[path = "../tests/util.rs"]
mod common;

use common::{
    force_route_options, inverse_dynamics_options, lugre_truth, no_oscillator_force_options,
    records, stiff_lugre_truth, stribeck_truth, three_tone_drive, NOISE,
};
use criterion::{criterion_group, BatchSize, Criterion};
use frictionid_engine::data::RecordSource;
use frictionid_engine::identify::Search;
use frictionid_engine::identify::{compare, fit, FitOptions, ParamOptions, SearchOptions};
use frictionid_engine::record::{Channel, TimeBase};
use frictionid_engine::{Oscillator, Record};
use frictionid_models::{default_model, Coulomb, FrictionModel, LuGre, ViscousCoulomb};
use std::hint::black_box;
use std::path::Path;

fn coulomb_and_compare(c: &mut Criterion) {
    let osc = Oscillator::fmm();
    let recs = records(&osc, &Coulomb { mu: 0.24 }, NOISE, 100);
    let fit_mu = |records: &[Record]| {
        fit(
            &osc,
            black_box(&Coulomb::default()),
            records,
            &FitOptions::default(),
        )
        .expect("fit")
    };
    c.bench_function("fit coulomb mu, 3 FMM records", |b| {
        b.iter(|| fit_mu(&recs))
    });
    // The same fit of records never fitted before: their noise levels are estimated again
    // (a record keeps them once estimated; the setup, not timed, rebuilds the records).
    let fresh = || -> Vec<Record> {
        recs.iter()
            .map(|r| {
                Record::new(
                    r.name.clone(),
                    r.time().to_vec(),
                    r.velocity().to_vec(),
                    r.x0,
                )
            })
            .collect()
    };
    c.bench_function("fit coulomb mu, 3 fresh FMM records", |b| {
        b.iter_batched(fresh, |records| fit_mu(&records), BatchSize::SmallInput)
    });
    let models: Vec<Box<dyn FrictionModel>> =
        ["coulomb", "viscous_coulomb", "stribeck", "dahl", "lugre"]
            .iter()
            .filter_map(|n| default_model(n).ok())
            .collect();
    let mut group = c.benchmark_group("compare");
    group.sample_size(10);
    group.bench_function("five models, 3 FMM records", |b| {
        b.iter(|| {
            compare(&osc, black_box(&models), &recs, &FitOptions::default()).expect("compare")
        })
    });
    let every: Vec<Box<dyn FrictionModel>> = frictionid_models::registry::names()
        .iter()
        .filter_map(|n| default_model(n).ok())
        .collect();
    let fixture = fixture_records();
    group.bench_function("five models, the FMM fixture", |b| {
        b.iter(|| {
            compare(&osc, black_box(&models), &fixture, &FitOptions::default()).expect("compare")
        })
    });
    group.bench_function("every registered model, the FMM fixture", |b| {
        b.iter(|| {
            compare(&osc, black_box(&every), &fixture, &FitOptions::default()).expect("compare")
        })
    });
    group.finish();
}

/// The bundled FMM fixture's three records (`fixtures/x10mm.csv`, ...), as
/// `fixtures/fmm-compare.toml` reads them.
fn fixture_records() -> Vec<Record> {
    let base = Path::new(env!("CARGO_MANIFEST_DIR")).join("../fixtures");
    [
        ("x10mm.csv", 0.010),
        ("x14mm.csv", 0.014),
        ("x22mm.csv", 0.022),
    ]
    .into_iter()
    .map(|(file, x0)| {
        let entry = RecordSource {
            file: Some(file.into()),
            x0: Some(x0),
            ..RecordSource::default()
        };
        entry.load(&base).expect("the bundled fixture")
    })
    .collect()
}

fn lugre(c: &mut Criterion) {
    let osc = Oscillator::fmm();
    let mut group = c.benchmark_group("lugre");
    group.sample_size(10);
    let recs = records(&osc, &lugre_truth(), NOISE, 41);
    group.bench_function("default start, 3 records of 2 s", |b| {
        b.iter(|| {
            let model = LuGre::default();
            fit(&osc, black_box(&model), &recs, &FitOptions::default()).expect("fit")
        })
    });
    let one_local_start = FitOptions {
        search: SearchOptions {
            strategy: Some(Search::Local),
            multistart: Some(1),
            ..SearchOptions::default()
        },
        ..FitOptions::default()
    };
    group.bench_function("one local start from the default, 3 records of 2 s", |b| {
        b.iter(|| {
            let model = LuGre::default();
            fit(&osc, black_box(&model), &recs, &one_local_start).expect("fit")
        })
    });
    let stiff = stiff_lugre_truth();
    let stiff_recs = records(&osc, &stiff, NOISE, 81);
    let at_truth = FitOptions {
        params: ParamOptions {
            guess: false,
            ..ParamOptions::default()
        },
        ..one_local_start.clone()
    };
    group.bench_function("from the truth, sigma0 1e7, 3 records of 2 s", |b| {
        b.iter(|| fit(&osc, black_box(&stiff), &stiff_recs, &at_truth).expect("fit"))
    });
    group.finish();
}

/// The force route (`domain = "force"`, the energy-based force of Eq. 7) against the
/// velocity fit of the same law on the same noisy records.
fn force_route(c: &mut Criterion) {
    let osc = Oscillator::fmm();
    let force = force_route_options();
    let velocity = FitOptions::default();
    let coulomb = Coulomb { mu: 0.24 };
    let stribeck = stribeck_truth();
    let laws: [(&str, &dyn FrictionModel); 2] = [("coulomb", &coulomb), ("stribeck", &stribeck)];
    let mut group = c.benchmark_group("force route");
    group.sample_size(20);
    for (name, truth) in laws {
        let recs = records(&osc, truth, NOISE, 100);
        let start = default_model(name).expect("a registered law");
        for (domain, opts) in [("force", &force), ("velocity", &velocity)] {
            group.bench_function(format!("{name}, {domain} domain, 3 FMM records"), |b| {
                b.iter(|| fit(&osc, black_box(start.as_ref()), &recs, opts).expect("fit"))
            });
        }
    }
    group.finish();
}

/// The driven axis of `benches/scipy_inverse_dynamics.py`, the same record: 25 000 samples at
/// 1 kHz of a prescribed three-tone velocity, the input u = M a + Fv v + Fc sgn(v) + offset
/// (M 8 kg, Fv 200 N s/m, Fc 20 N, offset 1.5 N) plus two high tones standing for noise.
fn driven_axis_record() -> Record {
    use std::f64::consts::TAU;
    const TONES: [(f64, f64, f64); 3] = [(0.2, 0.4, 0.0), (0.1, 1.1, 1.0), (0.05, 2.3, 2.0)];
    let time: Vec<f64> = (0..25_000).map(|i| i as f64 * 1e-3).collect();
    let tones = |t: f64, derivative: bool| -> f64 {
        TONES
            .iter()
            .map(|&(a, f, p)| match derivative {
                false => a * (TAU * f * t + p).sin(),
                true => a * TAU * f * (TAU * f * t + p).cos(),
            })
            .sum()
    };
    let v: Vec<f64> = time.iter().map(|&t| tones(t, false)).collect();
    let u: Vec<f64> = time
        .iter()
        .zip(&v)
        .map(|(&t, &v)| {
            let disturbance = 0.1 * (TAU * 123.4 * t + 0.7).sin() + 0.07 * (TAU * 211.1 * t).sin();
            8.0 * tones(t, true) + 200.0 * v + 20.0 * v.signum() + 1.5 + disturbance
        })
        .collect();
    Record::from_time_base("drive", TimeBase::new(time).expect("time"))
        .with_channel(Channel::Velocity, v)
        .with_channel(Channel::InputForce, u)
}

/// Inverse dynamics (`force_target = "inverse_dynamics"`): the mass, a viscous+Coulomb law
/// (its level a force: no normal force given) and an offset, on 25 000 samples.
fn inverse_dynamics(c: &mut Criterion) {
    let (osc, opts) = inverse_dynamics_options();
    let record = [driven_axis_record()];
    let mut group = c.benchmark_group("inverse dynamics");
    group.sample_size(20);
    group.bench_function("mass, viscous_coulomb and offset, 25 000 samples", |b| {
        b.iter(|| fit(&osc, black_box(&ViscousCoulomb::default()), &record, &opts).expect("fit"))
    });
    group.finish();
}

/// LuGre's friction force (in N: no normal force) along the velocity `v` sampled at 1 kHz,
/// linear between samples, by classical Runge-Kutta with 50 steps per sample from z = 0:
/// sigma0 1e5 N/m, sigma1 300 N s/m, sigma2 5 N s/m, F_c 20 N, F_s 30 N, v_s 0.01 m/s.
fn lugre_force_along(v: &[f64]) -> Vec<f64> {
    const SUBSTEPS: usize = 50;
    let (sigma0, sigma1, sigma2) = (1e5, 300.0, 5.0);
    let (fc, fs, vs) = (20.0, 30.0, 0.01);
    let rate = |z: f64, v: f64| {
        let g = fc + (fs - fc) * (-(v / vs).powi(2)).exp();
        v - sigma0 * v.abs() * z / g
    };
    let h = 1e-3 / SUBSTEPS as f64;
    let mut z = 0.0;
    let mut out = Vec::with_capacity(v.len());
    for (i, &vi) in v.iter().enumerate() {
        out.push(sigma0 * z + sigma1 * rate(z, vi) + sigma2 * vi);
        let Some(&next) = v.get(i + 1) else { break };
        let at = |s: f64| vi + (next - vi) * s / SUBSTEPS as f64;
        for k in 0..SUBSTEPS {
            let s = k as f64;
            let k1 = rate(z, at(s));
            let k2 = rate(z + 0.5 * h * k1, at(s + 0.5));
            let k3 = rate(z + 0.5 * h * k2, at(s + 0.5));
            let k4 = rate(z + h * k3, at(s + 1.0));
            z += h / 6.0 * (k1 + 2.0 * k2 + 2.0 * k3 + k4);
        }
    }
    out
}

/// A driven axis's record: 25 000 samples at 1 kHz of a three-tone velocity that reverses
/// (0.05, 0.03 and 0.01 m/s at 0.3, 1.1 and 2.9 Hz), measured with 0.1 mm/s noise, and its
/// LuGre friction force measured with 0.3 N noise.
fn drive_friction_record() -> Record {
    use frictionid_engine::synthetic::add_gaussian_noise;
    let (time, v) = three_tone_drive(25_000);
    let mut force = lugre_force_along(&v);
    add_gaussian_noise(&mut force, 0.3, 25);
    let mut measured_v = v;
    add_gaussian_noise(&mut measured_v, 1e-4, 26);
    Record::from_time_base("drive", TimeBase::new(time).expect("time"))
        .with_channel(Channel::Velocity, measured_v)
        .with_channel(Channel::Force, force)
}

/// coulomb, viscous_coulomb, stribeck, dahl and lugre compared in the force domain on the
/// driven axis's measured friction force (no oscillator given: the levels are forces in N).
fn drive_compare(c: &mut Criterion) {
    let (osc, opts) = no_oscillator_force_options();
    let models: Vec<Box<dyn FrictionModel>> =
        ["coulomb", "viscous_coulomb", "stribeck", "dahl", "lugre"]
            .iter()
            .filter_map(|n| default_model(n).ok())
            .collect();
    let record = [drive_friction_record()];
    let mut group = c.benchmark_group("compare");
    group.sample_size(10);
    group.bench_function(
        "five models, force domain, 25 000-sample drive record",
        |b| b.iter(|| compare(&osc, black_box(&models), &record, &opts).expect("compare")),
    );
    group.finish();
}

/// GMS (three elements, its sharpness free) fitted in the force domain to the first 20 000
/// samples of the driven axis's measured LuGre friction force: every element stepped exactly
/// at whatever sharpness the fit reaches, every Jacobian column from the replay's
/// sensitivities.
fn gms_force_fit(c: &mut Criterion) {
    let (osc, opts) = no_oscillator_force_options();
    let full = drive_friction_record();
    let keep = 20_000;
    let time = full.time()[..keep].to_vec();
    let mut record = Record::from_time_base("drive", TimeBase::new(time).expect("time"));
    for channel in [Channel::Velocity, Channel::Force] {
        let values = full.channel(channel).expect("a channel")[..keep].to_vec();
        record = record.with_channel(channel, values);
    }
    let model = default_model("gms").expect("gms");
    let record = [record];
    let mut group = c.benchmark_group("gms");
    group.sample_size(10);
    group.bench_function(
        "force-domain fit, 20 000 samples of the drive record",
        |b| b.iter(|| fit(&osc, black_box(model.as_ref()), &record, &opts).expect("fit")),
    );
    group.finish();
}

criterion_group!(
    benches,
    coulomb_and_compare,
    lugre,
    force_route,
    inverse_dynamics,
    drive_compare,
    gms_force_fit
);
/// criterion's main with the binary's allocator settings first.
fn main() {
    allocator::keep_freed_memory();
    benches();
    Criterion::default().configure_from_args().final_summary();
}
