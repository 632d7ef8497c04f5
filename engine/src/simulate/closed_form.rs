//! The exact propagator for laws affine in the velocity within a sliding mode
//! ([`frictionid_models::SwitchedLaw::affine_slip`]: F = a + b v): in each segment
//! m x'' + (c + b) x' + k x + a = 0 is a damped harmonic motion about x_eq = -a / k with the
//! closed-form solution
//!
//! u(tau) = e^(-sigma tau) (A cos(w_d tau) + B sin(w_d tau)),  u = x - x_eq,
//! v(tau) = e^(-sigma tau) (v0 cos(w_d tau) - D sin(w_d tau)),
//!
//! sigma = (c + b) / 2m, w_d = sqrt(k/m - sigma^2), A = u0, B = (v0 + sigma u0) / w_d,
//! D = (w0^2 u0 + sigma v0) / w_d. No ODE is solved: a "step" jumps to just past the next zero
//! of v (where the driver polishes the turning point on this closed form to 1e-13 s) or to the
//! end time, and samples on a uniform grid follow by the recurrence
//! (P, Q) <- e^(-sigma dt) (P cos(w_d dt) - Q sin(w_d dt), Q cos(w_d dt) + P sin(w_d dt)) for
//! P = e^(-sigma tau) cos(w_d tau), Q = e^(-sigma tau) sin(w_d tau).
//! Underdamped modes only (sigma < w0); the driver falls back to an ODE stepper otherwise.

use super::stepper::{
    current_point_accessors, AffineMotion, OdeSystem, StepCounts, StepOutcome, StepResult, Stepper,
};
use crate::error::IntegrationFailure;
use std::cell::Cell;
use std::f64::consts::PI;

/// How far past a zero of v a step ends, as a fraction of the half period: enough for v to
/// take the new sign well above round-off, small against any sample spacing.
const PAST_ZERO: f64 = 1e-9;

/// The closed form of one segment.
#[derive(Debug, Clone, Copy, Default)]
struct Mode {
    t0: f64,
    x_eq: f64,
    sigma: f64,
    omega_d: f64,
    a: f64,
    b: f64,
    v0: f64,
    d: f64,
}

impl Mode {
    /// (x, v) from the rotating pair P = e^(-sigma tau) cos, Q = e^(-sigma tau) sin.
    #[inline]
    fn state_at_pq(&self, p: f64, q: f64) -> (f64, f64) {
        (
            self.x_eq + self.a * p + self.b * q,
            self.v0 * p - self.d * q,
        )
    }

    /// (P, Q) at time t.
    #[inline]
    fn pq(&self, t: f64) -> (f64, f64) {
        let tau = t - self.t0;
        let e = (-self.sigma * tau).exp();
        let (s, c) = (self.omega_d * tau).sin_cos();
        (e * c, e * s)
    }

    /// The first tau > 0 where v = 0 (v ~ cos(w_d tau + phi)), as a phase in (0, pi].
    fn first_zero_phase(&self) -> f64 {
        let phi = self.d.atan2(self.v0);
        let theta = (0.5 * PI - phi).rem_euclid(PI);
        if theta > 0.0 {
            theta
        } else {
            PI
        }
    }

    /// The recurrence moved from `last` to `t`: one rotation when `t` is one sample spacing
    /// after `last`, a direct evaluation (and the rotation of the new spacing) otherwise.
    #[inline]
    fn advance(&self, last: Option<Recurrence>, t: f64) -> Recurrence {
        let Some(r) = last else {
            let (p, q) = self.pq(t);
            return Recurrence {
                t,
                p,
                q,
                dt: f64::NAN,
                rot_c: 0.0,
                rot_s: 0.0,
            };
        };
        let step = t - r.t;
        if step == 0.0 {
            return r;
        }
        if (step - r.dt).abs() <= 8.0 * f64::EPSILON * t.abs().max(1.0) {
            let p = r.rot_c * r.p - r.rot_s * r.q;
            let q = r.rot_c * r.q + r.rot_s * r.p;
            return Recurrence { t, p, q, ..r };
        }
        let (p, q) = self.pq(t);
        let decay = (-self.sigma * step).exp();
        let (s, c) = (self.omega_d * step).sin_cos();
        Recurrence {
            t,
            p,
            q,
            dt: step,
            rot_c: decay * c,
            rot_s: decay * s,
        }
    }
}

