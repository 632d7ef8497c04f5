//! Units on every rig, against records the engine's own simulator makes: a driven slide
//! (M x'' + Fv x' + Fc sgn x' + F0 = u under a multisine) and a free pendulum. Correct
//! records pass every unit check, whatever the mass, the channel the motion comes from, the
//! velocity noise or how rough the start of a fitted mass is (no false alarm); the same
//! motion in millimetres, micrometres, mm/s or degrees is named with the scale to set, and a
//! pendulum's angle in degrees is named whether its properties are known or not.

use crate::util::{multisine, sample_times, Tone};
use frictionid_engine::axis::{NoRestoring, Pendulum};
use frictionid_engine::identify::problem::unit_check::{
    balance_scale, check_driven_balance, check_swing, implied_inertia, MassReference,
};
use frictionid_engine::record::{Channel, TimeBase};
use frictionid_engine::{Axis, Initial, Oscillator, Record, Restoring, SimOptions};
use frictionid_models::{Coulomb, ViscousCoulomb};
use rand::rngs::StdRng;
use rand::SeedableRng;
use rand_distr::{Distribution, Normal};
use std::f64::consts::PI;

const RATE: f64 = 2000.0;
const DURATION: f64 = 3.0;

/// The slide of mass `mass` (viscous 30 N s/m, Coulomb 8 N, offset 0.5 N, all scaled with
/// the mass so that the motion stays the same: the Coulomb level through the normal force)
/// on `axis`.
fn slide(mass: f64, axis: Axis) -> Oscillator {
    Oscillator {
        mass,
        damping: 0.0,
        stiffness: 0.0,
        normal_force: mass / 12.0,
        restoring: Restoring::None(NoRestoring),
        input_offset: 0.5 * mass / 12.0,
        axis,
    }
}

/// The simulated motion of `osc` under a multisine scaled with its mass: (t, x, v, a, u).
fn drive(osc: &Oscillator) -> [Vec<f64>; 5] {
    let scale = osc.mass / 12.0;
    let t = sample_times(DURATION, RATE);
    let tones: [Tone; 4] = [
        (40.0, 0.7, 0.0),
        (25.0, 1.9, 1.0),
        (15.0, 3.3, 2.0),
        (10.0, 5.1, 0.5),
    ];
    let u: Vec<f64> = t.iter().map(|&t| scale * multisine(&tones, t)).collect();
    let law = ViscousCoulomb {
        mu: 8.0,
        viscous: 30.0 * scale,
    };
    let sim = crate::util::driven_from_rest(osc, &law, &t, &u);
    [t, sim.x, sim.v, sim.a, u]
}

/// How the record carries the motion.
#[derive(Clone, Copy, Debug)]
enum Carried {
    /// A position quantised to 1 um (of the true unit).
    Position,
    /// A velocity with 2 mm/s of noise.
    NoisyVelocity,
    /// A measured acceleration beside the velocity.
    Acceleration,
}

/// The record of `motion` carried as `carried`, its motion channel multiplied by `unit`.
fn record(motion: &[Vec<f64>; 5], carried: Carried, unit: f64) -> Record {
    let [t, x, v, a, u] = motion.clone();
    let base = Record::from_time_base("drive.csv", TimeBase::new(t).expect("a time base"))
        .with_channel(Channel::InputForce, u);
    let scaled = |s: Vec<f64>| s.into_iter().map(|y| y * unit).collect::<Vec<f64>>();
    match carried {
        Carried::Position => base.with_channel(
            Channel::Displacement,
            scaled(x.iter().map(|x| (x * 1e6).round() * 1e-6).collect()),
        ),
        Carried::NoisyVelocity => {
            let mut rng = StdRng::seed_from_u64(3);
            let noise = Normal::new(0.0, 2e-3).expect("a noise level");
            let v = v.iter().map(|v| v + noise.sample(&mut rng)).collect();
            base.with_channel(Channel::Velocity, scaled(v))
        }
        Carried::Acceleration => base
            .with_channel(Channel::Velocity, scaled(v))
            .with_channel(Channel::Acceleration, scaled(a)),
    }
}

const CARRIED: [Carried; 3] = [
    Carried::Position,
    Carried::NoisyVelocity,
    Carried::Acceleration,
];

/// The references a correct record meets: the mass fixed, or fitted from a start half or
/// twice the truth.
fn references(mass: f64) -> [MassReference; 3] {
    [
        MassReference::Fixed(mass),
        MassReference::Start(0.5 * mass),
        MassReference::Start(2.0 * mass),
    ]
}

