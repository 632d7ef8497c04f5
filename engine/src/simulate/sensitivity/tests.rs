//! The sensitivities against independent differences of plain simulations: central
//! differences away from turning points for smooth responses (LuGre, Stribeck with an
//! oscillator property free, GMS), and a brute-force perturbation p +- h over a whole record that
//! sticks and slips (Coulomb), where the jumps at the events carry the sensitivities across.

use super::*;
use crate::oscillator::Oscillator;
use crate::simulate::{simulate_driven, Initial, Input, SampleGrid, SimOptions, Trajectory};
use frictionid_models::{Coulomb, FrictionModel, LuGre, Stribeck};

/// Tight options, so that the differences of plain runs are accurate.
fn tight() -> SimOptions {
    SimOptions::tight_dopri5()
}

fn times(seconds: f64) -> Vec<f64> {
    (0..=(seconds * 1e3) as usize)
        .map(|i| i as f64 * 1e-3)
        .collect()
}

/// A world: the oscillator, the law, the release displacement, the integrator of its
/// plain runs (at the tight tolerances) and the measured input driving it, if any.
#[derive(Clone)]
struct World {
    osc: Oscillator,
    model: Box<dyn FrictionModel>,
    x0: f64,
    plain: Integrator,
    input: Option<Input>,
}

impl World {
    fn plain(&self, time: &[f64]) -> Trajectory {
        let init = Initial {
            x0: self.x0,
            v0: 0.0,
            z0: None,
        };
        let opts = SimOptions {
            integrator: self.plain,
            ..tight()
        };
        simulate_driven(self.inputs(&init, time, &opts)).unwrap()
    }

    /// A run of this world from `init`, sampled at `time`, with `opts`.
    fn inputs<'a>(
        &'a self,
        init: &'a Initial,
        time: &'a [f64],
        opts: &'a SimOptions,
    ) -> RunInputs<'a> {
        RunInputs {
            osc: &self.osc,
            model: self.model.as_ref(),
            init,
            input: self.input.as_ref(),
            channels: None,
            grid: SampleGrid {
                t_end: time.last().copied().unwrap_or(0.0),
                sample_times: time,
            },
            opts,
        }
    }

    fn sensitivities(&self, time: &[f64], params: &[SensitivityParam]) -> Sensitivities {
        self.try_sensitivities(time, params).unwrap()
    }

    /// The augmented run, `None` where it is not available or diverged.
    fn try_sensitivities(
        &self,
        time: &[f64],
        params: &[SensitivityParam],
    ) -> Option<Sensitivities> {
        let init = Initial {
            x0: self.x0,
            v0: 0.0,
            z0: None,
        };
        let opts = tight();
        let inputs = self.inputs(&init, time, &opts);
        simulate_sensitivities(inputs, params, SampledSeries::All).unwrap()
    }

    /// The world with `p` moved by `by`.
    fn moved(&self, p: SensitivityParam, by: f64) -> World {
        let mut w = self.clone();
        match p {
            SensitivityParam::Model(i) => {
                let mut values = w.model.params();
                values[i] += by;
                w.model.set_params(&values).unwrap();
            }
            SensitivityParam::Property(q) => w.osc = q.shifted(&w.osc, by),
            SensitivityParam::StartDisplacement => w.x0 += by,
        }
        w
    }

    fn value(&self, p: SensitivityParam) -> f64 {
        match p {
            SensitivityParam::Model(i) => self.model.params()[i],
            SensitivityParam::Property(q) => q.value(&self.osc).unwrap(),
            SensitivityParam::StartDisplacement => self.x0,
        }
    }

    /// Central differences of the sampled (x, v) along `p` with relative step `rel`.
    fn differences(&self, time: &[f64], p: SensitivityParam, rel: f64) -> (Vec<f64>, Vec<f64>) {
        let h = rel * self.value(p).abs().max(1e-3);
        let (plus, minus) = (self.moved(p, h).plain(time), self.moved(p, -h).plain(time));
        let quotient = |a: &[f64], b: &[f64]| -> Vec<f64> {
            a.iter().zip(b).map(|(a, b)| (a - b) / (2.0 * h)).collect()
        };
        (quotient(&plus.x, &minus.x), quotient(&plus.v, &minus.v))
    }
}

