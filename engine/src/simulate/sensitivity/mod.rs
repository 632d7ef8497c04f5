//! Forward sensitivities of a simulated motion: the derivatives of the sampled displacement
//! and velocity with respect to the law's parameters, the oscillator's properties and the
//! release displacement, integrated with the states in one augmented simulation.
//!
//! # Method
//! With y = [x, v, z...] and y' = f(t, y, p), each parameter's sensitivity s = dy/dp obeys
//! s' = J s + df/dp (J = df/dy, [`Dynamics::jacobian`]), integrated beside y by Dopri5
//! whose error control covers the states alone ([`Tolerance::control_first`]): the augmented
//! run takes the steps of the plain one. df/dp comes from the law (its force's parameter
//! gradient, [`ParamGradients::force_param_gradient`], and its states' rate's,
//! [`ParamGradients::state_param_gradient`]) and from the oscillator's balance
//! ([`OscillatorProperty::balance_column`]): d(x'')/dq = -column / m.
//!
//! A contact so stiff that Dopri5 would be held by stability ([`SENSITIVITY_STIFF_RATIO`])
//! is integrated by Rodas4 instead, at the plain stiff run's tolerances, its error control
//! over the states alone (as the explicit run's): LuGre and the default GMS match central
//! differences within 1e-4 and 1e-3; a stiff Dahl with alpha 1.5 or 3 within 1 %. Its
//! linear systems take the augmented system's Jacobian, block lower triangular (J on the
//! diagonal, H_j = d(s_j')/dy below it, by differences), and are solved block by block
//! with the factors of J's block alone ([`Rodas4::block_triangular`]): the sensitivities
//! cost their right-hand sides, not a larger factorisation. The default GMS (stiffness ratio 286) and the bristle laws far up
//! their presliding stiffness take this path; LuGre fitted to the bundled Coulomb fixture
//! went from 1 746 simulations (its columns differenced over Rodas4) to 612.
//!
//! At a turning point t_e (v(t_e) = 0, a state-dependent event) the sensitivities jump by
//! (f- - f+) dt_e/dp with dt_e/dp = -s_v / a- (the event function is v; f- and f+ are the
//! right-hand sides before and after, a- = x'' before): at a reversal of a switched law
//! the force flips, at a stick the motion stops (f+ = 0, so dv/dp is 0 from there on). A
//! smooth law's right-hand side is continuous there: no jump. Under a measured input a
//! stick lasts until the input breaks it away, where the plain driver puts it
//! ([`Dynamics::breakaway`]); the sensitivities jump there by -(0, a+) dt_b/dp, dt_b/dp
//! from the band the input leaves (`breakaway.rs`).
//!
//! An explicit run's steps are set by the states' error alone: over a stretch stiff enough
//! (Dahl at sigma0 3e5 N/m sliding at a few cm/s) they can exceed the stability bound of the
//! sensitivities, which the states do not excite but the direct terms do, and the
//! sensitivities then grow without limit while the states stay right. A run whose sampled
//! sensitivities pass a bound no motion reaches (`believable_sizes`) is given up: `None`.
//!
//! # Where it applies
//! Free vibration, or a drive by a measured input (the steps stop at the input's knots, as
//! the plain run's; a switched law's sticks end at the breakaways it forces), stiff or not (Rodas4 takes the augmented system's time derivative, the input's slope in
//! the acceleration and in the mass's direct term, [`OdeSystem::time_derivative`]), of a
//! law that reads no conditions, every parameter with its derivative available (a law with
//! [`ParamGradients`], and states' rate gradients for a dynamic law; the normal force is
//! never differentiated), not the Euler integrator
//! (whose trajectory the sensitivities of the exact motion would not describe), and a
//! states' Jacobian finite where the run starts and slides (Dahl with alpha < 1 has an
//! unbounded slope at its level; a stiff run whose sensitivities still leave the finite
//! numbers is given up the same way). Elsewhere [`simulate_sensitivities`] returns `None`
//! and the caller takes difference quotients.
//!
//! [`Rodas4::block_triangular`]: super::Rodas4::block_triangular
//! [`Dynamics::breakaway`]: super::Dynamics::breakaway
//! [`OdeSystem::time_derivative`]: super::stepper::OdeSystem::time_derivative
//! [`Tolerance::control_first`]: super::Tolerance::control_first
//! [`ParamGradients`]: frictionid_models::ParamGradients
//! [`ParamGradients::force_param_gradient`]: frictionid_models::ParamGradients::force_param_gradient
//! [`ParamGradients::state_param_gradient`]: frictionid_models::ParamGradients::state_param_gradient

