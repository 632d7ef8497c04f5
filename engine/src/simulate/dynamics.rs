//! The equation of motion J q'' + c q' + R(q) + F_f = u(t) - F_0 of an oscillator with its
//! friction law: the right-hand side, the modes of a switched law and the start of a segment.

use super::conditions::{BoundConditions, ConditionValues};
use super::{AffineMotion, ClosedForm, Input};
use crate::error::EngineError;
use crate::oscillator::Oscillator;
use frictionid_models::{sgn, Derivatives, FrictionModel, InternalStates, SwitchedLaw};

/// A knot of the input closer than this (relative to 1 + |t|) after a segment's start is not
/// stopped at: a step that short is lost in round-off, and the kink it would resolve spans
/// nothing.
const KNOT_GAP: f64 = 1e-9;

/// How the friction law is treated.
#[derive(Debug, Clone, Copy)]
pub(crate) enum Law<'a> {
    /// Static law with a set-valued force at v = 0: switched system (slip+, slip-, stick);
    /// it sticks while the held force less `offset` is within +-`limit` (an offset for
    /// levels that differ by direction).
    Switched { limit: f64, offset: f64 },
    /// Smooth static law: no mode switch, restart at turning points.
    Smooth,
    /// Dynamic model with internal states integrated alongside x and v: its states' law
    /// and derivatives, fetched once for the run.
    Dynamic {
        states: &'a dyn InternalStates,
        derivatives: Derivatives<'a>,
    },
}

/// The equation of motion with its friction law.
#[derive(Clone, Copy)]
pub(crate) struct Dynamics<'a> {
    /// The oscillator: inertia, damping, restoring law, normal force and input offset F_0.
    pub osc: Oscillator,
    /// The normal force N on the contact (the oscillator's).
    pub normal: f64,
    pub model: &'a dyn FrictionModel,
    /// The law's switched-system facts, fetched once for the run.
    pub switching: Option<&'a dyn SwitchedLaw>,
    pub law: Law<'a>,
    /// The measured input (`None`: free vibration).
    pub input: Option<&'a Input>,
    /// Where the law's conditions come from (`None`: it reads none).
    pub conditions: Option<&'a BoundConditions<'a>>,
}

/// What happens at a state with (possibly) zero velocity.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) enum Start {
    /// Slip in this direction (+1 or -1).
    Slip(f64),
    /// The mass stays at rest.
    Rest,
}

impl<'a> Dynamics<'a> {
    /// The equation of motion of `osc` with `model` (its law classified at the normal force).
    pub(crate) fn new(osc: &Oscillator, model: &'a dyn FrictionModel) -> Result<Self, EngineError> {
        Ok(Self {
            osc: *osc,
            normal: osc.normal_force,
            model,
            switching: model.switching(),
            law: classify_law(model, osc.normal_force)?,
            input: None,
            conditions: None,
        })
    }

    /// The same equation of motion driven by `input`.
    pub(crate) fn driven_by(self, input: Option<&'a Input>) -> Self {
        Self { input, ..self }
    }

    /// The same equation of motion with the law's conditions read from `conditions`.
    pub(crate) fn reading(self, conditions: Option<&'a BoundConditions<'a>>) -> Self {
        Self { conditions, ..self }
    }
}

