//! Synthetic FMM records made by the engine with known truths and noise: the oracles of the
//! identifier's recovery tests.
#![allow(dead_code)]

use frictionid_engine::identify::{
    fit, Check, Finding, FitDomain, FitOptions, FitResult, ForceTarget, OscillatorParam,
    ParamOptions, Status, TargetOptions,
};
use frictionid_engine::oscillator::{OscillatorProperty, PartialOscillator};
use frictionid_engine::record::{Channel, TimeBase};
use frictionid_engine::simulate::{simulate_driven, Input, RunInputs, SampleGrid, Trajectory};
use frictionid_engine::synthetic::release_records;
use frictionid_engine::{Initial, Oscillator, Record, SimOptions};
use frictionid_models::{Coulomb, FrictionModel, Gms, LuGre, Stribeck};
use std::f64::consts::PI;

/// A tone of a multisine: amplitude, frequency [Hz] and phase [rad].
pub type Tone = (f64, f64, f64);

/// The multisine of `tones` at time `t`: the sum of a sin(2 pi f t + phase).
pub fn multisine(tones: &[Tone], t: f64) -> f64 {
    tones
        .iter()
        .map(|&(a, f, phase)| a * (2.0 * PI * f * t + phase).sin())
        .sum()
}

/// Four tones of 12, 8, 5 and 3 N at `first`, 1.9, 3.3 and 5.1 Hz, their phases (0, 1, 2 and
/// 0.5 rad) shifted by `shift` rad: the input of the driven-slide tests.
pub fn four_tones(first: f64, shift: f64) -> [Tone; 4] {
    [
        (12.0, first, shift),
        (8.0, 1.9, 1.0 + shift),
        (5.0, 3.3, 2.0 + shift),
        (3.0, 5.1, 0.5 + shift),
    ]
}

/// Five tones from 0.3 to 3.4 Hz of 12, 8, 6, 4 and 3 N times `gain`: the input of the
/// inverse-dynamics drives.
pub fn five_tones(gain: f64) -> [Tone; 5] {
    [
        (12.0 * gain, 0.3, 0.0),
        (8.0 * gain, 0.7, 1.1),
        (6.0 * gain, 1.3, 2.3),
        (4.0 * gain, 2.1, 0.4),
        (3.0 * gain, 3.4, 4.0),
    ]
}

/// The sample times of `duration` seconds at `rate` Hz from 0, both ends included.
pub fn sample_times(duration: f64, rate: f64) -> Vec<f64> {
    let n = (duration * rate) as usize + 1;
    (0..n).map(|i| i as f64 / rate).collect()
}

/// d(series)/dp at every sample by central differences with steps h and h/2 (h = 1e-6 of |p|,
/// 1e-6 at p = 0), extrapolated: `series(value)` is the series with the parameter at `value`.
pub fn central_difference(p: f64, series: impl Fn(f64) -> Vec<f64>) -> Vec<f64> {
    let h = 1e-6 * if p == 0.0 { 1.0 } else { p.abs() };
    let central = |h: f64| -> Vec<f64> {
        let (up, down) = (series(p + h), series(p - h));
        up.iter()
            .zip(&down)
            .map(|(a, b)| (a - b) / (2.0 * h))
            .collect()
    };
    let (wide, narrow) = (central(h), central(0.5 * h));
    wide.iter().zip(&narrow).map(|(w, n)| 2.0 * n - w).collect()
}

/// `derivative(k)` is within `rtol` of the largest |expected| of `expected[k]` at every sample;
/// `what` names the derivative in the failure.
pub fn assert_derivative_matches(
    derivative: impl Fn(usize) -> f64,
    expected: &[f64],
    rtol: f64,
    what: &str,
) {
    let largest = expected.iter().fold(0.0f64, |a, e| a.max(e.abs()));
    let worst = (0..expected.len())
        .map(|k| (derivative(k) - expected[k]).abs())
        .fold(0.0f64, f64::max);
    assert!(
        worst <= rtol * largest,
        "{what}: worst difference {worst:e}, largest derivative {largest:e}"
    );
}