/// Whether sample `i` lies within `margin` samples of an event of `events`.
fn near_event(time: &[f64], events: &[f64], i: usize, margin: f64) -> bool {
    let dt = time.get(1).map_or(1.0, |t1| t1 - time[0]);
    events.iter().any(|&e| (time[i] - e).abs() <= margin * dt)
}

/// The largest difference between `got` and `expected` over the samples not excluded,
/// relative to the largest |expected|.
fn worst(got: &[f64], expected: &[f64], excluded: impl Fn(usize) -> bool) -> f64 {
    let scale = expected
        .iter()
        .fold(0.0f64, |m, e| m.max(e.abs()))
        .max(1e-300);
    let diff = got
        .iter()
        .zip(expected)
        .enumerate()
        .filter(|(i, _)| !excluded(*i))
        .fold(0.0f64, |m, (_, (g, e))| m.max((g - e).abs()));
    diff / scale
}

/// Checks every parameter's sampled sensitivities against central differences, away from
/// the turning points (a sample on each side), to `tol` of each column's scale.
fn check_against_differences(world: &World, time: &[f64], params: &[SensitivityParam], tol: f64) {
    check_against_differences_by(world, time, params, 1e-5, tol);
}

/// The same with central differences at the relative step `rel`.
fn check_against_differences_by(
    world: &World,
    time: &[f64],
    params: &[SensitivityParam],
    rel: f64,
    tol: f64,
) {
    let sens = world.sensitivities(time, params);
    let plain = world.plain(time);
    let events: Vec<f64> = plain.events.iter().map(|e| e.time).collect();
    assert!(events.len() >= 2, "the record holds turning points");
    for (i, (got, expected)) in sens.v.iter().zip(&plain.v).enumerate() {
        assert!((got - expected).abs() < 1e-7, "v[{i}] {got} vs {expected}");
    }
    for (j, &p) in params.iter().enumerate() {
        let (dx, dv) = world.differences(time, p, rel);
        let away = |i: usize| near_event(time, &events, i, 1.0);
        let ex = worst(&sens.dx[j], &dx, away);
        let ev = worst(&sens.dv[j], &dv, away);
        assert!(
            ex < tol && ev < tol,
            "{p:?}: dx off by {ex:e}, dv by {ev:e}"
        );
    }
}

#[test]
fn lugre_sensitivities_match_central_differences() {
    let world = released(Box::new(LuGre::default()), Integrator::Dopri5);
    let params = [
        SensitivityParam::Model(0),
        SensitivityParam::Model(1),
        SensitivityParam::Model(3),
        SensitivityParam::Model(5),
        SensitivityParam::Property(OscillatorProperty::Stiffness),
        SensitivityParam::StartDisplacement,
    ];
    check_against_differences(&world, &times(0.6), &params, 1e-4);
}

#[test]
fn stribeck_sensitivities_with_a_free_damping_match_central_differences() {
    let world = released(Box::new(Stribeck::default()), Integrator::Dopri5);
    let params = [
        SensitivityParam::Model(0),
        SensitivityParam::Model(1),
        SensitivityParam::Model(2),
        SensitivityParam::Model(4),
        SensitivityParam::Property(OscillatorProperty::Damping),
        SensitivityParam::Property(OscillatorProperty::Mass),
    ];
    check_against_differences(&world, &times(0.6), &params, 1e-4);
}

/// GMS (three elements soft enough for the augmented Dopri5 run, damped, at a sharpness
/// without a closed form) on the FMM stage: every
/// element's stiffness, weight and damping, the Stribeck parameters, the sharpness and the
/// viscous term against central differences.
#[test]
fn gms_sensitivities_match_central_differences() {
    let built = frictionid_models::build_json(&serde_json::json!({
        "type": "gms", "stiffness": [3.0e4, 1.0e4, 3.0e3], "damping": 2.0, "sharpness": 1.6
    }))
    .unwrap();
    let world = released(built.model, Integrator::Dopri5);
    assert!(world.model.params().len() == 15, "three elements");
    let params = [0, 2, 4, 6, 8, 9, 10, 11, 13, 14].map(SensitivityParam::Model);
    // The elements' compliance leaves the plain runs' integration error 1e-3 times the
    // LuGre case's relative to some columns (the dampings'): a step of 1e-3, whose truncation
    // error is about 1e-6, keeps it out of the differences.
    check_against_differences_by(&world, &times(0.6), &params, 1e-3, 1e-3);
}

