//! The friction-damper benchmark (`engine/benches/data/damper.rs`): Coulomb and Dahl at
//! alpha = 1 fitted in the force domain, with a load-cell offset, to each of 30 damper strokes
//! of 28 672 samples, as `frictionid campaign target/bench-data/damper/campaign.toml` fits
//! them: each record read from its CSV file and the two models compared on it
//! (`identify::compare`), the records in parallel as the campaign's groups are.
//! `benches/scipy_damper.py` is SciPy's counterpart on the same files.

/// The allocator of the `frictionid` binary and the Python module.
#[path = "../../cli/src/allocator.rs"]
mod allocator;

#[path = "data/damper.rs"]
mod damper;

use criterion::{criterion_group, Criterion};
use frictionid_engine::data::{RecordSource, RecordUse};
use frictionid_engine::identify::{
    compare, Comparison, FitDomain, FitOptions, ParamOptions, TargetOptions,
};
use frictionid_engine::oscillator::PartialOscillator;
use frictionid_engine::{Oscillator, Record};
use frictionid_models::{Coulomb, Dahl, FrictionModel};
use rayon::prelude::*;
use std::hint::black_box;

/// The records of the sweep, read as the campaign reads them (no x0: replayed as measured).
fn damper_records() -> Vec<Record> {
    let dir = damper::damper_dir();
    damper::write_damper_data(&dir).expect("the damper records written");
    damper::damper_cases()
        .iter()
        .enumerate()
        .map(|(i, case)| {
            let entry = RecordSource {
                file: Some(case.file()),
                ..RecordSource::default()
            };
            let resolved = entry
                .resolve_for(i + 1, &dir, RecordUse::Replayed)
                .expect("a damper record's entry");
            resolved.load().expect("a damper record")
        })
        .collect()
}

/// The campaign's options: the force domain, a force offset per record, Dahl's alpha fixed
/// (not in `free`), no oscillator given (the levels are forces in N).
fn damper_options() -> (Oscillator, FitOptions) {
    let (osc, unknown) = PartialOscillator::default().resolve();
    let opts = FitOptions {
        target: TargetOptions {
            domain: FitDomain::Force,
            force_offset: true,
            unknown_oscillator: unknown,
            ..TargetOptions::default()
        },
        params: ParamOptions {
            free: Some(vec!["mu".into(), "sigma0".into(), "mu_c".into()]),
            ..ParamOptions::default()
        },
        ..FitOptions::default()
    };
    (osc, opts)
}

fn damper_fits(c: &mut Criterion) {
    let records = damper_records();
    let (osc, opts) = damper_options();
    let models: Vec<Box<dyn FrictionModel>> =
        vec![Box::new(Coulomb::default()), Box::new(Dahl::default())];
    let fit_one = |record: &Record| -> Comparison {
        compare(
            &osc,
            black_box(&models),
            std::slice::from_ref(record),
            &opts,
        )
        .expect("compare")
    };
    let mut group = c.benchmark_group("damper");
    group.sample_size(10);
    // The fastest stroke and the widest: 8 mm at 8 Hz.
    let widest = records.last().expect("30 records");
    group.bench_function("coulomb and dahl, one stroke of 28 672 samples", |b| {
        b.iter(|| fit_one(widest))
    });
    group.bench_function("coulomb and dahl, 30 strokes", |b| {
        b.iter(|| records.par_iter().map(fit_one).collect::<Vec<_>>())
    });
    group.finish();
}

criterion_group!(benches, damper_fits);
/// criterion's main with the binary's allocator settings first.
fn main() {
    allocator::keep_freed_memory();
    benches();
    Criterion::default().configure_from_args().final_summary();
}
