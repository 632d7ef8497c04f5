//! The generalized Maxwell-slip model in the engine.
//!
//! Oracles: one element is a Maxwell element (an elastic spring k_1 in series with a slider
//! of force s), so
//! - released by less than its breakaway displacement, the mass oscillates without sliding at
//!   the combined stiffness, omega = sqrt((k + k_1) / m), about the centre
//!   x_c = k_1 x0 / (k + k_1), with the element deflection following the mass, z = x - x0;
//! - released far, it slides at the sliding level s (the Stribeck curve; s = mu N without a
//!   Stribeck dip) and its turning points follow the energy balance of an ideal
//!   elasto-plastic element, until it is trapped in presliding;
//! - KE + PE + stored energy never increases (a passive model), and a release at -x0 is the
//!   mirror image of the release at x0.

#![allow(clippy::needless_range_loop)]

use frictionid::engine::synthetic::uniform_times;
use frictionid::engine::{simulate, EventKind, Initial, Oscillator, SimOptions, Trajectory};
use frictionid::models::testing::motion::{first_energy_rise, first_unmirrored};
use frictionid::models::{FrictionModel, Gms, GmsElement};

const MASS: f64 = 10.391;
const K: f64 = 1982.0;
const N: f64 = 14.5;

/// The FMM stage without viscous damping (the oracles below are for c = 0).
fn undamped() -> Oscillator {
    Oscillator::new(MASS, 0.0, K, N).unwrap()
}

/// One element of stiffness `k1` and weight 1.
fn one_element(k1: f64, mu_c: f64, mu_s: f64, sharpness: f64) -> Gms {
    Gms {
        elements: vec![GmsElement {
            stiffness: k1,
            weight: 1.0,
            damping: 0.0,
        }],
        mu_c,
        mu_s,
        v_s: 0.01,
        delta: 2.0,
        sharpness,
        viscous: 0.0,
    }
}

fn run(osc: &Oscillator, model: &dyn FrictionModel, x0: f64, t_end: f64, rate: f64) -> Trajectory {
    run_with(osc, model, x0, t_end, rate, &SimOptions::default())
}

fn run_with(
    osc: &Oscillator,
    model: &dyn FrictionModel,
    x0: f64,
    t_end: f64,
    rate: f64,
    opts: &SimOptions,
) -> Trajectory {
    let times = uniform_times(t_end, rate);
    simulate(osc, model, &Initial::at_rest(x0), t_end, &times, opts).unwrap()
}

fn turning_points(sim: &Trajectory) -> Vec<(f64, f64)> {
    sim.events
        .iter()
        .filter(|e| e.kind == EventKind::TurningPoint)
        .map(|e| (e.time, e.displacement))
        .collect()
}

/// The combined angular frequency of the mass on the spring and one stuck element.
fn omega_combined(k1: f64) -> f64 {
    ((K + k1) / MASS).sqrt()
}

#[test]
fn one_element_presliding_oscillates_at_the_combined_stiffness() {
    let osc = undamped();
    let k1 = 2e4;
    let half_period = std::f64::consts::PI / omega_combined(k1);
    // Releases well inside the breakaway displacement (element force at most 0.25 mu_c N):
    // the element sticks and the mass oscillates on k + k1 about x_c = k1 x0 / (k + k1). The
    // smooth element slips by a fraction rho^sharpness of the motion, so the sharp element
    // (20) is tested at a larger amplitude than the default one (2).
    for (sharpness, x0, tol) in [(20.0, 2e-4, 1e-8), (2.0, 2e-7, 1e-6), (2.0, -2e-7, 1e-6)] {
        let model = one_element(k1, 0.2, 0.3, sharpness);
        let amplitude = (K * x0 / (K + k1)).abs();
        // An absolute tolerance far below the tiny amplitude.
        let opts = SimOptions {
            atol: 1e-6 * tol * amplitude,
            rtol: 1e-11,
            ..SimOptions::default()
        };
        let sim = run_with(&osc, &model, x0, 1.0, 2000.0, &opts);
        let centre = k1 * x0 / (K + k1);
        let tp = turning_points(&sim);
        // 1 s at omega = 46 rad/s: 14 turning points, and the mass never comes to rest.
        assert_eq!(tp.len(), 14, "sharpness {sharpness}");
        assert!(sim.rest.is_none());
        let mut previous = (0.0, x0);
        for (k, &(t, x)) in tp.iter().enumerate() {
            assert!(
                ((t - previous.0) - half_period).abs() < tol * half_period,
                "sharpness {sharpness}: half-period {} vs {half_period}",
                t - previous.0
            );
            // The turning points alternate between the far side 2 x_c - x0 and x0.
            let expected = if k % 2 == 0 { 2.0 * centre - x0 } else { x0 };
            assert!(
                (x - expected).abs() < tol * amplitude,
                "sharpness {sharpness}: turning point {x} vs {expected}"
            );
            previous = (t, x);
        }
        // No sliding: the element deflection follows the mass, z = x - x0.
        for i in 0..sim.x.len() {
            let z = sim.states[0][i];
            assert!(
                (z - (sim.x[i] - x0)).abs() < tol * amplitude,
                "sharpness {sharpness}: z = {z} vs x - x0 = {} at t = {}",
                sim.x[i] - x0,
                sim.time[i]
            );
        }
    }
}