/// Dahl at sigma0 = 3e5 N/m released from 22 mm: after 1.16 s, sliding at a few cm/s, the
/// explicit augmented run's steps (set by the states' error) pass the sensitivities' stability
/// bound and they grew to 1e215 while the states stayed right. The run is given up (`None`:
/// a fit takes difference quotients); central differences of plain runs show that the true
/// sensitivities stay within a thousand times the motion's scale over the whole record.
#[test]
fn a_diverging_explicit_run_is_given_up() {
    let world = released(
        Box::new(frictionid_models::Dahl {
            sigma0: 3e5,
            mu_c: 0.21,
            alpha: 1.0,
        }),
        Integrator::Dopri5,
    );
    let time = times(2.0);
    let params: Vec<_> = (0..3).map(SensitivityParam::Model).collect();
    assert!(world.try_sensitivities(&time, &params).is_none());
    let values = world.model.params();
    let speed = 2.0 * std::f64::consts::PI / world.osc.natural_period() * world.x0;
    for (j, &p) in params.iter().enumerate() {
        let (_, dv) = world.differences(&time, p, 1e-4);
        let largest = dv.iter().fold(0.0f64, |m, d| m.max(d.abs())) * values[j].abs();
        assert!(
            largest.is_finite() && largest < 1e3 * speed,
            "{p:?}: {largest:e}"
        );
    }
}

/// Whether the augmented run took the stiff stepper: its Jacobian evaluations include those
/// of the stepper's linear systems, so they exceed its right-hand sides (the explicit run
/// evaluates one Jacobian per right-hand side).
fn took_the_stiff_stepper(sens: &Sensitivities) -> bool {
    sens.stats.jacobian_evaluations > sens.stats.rhs_evaluations
}

/// `model` on the FMM stage released from 22 mm, its plain runs on `plain`.
fn released(model: Box<dyn FrictionModel>, plain: Integrator) -> World {
    World {
        osc: Oscillator::fmm(),
        model,
        x0: 0.022,
        plain,
        input: None,
    }
}

/// LuGre with sigma0 = 1e7 N/m is far beyond the explicit augmented run's stiffness: its
/// sensitivities come from Rodas4, and match central differences of plain Rodas4 runs at the
/// tight tolerances (every parameter, a property and the release).
#[test]
fn stiff_lugre_sensitivities_from_the_stiff_stepper_match_central_differences() {
    let model = LuGre {
        sigma0: 1e7,
        sigma1: 5000.0,
        ..LuGre::default()
    };
    let world = released(Box::new(model), Integrator::Rodas);
    let law: Vec<_> = (0..6).map(SensitivityParam::Model).collect();
    let time = times(0.6);
    assert!(took_the_stiff_stepper(&world.sensitivities(&time, &law)));
    // The stiff plain runs' integration error would swamp differences at the default step
    // for sigma0 and sigma1, which barely move a motion this close to the rigid limit.
    check_against_differences_by(&world, &time, &law, 1e-3, 1e-4);
    // The stiffness moves the turning points: at the default step the samples next to them
    // stay on the same side in the perturbed runs.
    let mechanics = [
        SensitivityParam::Property(OscillatorProperty::Stiffness),
        SensitivityParam::StartDisplacement,
    ];
    check_against_differences(&world, &time, &mechanics, 1e-4);
}

/// The default GMS (three elements of 1e5, 3.3e4 and 1.1e4 N/m) is stiff when its elements
/// load: every parameter's sensitivity from the stiff stepper against central differences.
#[test]
fn stiff_gms_sensitivities_from_the_stiff_stepper_match_central_differences() {
    let built = frictionid_models::build_json(&serde_json::json!({
        "type": "gms", "damping": 2.0, "sharpness": 1.6
    }))
    .unwrap();
    let world = released(built.model, Integrator::Rodas);
    let params: Vec<_> = (0..15).map(SensitivityParam::Model).collect();
    let time = times(0.6);
    assert!(took_the_stiff_stepper(&world.sensitivities(&time, &params)));
    // The elements' dampings move the motion by a few parts in a million of the others'
    // columns: a step of 1e-2 keeps the plain runs' integration error out of their
    // differences.
    check_against_differences_by(&world, &time, &params, 1e-2, 1e-3);
}