impl Dynamics<'_> {
    /// The values of the law's conditions at time `t` and displacement `x` (`None` for a
    /// law that reads none).
    #[inline]
    fn conditions_at(&self, t: f64, x: f64) -> Option<ConditionValues> {
        self.conditions.map(|c| c.values(t, x))
    }

    /// The friction force at time `t` and displacement `x` in slip direction `dir` (static
    /// laws) or from the states (dynamic).
    #[inline]
    pub(crate) fn force(&self, t: f64, x: f64, v: f64, z: &[f64], dir: f64) -> f64 {
        match self.law {
            Law::Dynamic { .. } => match self.conditions_at(t, x) {
                Some(at) => self.model.force_in(v, z, self.normal, at.as_slice()),
                None => self.model.force(v, z, self.normal),
            },
            _ => self.slip_force(t, x, v, dir),
        }
    }

    /// The force of a static law at time `t` and displacement `x` slipping in direction
    /// `dir` (its force at `v` when it is not a switched law).
    #[inline]
    pub(crate) fn slip_force(&self, t: f64, x: f64, v: f64, dir: f64) -> f64 {
        match (self.switching, self.conditions_at(t, x)) {
            (Some(law), None) => law.slip_force(v, dir, self.normal),
            (Some(law), Some(at)) => law.slip_force_in(v, dir, self.normal, at.as_slice()),
            (None, None) => self.model.force(v, &[], self.normal),
            (None, Some(at)) => self.model.force_in(v, &[], self.normal, at.as_slice()),
        }
    }

    /// The stick band of a switched law at time `t` and displacement `x`: its static limit
    /// and the band's offset, read at the conditions there for a law that reads some (a
    /// limit that is not finite holds nothing).
    #[inline]
    pub(crate) fn stick_band(&self, t: f64, x: f64) -> Option<(f64, f64)> {
        let Law::Switched { limit, offset } = self.law else {
            return None;
        };
        let (Some(law), Some(at)) = (self.switching, self.conditions_at(t, x)) else {
            return Some((limit, offset));
        };
        let at = at.as_slice();
        let limit = law
            .static_limit_in(self.normal, at)
            .filter(|l| l.is_finite())
            .unwrap_or(-1.0);
        Some((limit, law.static_offset_in(self.normal, at)))
    }

    /// The restoring force R(x) ([`Oscillator::restoring_force`]).
    #[inline]
    pub(crate) fn restoring_force(&self, x: f64) -> f64 {
        self.osc.restoring_force(x)
    }

    /// dR/dx at x ([`Oscillator::restoring_stiffness`]).
    #[inline]
    pub(crate) fn restoring_stiffness(&self, x: f64) -> f64 {
        self.osc.restoring_stiffness(x)
    }

    /// The external force u(t) - F_0 (0 in free vibration).
    #[inline]
    pub(crate) fn input_at(&self, t: f64) -> f64 {
        self.input.map_or(0.0, |u| u.at(t)) - self.osc.input_offset
    }

    /// The next knot after `t` of the input or of a channel the law reads (the same kink in
    /// a condition's slope), if any: a step of any stepper stops there.
    pub(crate) fn next_knot(&self, t: f64) -> Option<f64> {
        let gap = KNOT_GAP * (1.0 + t.abs());
        let input = self.input.and_then(|u| u.next_knot(t, gap));
        let channels = self.conditions.and_then(|c| c.next_knot(t, gap));
        match (input, channels) {
            (Some(a), Some(b)) => Some(a.min(b)),
            (a, b) => a.or(b),
        }
    }

    /// Where a step from `t` must stop: the next knot (a step across one straddles the kink
    /// of u's slope there, which the error estimate cannot resolve: Dopri5 rejected nine
    /// steps in ten under a multisine sampled at 1 kHz and left errors of 1e-7 m/s that
    /// changed erratically with the parameters), else `t_end`.
    pub(crate) fn stop_after(&self, t: f64, t_end: f64) -> f64 {
        self.next_knot(t).map_or(t_end, |knot| knot.min(t_end))
    }

    /// The direction the measured input moves in just after `t` (the sign of its slope to
    /// its next knot); `None` without an input or while it stays where it is.
    pub(crate) fn input_departure(&self, t: f64) -> Option<f64> {
        let u = self.input?;
        let next = self.next_knot(t)?;
        let rise = u.at(next) - u.at(t);
        (rise != 0.0).then(|| sgn(rise))
    }

    /// Whether an input or a constant force acts (else the motion is free vibration).
    #[inline]
    pub(crate) fn driven(&self) -> bool {
        self.input.is_some() || self.osc.input_offset != 0.0
    }

    /// The force the contact holds at rest at (t, x): u(t) - F_0 - R(x) (the static
    /// friction that keeps the mass where it is).
    #[inline]
    pub(crate) fn held_force(&self, t: f64, x: f64) -> f64 {
        if self.driven() {
            self.input_at(t) - self.restoring_force(x)
        } else {
            -self.restoring_force(x)
        }
    }

    /// The acceleration at time `t` for friction force `f`.
    #[inline]
    pub(crate) fn accel(&self, t: f64, x: f64, v: f64, f: f64) -> f64 {
        -(self.osc.damping * v + self.restoring_force(x) + f - self.input_at(t)) / self.osc.mass
    }

    /// The right-hand side of the first-order system y = [x, v, z...] at time `t` in
    /// direction `dir`.
    #[inline]
    pub(crate) fn rhs(&self, t: f64, y: &[f64], dy: &mut [f64], dir: f64) {
        let ([x, v, z @ ..], [dx, dv, dz @ ..]) = (y, dy) else {
            return;
        };
        let f = match (self.law, self.conditions) {
            (Law::Dynamic { states, .. }, None) => {
                states.state_derivative_and_force(*v, z, self.normal, dz)
            }
            (Law::Dynamic { states, .. }, Some(_)) => {
                states.state_derivative(*v, z, self.normal, dz);
                self.force(t, *x, *v, z, dir)
            }
            _ => self.slip_force(t, *x, *v, dir),
        };
        *dx = *v;
        *dv = self.accel(t, *x, *v, f);
    }

    /// Writes df/dt of [`Dynamics::rhs`] at (t, y) in direction `dir` (the explicit
    /// dependence on time at fixed y) into `dfdt` and returns true; false, `dfdt` untouched,
    /// when nothing in it varies with time (no measured input, no channel the law reads).
    /// Only the acceleration row moves: (u'(t) - dF/dt) / m, with u' the input's slope over
    /// the stretch a step from `t` covers (steps stop at its knots, so that slope holds over
    /// the whole step) and dF/dt the friction's change through the channels it reads; the
    /// states' rates do not read the time.
    pub(crate) fn time_derivative(&self, t: f64, y: &[f64], dir: f64, dfdt: &mut [f64]) -> bool {
        let gap = KNOT_GAP * (1.0 + t.abs());
        let input_rate = self.input.map(|u| u.slope_after(t, gap));
        let friction_rate = self.friction_time_rate(t, y, dir);
        if input_rate.is_none() && friction_rate.is_none() {
            return false;
        }
        dfdt.fill(0.0);
        if let Some(dv) = dfdt.get_mut(1) {
            *dv = (input_rate.unwrap_or(0.0) - friction_rate.unwrap_or(0.0)) / self.osc.mass;
        }
        true
    }

    /// dF/dt at fixed (x, v, z) in direction `dir` when the law reads a condition that
    /// varies with time (the input force, a channel), else `None`: a forward difference
    /// over a step short of the next knot, within which the conditions are linear in t.
    fn friction_time_rate(&self, t: f64, y: &[f64], dir: f64) -> Option<f64> {
        let conditions = self.conditions?;
        let [x, v, z @ ..] = y else {
            return None;
        };
        let knot = conditions.next_knot(t, KNOT_GAP * (1.0 + t.abs()))?;
        let dt = (f64::EPSILON.sqrt() * (1.0 + t.abs())).min(0.5 * (knot - t));
        if dt <= 0.0 {
            return None;
        }
        let later = t + dt;
        let force = |at: f64| self.force(at, *x, *v, z, dir);
        Some((force(later) - force(t)) / (later - t))
    }

    /// The segment's linear equation when the law is affine in v in direction `dir`, on a
    /// linear spring in free vibration.
    pub(crate) fn affine_motion(&self, dir: f64) -> Option<AffineMotion> {
        if matches!(self.law, Law::Dynamic { .. })
            || self.driven()
            || !self.osc.has_linear_spring()
            || self.conditions.is_some()
        {
            return None;
        }
        let (offset, slope) = self.switching?.affine_slip(dir, self.normal)?;
        Some(AffineMotion {
            mass: self.osc.mass,
            damping: self.osc.damping + slope,
            stiffness: self.osc.stiffness,
            offset,
        })
    }

    /// Whether every sliding mode of this law is solved in closed form.
    pub(crate) fn closed_form_applies(&self) -> bool {
        [1.0, -1.0].into_iter().all(|dir| {
            self.affine_motion(dir)
                .is_some_and(|m| ClosedForm::supports(&m))
        })
    }

    /// The mode at the start of a segment from state (x, v, z) at time `t`: with a
    /// set-valued law the mass sticks while the force it must hold, |u - R(x)|, is within
    /// the static limit.
    pub(crate) fn start(&self, t: f64, x: f64, v: f64, z: &[f64]) -> Start {
        if v != 0.0 {
            return Start::Slip(sgn(v));
        }
        if let Some((limit, offset)) = self.stick_band(t, x) {
            let held = self.held_force(t, x);
            if (held - offset).abs() <= limit {
                return Start::Rest;
            }
            let dir = sgn(held - offset);
            let a = self.accel(t, x, 0.0, self.slip_force(t, x, 0.0, dir));
            return if dir * a > 0.0 {
                Start::Slip(dir)
            } else {
                Start::Rest
            };
        }
        match self.law {
            Law::Switched { .. } => Start::Rest,
            Law::Smooth | Law::Dynamic { .. } => {
                let a = self.accel(t, x, 0.0, self.force(t, x, 0.0, z, 0.0));
                if a.is_finite() && a != 0.0 {
                    Start::Slip(sgn(a))
                } else if a == 0.0 {
                    // In balance at this instant (a drive starting from rest with u = 0):
                    // nothing holds a law without a static limit, so the input's next move
                    // sets the mass going.
                    self.input_departure(t).map_or(Start::Rest, Start::Slip)
                } else {
                    Start::Rest
                }
            }
        }
    }
}

