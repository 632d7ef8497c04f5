//! The false-alarm matrix on pendulums and displacement channels. The truth is viscous +
//! Coulomb friction (a switched law) made by an independent simulator written here: a
//! fixed-step classical Runge-Kutta scheme of 10 us on J q'' = -R(q) - (T_c s + b q'), each
//! sliding phase ended at its reversal (bisection on the last step), where the axis sticks
//! when |R(q)| <= T_c. The rigs, each read by its displacement (angle) channel:
//! - a free pendulum (R = M_g sin q) fitted with its gravity moment free;
//! - a torsion pendulum (R = k q, k known);
//! - the FMM slide read by an interferometer (velocity route on a displacement channel);
//! - a tribometer stroke x = A sin w t whose friction force is measured (force domain, the
//!   motion from the displacement channel).
//!
//! Each with white noise, AR(1) noise of lag-1 correlation 0.9 and a ringing (an AR(2)
//! resonant at 2 % of the rate): the true law (viscous_coulomb) raises no failed diagnostic;
//! its wrong-law twin (Coulomb alone) on the same records warns or fails in every case.

use crate::util::{false_alarms, no_oscillator_force_options, unflagged};
use frictionid_engine::axis::{Axis, Pendulum, Restoring};
use frictionid_engine::identify::{fit, FitOptions, FitResult, OscillatorParam};
use frictionid_engine::record::{Channel, TimeBase};
use frictionid_engine::synthetic::{add_coloured_noise, add_gaussian_noise, uniform_times};
use frictionid_engine::{Oscillator, Record};
use frictionid_models::{Coulomb, FrictionModel, ViscousCoulomb};
use std::f64::consts::PI;

/// The simulator's step [s].
const STEP: f64 = 1e-5;
/// Sample rate [Hz].
const RATE: f64 = 500.0;

#[derive(Debug, Clone, Copy, PartialEq)]
enum Noise {
    White,
    Ar1,
    Ringing,
}

const NOISES: [Noise; 3] = [Noise::White, Noise::Ar1, Noise::Ringing];

/// Adds `kind` of noise of about `sigma` to `values` (seeded by `seed`).
fn add_noise(values: &mut [f64], kind: Noise, sigma: f64, seed: u64) {
    match kind {
        Noise::White => add_gaussian_noise(values, sigma, seed),
        Noise::Ar1 => add_coloured_noise(values, sigma, 0.9, seed),
        Noise::Ringing => {
            // e_k = 1.8 cos(theta) e_{k-1} - 0.81 e_{k-2} + w_k: a resonance at theta.
            let theta = 2.0 * PI * 0.02;
            let (a1, a2) = (1.8 * theta.cos(), -0.81);
            let mut white = vec![0.0; values.len()];
            add_gaussian_noise(&mut white, 0.25 * sigma, seed);
            let (mut e1, mut e2) = (0.0, 0.0);
            for (v, w) in values.iter_mut().zip(white) {
                let e = a1 * e1 + a2 * e2 + w;
                (e2, e1) = (e1, e);
                *v += e;
            }
        }
    }
}

/// A rig with viscous + Coulomb friction: inertia, restoring law, Coulomb level and viscous
/// coefficient (SI on its axis).
struct Rig {
    inertia: f64,
    restoring: fn(f64) -> f64,
    coulomb: f64,
    viscous: f64,
}

impl Rig {
    fn acceleration(&self, q: f64, w: f64, s: f64) -> f64 {
        -((self.restoring)(q) + self.coulomb * s + self.viscous * w) / self.inertia
    }

    fn rk4(&self, (q, w): (f64, f64), s: f64, h: f64) -> (f64, f64) {
        let f = |q: f64, w: f64| (w, self.acceleration(q, w, s));
        let k1 = f(q, w);
        let k2 = f(q + 0.5 * h * k1.0, w + 0.5 * h * k1.1);
        let k3 = f(q + 0.5 * h * k2.0, w + 0.5 * h * k2.1);
        let k4 = f(q + h * k3.0, w + h * k3.1);
        (
            q + h / 6.0 * (k1.0 + 2.0 * k2.0 + 2.0 * k3.0 + k4.0),
            w + h / 6.0 * (k1.1 + 2.0 * k2.1 + 2.0 * k3.1 + k4.1),
        )
    }