/// The explicit augmented run is told apart from the stiff one by its counts.
#[test]
fn a_soft_contact_keeps_the_explicit_stepper() {
    let world = released(Box::new(LuGre::default()), Integrator::Dopri5);
    let sens = world.sensitivities(&times(0.2), &[SensitivityParam::Model(0)]);
    assert!(!took_the_stiff_stepper(&sens));
}

/// Coulomb on the FMM stage from 10 mm reverses a few times and sticks for good: over the
/// whole record (rest included) the sensitivities equal the difference of two simulations at
/// p +- h, but for the samples between the events of the two (one on each side of each
/// event).
#[test]
fn coulomb_sensitivities_carry_across_reversals_and_the_stick() {
    let world = World {
        osc: Oscillator::fmm(),
        model: Box::new(Coulomb { mu: 0.24 }),
        x0: 0.010,
        plain: Integrator::Dopri5,
        input: None,
    };
    let time = times(1.5);
    let params = [
        SensitivityParam::Model(0),
        SensitivityParam::StartDisplacement,
        SensitivityParam::Property(OscillatorProperty::Stiffness),
    ];
    let sens = world.sensitivities(&time, &params);
    let plain = world.plain(&time);
    assert!(plain.rest.is_some(), "the motion sticks");
    let events: Vec<f64> = plain.events.iter().map(|e| e.time).collect();
    assert!(events.len() >= 3, "{events:?}");
    for (j, &p) in params.iter().enumerate() {
        let (dx, dv) = world.differences(&time, p, 1e-6);
        let near = |i: usize| near_event(&time, &events, i, 1.0);
        let (ex, ev) = (worst(&sens.dx[j], &dx, near), worst(&sens.dv[j], &dv, near));
        assert!(
            ex < 1e-5 && ev < 1e-5,
            "{p:?}: dx off by {ex:e}, dv by {ev:e}"
        );
        // At rest the velocity's sensitivity is zero and the displacement's that of the rest
        // position.
        let last = time.len() - 1;
        assert_eq!(sens.dv[j][last], 0.0);
        assert!((sens.dx[j][last] - dx[last]).abs() <= 1e-5 * dx[last].abs().max(1e-9));
    }
    // The stiffness moves the reversals (the half-period is pi / omega_n whatever mu and
    // x0): dv/dk jumps there by (a- - a+) dt_e/dk, a good part of its scale, which the
    // comparison above holds one sample after each event.
    let dv_dk = &sens.dv[2];
    let scale = dv_dk.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    let first = time.partition_point(|&t| t < events[0]);
    let continued = 2.0 * dv_dk[first - 2] - dv_dk[first - 3];
    let jump = dv_dk[first + 1] - continued;
    assert!(jump.abs() > 0.2 * scale, "jump {jump:e}, scale {scale:e}");
}

/// A plugin-like law without parameter gradients, a measured input or the Euler integrator:
/// no sensitivities, the caller takes differences.
#[test]
fn laws_without_gradients_and_driven_or_euler_runs_give_none() {
    let osc = Oscillator::fmm();
    let built = frictionid_models::build_json(&serde_json::json!({
        "type": "expression", "force": "mu * N * v / abs(v)", "params": { "mu": 0.2 }
    }))
    .unwrap();
    let init = Initial {
        x0: 0.01,
        v0: 0.0,
        z0: None,
    };
    let time = times(0.2);
    let run = |model: &dyn FrictionModel, opts: &SimOptions| {
        let inputs = RunInputs {
            osc: &osc,
            model,
            init: &init,
            input: None,
            channels: None,
            grid: SampleGrid {
                t_end: 0.2,
                sample_times: &time,
            },
            opts,
        };
        simulate_sensitivities(inputs, &[SensitivityParam::Model(0)], SampledSeries::All).unwrap()
    };
    assert!(run(built.model.as_ref(), &tight()).is_none());
    let euler = SimOptions {
        integrator: Integrator::Euler {
            steps_per_period: 1e4,
        },
        ..tight()
    };
    assert!(run(&Coulomb { mu: 0.2 }, &euler).is_none());
    assert!(run(&Coulomb { mu: 0.2 }, &tight()).is_some());
}

