//! The embedded Bogacki-Shampine 3(2) stepper (Bogacki & Shampine 1989), used to integrate a
//! friction model's internal states along a measured motion.
//!
//! Error control: the max norm of the local error over atol + rtol max(|z|, |z_new|), step
//! factor 0.9 err^(-1/3) within [0.2, 5]. The step size learnt in one interval is carried into
//! the next reset (a short last step landing on the end time does not shrink it), so a long
//! sequence of sample intervals costs what the states' dynamics need, not a fresh start each.
//! Dense output: the cubic Hermite interpolant through both ends of the step.

use super::stepper::{
    current_point_accessors, OdeSystem, StepCounts, StepOutcome, StepResult, Stepper, Tolerance,
};
use crate::error::IntegrationFailure;

/// Bogacki-Shampine 3(2) with error control and cubic Hermite dense output.
#[derive(Debug, Clone)]
pub struct BogackiShampine {
    tol: Tolerance,
    /// The step size to try next.
    h: f64,
    t: f64,
    t_prev: f64,
    t_end: f64,
    /// The span of the current reset interval (scales the underflow test and the end snap).
    span: f64,
    y: Vec<f64>,
    y_prev: Vec<f64>,
    /// k[0]: f at the current state; k[3]: f at the candidate; k[4]: f at the previous state.
    k: [Vec<f64>; 5],
    tmp: Vec<f64>,
    next: Vec<f64>,
    counts: StepCounts,
}

impl BogackiShampine {
    /// A stepper for `dim` equations with tolerances `rtol` and `atol`.
    pub fn new(dim: usize, rtol: f64, atol: f64) -> Self {
        let zeros = || vec![0.0; dim];
        Self {
            tol: Tolerance { rtol, atol },
            h: 0.0,
            t: 0.0,
            t_prev: 0.0,
            t_end: 0.0,
            span: 0.0,
            y: zeros(),
            y_prev: zeros(),
            k: std::array::from_fn(|_| zeros()),
            tmp: zeros(),
            next: zeros(),
            counts: StepCounts::default(),
        }
    }

    /// The three new stages of a step of size `h`; the candidate goes to `next`, f there to
    /// k[3]. Returns the error norm (infinite when not finite).
    fn attempt<S: OdeSystem>(&mut self, system: &S, h: f64) -> f64 {
        let t = self.t;
        let [k1, k2, k3, k4, _] = &mut self.k;
        for ((tmp, &z), &d) in self.tmp.iter_mut().zip(&self.y).zip(k1.iter()) {
            *tmp = z + 0.5 * h * d;
        }
        system.rhs(t + 0.5 * h, &self.tmp, k2);
        for ((tmp, &z), &d) in self.tmp.iter_mut().zip(&self.y).zip(k2.iter()) {
            *tmp = z + 0.75 * h * d;
        }
        system.rhs(t + 0.75 * h, &self.tmp, k3);
        for j in 0..self.y.len() {
            self.next[j] =
                self.y[j] + h * (2.0 / 9.0 * k1[j] + 1.0 / 3.0 * k2[j] + 4.0 / 9.0 * k3[j]);
        }
        system.rhs(t + h, &self.next, k4);
        self.counts.rhs_evaluations += 3;
        let mut err: f64 = 0.0;
        for j in 0..self.y.len() {
            let low = self.y[j]
                + h * (7.0 / 24.0 * k1[j] + 0.25 * k2[j] + 1.0 / 3.0 * k3[j] + 0.125 * k4[j]);
            let scale = self.tol.scale(self.y[j], self.next[j]);
            err = err.max((self.next[j] - low).abs() / scale);
        }
        if err.is_finite() {
            err
        } else {
            f64::INFINITY
        }
    }

    /// Moves to the accepted candidate at `t_new`.
    fn accept(&mut self, t_new: f64) {
        std::mem::swap(&mut self.y_prev, &mut self.y);
        self.y.copy_from_slice(&self.next);
        let [k1, _, _, k4, k_prev] = &mut self.k;
        k_prev.copy_from_slice(k1);
        k1.copy_from_slice(k4);
        self.t_prev = self.t;
        self.t = t_new;
    }
}

impl Stepper for BogackiShampine {
    current_point_accessors!();

    fn reset<S: OdeSystem>(&mut self, system: &S, t: f64, y: &[f64], t_end: f64) -> StepResult<()> {
        self.span = t_end - t;
        if self.h.is_nan() || self.h <= 0.0 || self.h > self.span {
            self.h = self.span;
        }
        self.t = t;
        self.t_prev = t;
        self.t_end = t_end;
        self.y.copy_from_slice(y);
        self.y_prev.copy_from_slice(y);
        system.rhs(t, &self.y, &mut self.k[0]);
        let [k1, .., k_prev] = &mut self.k;
        k_prev.copy_from_slice(k1);
        self.counts.rhs_evaluations += 1;
        Ok(())
    }

    fn step<S: OdeSystem>(&mut self, system: &S) -> StepResult<StepOutcome> {
        let last = self.t + self.h >= self.t_end - 1e-12 * self.span;
        let h = if last { self.t_end - self.t } else { self.h };
        let err = self.attempt(system, h);
        let accepted = err <= 1.0;
        if accepted {
            self.accept(if last { self.t_end } else { self.t + h });
            self.counts.accepted += 1;
        } else {
            self.counts.rejected += 1;
        }
        let factor = if err == 0.0 {
            5.0
        } else {
            (0.9 * err.powf(-1.0 / 3.0)).clamp(0.2, 5.0)
        };
        let proposed = h * factor;
        // Keep the step size learnt in the interval, unless the last (shortened) step was
        // accepted: then carry the regular step into the next interval.
        self.h = if last && accepted && h < self.h {
            self.h.max(proposed)
        } else {
            proposed
        };
        if self.h < 1e-14 * self.span.max(1e-300) {
            return Err(IntegrationFailure::StepSizeTooSmall {
                time: self.t,
                step: self.h,
            });
        }
        Ok(if accepted {
            StepOutcome::Accepted
        } else {
            StepOutcome::Rejected
        })
    }

    fn interpolate(&self, t: f64, out: &mut [f64]) {
        let h = self.t - self.t_prev;
        if h <= 0.0 {
            out.copy_from_slice(&self.y);
            return;
        }
        let s = (t.clamp(self.t_prev, self.t) - self.t_prev) / h;
        // Cubic Hermite basis on [0, 1].
        let h00 = (1.0 + 2.0 * s) * (1.0 - s) * (1.0 - s);
        let h10 = s * (1.0 - s) * (1.0 - s);
        let h01 = s * s * (3.0 - 2.0 * s);
        let h11 = s * s * (s - 1.0);
        let [f1, _, _, _, f0] = &self.k;
        for (j, o) in out.iter_mut().enumerate() {
            *o = h00 * self.y_prev[j] + h10 * h * f0[j] + h01 * self.y[j] + h11 * h * f1[j];
        }
    }
}
