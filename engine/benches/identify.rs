//! Identifier benchmarks: the Coulomb mu fit on the three FMM records, and the five-model
//! comparison.

use criterion::{criterion_group, criterion_main, Criterion};
use frictionid_engine::identify::{compare, fit, FitOptions};
use frictionid_engine::synthetic::release_records;
use frictionid_engine::{Oscillator, Record};
use frictionid_models::{default_model, Coulomb, FrictionModel};
use std::hint::black_box;

fn records(osc: &Oscillator, model: &dyn FrictionModel) -> Vec<Record> {
    release_records(osc, model, &[0.010, 0.014, 0.022], 2.0, 1000.0, 2e-4, 100)
        .expect("truth simulation")
}

fn bench(c: &mut Criterion) {
    let osc = Oscillator::fmm();
    let recs = records(&osc, &Coulomb { mu: 0.24 });
    c.bench_function("fit coulomb mu, 3 FMM records", |b| {
        b.iter(|| {
            fit(
                &osc,
                black_box(&Coulomb::default()),
                &recs,
                &FitOptions::default(),
            )
            .expect("fit")
        })
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
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
