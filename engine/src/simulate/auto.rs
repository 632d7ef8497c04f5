//! The choice of `Integrator::Auto`: the exact propagator for laws affine in v, the stiff
//! Rodas4 when a stiffness estimate says an explicit method would be stability-limited,
//! Dopri5 otherwise.
//!
//! Stiffness estimate: the spectral radius rho of the Jacobian of the full system at a
//! representative sliding state (x = 0, v = the larger of |v0| and omega_n |x0|, the initial
//! internal states, and the law's steady sliding states where it states them:
//! `InternalStates::sliding_states`; GMS elements are soft when relaxed and stiff when
//! loaded, and Dahl's rate with alpha < 1 has an unbounded slope where its force reaches its
//! level), times the step Dopri5 takes for accuracy on a free vibration at the
//! default tolerances (about T_n / 100). Dopri5's stability region reaches about 3.3 along
//! the negative real axis: beyond that its steps are set by stability, not accuracy, and its
//! cost grows with the ratio, while Rodas4 (a few times the cost per step, no stability
//! bound) takes about the same steps at any stiffness. They break even near a ratio of 50
//! (the fits switch at 25, [`STIFF_RATIO`]): on the FMM rig LuGre and Dahl at the default sigma0 = 1e5 N/m give 48
//! (Dopri5 1.15 and 1.43 ms, Rodas4 1.22 and 1.19 ms), at 1e7 about 4 800; the default GMS
//! gives 286 (Dopri5 66 000 RHS, Rodas4 6 800).

use super::{Dynamics, Integrator, Law};
use crate::error::EngineError;
use frictionid_models::InternalStates;
use nalgebra::DMatrix;

/// Dopri5's accuracy-limited step on a free vibration, as a fraction of T_n.
const ACCURACY_STEP_PERIODS: f64 = 1.0 / 100.0;

/// rho(J) h above which the stiff method is chosen: near where the two methods break even
/// (see the module docs), lowered to where the fits are fastest. Inside a fit, where trial
/// points wander, the FMM five-model `compare` took 3.4 s with 50, 4.0 s with 100 and 4.3-7 s
/// with 500 (back to back, median of 3); with 5 it took 9.9 s (Dahl's Rodas4 steps cost a
/// `powf` per Jacobian as well). With the rigid-limit test in the fits: 3.7-4.1 s with 50,
/// 3.6 with 35, 3.0-3.3 with 25, 3.4-3.6 with 18, 3.2-3.4 with 12 (two rounds each):
/// Dahl's Dopri5 right-hand side costs a `powf`, so it breaks even below LuGre's ratio.
pub(crate) const STIFF_RATIO: f64 = 25.0;

/// The concrete method for `requested`: `Auto` picks the exact propagator where it applies,
/// Rodas4 where the motion is stiff, Dopri5 otherwise; `Exact` where it does not apply is an
/// input error.
pub(crate) fn resolve_method(
    requested: Integrator,
    dynamics: &Dynamics<'_>,
    y0: &[f64],
    period: f64,
) -> Result<Integrator, EngineError> {
    match requested {
        Integrator::Auto if dynamics.closed_form_applies() => Ok(Integrator::Exact),
        Integrator::Auto if stiffness_ratio(dynamics, y0, period) > STIFF_RATIO => {
            Ok(Integrator::Rodas)
        }
        Integrator::Auto => Ok(Integrator::Dopri5),
        Integrator::Exact if !dynamics.closed_form_applies() => {
            Err(EngineError::InvalidInput(format!(
                "integrator `exact` needs a law affine in v within each sliding mode \
                 (coulomb, viscous_coulomb, none) and an underdamped oscillator; model `{}` \
                 does not qualify here",
                dynamics.model.name()
            )))
        }
        other => Ok(other),
    }
}

/// rho(J) times Dopri5's accuracy step at a representative motion: sliding at x = 0 for a
/// dynamic law (with its initial and its steady sliding states), passing through v = 0 and
/// sliding for a smooth static law (a steep smoothed Coulomb step, makkar's g5 or a tanh
/// formula, is stiff only near rest), 0 for a switched law (its stick is an event, not a
/// stiff stretch of motion).
pub(crate) fn stiffness_ratio(dynamics: &Dynamics<'_>, y0: &[f64], period: f64) -> f64 {
    let [x0, v0, z0 @ ..] = y0 else {
        return 0.0;
    };
    let omega = 2.0 * std::f64::consts::PI / period;
    let speed = v0.abs().max(omega * x0.abs());
    if !(speed.is_finite() && speed > 0.0) {
        return 0.0;
    }
    let radius = match dynamics.law {
        Law::Switched { .. } => 0.0,
        Law::Smooth => [0.0, speed]
            .map(|v| spectral_radius(dynamics, v, &[]))
            .into_iter()
            .fold(0.0, f64::max),
        Law::Dynamic { states, .. } => dynamic_radius(dynamics, states, speed, z0),
    };
    radius * period * ACCURACY_STEP_PERIODS
}

/// The larger rho(J) of a dynamic law sliding at `speed` with its initial states `z0` and
/// with its steady sliding states (`InternalStates::sliding_states`, where the law states
/// them).
fn dynamic_radius(
    dynamics: &Dynamics<'_>,
    states: &dyn InternalStates,
    speed: f64,
    z0: &[f64],
) -> f64 {
    let mut loaded = vec![0.0; z0.len()];
    let sliding = states
        .sliding_states(speed, dynamics.normal, &mut loaded)
        .then_some(loaded);
    [Some(z0.to_vec()), sliding]
        .into_iter()
        .flatten()
        .map(|z| spectral_radius(dynamics, speed, &z))
        .fold(0.0, f64::max)
}

