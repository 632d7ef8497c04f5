//! The full energy analysis (integration, Savitzky-Golay or paper differentiation, Eq. 7,
//! turning points and half-cycles) of a 2000-sample FMM record with vibrometer-like noise,
//! and the model force along it.

/// mimalloc, as the `frictionid` binary and the Python module use (glibc's malloc returned
/// and refaulted the fits' buffers, a sixth of a Coulomb fit's time).
#[global_allocator]
static ALLOCATOR: mimalloc::MiMalloc = mimalloc::MiMalloc;

use criterion::{criterion_group, criterion_main, Criterion};
use frictionid_engine::exact::coulomb_free_vibration;
use frictionid_engine::synthetic::{add_gaussian_noise, uniform_times};
use frictionid_engine::{
    analyze_record, model_force_along, Differentiator, EnergyOptions, Oscillator, Record,
};
use frictionid_models::LuGre;
use std::hint::black_box;

fn fmm_record() -> Option<Record> {
    let osc = Oscillator::fmm();
    let times = uniform_times(1.999, 1000.0);
    let ex = coulomb_free_vibration(&osc, 0.24 * osc.normal_force, 0.022, &times).ok()?;
    let mut v = ex.v;
    add_gaussian_noise(&mut v, 2e-4, 1);
    Some(Record::new("bench", ex.time, v, 0.022))
}

fn bench(c: &mut Criterion) {
    let Some(record) = fmm_record() else {
        return;
    };
    assert_eq!(record.len(), 2000);
    let osc = Oscillator::fmm();
    let sg = EnergyOptions::default();
    let paper = EnergyOptions {
        differentiator: Differentiator::Paper,
        ..sg
    };
    c.bench_function("analyze_record_2000_savitzky_golay", |b| {
        b.iter(|| analyze_record(black_box(&record), &osc, &sg))
    });
    c.bench_function("analyze_record_2000_paper", |b| {
        b.iter(|| analyze_record(black_box(&record), &osc, &paper))
    });
    let lugre = LuGre::default();
    c.bench_function("model_force_along_2000_lugre", |b| {
        b.iter(|| model_force_along(&lugre, &osc, black_box(record.time()), record.velocity()))
    });
}

criterion_group!(benches, bench);
criterion_main!(benches);