mod breakaway;
mod run;
mod system;

use super::auto::stiffness_ratio;
use super::dynamics::{Dynamics, Law};
use super::run::{check_system, component_tolerance_scales};
use super::values::{Integrator, RunInputs, SimStats};
use crate::error::{EngineError, IntegrationFailure};
use crate::oscillator::OscillatorProperty;
use system::DirectTerms;

/// The stiffness ratio (`auto`'s estimate, rho(J) times Dopri5's accuracy step) above which
/// the augmented run takes Rodas4: Dopri5's steps would be set by stability and grow in
/// number with the ratio.
pub const SENSITIVITY_STIFF_RATIO: f64 = 200.0;

/// What a sensitivity is taken with respect to.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SensitivityParam {
    /// The law's parameter at this index of its `params()`.
    Model(usize),
    /// A property of the oscillator.
    Property(OscillatorProperty),
    /// The displacement at the release.
    StartDisplacement,
}

/// Which series an augmented run keeps at the samples: a fit that compares only the
/// velocity needs only its sensitivities, and holding no more keeps a long record's fit
/// within its memory bound.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SampledSeries {
    /// dv/dp alone (`x`, `v` and `dx` stay empty).
    VelocitySensitivities,
    /// The displacement, the velocity and both their sensitivities.
    All,
}

/// The sampled motion and its sensitivities.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Sensitivities {
    /// Displacement at each sample time.
    pub x: Vec<f64>,
    /// Velocity at each sample time.
    pub v: Vec<f64>,
    /// dx/dp, one series per parameter (in the order asked).
    pub dx: Vec<Vec<f64>>,
    /// dv/dp, one series per parameter.
    pub dv: Vec<Vec<f64>>,
    /// The work of the augmented run.
    pub stats: SimStats,
}

/// Simulates `inputs` with the sensitivities of the sampled displacement and velocity with
/// respect to `params`; `None` where they are not available (see the module docs), an error
/// where the run fails.
pub fn simulate_sensitivities(
    inputs: RunInputs<'_>,
    params: &[SensitivityParam],
    kept: SampledSeries,
) -> Result<Option<Sensitivities>, EngineError> {
    let RunInputs {
        osc,
        model,
        init,
        input,
        channels,
        grid,
        opts,
    } = inputs;
    // A law that reads conditions (x, a channel) is differentiated by difference quotients:
    // its force's dependence on x and on the channels is not among the direct terms.
    if channels.is_some()
        || !model.conditions().is_empty()
        || matches!(opts.integrator, Integrator::Euler { .. })
    {
        return Ok(None);
    }
    check_system(osc, model)?;
    let dynamics = Dynamics::new(osc, model)?.driven_by(input);
    let mut y0 = vec![init.x0, init.v0];
    match &init.z0 {
        Some(z0) if z0.len() == model.n_states() => y0.extend_from_slice(z0),
        Some(_) => return Ok(None),
        None => y0.resize(2 + model.n_states(), 0.0),
    }
    let Some(terms) = DirectTerms::new(&dynamics, params, &y0) else {
        return Ok(None);
    };
    let period = osc.period().unwrap_or(grid.t_end.max(1.0));
    let scale = motion_scale(&dynamics, &y0, period);
    let ratio = match dynamics.law {
        Law::Switched { .. } => 0.0,
        _ => {
            // At the motion's scale: a drive starting from rest has none of its own.
            let mut probe = y0.clone();
            probe[0] = scale.0.copysign(y0[0]);
            probe[1] = scale.1.copysign(y0[1]);
            stiffness_ratio(&dynamics, &probe, period)
        }
    };
    if !ratio.is_finite() {
        // A states' Jacobian without a finite value (Dahl with alpha < 1 at its level):
        // the sensitivities' equations are singular there.
        return Ok(None);
    }
    let method = match ratio > SENSITIVITY_STIFF_RATIO {
        true => run::Method::Rodas4 {
            typical: typical_sizes(&dynamics, scale),
            atol_scales: component_tolerance_scales(model, y0.len()),
        },
        false => run::Method::Dopri5,
    };
    let sizes = parameter_sizes(&dynamics, &terms, &y0);
    let believable = believable_sizes(&sizes, scale);
    let outcome = run::run(run::Setup {
        dynamics,
        terms: &terms,
        y0: &y0,
        grid,
        opts,
        period,
        kept,
        believable,
        method,
    });
    match outcome {
        // Sensitivities that leave the finite numbers where the states do not (a Jacobian
        // unbounded at a state the run reaches) have diverged as well: differences take over.
        Err(EngineError::Integration(IntegrationFailure::NonFiniteState { .. })) => Ok(None),
        other => other,
    }
}

