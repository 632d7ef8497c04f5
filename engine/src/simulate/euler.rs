//! The paper's fixed-step explicit Euler: y += h f(y) (x += h v, v += h a, both from the old
//! state), with steps counted from the segment start (t_seg + i h, the last one cut at the end
//! time). Its dense output is the straight line between the step's ends, so turning points and
//! samples are interpolated linearly.

use super::stepper::{
    current_point_accessors, OdeSystem, StepCounts, StepOutcome, StepResult, Stepper,
};

/// Fixed-step explicit Euler.
#[derive(Debug, Clone)]
pub struct Euler {
    h: f64,
    t_seg: f64,
    steps_in_segment: u64,
    t: f64,
    t_prev: f64,
    t_end: f64,
    y: Vec<f64>,
    y_prev: Vec<f64>,
    dy: Vec<f64>,
    counts: StepCounts,
}

impl Euler {
    /// A stepper for `dim` equations with step `h` [s].
    pub fn new(dim: usize, h: f64) -> Self {
        Self {
            h,
            t_seg: 0.0,
            steps_in_segment: 0,
            t: 0.0,
            t_prev: 0.0,
            t_end: 0.0,
            y: vec![0.0; dim],
            y_prev: vec![0.0; dim],
            dy: vec![0.0; dim],
            counts: StepCounts::default(),
        }
    }
}

impl Stepper for Euler {
    current_point_accessors!();

    fn reset<S: OdeSystem>(&mut self, _: &S, t: f64, y: &[f64], t_end: f64) -> StepResult<()> {
        self.t_seg = t;
        self.steps_in_segment = 0;
        self.t = t;
        self.t_prev = t;
        self.t_end = t_end;
        self.y.copy_from_slice(y);
        self.y_prev.copy_from_slice(y);
        Ok(())
    }

    /// The steps keep counting from the segment's start; the one that would pass `t_end` is
    /// cut there.
    fn continue_to(&mut self, t_end: f64) {
        self.t_end = t_end;
    }

    fn step<S: OdeSystem>(&mut self, system: &S) -> StepResult<StepOutcome> {
        self.steps_in_segment += 1;
        let t_next = (self.t_seg + self.steps_in_segment as f64 * self.h).min(self.t_end);
        let hs = t_next - self.t;
        system.rhs(self.t, &self.y, &mut self.dy);
        std::mem::swap(&mut self.y, &mut self.y_prev);
        for ((yn, &yo), &d) in self.y.iter_mut().zip(&self.y_prev).zip(&self.dy) {
            *yn = yo + hs * d;
        }
        self.t_prev = self.t;
        self.t = t_next;
        self.counts.accepted += 1;
        self.counts.rhs_evaluations += 1;
        Ok(StepOutcome::Accepted)
    }

    fn interpolate(&self, t: f64, out: &mut [f64]) {
        let frac = if self.t > self.t_prev {
            ((t - self.t_prev) / (self.t - self.t_prev)).clamp(0.0, 1.0)
        } else {
            0.0
        };
        for ((o, &a0), &a1) in out.iter_mut().zip(&self.y_prev).zip(&self.y) {
            *o = a0 + frac * (a1 - a0);
        }
    }
}
