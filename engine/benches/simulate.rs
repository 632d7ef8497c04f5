//! Criterion benchmarks of the simulation engine: one run per registered model for the FMM case
//! (N = 14.5 N, x0 = 22 mm, 2 s sampled at 1 kHz, default Dopri5), the paper's 140 mm Coulomb case (N = m g, mu = 0.24)
//! with Dopri5, the closed form and the paper's Euler (T_n / 1e6), and the stiff bristle models
//! (sigma0 = 1e7 N/m), among them the `simulate` command's default (`auto`). The RHS counts are printed once per case (stderr) for the
//! table in benches/README.md.

/// mimalloc, as the `frictionid` binary and the Python module use (glibc's malloc returned
/// and refaulted the fits' buffers, a sixth of a Coulomb fit's time).
#[global_allocator]
static ALLOCATOR: mimalloc::MiMalloc = mimalloc::MiMalloc;

use criterion::measurement::WallTime;
use criterion::{criterion_group, criterion_main, BenchmarkGroup, Criterion};
use frictionid_engine::synthetic::uniform_times;
use frictionid_engine::{simulate, Initial, Integrator, Oscillator, SimOptions};
use frictionid_models::{default_model, names, Coulomb, FrictionModel};
use std::hint::black_box;
use std::time::Duration;

fn run(
    osc: &Oscillator,
    model: &dyn FrictionModel,
    x0: f64,
    t_end: f64,
    times: &[f64],
    opts: &SimOptions,
) -> u64 {
    match simulate(osc, model, &Initial::at_rest(x0), t_end, times, opts) {
        Ok(sim) => sim.stats.rhs_evaluations,
        Err(e) => {
            eprintln!("simulation failed: {e}");
            0
        }
    }
}

fn fmm_models(c: &mut Criterion) {
    let osc = Oscillator::fmm();
    let times = uniform_times(2.0, 1000.0);
    let opts = SimOptions::default();
    let mut group = c.benchmark_group("fmm_22mm_2s_1kHz");
    for name in names() {
        let Ok(model) = default_model(&name) else {
            continue;
        };
        let rhs = run(&osc, model.as_ref(), 0.022, 2.0, &times, &opts);
        eprintln!("fmm_22mm_2s_1kHz/{name}: {rhs} RHS evaluations");
        group.bench_function(name.as_str(), |b| {
            b.iter(|| {
                run(
                    &osc,
                    black_box(model.as_ref()),
                    black_box(0.022),
                    2.0,
                    &times,
                    &opts,
                )
            })
        });
    }
    group.finish();
}

/// The stiff end of the bristle models (sigma0 = 1e7 N/m, LuGre with sigma1 =
/// 5000 N s/m) with the explicit integrator and with Rodas4, and Rodas4 at 1e8 and 1e9;
/// Rodas4 at the default 1e5 (against the `fmm_22mm_2s_1kHz` Dopri5 rows: where `auto`
/// should switch); and Dahl saturating in finite time.
fn fmm_stiff(c: &mut Criterion) {
    let osc = Oscillator::fmm();
    let times = uniform_times(2.0, 1000.0);
    let mut group = c.benchmark_group("fmm_22mm_2s_1kHz_stiff");
    group.sample_size(10);
    group.measurement_time(Duration::from_secs(3));
    let cases = [
        ("rodas", 1e5),
        ("dopri5", 1e7),
        ("rodas", 1e7),
        ("rodas", 1e8),
        ("rodas", 1e9),
    ];
    for name in ["lugre", "dahl"] {
        for (method, sigma0) in cases {
            let mut json = serde_json::json!({ "type": name, "sigma0": sigma0 });
            if name == "lugre" {
                json["sigma1"] = serde_json::json!(5000.0);
            }
            let Ok(built) = frictionid_models::build_json(&json) else {
                continue;
            };
            let opts = SimOptions {
                integrator: if method == "rodas" {
                    Integrator::Rodas
                } else {
                    Integrator::Dopri5
                },
                ..SimOptions::default()
            };
            let model = built.model;
            let label = format!("{name}_{sigma0:e}_{method}");
            let rhs = run(&osc, model.as_ref(), 0.022, 2.0, &times, &opts);
            eprintln!("fmm_22mm_2s_1kHz_stiff/{label}: {rhs} RHS evaluations");
            group.bench_function(label, |b| {
                b.iter(|| run(&osc, model.as_ref(), black_box(0.022), 2.0, &times, &opts))
            });
        }
    }
    saturating_dahl(&mut group, &osc, &times);
    simulate_default(&mut group, &osc, &times);
    group.finish();
}