/// The last sample evaluated and the rotation of the last sample spacing.
#[derive(Debug, Clone, Copy)]
struct Recurrence {
    t: f64,
    p: f64,
    q: f64,
    dt: f64,
    rot_c: f64,
    rot_s: f64,
}

/// The exact propagator as a [`Stepper`] over `[x, v]`.
#[derive(Debug, Clone, Default)]
pub struct ClosedForm {
    mode: Mode,
    t: f64,
    t_prev: f64,
    t_end: f64,
    /// Phase w_d tau of the next candidate zero of v.
    next_phase: f64,
    y: [f64; 2],
    /// The sample recurrence where the last sweep over a grid left it (reset per segment).
    cache: Cell<Option<Recurrence>>,
    counts: StepCounts,
}

impl ClosedForm {
    /// A closed-form propagator (the motion comes from the system at each reset).
    pub fn new() -> Self {
        Self::default()
    }

    /// Whether the segment `motion` is solved in closed form (underdamped).
    pub fn supports(motion: &AffineMotion) -> bool {
        let w0_sq = motion.stiffness / motion.mass;
        let sigma = 0.5 * (motion.damping) / motion.mass;
        motion.mass > 0.0 && motion.stiffness > 0.0 && sigma >= 0.0 && sigma * sigma < w0_sq
    }
}

impl Stepper for ClosedForm {
    current_point_accessors!();

    fn reset<S: OdeSystem>(&mut self, system: &S, t: f64, y: &[f64], t_end: f64) -> StepResult<()> {
        let unavailable = IntegrationFailure::ClosedFormUnavailable { time: t };
        let Some(motion) = system.affine_motion() else {
            return Err(unavailable);
        };
        let (&[x0, v0], true) = (y, Self::supports(&motion)) else {
            return Err(unavailable);
        };
        let w0_sq = motion.stiffness / motion.mass;
        let sigma = 0.5 * motion.damping / motion.mass;
        let omega_d = (w0_sq - sigma * sigma).sqrt();
        let x_eq = -motion.offset / motion.stiffness;
        let u0 = x0 - x_eq;
        self.mode = Mode {
            t0: t,
            x_eq,
            sigma,
            omega_d,
            a: u0,
            b: (v0 + sigma * u0) / omega_d,
            v0,
            d: (w0_sq * u0 + sigma * v0) / omega_d,
        };
        self.next_phase = self.mode.first_zero_phase();
        self.t = t;
        self.t_prev = t;
        self.t_end = t_end;
        self.y = [x0, v0];
        self.cache.set(None);
        Ok(())
    }

    /// The motion is exact whatever the end: only the last step moves.
    fn continue_to(&mut self, t_end: f64) {
        self.t_end = t_end;
    }

    fn step<S: OdeSystem>(&mut self, _system: &S) -> StepResult<StepOutcome> {
        let candidate = self.mode.t0 + (self.next_phase + PAST_ZERO * PI) / self.mode.omega_d;
        self.next_phase += PI;
        let t_next = candidate.min(self.t_end);
        let (p, q) = self.mode.pq(t_next);
        let (x, v) = self.mode.state_at_pq(p, q);
        self.t_prev = self.t;
        self.t = t_next;
        self.y = [x, v];
        self.counts.accepted += 1;
        Ok(StepOutcome::Accepted)
    }

    /// One sweep of the recurrence over the grid (the same values as time-by-time
    /// interpolation, without the per-sample cache round trip).
    fn interpolate_motion(&self, times: &[f64], x: &mut [f64], v: &mut [f64], _buf: &mut [f64]) {
        let mut last = self.cache.get();
        for ((&t, xo), vo) in times.iter().zip(x).zip(v) {
            let r = self.mode.advance(last, t.clamp(self.t_prev, self.t));
            (*xo, *vo) = self.mode.state_at_pq(r.p, r.q);
            last = Some(r);
        }
        self.cache.set(last);
    }

    #[inline]
    /// A single time (the driver's turning-point search): evaluated directly, leaving the
    /// sample recurrence of [`Stepper::interpolate_motion`] where it stands.
    fn interpolate(&self, t: f64, out: &mut [f64]) {
        let (p, q) = self.mode.pq(t.clamp(self.t_prev, self.t));
        let (x, v) = self.mode.state_at_pq(p, q);
        if let [xo, vo, ..] = out {
            *xo = x;
            *vo = v;
        }
    }
}