/// |a - b| / |b|: the relative error of `a` against the truth `b`.
pub fn rel(a: f64, b: f64) -> f64 {
    (a - b).abs() / b.abs()
}

/// Coulomb friction of start level `mu` fitted to `records` from `start`, with the
/// oscillator properties `free` fitted alongside (the rest of the options the defaults).
pub fn fit_coulomb_and_properties(
    start: &Oscillator,
    mu: f64,
    free: Vec<OscillatorParam>,
    records: &[Record],
) -> FitResult {
    let opts = FitOptions {
        params: ParamOptions {
            oscillator: free,
            ..ParamOptions::default()
        },
        ..FitOptions::default()
    };
    fit(start, &Coulomb { mu }, records, &opts).expect("a fit")
}

/// The releases of the paper: 10, 14 and 22 mm.
pub const RELEASES: [f64; 3] = [0.010, 0.014, 0.022];
/// The noise level of the acceptance set-up [m/s].
pub const NOISE: f64 = 2e-4;

/// Records of `model` on `osc` from the three releases, 2 s at 1 kHz, with Gaussian noise of
/// `noise` m/s (seeds `seed`, `seed + 1`, `seed + 2`).
pub fn records(osc: &Oscillator, model: &dyn FrictionModel, noise: f64, seed: u64) -> Vec<Record> {
    release_records(osc, model, &RELEASES, 2.0, 1000.0, noise, seed)
        .expect("simulation of the truth")
}

/// GMS with two elements (stiffnesses 1.5e5 and 2e4 N/m, weights 0.6 and 0.4, undamped) over
/// a Stribeck curve mu_c 0.20, mu_s 0.27, v_s 0.01 m/s.
pub fn two_element_gms() -> Gms {
    let mut truth = Gms::with_elements(2);
    truth.elements[0].stiffness = 1.5e5;
    truth.elements[0].weight = 0.6;
    truth.elements[1].stiffness = 2e4;
    truth.elements[1].weight = 0.4;
    truth.mu_c = 0.2;
    truth.mu_s = 0.27;
    truth.v_s = 0.01;
    truth
}

/// The LuGre truth of the dynamic-model recovery tests: sigma0 1e5 N/m, sigma1
/// 500 N s/m, sigma2 1 N s/m, mu_c 0.22, mu_s 0.30, v_s 0.01 m/s.
pub fn lugre_truth() -> LuGre {
    LuGre {
        sigma0: 1e5,
        sigma1: 500.0,
        sigma2: 1.0,
        mu_c: 0.22,
        mu_s: 0.30,
        v_s: 0.01,
    }
}

/// The stiff LuGre truth of the recovery tests: bristles of sigma0 1e7 N/m.
pub fn stiff_lugre_truth() -> LuGre {
    LuGre {
        sigma0: 1e7,
        sigma1: 4000.0,
        sigma2: 2.0,
        mu_c: 0.18,
        mu_s: 0.26,
        v_s: 0.005,
    }
}

/// LuGre bristles too stiff for a 1 kHz vibrometer on the FMM stage: sigma0 1e10 N/m (the
/// bristle rings at sqrt(sigma0 / m) / 2 pi = 4.9 kHz, above 1 kHz's Nyquist frequency and
/// below 20 kHz's; a presliding displacement of 0.26 nm), lightly damped (sigma1 13 000 N s/m,
/// a damping ratio of 0.02), sigma2 2 N s/m and the levels of [`stiff_lugre_truth`].
pub fn unresolved_lugre_truth() -> LuGre {
    LuGre {
        sigma0: 1e10,
        sigma1: 13_000.0,
        ..stiff_lugre_truth()
    }
}

