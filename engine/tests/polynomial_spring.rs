//! A torsion pendulum on an asymmetric flat spring, R(q) = k1 q + k2 q^2, with viscous
//! damping and a Coulomb torque, released at 0.2 rad: the engine's simulator (integrating
//! the polynomial law) gives the record with velocity noise, and the fit of k1, k2, the
//! damping and the Coulomb torque recovers them; the linear spring fitted to the same record
//! leaves a residual at least twice as large.

use crate::util::{fit_coulomb_and_properties, rel};
use frictionid_engine::axis::{Axis, Polynomial, Restoring};
use frictionid_engine::identify::{FitResult, OscillatorParam};
use frictionid_engine::synthetic::release_records;
use frictionid_engine::{Oscillator, Record};
use frictionid_models::Coulomb;

/// Inertia J [kg m^2], k1 [N m/rad], k2 [N m/rad^2], damping [N m s/rad], Coulomb torque
/// [N m] (normal force 1): small swings have a period of 2 pi sqrt(J / k1) = 0.89 s.
const J: f64 = 0.01;
const K1: f64 = 0.5;
const K2: f64 = 0.5;
const DAMPING: f64 = 0.002;
const COULOMB: f64 = 0.003;
/// Velocity noise [rad/s]: about 0.15 % of the first swing's peak speed.
const NOISE: f64 = 2e-3;

fn pendulum(k1: f64, restoring: Restoring, damping: f64) -> Oscillator {
    Oscillator {
        mass: J,
        damping,
        stiffness: k1,
        normal_force: 1.0,
        axis: Axis::Rotary,
        restoring,
        input_offset: 0.0,
    }
}

fn polynomial(k2: f64) -> Restoring {
    Restoring::Polynomial(Polynomial {
        quadratic_stiffness: k2,
        cubic_stiffness: 0.0,
    })
}

fn records() -> Vec<Record> {
    let truth = pendulum(K1, polynomial(K2), DAMPING);
    release_records(
        &truth,
        &Coulomb { mu: COULOMB },
        &[0.2],
        3.0,
        1000.0,
        NOISE,
        7,
    )
    .expect("the truth simulates")
}

fn fit_with(start: &Oscillator, free: Vec<OscillatorParam>, records: &[Record]) -> FitResult {
    fit_coulomb_and_properties(start, 0.002, free, records)
}

#[test]
fn the_quadratic_spring_is_recovered_and_the_linear_spring_is_rejected() {
    let records = records();
    let start = pendulum(1.1 * K1, polynomial(0.5 * K2), 0.6 * DAMPING);
    let free = vec![
        OscillatorParam::Damping,
        OscillatorParam::Stiffness,
        OscillatorParam::QuadraticStiffness,
    ];
    let r = fit_with(&start, free, &records);
    let k2 = r.oscillator.restoring.parameter("quadratic_stiffness");
    let (k1, c) = (r.oscillator.stiffness, r.oscillator.damping);
    let t_c = r.value("mu").unwrap_or(f64::NAN);
    eprintln!(
        "polynomial: k1 {k1} ({K1}), k2 {k2:?} ({K2}), c {c} ({DAMPING}), T_c {t_c} \
         ({COULOMB}); rms {} rad/s",
        r.rms_residual
    );
    assert!(r.converged, "{}", r.termination);
    assert!(rel(k1, K1) < 0.02, "{k1}");
    assert!(k2.is_some_and(|k2| rel(k2, K2) < 0.02), "{k2:?}");
    assert!(rel(c, DAMPING) < 0.02, "{c}");
    assert!(rel(t_c, COULOMB) < 0.02, "{t_c}");

    let spring = pendulum(1.1 * K1, Restoring::default(), 0.6 * DAMPING);
    let free = vec![OscillatorParam::Damping, OscillatorParam::Stiffness];
    let s = fit_with(&spring, free, &records);
    eprintln!(
        "linear spring: k {} c {} T_c {:?}; rms {} rad/s",
        s.oscillator.stiffness,
        s.oscillator.damping,
        s.value("mu"),
        s.rms_residual
    );
    assert!(s.rms_residual > 2.0 * r.rms_residual);
}

/// An asymmetric spring with direction-dependent friction, released from either side: the
/// total energy (kinetic plus the polynomial's potential) never rises, and the mass comes to
/// rest where the force the friction holds, -R(q), lies within its stick band
/// [-mu_neg N, mu_pos N].
#[test]
fn an_asymmetric_spring_with_asymmetric_friction_loses_energy_and_sticks_in_its_band() {
    use frictionid_engine::simulate::{simulate, Initial, SimOptions};
    use frictionid_engine::synthetic::uniform_times;
    use frictionid_models::ViscousCoulombAsymmetric;

    let osc = Oscillator {
        restoring: Restoring::Polynomial(Polynomial {
            quadratic_stiffness: 5e4,
            cubic_stiffness: -2e5,
        }),
        ..Oscillator::fmm()
    };
    let law = ViscousCoulombAsymmetric {
        mu_pos: 0.25,
        mu_neg: 0.1,
        viscous: 0.5,
    };
    let n = osc.normal_force;
    let times = uniform_times(4.0, 1000.0);
    for x0 in [0.014, -0.014] {
        let sim = simulate(
            &osc,
            &law,
            &Initial::at_rest(x0),
            4.0,
            &times,
            &SimOptions::default(),
        )
        .expect("a simulation");
        let energy = sim.total_energy();
        let tolerance = 1e-9 * energy[0];
        let rise = energy
            .windows(2)
            .map(|w| w[1] - w[0])
            .fold(f64::MIN, f64::max);
        assert!(rise <= tolerance, "from {x0}: energy rises by {rise}");
        assert!(energy[0] > 0.1, "{}", energy[0]);
        let rest = sim.rest.expect("the mass comes to rest").displacement;
        // The friction must hold -R(q) at rest: -mu_neg N <= -R(q) <= mu_pos N.
        let held = -osc.restoring_force(rest);
        eprintln!("from {x0}: rest at {rest} m, held force {held} N");
        assert!(
            -law.mu_neg * n - 1e-9 <= held && held <= law.mu_pos * n + 1e-9,
            "from {x0}: {held}"
        );
    }
}