/// How the engine treats `model`'s law: dynamic, switched (with its static limit) or smooth.
fn classify_law(model: &dyn FrictionModel, normal: f64) -> Result<Law<'_>, EngineError> {
    if let Some(states) = model.states().filter(|s| s.n_states() > 0) {
        let derivatives = Derivatives::of(states);
        return Ok(Law::Dynamic {
            states,
            derivatives,
        });
    }
    let offset = model
        .switching()
        .map_or(0.0, |law| law.static_offset(normal));
    match model.switching().and_then(|law| law.static_limit(normal)) {
        Some(limit) if limit.is_finite() && limit >= 0.0 && offset.abs() <= limit => {
            Ok(Law::Switched { limit, offset })
        }
        Some(limit) => Err(EngineError::InvalidInput(format!(
            "model `{}` reports a static limit of {limit} N",
            model.name()
        ))),
        None => Ok(Law::Smooth),
    }
}

#[cfg(test)]
mod tests {
    use super::super::conditions::{BoundConditions, ChannelSeries};
    use super::*;
    use frictionid_models::default_model;

    /// The acceleration row of the right-hand side at time `t`, from (x, v) = (0.01, 0.05).
    fn accel_at(d: &Dynamics<'_>, t: f64) -> f64 {
        let mut dy = [0.0; 2];
        d.rhs(t, &[0.01, 0.05], &mut dy, 1.0);
        dy[1]
    }