/// Stiff LuGre (sigma0 = 1e7 N/m, the default sigma1 = 300 N s/m, and sigma1 = 5000 N s/m)
/// on the `simulate` command's default path: `[simulation.integrator]` left out, so the
/// spec's default options (`auto`, the engine's tolerances). SciPy's `lugre sigma0=1e7` rows
/// of benches/scipy_reference.py are the same cases.
fn simulate_default(group: &mut BenchmarkGroup<'_, WallTime>, osc: &Oscillator, times: &[f64]) {
    let opts = frictionid_engine::spec::IntegratorSpec::default().sim_options();
    for sigma1 in [300.0, 5000.0] {
        let json = serde_json::json!({ "type": "lugre", "sigma0": 1e7, "sigma1": sigma1 });
        let Ok(built) = frictionid_models::build_json(&json) else {
            continue;
        };
        let model = built.model;
        let label = format!("lugre_1e7_sigma1_{sigma1}_simulate_default");
        let rhs = run(osc, model.as_ref(), 0.022, 2.0, times, &opts);
        eprintln!("fmm_22mm_2s_1kHz_stiff/{label}: {rhs} RHS evaluations");
        group.bench_function(label, |b| {
            b.iter(|| run(osc, model.as_ref(), black_box(0.022), 2.0, times, &opts))
        });
    }
}

fn paper_140mm(c: &mut Criterion) {
    let mut osc = Oscillator::fmm();
    osc.normal_force = osc.mass * 9.81;
    let model = Coulomb { mu: 0.24 };
    let times = uniform_times(2.0, 1000.0);
    let opts = SimOptions {
        integrator: Integrator::Dopri5,
        ..SimOptions::default()
    };
    let exact = SimOptions {
        integrator: Integrator::Exact,
        ..SimOptions::default()
    };
    let euler = SimOptions {
        integrator: Integrator::Euler {
            steps_per_period: 1e6,
        },
        ..SimOptions::default()
    };
    let mut group = c.benchmark_group("paper_140mm_coulomb");
    let cases: [(&str, &[f64], &SimOptions); 5] = [
        ("dopri5_events_only", &[], &opts),
        ("dopri5_2s_1kHz", &times, &opts),
        ("exact_events_only", &[], &exact),
        ("exact_2s_1kHz", &times, &exact),
        ("euler_1e6_2s_1kHz", &times, &euler),
    ];
    for (label, t, o) in cases {
        let rhs = run(&osc, &model, 0.140, 2.0, t, o);
        eprintln!("paper_140mm_coulomb/{label}: {rhs} RHS evaluations");
        if label.starts_with("euler") {
            group.sample_size(10);
            group.measurement_time(Duration::from_secs(5));
        }
        group.bench_function(label, |b| {
            b.iter(|| run(&osc, &model, black_box(0.140), 2.0, t, o))
        });
    }
    group.finish();
}

/// Dahl with alpha < 1, whose force reaches its Coulomb level in finite time: the explicit
/// method chatters there, and `auto` (the fits' choice) takes Rodas4 (it looks at the sliding
/// state).
fn saturating_dahl(group: &mut BenchmarkGroup<'_, WallTime>, osc: &Oscillator, times: &[f64]) {
    let json = serde_json::json!({ "type": "dahl", "sigma0": 1e5, "mu_c": 0.35, "alpha": 0.8 });
    let Ok(built) = frictionid_models::build_json(&json) else {
        return;
    };
    let model = built.model;
    for (method, integrator) in [("auto", Integrator::Auto), ("dopri5", Integrator::Dopri5)] {
        let opts = SimOptions {
            integrator,
            ..SimOptions::default()
        };
        let label = format!("dahl_alpha_0.8_{method}");
        let rhs = run(osc, model.as_ref(), 0.022, 2.0, times, &opts);
        eprintln!("fmm_22mm_2s_1kHz_stiff/{label}: {rhs} RHS evaluations");
        group.bench_function(label, |b| {
            b.iter(|| run(osc, model.as_ref(), black_box(0.022), 2.0, times, &opts))
        });
    }
}

criterion_group!(benches, fmm_models, fmm_stiff, paper_140mm);
criterion_main!(benches);
