//! Cost of one force evaluation: built-in laws against the same law as an `expression`
//! formula, and the gms right-hand side.

use criterion::{criterion_group, criterion_main, Criterion};
use frictionid_models::{
    Expression, FrictionModel, Gms, InternalStates, Makkar, Stribeck, SwitchedLaw,
};
use std::hint::black_box;

const N: f64 = 14.5;

fn forces(c: &mut Criterion) {
    let st = Stribeck::default();
    let ex = Expression::new(
        "N * (mu_c + (mu_s - mu_c) * exp(-abs(v / v_s)^delta)) * sign(v) + viscous * v",
        &[
            ("mu_c", st.mu_c),
            ("mu_s", st.mu_s),
            ("v_s", st.v_s),
            ("delta", st.delta),
            ("viscous", st.viscous),
        ],
    )
    .expect("the benchmark formula parses");
    let coulomb_ex =
        Expression::new("mu * N * sign(v)", &[("mu", 0.2)]).expect("the benchmark formula parses");
    let mk = Makkar::default();
    let gms = Gms::default();
    let z = [3e-6, -1e-5, 2e-5];
    let mut dz = [0.0; 3];
    let mut g = c.benchmark_group("force");
    g.bench_function("stribeck (native)", |b| {
        b.iter(|| st.force(black_box(0.013), &[], N))
    });
    g.bench_function("stribeck (expression)", |b| {
        b.iter(|| ex.force(black_box(0.013), &[], N))
    });
    g.bench_function("stribeck slip_force (expression)", |b| {
        b.iter(|| ex.slip_force(black_box(0.013), 1.0, N))
    });
    g.bench_function("coulomb (expression)", |b| {
        b.iter(|| coulomb_ex.force(black_box(0.013), &[], N))
    });
    g.bench_function("makkar", |b| b.iter(|| mk.force(black_box(0.013), &[], N)));
    g.bench_function("gms 3 elements: state_derivative + force", |b| {
        b.iter(|| {
            gms.state_derivative(black_box(0.013), &z, N, &mut dz);
            gms.force(black_box(0.013), &z, N) + dz[0]
        })
    });
    g.finish();
}

criterion_group!(benches, forces);
criterion_main!(benches);
