//! Identifier benchmarks: the Coulomb mu fit on the three FMM records, the
//! five-model comparison, and LuGre fits from the default start and from the truth of stiff
//! (sigma0 = 1e7) records. Records: the acceptance set-up of the tests (releases of 10, 14
//! and 22 mm, 2 s at 1 kHz, 0.2 mm/s noise).

/// mimalloc, as the `frictionid` binary and the Python module use (glibc's malloc returned
/// and refaulted the fits' buffers, a sixth of a Coulomb fit's time).
#[global_allocator]
static ALLOCATOR: mimalloc::MiMalloc = mimalloc::MiMalloc;

#[path = "../tests/common/mod.rs"]
mod common;

use common::{lugre_truth, records, stiff_lugre_truth, stribeck_truth, NOISE};
use criterion::{criterion_group, criterion_main, BatchSize, Criterion};
use frictionid_engine::data::RecordSource;
use frictionid_engine::identify::{compare, fit, FitDomain, FitOptions, Search};
use frictionid_engine::{Oscillator, Record};
use frictionid_models::{default_model, Coulomb, FrictionModel, LuGre};
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
    let stiff = stiff_lugre_truth();
    let stiff_recs = records(&osc, &stiff, NOISE, 81);
    let at_truth = FitOptions {
        guess: false,
        search: Some(Search::Local),
        multistart: Some(1),
        ..FitOptions::default()
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
    let force = FitOptions {
        domain: FitDomain::Force,
        ..FitOptions::default()
    };
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

criterion_group!(benches, coulomb_and_compare, lugre, force_route);
criterion_main!(benches);