/// The next turning point of a mass on spring `K` with one ideal elasto-plastic element
/// (stiffness `k1`, sliding force `s`), from the turning point `x_a` reached while moving in
/// direction `d` (element force d s). Returns the point and whether the element slid.
fn ideal_next(x_a: f64, d: f64, k1: f64, s: f64) -> (f64, bool) {
    // Elastic motion back from x_a: m x'' = -K x - d s - k1 (x - x_a), centre x_e.
    let x_e = (k1 * x_a - d * s) / (K + k1);
    if d * (x_a - x_e) <= s / k1 {
        // The swing 2 (x_a - x_e) does not reverse the element force: trapped.
        return (2.0 * x_e - x_a, false);
    }
    // Slip: the work K (x_a^2 - x_b^2) / 2 goes into s times the slip distance
    // u - 2 s / k1 (the stored energy s^2 / (2 k1) is the same at both ends).
    (x_a - d * slip_distance(x_a, d, s, 2.0 * s * s / k1), true)
}

/// The distance u travelled from the turning point `x_a` against direction `d` with sliding
/// force `s`: the root of K u^2 / 2 + (s - K d x_a) u - q = 0, q being the energy that the
/// element's elasticity returns (2 s^2 / k1 after a reversal, s^2 / (2 k1) from rest).
fn slip_distance(x_a: f64, d: f64, s: f64, q: f64) -> f64 {
    let b = s - K * d * x_a;
    (-b + (b * b + 2.0 * K * q).sqrt()) / K
}

#[test]
fn one_element_large_release_slides_at_the_coulomb_level_then_is_trapped() {
    let osc = undamped();
    let k1 = 2e4;
    let s = 0.2 * N;
    let x0 = 0.014;
    let model = one_element(k1, 0.2, 0.2, 20.0);
    let sim = run(&osc, &model, x0, 2.0, 2000.0);
    let tp = turning_points(&sim);
    // First slip from rest: the element loads from z = 0 (returns s^2 / (2 k1)).
    let first = x0 - slip_distance(x0, 1.0, s, s * s / (2.0 * k1));
    assert!((tp[0].1 - first).abs() < 2e-6, "{} vs {first}", tp[0].1);
    // Every further turning point from the previous one (one-step predictions).
    let mut slips = 1;
    let mut trapped_at = None;
    for k in 1..tp.len() {
        let x_a = tp[k - 1].1;
        let from = if k == 1 { x0 } else { tp[k - 2].1 };
        let d = (x_a - from).signum();
        let (expected, slid) = ideal_next(x_a, d, k1, s);
        assert!(
            (tp[k].1 - expected).abs() < 2e-6,
            "turning point {k}: {} vs ideal {expected} (slid: {slid})",
            tp[k].1
        );
        if !slid {
            trapped_at = Some(k);
            break;
        }
        slips += 1;
    }
    // Pure Coulomb friction would stop after 5 slips at 14 mm too, but at other points: the
    // presliding stiffness returns energy at each reversal. The ideal element slides 5 times.
    assert_eq!(slips, 5);
    let trapped_at = trapped_at.expect("the mass is trapped in presliding");
    // The slides run at the Coulomb level mu N (well past each reversal).
    let mut checked = 0;
    let mut last = x0;
    let mut k = 0;
    for i in 0..sim.x.len() {
        while k < tp.len() && tp[k].0 <= sim.time[i] {
            last = tp[k].1;
            k += 1;
        }
        if k >= slips {
            break;
        }
        if (sim.x[i] - last).abs() > 6.0 * s / k1 {
            let expected = s * sim.v[i].signum();
            assert!(
                (sim.friction[i] - expected).abs() < 1e-5 * s,
                "friction {} vs {expected} at t = {}",
                sim.friction[i],
                sim.time[i]
            );
            checked += 1;
        }
    }
    assert!(checked > 1000, "{checked} sliding samples");
    // Trapped: the element force stays below s and the mass swings at the combined stiffness.
    let t_trap = tp[trapped_at - 1].0;
    let half_period = std::f64::consts::PI / omega_combined(k1);
    // (The smooth element still yields slightly where its force nears s: within 1 %.)
    for w in tp[trapped_at..].windows(2) {
        let dt = w[1].0 - w[0].0;
        assert!(
            (dt - half_period).abs() < 1e-2 * half_period,
            "{dt} vs {half_period}"
        );
    }
    assert!(tp.len() - trapped_at > 10);
    for i in 0..sim.x.len() {
        if sim.time[i] > t_trap {
            assert!(sim.friction[i].abs() < s, "t = {}", sim.time[i]);
        }
    }
}