    /// The angle (displacement) at `times`, released from rest at `q0`.
    fn release(&self, q0: f64, times: &[f64]) -> Vec<f64> {
        let mut y = (q0, 0.0);
        let mut s = -(self.restoring)(q0).signum();
        let mut stuck = (self.restoring)(q0).abs() <= self.coulomb;
        let mut t = 0.0;
        let mut out = Vec::with_capacity(times.len());
        for &target in times {
            while !stuck && t < target - 1e-12 {
                let h = STEP.min(target - t);
                let next = self.rk4(y, s, h);
                if next.1 * s > 0.0 {
                    t += h;
                    y = next;
                    continue;
                }
                let (mut lo, mut hi) = (0.0, h);
                while hi - lo > 1e-13 {
                    let mid = 0.5 * (lo + hi);
                    if self.rk4(y, s, mid).1 * s > 0.0 {
                        lo = mid;
                    } else {
                        hi = mid;
                    }
                }
                t += hi;
                y = (self.rk4(y, s, hi).0, 0.0);
                let held = (self.restoring)(y.0);
                if held.abs() <= self.coulomb {
                    stuck = true;
                } else {
                    s = -held.signum();
                }
            }
            out.push(y.0);
        }
        out
    }
}

/// Free pendulum: J 0.02 kg m^2, M_g 0.5 N m, T_c 0.01 N m, b 0.004 N m s/rad.
const GRAVITY_MOMENT: f64 = 0.5;
fn free_pendulum() -> (Rig, Oscillator) {
    let rig = Rig {
        inertia: 0.02,
        restoring: |q| GRAVITY_MOMENT * q.sin(),
        coulomb: 0.01,
        viscous: 0.004,
    };
    let osc = Oscillator {
        mass: 0.02,
        damping: 0.0,
        stiffness: 1.0,
        normal_force: 1.0,
        axis: Axis::Rotary,
        // The fit starts 5 % off.
        restoring: Restoring::Pendulum(Pendulum {
            gravity_moment: 0.95 * GRAVITY_MOMENT,
        }),
        input_offset: 0.0,
    };
    (rig, osc)
}

/// Torsion pendulum: J 0.01 kg m^2, k 0.4 N m/rad, T_c 0.004 N m, b 0.002 N m s/rad.
fn torsion_pendulum() -> (Rig, Oscillator) {
    let rig = Rig {
        inertia: 0.01,
        restoring: |q| 0.4 * q,
        coulomb: 0.004,
        viscous: 0.002,
    };
    let osc = Oscillator {
        mass: 0.01,
        damping: 0.0,
        stiffness: 0.4,
        normal_force: 1.0,
        axis: Axis::Rotary,
        ..Oscillator::fmm()
    };
    (rig, osc)
}

/// The FMM slide (k 1982 N/m, m 10.391 kg) with Coulomb 0.2 x 14.5 N and viscous 2 N s/m.
fn slide() -> (Rig, Oscillator) {
    let rig = Rig {
        inertia: 10.391,
        restoring: |x| 1982.0 * x,
        coulomb: 0.2 * 14.5,
        viscous: 2.0,
    };
    let osc = Oscillator {
        damping: 0.0,
        ..Oscillator::fmm()
    };
    (rig, osc)
}

/// Displacement records of `rig` released at each of `releases`, `duration` s, with `kind`
/// of noise of `sigma`.
fn released(
    rig: &Rig,
    releases: &[f64],
    duration: f64,
    kind: Noise,
    sigma: f64,
    seed: u64,
) -> Vec<Record> {
    let times = uniform_times(duration, RATE);
    releases
        .iter()
        .enumerate()
        .map(|(i, &q0)| {
            let mut q = rig.release(q0, &times);
            add_noise(&mut q, kind, sigma, seed + i as u64);
            let base = TimeBase::new(times.clone()).expect("uniform times");
            let mut r = Record::from_time_base(format!("release{i}"), base)
                .with_channel(Channel::Displacement, q);
            r.x0 = q0;
            r
        })
        .collect()
}

