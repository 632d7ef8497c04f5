//! The sensitivities' jump where a measured input breaks a stuck mass away.
//!
//! A switched law's mass sticks at x_s until the force it must hold leaves the law's band:
//! the breakaway time t_b solves g(t, x_s, p) = 0 with
//!
//! g = d (u(t) - F_0 - R(x_s) - offset(p)) - limit(p),
//!
//! d the direction it breaks away in. While it sticks the right-hand side is 0: dx/dp stays
//! that of x_s and dv/dp is 0. Differentiating g(t_b(p), x_s(p), p) = 0 gives
//!
//! dt_b/dp = -(dg/dp + dg/dx dx_s/dp) / (d u'(t_b)),  dg/dx = -d R'(x_s),
//!
//! u' the slope of the input's piece that reaches t_b (the band is left at an arrival). The
//! state y(t_b) is continuous; the right-hand side steps from f- = 0 to f+ = (0, a+), a+ the
//! acceleration the slip starts with, so the sensitivities jump by (f- - f+) dt_b/dp: dv/dp
//! by -a+ dt_b/dp. A law whose slip force at rest equals its band's edge (Coulomb,
//! Stribeck) starts its slip at a+ = 0: no jump, and the breakaway's shift enters through
//! the direct terms of the slip that follows.
//!
//! dg/dp of a law parameter is the derivative of the band's edge d offset + limit, taken by
//! central differences of the law's static limit and offset (algebraic in the parameters:
//! exact to rounding); of an oscillator property, -d times its balance column at rest.

use super::super::dynamics::{Dynamics, Law};
use super::system::DirectTerms;
use super::SensitivityParam;
use frictionid_models::clone_model;

/// Relative step of the central differences of the band's edge.
const EDGE_STEP: f64 = 1e-6;

/// Applies the jump at a breakaway at `t_b` in direction `dir` to the augmented state `y`
/// ([x, v, s_1, ..., s_n] with v = 0); `None` where it cannot be taken (the input arrives at
/// the band's edge with zero slope, or a law parameter's edge has no derivative).
pub(super) fn apply_breakaway_jump(
    dynamics: &Dynamics<'_>,
    terms: &DirectTerms<'_>,
    t_b: f64,
    dir: f64,
    y: &mut [f64],
) -> Option<()> {
    let Law::Switched { .. } = dynamics.law else {
        // A law without a static limit resumes where the input leaves a flat stretch: a time
        // no parameter moves, at an acceleration of 0.
        return Some(());
    };
    let n = 2;
    let x = *y.first()?;
    let mut after = [0.0; 2];
    dynamics.rhs(t_b, &[x, 0.0], &mut after, dir);
    let a_after = after[1];
    if a_after == 0.0 {
        // The slip starts at the band's edge force (Coulomb, Stribeck): no jump to take.
        return Some(());
    }
    let departure = dir * dynamics.input.map_or(0.0, |u| u.slope_arriving_at(t_b));
    if !(departure.is_finite() && departure != 0.0) {
        return None;
    }
    let dg_dx = -dir * dynamics.restoring_stiffness(x);
    for (&p, s) in terms.params().iter().zip(y[n..].chunks_exact_mut(n)) {
        let dg_dp = band_rate(dynamics, p, x, dir)?;
        let dt_dp = -(dg_dp + dg_dx * s[0]) / departure;
        s[1] -= a_after * dt_dp;
    }
    Some(())
}

/// dg/dp at rest at `x` for breakaway direction `dir` (see the module docs).
fn band_rate(dynamics: &Dynamics<'_>, p: SensitivityParam, x: f64, dir: f64) -> Option<f64> {
    match p {
        SensitivityParam::Model(i) => edge_derivative(dynamics, i, dir).map(|d| -d),
        SensitivityParam::Property(q) => Some(-dir * q.balance_column(0.0, 0.0, x)),
        SensitivityParam::StartDisplacement => Some(0.0),
    }
}

/// d(dir offset + limit)/dp_i of the law, by central differences.
fn edge_derivative(dynamics: &Dynamics<'_>, i: usize, dir: f64) -> Option<f64> {
    let values = dynamics.model.params();
    let p = *values.get(i)?;
    let h = EDGE_STEP * p.abs().max(1e-3);
    let edge_at = |value: f64| -> Option<f64> {
        let mut moved = clone_model(dynamics.model);
        let mut shifted = values.clone();
        shifted[i] = value;
        moved.set_params(&shifted).ok()?;
        let law = moved.switching()?;
        let limit = law.static_limit(dynamics.normal)?;
        Some(dir * law.static_offset(dynamics.normal) + limit)
    };
    let slope = (edge_at(p + h)? - edge_at(p - h)?) / (2.0 * h);
    slope.is_finite().then_some(slope)
}