/// rho(J) of the full system at x = 0, v = `speed` and states `z` (infinite when J is not
/// finite).
fn spectral_radius(dynamics: &Dynamics<'_>, speed: f64, z: &[f64]) -> f64 {
    let mut y = vec![0.0, speed];
    y.extend_from_slice(z);
    let n = y.len();
    let mut jac = vec![0.0; n * n];
    dynamics.jacobian(0.0, &y, 1.0, &mut jac);
    if jac.iter().any(|j| !j.is_finite()) {
        return f64::INFINITY;
    }
    DMatrix::from_row_slice(n, n, &jac)
        .complex_eigenvalues()
        .iter()
        .map(|l| l.norm())
        .fold(0.0, f64::max)
}

#[cfg(test)]
mod tests {
    use super::super::Dynamics;
    use super::*;
    use crate::oscillator::Oscillator;
    use frictionid_models::{build_json, FrictionModel};

    fn ratio(model: &dyn FrictionModel) -> f64 {
        let osc = Oscillator::fmm();
        let dynamics = Dynamics::new(&osc, model).expect("a classifiable law");
        let mut y0 = vec![0.022, 0.0];
        y0.resize(2 + model.n_states(), 0.0);
        stiffness_ratio(&dynamics, &y0, osc.natural_period())
    }

    fn model(json: serde_json::Value) -> Box<dyn FrictionModel> {
        build_json(&json)
            .map(|b| b.model)
            .unwrap_or_else(|e| panic!("{e}"))
    }

    #[test]
    fn the_stiffness_estimate_grows_with_the_bristle_stiffness() {
        for name in ["lugre", "dahl"] {
            let r = |s: f64| ratio(model(serde_json::json!({"type": name, "sigma0": s})).as_ref());
            let (soft, mid, stiff) = (r(1e3), r(1e5), r(1e7));
            eprintln!("{name}: {soft:.3e} {mid:.3e} {stiff:.3e}");
            // The default 1e5 lies near the break-even of the two methods (48, module docs);
            // the fits' switch is below it.
            assert!(soft < STIFF_RATIO, "{name} {soft}");
            assert!(mid > 40.0 && mid < 60.0, "{name} {mid}");
            assert!(stiff > 5.0 * STIFF_RATIO, "{name} {stiff}");
            assert!(soft < mid && mid < stiff);
        }
        // Switched static laws are never stiff: their stick is an event.
        assert_eq!(
            ratio(model(serde_json::json!({"type": "stribeck"})).as_ref()),
            0.0
        );
    }

    /// A smooth static law is stiff where its smoothed Coulomb step is steep: makkar's
    /// rho(J) near rest is about g4 g5 / m. Its default g5 = 1000 s/m is not stiff (ratio about
    /// 1.4 on the FMM rig); the FMM Coulomb records pull g5 to about 4.5e5 s/m.
    #[test]
    fn a_steep_smooth_static_law_is_stiff_near_rest() {
        let makkar = |g5: f64| model(serde_json::json!({"type": "makkar", "g5": g5}));
        let osc = Oscillator::fmm();
        let expected = |g5: f64| {
            let slope = 1.9 * (200.0 - 20.0) + 2.9 * g5 + 0.5 + osc.damping;
            slope / osc.mass * osc.natural_period() * ACCURACY_STEP_PERIODS
        };
        for g5 in [1e3, 1e5, 4.5e5] {
            let r = ratio(makkar(g5).as_ref());
            assert!(
                (r / expected(g5) - 1.0).abs() < 0.01,
                "g5 {g5}: {r} vs {}",
                expected(g5)
            );
        }
        assert!(ratio(makkar(1e3).as_ref()) < STIFF_RATIO);
        assert!(ratio(makkar(4.5e5).as_ref()) > STIFF_RATIO);
    }

    /// Dahl's force reaches its Coulomb level in finite time when alpha < 1 (|r|^alpha is not
    /// Lipschitz at r = 0), and an explicit method chatters about it there: the estimate at
    /// the sliding state picks Rodas4 for such a law at a rest stiffness where the linear
    /// hysteresis (alpha = 1, the same slope at every state) stays with Dopri5.
    #[test]
    fn a_dahl_law_that_saturates_in_finite_time_is_stiff_where_it_slides() {
        let dahl =
            |alpha: f64| model(serde_json::json!({"type": "dahl", "sigma0": 3e4, "alpha": alpha}));
        assert!(ratio(dahl(1.0).as_ref()) < STIFF_RATIO);
        for alpha in [0.5, 0.8, 0.95] {
            let r = ratio(dahl(alpha).as_ref());
            assert!(r > STIFF_RATIO, "alpha {alpha}: {r}");
        }
    }

    /// GMS elements have no stiffness while relaxed (the rate's slope vanishes at z = 0 for a
    /// sharpness above 1) and much when loaded: the estimate at the steady sliding states
    /// picks Rodas4 for the default law (Dopri5 took 66 000 RHS on the FMM release, Rodas4
    /// 6 800), and only there.
    #[test]
    fn loaded_gms_elements_are_stiff() {
        let gms = model(serde_json::json!({"type": "gms"}));
        assert!(ratio(gms.as_ref()) > STIFF_RATIO, "{}", ratio(gms.as_ref()));
        let osc = Oscillator::fmm();
        let dynamics = Dynamics::new(&osc, gms.as_ref()).expect("a classifiable law");
        let relaxed = vec![0.0; gms.n_states()];
        let at_rest = spectral_radius(&dynamics, 0.3, &relaxed);
        assert!(at_rest * osc.natural_period() * ACCURACY_STEP_PERIODS < STIFF_RATIO);
    }
}