/// The size |p| of each parameter of `terms` at the run's values (the release displacement
/// for its own): 1 where it is zero or not finite.
fn parameter_sizes(dynamics: &Dynamics<'_>, terms: &DirectTerms<'_>, y0: &[f64]) -> Vec<f64> {
    let values = dynamics.model.params();
    terms
        .params()
        .iter()
        .map(|p| match *p {
            SensitivityParam::Model(i) => values.get(i).copied(),
            SensitivityParam::Property(q) => q.value(&dynamics.osc),
            SensitivityParam::StartDisplacement => y0.first().map(|x| x.abs().max(1e-9)),
        })
        .map(|v| {
            v.map(f64::abs)
                .filter(|v| v.is_finite() && *v > 0.0)
                .unwrap_or(1.0)
        })
        .collect()
}

/// How far a sensitivity beyond any the motion can have is taken to mean a diverged run:
/// the sampled x and v may change by this many times their scale for a relative change of
/// a parameter.
const BELIEVABLE_GAIN: f64 = 1e8;

/// The largest believable |dx/dp| and |dv/dp| of each parameter, of size `sizes`, in a run
/// whose motion has the scale `(x_scale, v_scale)` ([`motion_scale`]): [`BELIEVABLE_GAIN`]
/// times that scale over the parameter's size. A diverged run grows exponentially and passes
/// it within a few steps; a true sensitivity near a stick or a reversal stays orders of
/// magnitude below it.
fn believable_sizes(sizes: &[f64], (x_scale, v_scale): (f64, f64)) -> Vec<(f64, f64)> {
    sizes
        .iter()
        .map(|size| {
            let gain = BELIEVABLE_GAIN / size;
            (gain * x_scale, gain * v_scale)
        })
        .collect()
}

/// The scale of the motion of a run from `y0`: the release displacement (at least 1e-9 m)
/// and the speed omega |x0| it turns into or the starting speed, whichever is larger, with
/// omega = 2 pi / `period`; under a measured input at least the displacement and the speed
/// its largest force |u - F_0| drives the mass to at omega, |u| / (m omega^2) and
/// |u| / (m omega).
fn motion_scale(dynamics: &Dynamics<'_>, y0: &[f64], period: f64) -> (f64, f64) {
    let omega = 2.0 * std::f64::consts::PI / period;
    let x0 = y0.first().map_or(0.0, |x| x.abs());
    let v0 = y0.get(1).map_or(0.0, |v| v.abs());
    let driving = dynamics.input.map_or(0.0, |u| {
        let offset = dynamics.osc.input_offset;
        u.values()
            .iter()
            .fold(0.0, |m: f64, f| m.max((f - offset).abs()))
    });
    let driven_x = driving / (dynamics.osc.mass * omega * omega);
    let x_scale = x0.max(driven_x).max(1e-9);
    let v_scale = (omega * x_scale).max(v0);
    (x_scale, v_scale)
}

/// Each state's typical size in a run whose motion has the scale `(x_scale, speed)`
/// ([`motion_scale`]): those two, and the law's steady sliding states at that speed (where
/// the law states them; else a millionth of the state's tolerance scale).
fn typical_sizes(dynamics: &Dynamics<'_>, (x_scale, speed): (f64, f64)) -> Vec<f64> {
    let mut typical = vec![x_scale, speed];
    let model = dynamics.model;
    if let Some(states) = model.states().filter(|s| s.n_states() > 0) {
        let mut sliding = vec![0.0; states.n_states()];
        let stated = states.sliding_states(speed, dynamics.normal, &mut sliding);
        let scales = states.state_tolerance_scales();
        typical.extend(sliding.iter().zip(&scales).map(|(&z, &scale)| {
            let floor = if scale.is_finite() && scale > 0.0 {
                1e-6 * scale
            } else {
                1e-6
            };
            if stated && z.is_finite() {
                z.abs().max(floor)
            } else {
                floor
            }
        }));
    }
    typical
}

#[cfg(test)]
mod tests;