/// A Stribeck law with a pronounced dip and viscous drag: mu_c 0.20, mu_s 0.28, v_s 0.02 m/s,
/// delta 2, viscous 3 N s/m.
pub fn stribeck_truth() -> Stribeck {
    Stribeck {
        mu_c: 0.20,
        mu_s: 0.28,
        v_s: 0.02,
        delta: 2.0,
        viscous: 3.0,
    }
}

/// The force route (`domain = "force"`), every other option at its default.
pub fn force_route_options() -> FitOptions {
    FitOptions {
        target: TargetOptions {
            domain: FitDomain::Force,
            ..TargetOptions::default()
        },
        ..FitOptions::default()
    }
}

/// The force route on a measured friction force, where only the normal force plays a part:
/// the mass, damping and stiffness unknown.
pub fn measured_force_options() -> FitOptions {
    let mut opts = force_route_options();
    opts.target.unknown_oscillator = vec![
        OscillatorProperty::Mass,
        OscillatorProperty::Damping,
        OscillatorProperty::Stiffness,
    ];
    opts
}

/// The force route with no oscillator given (every property unknown, the levels forces in N):
/// the placeholder oscillator and the options.
pub fn no_oscillator_force_options() -> (Oscillator, FitOptions) {
    let (osc, unknown) = PartialOscillator::default().resolve();
    let mut opts = force_route_options();
    opts.target.unknown_oscillator = unknown;
    (osc, opts)
}

/// Inverse dynamics of a driven axis (`force_target = "inverse_dynamics"`): the mass and an
/// input offset fitted, no normal force and no spring given.
pub fn inverse_dynamics_options() -> (Oscillator, FitOptions) {
    let (osc, mut opts) = no_oscillator_force_options();
    opts.target.force_target = ForceTarget::InverseDynamics;
    opts.target.force_offset = true;
    opts.params.oscillator = vec![OscillatorParam::Mass];
    (osc, opts)
}

/// `opts` run on one thread (results that must not depend on the machine's cores).
pub fn serial(mut opts: FitOptions) -> FitOptions {
    opts.hooks.parallel = false;
    opts
}

/// `names` as the free-parameter list of [`ParamOptions::free`](frictionid_engine::identify::ParamOptions).
pub fn free(names: &[&str]) -> Option<Vec<String>> {
    Some(names.iter().map(|s| s.to_string()).collect())
}

/// The motion of `osc` with friction `model` from rest at t = 0 under the input `u` sampled at
/// the times `t` (linear between samples), sampled at the same times.
pub fn driven_from_rest(
    osc: &Oscillator,
    model: &dyn FrictionModel,
    t: &[f64],
    u: &[f64],
) -> Trajectory {
    let input = Input::new(t.to_vec(), u.to_vec()).expect("an input");
    simulate_driven(RunInputs {
        osc,
        model,
        init: &Initial::at_rest(0.0),
        input: Some(&input),
        channels: None,
        grid: SampleGrid {
            t_end: *t.last().expect("samples"),
            sample_times: t,
        },
        opts: &SimOptions::default(),
    })
    .expect("a simulation")
}

/// (value, standard error) of the fitted parameter `name` (or of its first per-record copy
/// `name[...]`); the standard error NaN where there is none.
pub fn estimate(result: &FitResult, name: &str) -> (f64, f64) {
    let p = result
        .parameters
        .iter()
        .find(|p| p.name == name || p.name.starts_with(&format!("{name}[")))
        .unwrap_or_else(|| panic!("no parameter {name}"));
    (p.value, p.std_error.unwrap_or(f64::NAN))
}

/// The finding of `check` in `result`, if the fit made one.
pub(crate) fn finding(result: &FitResult, check: Check) -> Option<&Finding> {
    result.diagnostics.iter().find(|d| d.check == check)
}

