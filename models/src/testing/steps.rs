//! The checks of the optional groups a force-domain fit differentiates through: a law's exact
//! steps ([`crate::Propagator`]) against the harness's reference integration of its
//! `state_derivative` ([`super::reference`]) and their sensitivities against central
//! differences of the step; the force's parameter gradient ([`crate::ParamGradients`]) against
//! central differences of `force`.

use super::reference::{integrate, Tolerance};
use super::{ensure, fail, for_each_probe, states, Check, Model, Outcome, NORMAL_FORCES};
use crate::interval::Interval;
use crate::model::{FrictionModel, Propagator};

/// Velocities [m/s] of the exact-step probes (both signs are used).
pub const STEP_VELOCITIES: [f64; 4] = [1e-4, 3e-3, 0.05, 0.3];
/// Interval lengths \[s\] of the exact-step probes.
pub const STEP_DURATIONS: [f64; 3] = [1e-4, 1e-3, 1e-2];
/// The agreement asked of an exact step with the reference integration, relative to the
/// state's scale.
pub const STEP_TOLERANCE: f64 = 1e-9;
/// The agreement asked of a sensitivity or gradient with central differences, relative.
pub const DERIVATIVE_TOLERANCE: f64 = 1e-6;
/// Relative step of the central differences.
const STEP: f64 = 1e-6;

/// A parameter value's scale: |p|, or 1 for p = 0.
fn param_scale(p: f64) -> f64 {
    if p == 0.0 {
        1.0
    } else {
        p.abs()
    }
}

/// `model` with parameter `j` at `value`.
fn with_param(model: &Model, j: usize, value: f64) -> Result<Box<dyn FrictionModel>, String> {
    let mut m = crate::clone_model(model);
    let mut values = model.params();
    values[j] = value;
    m.set_params(&values).map_err(|e| e.to_string())?;
    Ok(m)
}

/// The exact step of `model` from `z0` (no sensitivities).
fn stepped(model: &Model, interval: Interval, z0: &[f64]) -> Vec<f64> {
    let mut z = z0.to_vec();
    if let Some(p) = model.states().and_then(|s| s.propagator()) {
        p.propagate(interval, &mut z);
    }
    z
}

/// [`Check::ExactSteps`]: where the law has a propagator that is exact at its parameters, at
/// every probe (velocities of [`STEP_VELOCITIES`], both signs, durations of
/// [`STEP_DURATIONS`], the harness's normal forces and states) the step equals the reference
/// integration to [`STEP_TOLERANCE`] of the state's scale, `propagate_with_sensitivities`
/// gives `propagate`'s states to the bit, and its sensitivities (carried from a nonzero
/// start) equal (dz1/dz0) S0 + dz1/dp by central differences to [`DERIVATIVE_TOLERANCE`].
pub fn check_exact_steps(model: &Model) -> Outcome {
    let Some(law) = model.states() else {
        return Ok(());
    };
    let Some(propagator) = law.propagator() else {
        return Ok(());
    };
    if !propagator.propagates_exactly() {
        return Ok(());
    }
    for normal in NORMAL_FORCES {
        for z0 in states(law.n_states()) {
            for v in STEP_VELOCITIES.iter().flat_map(|&v| [v, -v]) {
                for dt in STEP_DURATIONS {
                    check_step(model, Interval { v, normal, dt }, &z0)?;
                }
            }
        }
    }
    Ok(())
}

/// [`Check::ExactSteps`] at one probe: the step of `model` (which must have a propagator
/// exact at its parameters) over `interval` from `z0`.
pub fn check_step(model: &Model, interval: Interval, z0: &[f64]) -> Outcome {
    let Some(propagator) = model.states().and_then(|s| s.propagator()) else {
        return fail(model, Check::ExactSteps, "the law has no propagator".into());
    };
    let scales = state_scales(model, interval, z0);
    check_against_reference(model, interval, z0, &scales)?;
    check_sensitivities(model, propagator, interval, z0, &scales)
}

/// Each state's scale at a probe: the largest of |z0|, |z1|, the sliding state and a floor of
/// 1e-12 m of deflection.
fn state_scales(model: &Model, interval: Interval, z0: &[f64]) -> Vec<f64> {
    let Some(law) = model.states() else {
        return Vec::new();
    };
    let z1 = stepped(model, interval, z0);
    let mut sliding = vec![0.0; z0.len()];
    if !law.sliding_states(interval.v, interval.normal, &mut sliding) {
        sliding.iter_mut().for_each(|s| *s = 0.0);
    }
    let floors = law.state_tolerance_scales();
    (0..z0.len())
        .map(|j| {
            [
                z0[j].abs(),
                z1[j].abs(),
                sliding[j].abs(),
                1e-12 * floors[j],
            ]
            .into_iter()
            .fold(0.0, f64::max)
        })
        .collect()
}