/// A tribometer stroke x = 5 mm sin(2 pi 0.5 t) over 4 s: its displacement (white noise of
/// 0.1 um) and its measured friction force 3 N sgn(v) + 150 N s/m v with `kind` of noise of
/// 0.05 N.
fn stroke(kind: Noise, seed: u64) -> Record {
    let times = uniform_times(4.0, RATE);
    let w = 2.0 * PI * 0.5;
    let mut x: Vec<f64> = times.iter().map(|t| 5e-3 * (w * t).sin()).collect();
    let mut force: Vec<f64> = times
        .iter()
        .map(|t| {
            let v = 5e-3 * w * (w * t).cos();
            3.0 * v.signum() + 150.0 * v
        })
        .collect();
    add_gaussian_noise(&mut x, 1e-7, seed);
    add_noise(&mut force, kind, 0.05, seed + 1);
    Record::from_time_base("stroke", TimeBase::new(times).expect("uniform times"))
        .with_channel(Channel::Displacement, x)
        .with_channel(Channel::Force, force)
}

/// Whether `model` is the true law's (viscous + Coulomb) or the wrong one's (Coulomb).
fn law(correct: bool, level: f64, viscous: f64) -> Box<dyn FrictionModel> {
    if correct {
        Box::new(ViscousCoulomb { mu: level, viscous })
    } else {
        Box::new(Coulomb { mu: level })
    }
}

/// Every case of the matrix fitted with the true law (`correct`) or its wrong twin.
fn cases(correct: bool) -> Vec<(String, FitResult)> {
    use rayon::prelude::*;
    let mut jobs: Vec<(&str, Noise)> = Vec::new();
    for rig in ["free pendulum", "torsion pendulum", "slide", "stroke"] {
        for kind in NOISES {
            jobs.push((rig, kind));
        }
    }
    jobs.par_iter()
        .enumerate()
        .map(|(k, &(rig, kind))| {
            let seed = 700 + 10 * k as u64;
            let label = format!("{rig}, {kind:?}");
            let result = match rig {
                "free pendulum" | "torsion pendulum" => {
                    let (truth, osc) = if rig == "free pendulum" {
                        free_pendulum()
                    } else {
                        torsion_pendulum()
                    };
                    let recs = released(&truth, &[1.0, 1.5], 6.0, kind, 2e-4, seed);
                    let mut opts = FitOptions::default();
                    if rig == "free pendulum" {
                        opts.params.oscillator = vec![OscillatorParam::GravityMoment];
                    }
                    let model = law(correct, 0.8 * truth.coulomb, 0.5 * truth.viscous);
                    fit(&osc, model.as_ref(), &recs, &opts)
                }
                "slide" => {
                    let (truth, osc) = slide();
                    let recs = released(&truth, &[0.010, 0.022], 1.5, kind, 5e-7, seed);
                    let model = law(correct, 0.18, 1.0);
                    fit(&osc, model.as_ref(), &recs, &FitOptions::default())
                }
                _ => {
                    let (osc, opts) = no_oscillator_force_options();
                    let model = law(correct, 2.5, 100.0);
                    fit(&osc, model.as_ref(), &[stroke(kind, seed)], &opts)
                }
            };
            (
                label,
                result.unwrap_or_else(|e| panic!("{rig} {kind:?}: {e}")),
            )
        })
        .collect()
}

#[test]
fn correct_laws_on_pendulums_and_displacement_channels_raise_no_failed_diagnostic() {
    let outcomes = cases(true);
    let alarmed = false_alarms(&outcomes);
    assert!(alarmed.is_empty(), "false alarms: {alarmed:?}");
}

#[test]
fn a_wrong_law_on_pendulums_and_displacement_channels_is_flagged() {
    let outcomes = cases(false);
    let missed = unflagged(&outcomes);
    assert!(missed.is_empty(), "not flagged: {missed:?}");
}