/// Asserts that `result` warns or fails `check`.
pub(crate) fn assert_flagged(result: &FitResult, check: Check) {
    let f =
        finding(result, check).unwrap_or_else(|| panic!("{}: no {check:?} finding", result.model));
    assert!(
        matches!(f.status, Status::Warn | Status::Fail),
        "{}: {}",
        result.model,
        f.message
    );
}

/// The diagnostics of `result` with `status`, each as "check: message".
pub(crate) fn findings_at(result: &FitResult, status: Status) -> Vec<String> {
    result
        .diagnostics
        .iter()
        .filter(|d| d.status == status)
        .map(|d| format!("{:?}: {}", d.check, d.message))
        .collect()
}

/// The labels of the correct fits among `outcomes` that fail a diagnostic (a false alarm),
/// each fit's findings printed for the reader of a failing run.
pub(crate) fn false_alarms(outcomes: &[(String, FitResult)]) -> Vec<String> {
    let mut alarmed = Vec::new();
    for (label, result) in outcomes {
        let failed = findings_at(result, Status::Fail);
        let warned = findings_at(result, Status::Warn);
        eprintln!(
            "{label}: rms {:.3e}, {} failed, {} warned",
            result.rms_residual,
            failed.len(),
            warned.len()
        );
        for w in &warned {
            eprintln!("  warn {w}");
        }
        if !failed.is_empty() {
            alarmed.push(label.clone());
            eprintln!("  {}", failed.join("\n  "));
        }
    }
    eprintln!(
        "{} false alarms in {} correct fits",
        alarmed.len(),
        outcomes.len()
    );
    alarmed
}

/// The labels of the wrong-law fits among `outcomes` that neither warn nor fail (a miss).
pub(crate) fn unflagged(outcomes: &[(String, FitResult)]) -> Vec<String> {
    let mut missed = Vec::new();
    for (label, result) in outcomes {
        let flagged: Vec<String> = [Status::Warn, Status::Fail]
            .into_iter()
            .flat_map(|s| findings_at(result, s))
            .collect();
        eprintln!("{label}: rms {:.3e}, {flagged:?}", result.rms_residual);
        if flagged.is_empty() {
            missed.push(label.clone());
        }
    }
    eprintln!(
        "{} of {} wrong fits flagged",
        outcomes.len() - missed.len(),
        outcomes.len()
    );
    missed
}

/// Classical Runge-Kutta steps per sample of [`rk4_free_decay`] at 1 kHz: a step of 10 us,
/// a tenth of the bristles' fastest relaxation time on the FMM records (sigma0 |v| / g,
/// about 1e4 /s at 0.3 m/s for a bristle stiffness of 1e5 N/m).
pub const RK4_SUBSTEPS: usize = 100;

/// The free decay of `osc` (its mass, damping, linear stiffness and normal force) with the
/// friction law `model` released from rest at `x0` with relaxed (zero) internal states:
/// m x'' + c x' + k x + F(v, z, N) = 0 with dz/dt = h(v, z, N), integrated by fixed-step
/// classical Runge-Kutta over the whole state (x, v, z), `substeps` steps per sample, and
/// sampled at `rate` Hz for `duration` s (both ends included): times and velocities. An
/// independent reference for the engine's simulator: it reads only the law's public `force`
/// and `state_derivative`, locates no events and so suits smooth laws (LuGre, Dahl, GMS),
/// not a switching one that sticks.
pub fn rk4_free_decay(
    osc: &Oscillator,
    model: &dyn FrictionModel,
    x0: f64,
    (duration, rate, substeps): (f64, f64, usize),
) -> (Vec<f64>, Vec<f64>) {
    let n_z = model.n_states();
    let states = model.states();
    let (m, c, k, normal) = (osc.mass, osc.damping, osc.stiffness, osc.normal_force);
    let rhs = |y: &[f64], dy: &mut [f64]| {
        let (v, z) = (y[1], &y[2..]);
        if let Some(s) = states {
            s.state_derivative(v, z, normal, &mut dy[2..]);
        }
        let f = model.force(v, z, normal);
        dy[0] = v;
        dy[1] = -(c * v + k * y[0] + f) / m;
    };
    let h = 1.0 / (rate * substeps as f64);
    let mut y = vec![0.0; 2 + n_z];
    y[0] = x0;
    let mut ks = vec![vec![0.0; 2 + n_z]; 4];
    let mut stage = vec![0.0; 2 + n_z];
    let times = sample_times(duration, rate);
    let mut v = Vec::with_capacity(times.len());
    for _ in &times {
        v.push(y[1]);
        for _ in 0..substeps {
            for s in 0..4 {
                let a = [0.0, 0.5, 0.5, 1.0][s];
                for (i, st) in stage.iter_mut().enumerate() {
                    *st = y[i] + if s == 0 { 0.0 } else { a * h * ks[s - 1][i] };
                }
                rhs(&stage, &mut ks[s]);
            }
            for (i, yi) in y.iter_mut().enumerate() {
                *yi += h / 6.0 * (ks[0][i] + 2.0 * ks[1][i] + 2.0 * ks[2][i] + ks[3][i]);
            }
        }
    }
    (times, v)
}