fn check_against_reference(
    model: &Model,
    interval: Interval,
    z0: &[f64],
    scales: &[f64],
) -> Outcome {
    let Some(law) = model.states() else {
        return Ok(());
    };
    let exact = stepped(model, interval, z0);
    let mut reference = z0.to_vec();
    if let Err(e) = integrate(law, interval, &mut reference, &Tolerance::relative(scales)) {
        return fail(
            model,
            Check::ExactSteps,
            format!("the reference integration failed at {interval:?} from {z0:?}: {e:?}"),
        );
    }
    let close =
        (0..z0.len()).all(|j| (exact[j] - reference[j]).abs() <= STEP_TOLERANCE * scales[j]);
    ensure(model, Check::ExactSteps, close, || {
        format!("the step over {interval:?} from {z0:?} gives {exact:?}, the reference integration {reference:?}")
    })
}

/// The sensitivities' start: a pattern of entries of the size of a state's scale over a
/// parameter's.
fn start_sensitivities(scales: &[f64], params: &[f64]) -> Vec<f64> {
    let pattern = [0.5, -0.25, 1.0, -2.0, 0.125];
    let np = params.len();
    (0..scales.len() * np)
        .map(|k| pattern[k % pattern.len()] * scales[k / np] / param_scale(params[k % np]))
        .collect()
}

/// The derivative of `f` at 0 by central differences with steps `h` and `h/2`, extrapolated
/// (2 D(h/2) - D(h)): exact to second order where `f` is smooth, and to first order where its
/// second derivative jumps at 0 (a load crossing zero, where a plain central difference is
/// off by a fraction of h times the jump).
fn derivative(f: impl Fn(f64) -> Vec<f64>, h: f64) -> Vec<f64> {
    let central = |h: f64| -> Vec<f64> {
        let (a, b) = (f(h), f(-h));
        a.iter().zip(&b).map(|(a, b)| (a - b) / (2.0 * h)).collect()
    };
    let (wide, narrow) = (central(h), central(0.5 * h));
    wide.iter().zip(&narrow).map(|(w, n)| 2.0 * n - w).collect()
}

/// Columns of derivatives of the step's end states: by state, then by parameter.
type Differences = (Vec<Vec<f64>>, Vec<Vec<f64>>);

/// Differences of the step's end states: dz1/dz0 (column k for state k) and dz1/dp (column
/// j for parameter j).
fn differences(
    model: &Model,
    interval: Interval,
    z0: &[f64],
    scales: &[f64],
) -> Result<Differences, String> {
    let by_state = (0..z0.len())
        .map(|k| {
            let moved = |d: f64| {
                let mut z = z0.to_vec();
                z[k] += d;
                stepped(model, interval, &z)
            };
            derivative(moved, STEP * scales[k])
        })
        .collect();
    let params = model.params();
    let mut by_param = Vec::with_capacity(params.len());
    for (j, &p) in params.iter().enumerate() {
        let h = STEP * param_scale(p);
        let models = [h, -h, 0.5 * h, -0.5 * h].map(|d| with_param(model, j, p + d));
        let mut built = Vec::with_capacity(4);
        for (d, m) in [h, -h, 0.5 * h, -0.5 * h].into_iter().zip(models) {
            built.push((d, m?));
        }
        let moved = |d: f64| {
            built
                .iter()
                .find(|(step, _)| *step == d)
                .map_or_else(Vec::new, |(_, m)| stepped(m.as_ref(), interval, z0))
        };
        by_param.push(derivative(moved, h));
    }
    Ok((by_state, by_param))
}

fn check_sensitivities(
    model: &Model,
    propagator: &dyn Propagator,
    interval: Interval,
    z0: &[f64],
    scales: &[f64],
) -> Outcome {
    let params = model.params();
    let np = params.len();
    let start = start_sensitivities(scales, &params);
    let (mut z, mut sens) = (z0.to_vec(), start.clone());
    propagator.propagate_with_sensitivities(interval, &mut z, &mut sens);
    let plain = stepped(model, interval, z0);
    let same = z
        .iter()
        .zip(&plain)
        .all(|(a, b)| a.to_bits() == b.to_bits());
    ensure(model, Check::ExactSteps, same, || {
        format!("over {interval:?} from {z0:?} the step with sensitivities gives {z:?}, without {plain:?}")
    })?;
    let (by_state, by_param) = match differences(model, interval, z0, scales) {
        Ok(d) => d,
        Err(e) => return fail(model, Check::ExactSteps, e),
    };
    let given = propagator.exact_sensitivities();
    for (j, &p) in params.iter().enumerate() {
        if !given.get(j).copied().unwrap_or(false) {
            continue;
        }
        for i in 0..z0.len() {
            let carried: f64 = (0..z0.len())
                .map(|k| by_state[k][i] * start[k * np + j])
                .sum();
            let expected = carried + by_param[j][i];
            let got = sens[i * np + j];
            let floor = 1e-8 * scales[i] / param_scale(p);
            let tol = DERIVATIVE_TOLERANCE * got.abs().max(expected.abs()) + floor;
            ensure(
                model,
                Check::ExactSteps,
                (got - expected).abs() <= tol,
                || {
                    format!(
                    "over {interval:?} from {z0:?}: dz{i}/dp{j} = {got}, central differences give {expected}"
                )
                },
            )?;
        }
    }
    Ok(())
}