#[test]
fn one_element_slides_on_the_stribeck_curve() {
    let osc = undamped();
    let k1 = 2e4;
    let model = one_element(k1, 0.2, 0.3, 20.0);
    let sim = run(&osc, &model, 0.014, 1.0, 5000.0);
    let tp = turning_points(&sim);
    let mut checked = 0;
    let mut last = 0.014;
    let mut k = 0;
    for i in 0..sim.x.len() {
        while k < tp.len() && tp[k].0 <= sim.time[i] {
            last = tp[k].1;
            k += 1;
        }
        if k >= 4 {
            break;
        }
        let v = sim.v[i];
        // Past the elastic reversal and above twice the Stribeck velocity (where the dip is
        // still 9 % of the Coulomb level): F = N (mu_c + (mu_s - mu_c) exp(-(v/v_s)^2)) sgn(v).
        if (sim.x[i] - last).abs() > 6.0 * 0.3 * N / k1 && v.abs() > 0.02 {
            let curve = N * (0.2 + 0.1 * (-(v / 0.01).powi(2)).exp()) * v.signum();
            assert!(
                (sim.friction[i] - curve).abs() < 5e-3 * curve.abs(),
                "friction {} vs the Stribeck curve {curve} at v = {v}",
                sim.friction[i]
            );
            checked += 1;
        }
    }
    assert!(checked > 1000, "{checked} sliding samples");
}

/// A three-element model with unequal weights and stiffnesses.
fn three_elements(sigma: [f64; 3], mu_s: f64) -> Gms {
    let k = [4e5, 1e5, 2.5e4];
    let w = [0.5, 0.3, 0.2];
    Gms {
        elements: (0..3)
            .map(|i| GmsElement {
                stiffness: k[i],
                weight: w[i],
                damping: sigma[i],
            })
            .collect(),
        mu_c: 0.2,
        mu_s,
        v_s: 0.01,
        delta: 2.0,
        sharpness: 2.0,
        viscous: 0.5,
    }
}

#[test]
fn energy_with_stored_energy_never_increases() {
    let osc = Oscillator::fmm();
    // Undamped elements on the Stribeck curve, and damped elements at a constant sliding
    // level (element damping is passive when the sliding force does not drop with speed).
    let cases = [
        (three_elements([0.0; 3], 0.3), "undamped, Stribeck"),
        (three_elements([20.0, 10.0, 5.0], 0.2), "damped"),
        (one_element(2e4, 0.2, 0.3, 20.0), "one sharp element"),
    ];
    for (model, label) in &cases {
        for x0 in [0.022, 0.003, -0.010] {
            let sim = run(&osc, model, x0, 2.0, 2000.0);
            let total = sim.total_energy();
            let scale = total[0];
            if let Some((i, rise)) = first_energy_rise(&total, 1e-9 * scale) {
                panic!(
                    "{label} from {x0}: KE + PE + stored rises by {rise:e} J at t = {}",
                    sim.time[i]
                );
            }
            // The stored energy is the elements' sum k_i z_i^2 / 2.
            for i in (0..total.len()).step_by(97) {
                let stored: f64 = model
                    .elements
                    .iter()
                    .enumerate()
                    .map(|(j, e)| 0.5 * e.stiffness * sim.states[j][i].powi(2))
                    .sum();
                assert!((sim.stored[i] - stored).abs() <= 1e-12 * scale);
            }
            // Friction dissipates: the motion loses energy overall.
            assert!(total[total.len() - 1] < 0.5 * scale, "{label} from {x0}");
        }
    }
}

#[test]
fn mirror_symmetry_of_multi_element_gms() {
    let osc = Oscillator::fmm();
    for model in [
        three_elements([0.0; 3], 0.3),
        three_elements([20.0, 10.0, 5.0], 0.2),
    ] {
        let a = run(&osc, &model, 0.022, 2.0, 1000.0);
        let b = run(&osc, &model, -0.022, 2.0, 1000.0);
        assert_eq!(a.x.len(), b.x.len());
        let motion = first_unmirrored(&a.x, &b.x, 1e-12).or(first_unmirrored(&a.v, &b.v, 1e-12));
        if let Some(i) = motion {
            panic!(
                "x(t) = {}, v(t) = {} but the mirrored run gives {}, {} at t = {}",
                a.x[i], a.v[i], b.x[i], b.v[i], a.time[i]
            );
        }
        for j in 0..3 {
            assert_eq!(
                first_unmirrored(&a.states[j], &b.states[j], 1e-12),
                None,
                "z{j}"
            );
        }
        assert_eq!(first_unmirrored(&a.friction, &b.friction, 1e-9), None);
        for i in 0..a.x.len() {
            assert!((a.stored[i] - b.stored[i]).abs() < 1e-12);
        }
        assert_eq!(a.events.len(), b.events.len());
        for (ea, eb) in a.events.iter().zip(&b.events) {
            assert_eq!(ea.kind, eb.kind);
            assert!((ea.time - eb.time).abs() < 1e-12);
        }
    }
}