/// Records of `model` on `osc` from the three [`RELEASES`], 2 s at 1 kHz, made by
/// [`rk4_free_decay`] (not by the engine's simulator), with Gaussian velocity noise of
/// `noise` m/s (seeds `seed`, `seed + 1`, `seed + 2`), named as [`records`] names them.
pub fn rk4_records(
    osc: &Oscillator,
    model: &dyn FrictionModel,
    noise: f64,
    seed: u64,
) -> Vec<Record> {
    RELEASES
        .iter()
        .enumerate()
        .map(|(i, &x0)| {
            let (t, mut v) = rk4_free_decay(osc, model, x0, (2.0, 1000.0, RK4_SUBSTEPS));
            frictionid_engine::synthetic::add_gaussian_noise(&mut v, noise, seed + i as u64);
            Record::new(format!("x{}mm", (x0 * 1e3).round()), t, v, x0)
        })
        .collect()
}

/// The free decay of a linear oscillator (inertia `inertia`, stiffness `stiffness`, viscous
/// damping `damping`) with Coulomb friction of level `coulomb` whose static level equals it,
/// released from rest at `x0`, in closed form: between two stops the motion is a damped
/// oscillation about the offset centre -coulomb d / stiffness (d the direction of motion),
/// each half-cycle lasting pi / omega_d; at a turning point where the spring's force is
/// within `coulomb` the oscillator sticks for good. An event-locating reference independent
/// of the engine's driver and its closed-form stepper.
#[derive(Debug, Clone, Copy)]
pub struct CoulombDecay {
    /// Mass or inertia.
    pub inertia: f64,
    /// Linear stiffness.
    pub stiffness: f64,
    /// Viscous damping (the oscillator's and the law's viscous term together).
    pub damping: f64,
    /// Coulomb level.
    pub coulomb: f64,
    /// Release displacement.
    pub x0: f64,
}

impl CoulombDecay {
    /// The undamped and damped angular frequencies and the damping ratio.
    fn frequencies(&self) -> (f64, f64, f64) {
        let omega = (self.stiffness / self.inertia).sqrt();
        let zeta = self.damping / (2.0 * (self.stiffness * self.inertia).sqrt());
        (omega, omega * (1.0 - zeta * zeta).sqrt(), zeta)
    }

    /// Each slip phase's start time, release displacement and direction, and the time the
    /// oscillator sticks.
    pub fn slips(&self) -> (Vec<(f64, f64, f64)>, f64) {
        let (omega, omega_d, zeta) = self.frequencies();
        let half = PI / omega_d;
        let (mut q, mut t) = (self.x0, 0.0);
        let mut out = Vec::new();
        while self.stiffness * q.abs() > self.coulomb {
            let d = -q.signum();
            out.push((t, q, d));
            let centre = -self.coulomb * d / self.stiffness;
            q = centre - (q - centre) * (-zeta * omega * half).exp();
            t += half;
        }
        (out, t)
    }

