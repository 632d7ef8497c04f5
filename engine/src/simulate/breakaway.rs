//! Where a stick under an input ends: the break-away time and direction of a mass held at
//! rest, shared by the plain driver and the augmented sensitivity run.

use super::driver::EVENT_TOL;
use super::root::illinois;
use super::{Dynamics, Law};
use frictionid_models::sgn;

impl Dynamics<'_> {
    /// When a mass stuck at (t, x) under an input breaks away, and in which direction: the
    /// first time |u - R(x)| exceeds the static limit (a switched law's stick), located on
    /// the piecewise-linear input. `None` in free vibration, for laws without a static limit
    /// and when the stick lasts to the end.
    pub(crate) fn breakaway(&self, t: f64, x: f64, t_end: f64) -> Option<(f64, f64)> {
        if !matches!(self.law, Law::Switched { .. }) {
            return self.input_resumes(t, t_end);
        }
        if self.conditions.is_some() {
            return self.breakaway_under_conditions(t, x, t_end);
        }
        let input = self.input?;
        let Law::Switched { limit, offset } = self.law else {
            return None;
        };
        // The input itself must leave the band about R(x) + F_0 (+ the law's offset).
        let centre = self.restoring_force(x) + self.osc.input_offset + offset;
        let t_b = input.first_exceedance(t, t_end, centre, limit)?;
        // A stick that the input leaves at once is a stick the slip force cannot end
        // (a law whose slip force at rest exceeds its static limit): it lasts.
        if t_b <= t {
            return None;
        }
        Some((t_b, sgn(self.held_force(t_b, x) - offset)))
    }

    /// When a law without a static limit, in balance at rest at `t` under a flat input,
    /// starts moving: where the input leaves the value it holds, in the direction it goes.
    /// `None` without an input, or when it stays flat to the end.
    fn input_resumes(&self, t: f64, t_end: f64) -> Option<(f64, f64)> {
        let input = self.input?;
        let t_b = input.first_exceedance(t, t_end, input.at(t), 0.0)?;
        let dir = self.input_departure(t_b).filter(|_| t_b > t)?;
        Some((t_b, dir))
    }

    /// [`Dynamics::breakaway`] of a law whose stick band moves with its conditions (a load, a
    /// temperature): the held force and the band are linear in time between the knots of
    /// the input and of the channels (up to the law's own curvature in them), so the first
    /// knot outside the band brackets the breakaway, located there by the Illinois method.
    /// Also in free vibration, where a shrinking band lets the mass go.
    fn breakaway_under_conditions(&self, t: f64, x: f64, t_end: f64) -> Option<(f64, f64)> {
        let excess = |s: f64| {
            let (limit, offset) = self.stick_band(s, x)?;
            Some((self.held_force(s, x) - offset).abs() - limit)
        };
        let mut t0 = t;
        while t0 < t_end {
            let t1 = self.stop_after(t0, t_end);
            let g1 = excess(t1)?;
            if g1 > 0.0 {
                let g0 = excess(t0)?;
                let g = |s: f64| excess(s).map(|e| -e);
                let t_b = if g0 > 0.0 {
                    t0
                } else {
                    illinois(g, t0, -g0, t1, -g1, EVENT_TOL)?
                };
                if t_b <= t {
                    return None;
                }
                let (_, offset) = self.stick_band(t_b, x)?;
                return Some((t_b, sgn(self.held_force(t_b, x) - offset)));
            }
            if t1 <= t0 {
                return None;
            }
            t0 = t1;
        }
        None
    }
}
