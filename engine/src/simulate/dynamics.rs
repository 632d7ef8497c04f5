//! The equation of motion J q'' + c q' + R(q) + F_f = u(t) - F_0 of an oscillator with its
//! friction law: the right-hand side, the modes of a switched law and the start of a segment.

use super::{AffineMotion, ClosedForm, Input};
use crate::error::EngineError;
use crate::oscillator::Oscillator;
use frictionid_models::{sgn, Derivatives, FrictionModel, InternalStates, SwitchedLaw};

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
        })
    }

    /// The same equation of motion driven by `input`.
    pub(crate) fn driven_by(self, input: Option<&'a Input>) -> Self {
        Self { input, ..self }
    }
}

impl Dynamics<'_> {
    /// The friction force in slip direction `dir` (static laws) or from the states (dynamic).
    #[inline]
    pub(crate) fn force(&self, v: f64, z: &[f64], dir: f64) -> f64 {
        match self.law {
            Law::Dynamic { .. } => self.model.force(v, z, self.normal),
            _ => self.slip_force(v, dir),
        }
    }

    /// The force of a static law slipping in direction `dir` (its force at `v` when it is
    /// not a switched law).
    #[inline]
    pub(crate) fn slip_force(&self, v: f64, dir: f64) -> f64 {
        match self.switching {
            Some(law) => law.slip_force(v, dir, self.normal),
            None => self.model.force(v, &[], self.normal),
        }
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
        let f = match self.law {
            Law::Dynamic { states, .. } => {
                states.state_derivative_and_force(*v, z, self.normal, dz)
            }
            _ => self.slip_force(*v, dir),
        };
        *dx = *v;
        *dv = self.accel(t, *x, *v, f);
    }

    /// The segment's linear equation when the law is affine in v in direction `dir`, on a
    /// linear spring in free vibration.
    pub(crate) fn affine_motion(&self, dir: f64) -> Option<AffineMotion> {
        if matches!(self.law, Law::Dynamic { .. }) || self.driven() || !self.osc.has_linear_spring()
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
        match self.law {
            Law::Switched { limit, offset } => {
                let held = self.held_force(t, x);
                if (held - offset).abs() <= limit {
                    return Start::Rest;
                }
                let dir = sgn(held - offset);
                let a = self.accel(t, x, 0.0, self.slip_force(0.0, dir));
                if dir * a > 0.0 {
                    Start::Slip(dir)
                } else {
                    Start::Rest
                }
            }
            Law::Smooth | Law::Dynamic { .. } => {
                let a = self.accel(t, x, 0.0, self.force(0.0, z, 0.0));
                if a == 0.0 || !a.is_finite() {
                    Start::Rest
                } else {
                    Start::Slip(sgn(a))
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