#[test]
fn correct_driven_records_pass_and_the_balance_implies_their_mass() {
    for mass in [0.5, 12.0, 300.0] {
        let osc = slide(mass, Axis::Linear);
        let motion = drive(&osc);
        for carried in CARRIED {
            let r = record(&motion, carried, 1.0);
            let j = implied_inertia(&r, &osc).expect("determined");
            assert!(
                (j / mass - 1.0).abs() < 0.1,
                "{mass} kg, {carried:?}: J = {j}"
            );
            for reference in references(mass) {
                assert_eq!(
                    balance_scale(&r, &osc, reference),
                    None,
                    "{mass} kg, {carried:?}, {reference:?}"
                );
            }
        }
    }
}

#[test]
fn a_driven_motion_in_the_wrong_unit_names_its_channel_and_scale() {
    let osc = slide(12.0, Axis::Linear);
    let motion = drive(&osc);
    let cases = [
        (
            Carried::Position,
            1e3,
            "displacement",
            1e-3,
            "millimetres read as metres",
        ),
        (
            Carried::Position,
            1e6,
            "displacement",
            1e-6,
            "micrometres read as metres",
        ),
        (
            Carried::NoisyVelocity,
            1e3,
            "velocity",
            1e-3,
            "mm/s read as m/s",
        ),
        (
            Carried::Acceleration,
            1e3,
            "acceleration",
            1e-3,
            "mm/s^2 read as m/s^2",
        ),
    ];
    for (carried, unit, channel, scale, words) in cases {
        let r = record(&motion, carried, unit);
        for reference in [MassReference::Fixed(12.0), MassReference::Start(10.0)] {
            let found = balance_scale(&r, &osc, reference)
                .unwrap_or_else(|| panic!("{carried:?} x{unit}, {reference:?}"));
            assert_eq!(
                (found.channel, found.scale, found.words),
                (channel, scale, words)
            );
        }
    }
    // A rotary drive's angle in degrees.
    let osc = slide(0.05, Axis::Rotary);
    let r = record(&drive(&osc), Carried::Position, 180.0 / PI);
    let found = balance_scale(&r, &osc, MassReference::Start(0.04)).expect("degrees");
    assert_eq!(found.words, "degrees read as radians");
    assert!((found.scale - PI / 180.0).abs() < 1e-12);
    let msg = check_driven_balance(&r, &osc, MassReference::Fixed(0.05))
        .unwrap_err()
        .to_string();
    assert!(
        msg.starts_with("drive.csv: the displacement looks like degrees read as radians")
            && msg.ends_with("set displacement_scale = 0.0174533"),
        "{msg}"
    );
}

/// A free pendulum (J 0.02 kg m^2, M_g 0.5 N m, c 0.002 N m s/rad, Coulomb 0.012 N m)
/// released at `angle` rad with speed `speed`, its angle at 200 Hz over 4 s in `unit`s of a
/// radian.
fn swing(angle: f64, speed: f64, unit: f64) -> Record {
    let osc = pendulum();
    let t: Vec<f64> = (0..800).map(|i| i as f64 / 200.0).collect();
    let sim = frictionid_engine::simulate(
        &osc,
        &Coulomb { mu: 0.012 },
        &Initial::new(angle, speed),
        4.0,
        &t,
        &SimOptions::default(),
    )
    .expect("a simulation");
    let q = sim.x.iter().map(|q| q * unit).collect();
    Record::from_time_base("swing.csv", TimeBase::new(t).expect("a time base"))
        .with_channel(Channel::Displacement, q)
}

fn pendulum() -> Oscillator {
    Oscillator {
        mass: 0.02,
        damping: 0.002,
        normal_force: 1.0,
        axis: Axis::Rotary,
        restoring: Restoring::Pendulum(Pendulum {
            gravity_moment: 0.5,
        }),
        ..Oscillator::fmm()
    }
}

#[test]
fn a_pendulum_in_degrees_is_named_from_its_swings_alone() {
    let osc = pendulum();
    // Released at 10 to 170 degrees, or thrown over the top first: radians pass.
    for (deg, speed) in [(10.0, 0.0), (60.0, 0.0), (170.0, 0.0), (0.0, 12.0)] {
        let angle: f64 = f64::to_radians(deg);
        check_swing(&swing(angle, speed, 1.0), &osc)
            .unwrap_or_else(|e| panic!("{deg} deg, {speed} rad/s: {e}"));
    }
    for deg in [10.0, 60.0, 170.0] {
        let angle: f64 = f64::to_radians(deg);
        let msg = check_swing(&swing(angle, 0.0, 180.0 / PI), &osc)
            .unwrap_err()
            .to_string();
        assert!(
            msg.starts_with("swing.csv: the angle swings")
                && msg.ends_with(
                    "is the angle in degrees? set displacement_scale = 0.0174533 (pi/180)"
                ),
            "{msg}"
        );
    }
}