/// A sine force of `amplitude` newtons at `hz` sampled at 1 kHz (the knots of a measured
/// input) for `seconds`, from 0.
fn sine_force(amplitude: f64, hz: f64, seconds: f64) -> Input {
    let time = times(seconds);
    let value = time
        .iter()
        .map(|t| amplitude * (2.0 * std::f64::consts::PI * hz * t).sin())
        .collect();
    Input::new(time, value).unwrap()
}

/// A force of 8 N at 1.5 Hz: enough to slide the FMM stage against a 3 N level and reverse
/// it every third of a second.
fn shaker(seconds: f64) -> Input {
    sine_force(8.0, 1.5, seconds)
}

/// `model` on the FMM stage driven by `input` from rest, its plain runs on `plain`.
fn driven_world(model: Box<dyn FrictionModel>, plain: Integrator, input: Input) -> World {
    World {
        osc: Oscillator::fmm(),
        model,
        x0: 0.0,
        plain,
        input: Some(input),
    }
}

/// Under a measured input, LuGre's sensitivities follow the input from knot to knot and
/// across its reversals: every parameter, the mass and the stiffness against central
/// differences of plain driven runs.
#[test]
fn driven_lugre_sensitivities_match_central_differences() {
    let world = driven_world(Box::new(LuGre::default()), Integrator::Dopri5, shaker(1.0));
    let time = times(1.0);
    let mut params: Vec<_> = (0..6).map(SensitivityParam::Model).collect();
    params.extend([
        SensitivityParam::Property(OscillatorProperty::Mass),
        SensitivityParam::Property(OscillatorProperty::Stiffness),
    ]);
    assert!(!took_the_stiff_stepper(
        &world.sensitivities(&time, &params)
    ));
    check_against_differences(&world, &time, &params, 1e-4);
}

/// Checks the sensitivities of a driven switched law over a record that sticks and breaks
/// away under the input: against central differences of plain runs at p +- h, h = `rel`
/// times the parameter (the plain driver locates each breakaway exactly on the
/// piecewise-linear input), but for the samples next to the events, to `tol` of each
/// column's scale.
fn check_across_sticks(
    world: &World,
    time: &[f64],
    params: &[SensitivityParam],
    rel: f64,
    tol: f64,
) {
    let plain = world.plain(time);
    let breakaways = plain
        .events
        .iter()
        .filter(|e| e.kind == crate::simulate::EventKind::Breakaway)
        .count();
    assert!(breakaways >= 2, "{:?}", plain.events);
    let sens = world.sensitivities(time, params);
    for (i, (got, expected)) in sens.v.iter().zip(&plain.v).enumerate() {
        assert!((got - expected).abs() < 1e-9, "v[{i}] {got} vs {expected}");
    }
    let events: Vec<f64> = plain.events.iter().map(|e| e.time).collect();
    let near = |i: usize| near_event(time, &events, i, 1.0);
    for (j, &p) in params.iter().enumerate() {
        let (dx, dv) = world.differences(time, p, rel);
        let (ex, ev) = (worst(&sens.dx[j], &dx, near), worst(&sens.dv[j], &dv, near));
        assert!(
            ex < tol && ev < tol,
            "{p:?}: dx off by {ex:e}, dv by {ev:e}"
        );
    }
}

/// A slow force (8 N at 0.5 Hz, well below the stage's 2.2 Hz): the stage follows it nearly
/// in balance and sticks at each of its turns until the force has swung across the band.
fn slow_force() -> Input {
    sine_force(8.0, 0.5, 3.0)
}

/// `model` on the FMM stage under [`slow_force`], its plain runs by Dopri5.
fn slowly_driven(model: Box<dyn FrictionModel>) -> World {
    driven_world(model, Integrator::Dopri5, slow_force())
}