/// [`Check::ParamGradients`]: where the law gives its force's parameter gradient, at every
/// probe it equals central differences of `force` in each parameter (states held) to
/// [`DERIVATIVE_TOLERANCE`].
pub fn check_param_gradients(model: &Model) -> Outcome {
    let Some(gradients) = model.param_gradients() else {
        return Ok(());
    };
    let params = model.params();
    let mut moved = Vec::with_capacity(params.len());
    for (j, &p) in params.iter().enumerate() {
        let h = STEP * param_scale(p);
        let pair = (with_param(model, j, p + h), with_param(model, j, p - h));
        match pair {
            (Ok(a), Ok(b)) => moved.push((h, a, b)),
            (Err(e), _) | (_, Err(e)) => return fail(model, Check::ParamGradients, e),
        }
    }
    let mut out = vec![0.0; params.len()];
    for_each_probe(model, |v, z, normal| {
        gradients.force_param_gradient(v, z, normal, &mut out);
        let force = model.force(v, z, normal).abs();
        for (j, (h, plus, minus)) in moved.iter().enumerate() {
            let expected = (plus.force(v, z, normal) - minus.force(v, z, normal)) / (2.0 * h);
            let floor = 1e-8 * force / param_scale(params[j]);
            let tol = DERIVATIVE_TOLERANCE * out[j].abs().max(expected.abs()) + floor;
            ensure(
                model,
                Check::ParamGradients,
                (out[j] - expected).abs() <= tol,
                || {
                    format!(
                    "dF/dp{j} = {} at v = {v:e}, z = {z:?}, N = {normal}; central differences give {expected}",
                    out[j]
                )
                },
            )?;
        }
        Ok(())
    })?;
    check_state_param_gradients(model, gradients, &moved)
}

/// A parameter's step and the model moved by it up and down.
type MovedParam = (f64, Box<dyn FrictionModel>, Box<dyn FrictionModel>);

/// The states' rate's parameter gradient, where the law gives it, against central
/// differences of `state_derivative` in each parameter (states held), as the force's.
fn check_state_param_gradients(
    model: &Model,
    gradients: &dyn crate::ParamGradients,
    moved: &[MovedParam],
) -> Outcome {
    let (Some(states), n_params) = (model.states(), moved.len()) else {
        return Ok(());
    };
    let nz = states.n_states();
    let mut out = vec![0.0; nz * n_params];
    let (mut plus, mut minus, mut rate) = (vec![0.0; nz], vec![0.0; nz], vec![0.0; nz]);
    let params = model.params();
    for_each_probe(model, |v, z, normal| {
        if !gradients.state_param_gradient(v, z, normal, &mut out) {
            return Ok(());
        }
        states.state_derivative(v, z, normal, &mut rate);
        for (j, (h, up, down)) in moved.iter().enumerate() {
            let (Some(up), Some(down)) = (up.states(), down.states()) else {
                continue;
            };
            up.state_derivative(v, z, normal, &mut plus);
            down.state_derivative(v, z, normal, &mut minus);
            for k in 0..nz {
                let expected = (plus[k] - minus[k]) / (2.0 * h);
                let got = out[k * n_params + j];
                // Rounding in the differences scales with the rate's terms: a rate that
                // cancels, v (1 - load^m) at a saturated element, still rounds like v.
                let floor = 1e-8 * rate[k].abs().max(v.abs()) / param_scale(params[j]);
                let tol = DERIVATIVE_TOLERANCE * got.abs().max(expected.abs()) + floor;
                ensure(
                    model,
                    Check::ParamGradients,
                    (got - expected).abs() <= tol,
                    || {
                        format!(
                            "d(dz{k}/dt)/dp{j} = {got} at v = {v:e}, z = {z:?}, N = {normal}; \
                         central differences give {expected}"
                        )
                    },
                )?;
            }
        }
        Ok(())
    })
}