    /// Under an input and a load channel (a law that reads it), df/dt is the change of the
    /// right-hand side in t over the stretch a step from t covers: a central difference
    /// inside a stretch, a forward one from a knot (where the slope changes).
    #[test]
    fn the_time_derivative_is_the_rate_of_the_stretch_ahead() {
        let model = default_model("coulomb_load").expect("registered");
        let input = Input::new(vec![0.0, 1.0, 2.0], vec![0.0, 4.0, -2.0]).expect("an input");
        let load = ChannelSeries::new("r")
            .with_channel("load", vec![0.0, 0.5, 2.0], vec![1.0, 3.0, -1.5])
            .expect("a channel");
        let bound = BoundConditions::bind(model.as_ref(), Some(&input), Some(&load))
            .expect("the channel is there")
            .expect("the law reads the load");
        let d = Dynamics::new(&Oscillator::fmm(), model.as_ref())
            .expect("a switched law")
            .driven_by(Some(&input))
            .reading(Some(&bound));
        let h = 1e-6;
        let central = |t: f64| (accel_at(&d, t + h) - accel_at(&d, t - h)) / (2.0 * h);
        let forward = |t: f64| (accel_at(&d, t + h) - accel_at(&d, t)) / h;
        for (t, expected) in [
            (0.25, central(0.25)),
            (0.75, central(0.75)),
            (1.0, forward(1.0)),
        ] {
            let mut dfdt = [f64::NAN; 2];
            assert!(d.time_derivative(t, &[0.01, 0.05], 1.0, &mut dfdt));
            assert_eq!(dfdt[0], 0.0);
            assert!(
                (dfdt[1] - expected).abs() <= 1e-6 * expected.abs().max(1.0),
                "t {t}: {} vs {expected}",
                dfdt[1]
            );
        }
        let free = Dynamics::new(&Oscillator::fmm(), &frictionid_models::Coulomb { mu: 0.2 })
            .expect("a switched law");
        let mut dfdt = [f64::NAN; 2];
        assert!(!free.time_derivative(0.25, &[0.01, 0.05], 1.0, &mut dfdt));
        assert!(dfdt.iter().all(|d| d.is_nan()), "left as it was");
    }
}