/// Coulomb under a slow force sticks at its start and at each turn until the input breaks
/// it away: the level, the mass, the damping, the stiffness and the input's offset carry
/// their sensitivities across every stick and breakaway.
#[test]
fn driven_coulomb_sensitivities_carry_across_sticks_and_breakaways() {
    let world = slowly_driven(Box::new(Coulomb { mu: 0.2 }));
    let params = [
        SensitivityParam::Model(0),
        SensitivityParam::Property(OscillatorProperty::Mass),
        SensitivityParam::Property(OscillatorProperty::Damping),
        SensitivityParam::Property(OscillatorProperty::Stiffness),
    ];
    check_across_sticks(&world, &times(3.0), &params, 1e-6, 1e-5);
    // The offset is 0: its step is 1e-3 of a newton's scale (a micronewton), where the
    // plain runs' integration error stays out of the differences.
    let offset = [SensitivityParam::Property(OscillatorProperty::InputOffset)];
    check_across_sticks(&world, &times(3.0), &offset, 1e-3, 1e-5);
}

/// Stribeck under a slow force breaks away at its static level mu_s N and slides on its
/// curve: mu_s moves the breakaways, mu_c, v_s and the viscous term the slides.
#[test]
fn driven_stribeck_sensitivities_carry_across_sticks_and_breakaways() {
    let world = slowly_driven(Box::new(Stribeck::default()));
    let params: Vec<_> = (0..Stribeck::default().params().len())
        .map(SensitivityParam::Model)
        .chain([SensitivityParam::Property(OscillatorProperty::Stiffness)])
        .collect();
    check_across_sticks(&world, &times(3.0), &params, 1e-6, 1e-5);
}

/// Coulomb friction with a static level above its sliding one: held up to mu_s N, sliding
/// at mu_k N. Its slip starts at an acceleration (mu_s - mu_k) N / m, so the sensitivities
/// jump at every breakaway (no built-in law with gradients breaks away with a jump).
#[derive(Debug, Clone, serde::Serialize, serde::Deserialize)]
#[serde(default)]
struct BreakingCoulomb {
    mu_s: f64,
    mu_k: f64,
}

impl Default for BreakingCoulomb {
    fn default() -> Self {
        Self {
            mu_s: 0.3,
            mu_k: 0.2,
        }
    }
}

#[typetag::serde(name = "test_laws_breaking_coulomb")]
impl FrictionModel for BreakingCoulomb {
    fn name(&self) -> &'static str {
        "test_laws_breaking_coulomb"
    }
    fn equation(&self) -> String {
        "F = mu_k N sgn(v), held up to mu_s N".into()
    }
    fn param_info(&self) -> Vec<frictionid_models::ParamInfo> {
        let level = |name: &str, value: f64| {
            frictionid_models::ParamInfo::new(name, "1", value, (0.0, 10.0), "level")
        };
        vec![level("mu_s", self.mu_s), level("mu_k", self.mu_k)]
    }
    fn params(&self) -> Vec<f64> {
        vec![self.mu_s, self.mu_k]
    }
    fn set_params(&mut self, values: &[f64]) -> Result<(), frictionid_models::ModelError> {
        if let [mu_s, mu_k] = values {
            (self.mu_s, self.mu_k) = (*mu_s, *mu_k);
        }
        Ok(())
    }
    fn force(&self, v: f64, _z: &[f64], normal: f64) -> f64 {
        self.mu_k * normal * frictionid_models::sgn(v)
    }
    frictionid_models::law_groups!(switching, param_gradients);
}

impl frictionid_models::SwitchedLaw for BreakingCoulomb {
    fn static_limit(&self, normal: f64) -> Option<f64> {
        Some(self.mu_s * normal)
    }
    fn slip_force(&self, _v: f64, direction: f64, normal: f64) -> f64 {
        self.mu_k * normal * direction
    }
}

impl frictionid_models::ParamGradients for BreakingCoulomb {
    fn force_param_gradient(&self, v: f64, _z: &[f64], normal: f64, out: &mut [f64]) {
        out.copy_from_slice(&[0.0, normal * frictionid_models::sgn(v)]);
    }
}