    /// The velocity at each of `times`.
    pub fn velocity(&self, times: &[f64]) -> Vec<f64> {
        let (omega, omega_d, zeta) = self.frequencies();
        let (slips, stuck_at) = self.slips();
        times
            .iter()
            .map(|&t| {
                let slip = slips.iter().rev().find(|s| s.0 <= t);
                match slip {
                    Some(&(start, q0, d)) if t < stuck_at => {
                        let u0 = q0 + self.coulomb * d / self.stiffness;
                        let tau = t - start;
                        -u0 * omega * omega / omega_d
                            * (-zeta * omega * tau).exp()
                            * (omega_d * tau).sin()
                    }
                    _ => 0.0,
                }
            })
            .collect()
    }
}

/// The samples `s` taken at `rate` from t = 0, linear between them (as the engine reads an
/// input and a channel), the last interval extended beyond the end.
pub fn linear_between_samples(s: &[f64], rate: f64, t: f64) -> f64 {
    let i = ((t * rate).floor() as usize).min(s.len() - 2);
    let w = t * rate - i as f64;
    s[i] + w * (s[i + 1] - s[i])
}

/// The Coulomb level L(t, x, d) >= 0 \[N\] of a [`SlideReference`] at time t and position x,
/// sliding or breaking away in the direction d (+1 or -1).
pub type SlideLevel<'a> = &'a dyn Fn(f64, f64, f64) -> f64;

/// An independent reference for a driven slide without a spring,
/// M a + c v + d L(t, x, d) = u(t) while sliding in d, stuck while -L(t, x, -1) <= u <=
/// L(t, x, +1): classical Runge-Kutta (1e-5 s, never across a sample time), the reversals
/// located by bisection on the step and the stick's end bisected.
pub struct SlideReference<'a> {
    /// The mass M \[kg\] and the viscous coefficient c \[N s/m\].
    mass: f64,
    viscous: f64,
    /// The input's samples \[N\] at `rate` \[Hz\] from t = 0, linear between them.
    u: &'a [f64],
    rate: f64,
    level: SlideLevel<'a>,
}

impl<'a> SlideReference<'a> {
    /// The Runge-Kutta step \[s\].
    const STEP: f64 = 1e-5;