/// A law that breaks away with a jump in its acceleration: dv/dp steps by -a+ dt_b/dp at
/// every breakaway, and both levels, the mass and the stiffness match central differences
/// across them. Without the jump the static level's column would be off by its whole
/// scale after the first breakaway (checked: the jump is a good part of it).
#[test]
fn sensitivities_jump_where_the_input_breaks_a_stick_away() {
    let world = slowly_driven(Box::new(BreakingCoulomb::default()));
    let params = [
        SensitivityParam::Model(0),
        SensitivityParam::Model(1),
        SensitivityParam::Property(OscillatorProperty::Mass),
        SensitivityParam::Property(OscillatorProperty::Stiffness),
    ];
    let time = times(3.0);
    check_across_sticks(&world, &time, &params, 1e-6, 1e-5);
    // The static level's column right after the first breakaway: all of it is the jump
    // (mu_s moves nothing before, and the slip's direct terms do not hold mu_s).
    let plain = world.plain(&time);
    let t_b = plain
        .events
        .iter()
        .find(|e| e.kind == crate::simulate::EventKind::Breakaway)
        .map(|e| e.time)
        .unwrap();
    let sens = world.sensitivities(&time, &params);
    let after = time.partition_point(|&t| t <= t_b) + 1;
    let scale = sens.dv[0].iter().fold(0.0f64, |m, d| m.max(d.abs()));
    assert!(
        sens.dv[0][after].abs() > 0.05 * scale,
        "{:e}",
        sens.dv[0][after]
    );
}

/// LuGre with sigma0 = 1e7 N/m on the FMM stage: far beyond the explicit augmented run's
/// stiffness, so plain and augmented runs alike take Rodas4.
fn stiff_lugre() -> Box<dyn FrictionModel> {
    Box::new(LuGre {
        sigma0: 1e7,
        sigma1: 5000.0,
        ..LuGre::default()
    })
}

/// Driven by [`shaker`], the stiff LuGre's plain Rodas4 run follows the input's change
/// within each step (each stage reads f at its own time and carries gamma_i h df/dt): its
/// velocity matches a Dopri5 run, whose explicit stages read the input at their own times,
/// within 1e-7 of the peak speed at the tight tolerances (6e-11 measured). Stepped as if
/// autonomous (every stage at the step's start time, no df/dt) it was 3.7e-3 of the peak
/// off; with the stages' times but without df/dt, 7.3e-7.
#[test]
fn a_driven_stiff_run_of_rodas4_matches_dopri5() {
    let time = times(1.0);
    let stiff = driven_world(stiff_lugre(), Integrator::Rodas, shaker(1.0)).plain(&time);
    let explicit = driven_world(stiff_lugre(), Integrator::Dopri5, shaker(1.0)).plain(&time);
    let peak = explicit.v.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    assert!(peak > 0.05, "the input drives the stage: peak {peak}");
    let off = worst(&stiff.v, &explicit.v, |_| false);
    eprintln!("Rodas4 off Dopri5 by {off:e} of the peak speed {peak} m/s");
    assert!(off < 1e-7, "off by {off:e} of the peak {peak}");
}

/// Under a measured input, the stiff LuGre's sensitivities come from Rodas4 with the
/// augmented system's time derivative, and match central differences of plain driven Rodas4
/// runs: every parameter of the law, the mass (whose direct term follows the input) and
/// the stiffness.
#[test]
fn driven_stiff_lugre_sensitivities_match_central_differences() {
    let world = driven_world(stiff_lugre(), Integrator::Rodas, shaker(1.0));
    let time = times(1.0);
    let law: Vec<_> = (0..6).map(SensitivityParam::Model).collect();
    let sens = world
        .try_sensitivities(&time, &law)
        .expect("a driven stiff contact has sensitivities");
    assert!(took_the_stiff_stepper(&sens));
    // As for the released stiff LuGre: a larger step keeps the plain runs' integration
    // error out of the differences of sigma0 and sigma1.
    check_against_differences_by(&world, &time, &law, 1e-3, 1e-4);
    let mechanics = [
        SensitivityParam::Property(OscillatorProperty::Mass),
        SensitivityParam::Property(OscillatorProperty::Stiffness),
    ];
    check_against_differences(&world, &time, &mechanics, 1e-4);
}