    /// The slide of mass `mass` and viscous coefficient `viscous` under the input samples
    /// `u` taken at `rate` from t = 0, with the level `level`.
    pub fn new(
        mass: f64,
        viscous: f64,
        (u, rate): (&'a [f64], f64),
        level: SlideLevel<'a>,
    ) -> Self {
        Self {
            mass,
            viscous,
            u,
            rate,
            level,
        }
    }

    /// The record `name` of the motion from rest at the input's sample times: displacement,
    /// velocity and the input.
    pub fn record(&self, name: &str) -> Record {
        let time: Vec<f64> = (0..self.u.len()).map(|i| i as f64 / self.rate).collect();
        let (xs, vs) = self.motion_from_rest(&time);
        Record::from_time_base(name, TimeBase::new(time).expect("a time base"))
            .with_channel(Channel::Displacement, xs)
            .with_channel(Channel::Velocity, vs)
            .with_channel(Channel::InputForce, self.u.to_vec())
    }

    /// The direction a slide stuck at x breaks away in at time t, or 0 while it holds.
    pub fn breakaway(&self, t: f64, x: f64) -> f64 {
        let u = linear_between_samples(self.u, self.rate, t);
        if u > (self.level)(t, x, 1.0) {
            1.0
        } else if u < -(self.level)(t, x, -1.0) {
            -1.0
        } else {
            0.0
        }
    }

    /// One RK4 step of (x, v) sliding in `d` from `t`.
    fn rk4(&self, t: f64, (x, v): (f64, f64), d: f64, h: f64) -> (f64, f64) {
        let acc = |t: f64, x: f64, v: f64| {
            (linear_between_samples(self.u, self.rate, t)
                - self.viscous * v
                - d * (self.level)(t, x, d))
                / self.mass
        };
        let (k1x, k1v) = (v, acc(t, x, v));
        let (k2x, k2v) = (
            v + 0.5 * h * k1v,
            acc(t + 0.5 * h, x + 0.5 * h * k1x, v + 0.5 * h * k1v),
        );
        let (k3x, k3v) = (
            v + 0.5 * h * k2v,
            acc(t + 0.5 * h, x + 0.5 * h * k2x, v + 0.5 * h * k2v),
        );
        let (k4x, k4v) = (v + h * k3v, acc(t + h, x + h * k3x, v + h * k3v));
        (
            x + h / 6.0 * (k1x + 2.0 * k2x + 2.0 * k3x + k4x),
            v + h / 6.0 * (k1v + 2.0 * k2v + 2.0 * k3v + k4v),
        )
    }

    /// From (t, x, v, d) to `until`: slipping, reversing or stuck.
    fn advance(&self, state: (f64, f64, f64, f64), until: f64) -> (f64, f64, f64, f64) {
        let (mut t, mut x, mut v, mut d) = state;
        while t < until {
            let h = Self::STEP.min(until - t);
            if d == 0.0 {
                if self.breakaway(t + h, x) == 0.0 {
                    t += h;
                    continue;
                }
                let (mut lo, mut hi) = (t, t + h);
                for _ in 0..80 {
                    let mid = 0.5 * (lo + hi);
                    if self.breakaway(mid, x) == 0.0 {
                        lo = mid;
                    } else {
                        hi = mid;
                    }
                }
                t = hi;
                d = self.breakaway(t, x);
                continue;
            }
            let (x1, v1) = self.rk4(t, (x, v), d, h);
            if d * v1 > 0.0 {
                (t, x, v) = (t + h, x1, v1);
                continue;
            }
            let (mut lo, mut hi) = (0.0, h);
            for _ in 0..60 {
                let mid = 0.5 * (lo + hi);
                if d * self.rk4(t, (x, v), d, mid).1 > 0.0 {
                    lo = mid;
                } else {
                    hi = mid;
                }
            }
            x = self.rk4(t, (x, v), d, hi).0;
            (t, v) = (t + hi, 0.0);
            d = self.breakaway(t, x);
        }
        (t, x, v, d)
    }

    /// The displacement and velocity from rest at x = 0 and t = 0, sampled at `time`.
    pub fn motion_from_rest(&self, time: &[f64]) -> (Vec<f64>, Vec<f64>) {
        let mut state = (0.0, 0.0, 0.0, self.breakaway(0.0, 0.0));
        let (mut xs, mut vs) = (
            Vec::with_capacity(time.len()),
            Vec::with_capacity(time.len()),
        );
        for &t_sample in time {
            state = self.advance(state, t_sample);
            xs.push(state.1);
            vs.push(state.2);
        }
        (xs, vs)
    }
}

/// `samples` at 1 kHz of a driven axis's three-tone velocity that reverses (0.05, 0.03 and
/// 0.01 m/s at 0.3, 1.1 and 2.9 Hz): the times and the velocities.
pub fn three_tone_drive(samples: usize) -> (Vec<f64>, Vec<f64>) {
    const TONES: [(f64, f64, f64); 3] = [(0.05, 0.3, 0.0), (0.03, 1.1, 1.0), (0.01, 2.9, 2.0)];
    let time: Vec<f64> = (0..samples).map(|i| i as f64 * 1e-3).collect();
    let v = time
        .iter()
        .map(|&t| {
            TONES
                .iter()
                .map(|&(a, f, p)| a * (std::f64::consts::TAU * f * t + p).sin())
                .sum()
        })
        .collect();
    (time, v)
}
