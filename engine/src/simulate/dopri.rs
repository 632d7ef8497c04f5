//! The Dormand-Prince 5(4) stepper with its 4th-order dense output (Dormand & Prince 1980;
//! Hairer, Norsett & Wanner, *Solving ODEs I*, II.5 and II.6).
//!
//! Step-size control is the PI controller of Hairer's DOPRI5 (safety 0.9, beta 0.04, step
//! factor within [0.2, 10], no growth right after a rejection), with the same starting-step
//! heuristic, error norm (RMS of the error over atol + rtol max(|y|, |y_new|)) and underflow
//! test as the ode_solvers crate the engine used before, so that trajectories and statistics
//! are those of that implementation. Unlike it, this stepper takes one step at a time, keeps
//! only the last step's dense output, and allocates nothing after construction.
//!
//! Bit-compatibility: at the start of a step (other than the first after a reset) the dense
//! output returns the previous step's interpolant at its end, as ode_solvers' output model
//! did. Changing this moves turning points by round-off only, yet it flips the default LuGre
//! fit (`engine/tests/dynamic.rs`, `lugre_is_recovered_from_the_default_configuration`) into
//! another local minimum (rms 3.7e-4 instead of about 2e-4 m/s): that fit is sensitive at the
//! round-off level.

use super::stepper::{
    current_point_accessors, IntervalStart, OdeSystem, StepControl, StepCounts, StepOutcome,
    StepResult, Stepper,
};

/// Stage times c_i.
const C: [f64; 7] = [0.0, 1.0 / 5.0, 3.0 / 10.0, 4.0 / 5.0, 8.0 / 9.0, 1.0, 1.0];
/// Runge-Kutta matrix, row i holds a_{i+1, j} for j < i+1 (row 6: the 5th-order weights b).
const A: [[f64; 6]; 6] = [
    [1.0 / 5.0, 0.0, 0.0, 0.0, 0.0, 0.0],
    [3.0 / 40.0, 9.0 / 40.0, 0.0, 0.0, 0.0, 0.0],
    [44.0 / 45.0, -56.0 / 15.0, 32.0 / 9.0, 0.0, 0.0, 0.0],
    [
        19372.0 / 6561.0,
        -25360.0 / 2187.0,
        64448.0 / 6561.0,
        -212.0 / 729.0,
        0.0,
        0.0,
    ],
    [
        9017.0 / 3168.0,
        -355.0 / 33.0,
        46732.0 / 5247.0,
        49.0 / 176.0,
        -5103.0 / 18656.0,
        0.0,
    ],
    [
        35.0 / 384.0,
        0.0,
        500.0 / 1113.0,
        125.0 / 192.0,
        -2187.0 / 6784.0,
        11.0 / 84.0,
    ],
];
/// Dense-output weights (Shampine's 4th-order continuous extension).
const D: [f64; 7] = [
    -12715105075.0 / 11282082432.0,
    0.0,
    87487479700.0 / 32700410799.0,
    -10690763975.0 / 1880347072.0,
    701980252875.0 / 199316789632.0,
    -1453857185.0 / 822651844.0,
    69997945.0 / 29380423.0,
];
/// Error weights b - b_hat.
const E: [f64; 7] = [
    71.0 / 57600.0,
    0.0,
    -71.0 / 16695.0,
    71.0 / 1920.0,
    -17253.0 / 339200.0,
    22.0 / 525.0,
    -1.0 / 40.0,
];

/// Safety factor of the step-size controller.
const SAFETY: f64 = 0.9;
/// PI-controller weight of the previous error.
const BETA: f64 = 0.04;
/// Exponent of the current error (0.2 - 0.75 beta).
const ALPHA: f64 = 0.2 - 0.75 * BETA;
/// Largest step shrink per step (1 / fac_min).
const MAX_SHRINK: f64 = 1.0 / 0.2;
/// Largest step growth per step (1 / fac_max, as a divisor).
const MAX_GROWTH_DIVISOR: f64 = 1.0 / 10.0;
/// Floor of the remembered error.
const MIN_OLD_ERROR: f64 = 1e-4;

/// Dormand-Prince 5(4) with error control and dense output over `Vec<f64>` states.
#[derive(Debug, Clone)]
pub struct Dopri5 {
    ctrl: StepControl,
    old_error: f64,
    y: Vec<f64>,
    y_next: Vec<f64>,
    /// The embedded error estimate of the last attempt.
    err_est: Vec<f64>,
    /// Stages k_1..k_7 (k[0] holds f at the current state: first same as last).
    k: [Vec<f64>; 7],
    /// Dense-output coefficients of the last accepted step.
    cont: [Vec<f64>; 5],
    counts: StepCounts,
    /// The dense output's value at the start of the last step: the previous step's interpolant
    /// at its end (c0 + c1, which may differ from the state by round-off), or the reset state.
    /// This keeps turning points bit-identical to the ode_solvers-based engine this stepper
    /// replaced, whose output model resolved a step boundary to the step ending there; the
    /// identification tests are sensitive to it (see the module docs).
    start_value: Vec<f64>,
}

impl Dopri5 {
    /// A stepper for `dim` equations with tolerances `rtol`, `atol` and largest step `h_max`.
    pub fn new(dim: usize, rtol: f64, atol: f64, h_max: f64) -> Self {
        let zeros = || vec![0.0; dim];
        Self {
            ctrl: StepControl::new(dim, rtol, atol, h_max),
            old_error: MIN_OLD_ERROR,
            y: zeros(),
            y_next: zeros(),
            err_est: zeros(),
            k: std::array::from_fn(|_| zeros()),
            cont: std::array::from_fn(|_| zeros()),
            counts: StepCounts::default(),
            start_value: zeros(),
        }
    }

    /// The same stepper with each component's absolute tolerance multiplied by its entry of
    /// `scales` (see [`Tolerance::scale_atol`]).
    pub fn with_atol_scales(mut self, scales: &[f64]) -> Self {
        self.ctrl.tol.scale_atol(scales);
        self
    }

    /// The same stepper with its error control over the first `controlled` components only
    /// (see [`Tolerance::control_first`](super::Tolerance::control_first)).
    pub fn controlling_first(mut self, controlled: usize) -> Self {
        self.ctrl.tol.control_first(controlled);
        self
    }

    /// The starting step of Hairer's DOPRI5 (two RHS evaluations, the first kept in k[0]).
    fn initial_step<S: OdeSystem>(&mut self, system: &S) -> f64 {
        let (f0, rest) = self.k.split_at_mut(1);
        let (f0, f1) = (&mut f0[0], &mut rest[0]);
        system.rhs(self.ctrl.t, &self.y, f0);
        let (h0, _, d1) = self.ctrl.tol.first_step_guess(&self.y, f0);
        let h0 = h0.min(self.ctrl.h_max);
        for ((yn, &yi), &fi) in self.y_next.iter_mut().zip(&self.y).zip(f0.iter()) {
            *yn = yi + fi * h0;
        }
        system.rhs(self.ctrl.t + h0, &self.y_next, f1);
        let mut d2 = 0.0;
        let controlled = self.ctrl.tol.atol.len();
        let pairs = self.y.iter().zip(f0.iter()).zip(f1.iter());
        for (i, ((&yi, &a), &b)) in pairs.enumerate().take(controlled) {
            let sc = self.ctrl.tol.scale(i, yi, yi);
            d2 += ((b - a) / sc) * ((b - a) / sc);
        }
        let d2 = d2.sqrt() / h0;
        let d1 = d1.sqrt();
        let h1 = if d1.max(d2.abs()) <= 1e-15 {
            1e-6f64.max(h0 * 1e-3)
        } else {
            (0.01 / d1.max(d2)).powf(0.2)
        };
        (100.0 * h0).min(h1.min(self.ctrl.h_max))
    }

    /// The six stages after k[0]; leaves the 5th-order solution in `y_next` and f there in k[6].
    fn stages<S: OdeSystem>(&mut self, system: &S, h: f64) {
        for s in 1..7 {
            let (done, todo) = self.k.split_at_mut(s);
            self.y_next.copy_from_slice(&self.y);
            for (kj, &a) in done.iter().zip(&A[s - 1]) {
                for (yn, &kv) in self.y_next.iter_mut().zip(kj) {
                    *yn += kv * h * a;
                }
            }
            system.rhs(self.ctrl.t + h * C[s], &self.y_next, &mut todo[0]);
        }
        self.counts.rhs_evaluations += 6;
    }

    /// Writes sum_i w[i] k_i h into `out` (k_2 is skipped: its weight is zero in D and E).
    fn combine(k: &[Vec<f64>; 7], w: &[f64; 7], h: f64, out: &mut [f64]) {
        for (i, o) in out.iter_mut().enumerate() {
            *o = (k[0][i] * w[0]
                + k[2][i] * w[2]
                + k[3][i] * w[3]
                + k[4][i] * w[4]
                + k[5][i] * w[5]
                + k[6][i] * w[6])
                * h;
        }
    }

    /// The RMS error norm of the embedded estimate.
    fn error_norm(&mut self, h: f64) -> f64 {
        Self::combine(&self.k, &E, h, &mut self.err_est);
        self.ctrl.tol.rms_norm(&self.y, &self.y_next, &self.err_est)
    }

    /// The PI controller: the next step size, and whether the step is accepted.
    fn control(&mut self, err: f64, h: f64) -> (bool, f64) {
        let err_alpha = err.powf(ALPHA);
        // min/max, not clamp: a NaN error must give the largest shrink, not a NaN step.
        #[allow(clippy::manual_clamp)]
        let fac = (err_alpha * self.old_error.powf(-BETA) / SAFETY)
            .min(MAX_SHRINK)
            .max(MAX_GROWTH_DIVISOR);
        let h_new = h / fac;
        if err <= 1.0 {
            self.old_error = err.max(MIN_OLD_ERROR);
            let mut h_new = h_new.min(self.ctrl.h_max);
            if self.ctrl.after_reject {
                h_new = h_new.min(h);
            }
            self.ctrl.after_reject = false;
            (true, h_new)
        } else {
            self.ctrl.after_reject = true;
            (false, h / MAX_SHRINK.min(err_alpha / SAFETY))
        }
    }

    /// Stores the dense output of the accepted step and moves to its end.
    fn accept(&mut self, h: f64) {
        if self.ctrl.t_prev < self.ctrl.t {
            for ((s, &c0), &c1) in self
                .start_value
                .iter_mut()
                .zip(&self.cont[0])
                .zip(&self.cont[1])
            {
                *s = c0 + c1;
            }
        } else {
            self.start_value.copy_from_slice(&self.y);
        }
        let [c0, c1, c2, c3, c4] = &mut self.cont;
        Self::combine(&self.k, &D, h, c4);
        for i in 0..self.y.len() {
            let diff = self.y_next[i] - self.y[i];
            let bspl = self.k[0][i] * h - diff;
            c0[i] = self.y[i];
            c1[i] = diff;
            c2[i] = bspl;
            c3[i] = -self.k[6][i] * h + diff - bspl;
        }
        let [k0, .., k6] = &mut self.k;
        k0.copy_from_slice(k6);
        std::mem::swap(&mut self.y, &mut self.y_next);
        self.ctrl.advance(h);
    }

    /// Starts an interval at state `y` at `t` towards `t_end` (the step size as it is): what
    /// a reset and a restart share.
    fn start_at(&mut self, t: f64, y: &[f64], t_end: f64) {
        self.ctrl.restart(t, t_end);
        self.y.copy_from_slice(y);
        self.old_error = MIN_OLD_ERROR;
    }
}

impl Stepper for Dopri5 {
    current_point_accessors!(ctrl);

    /// Starts with the step size the last run proposed (Hairer's starting step only when
    /// there is none yet): for a sequence of intervals whose right-hand side jumps between
    /// them but keeps its scale (the sample intervals of a replayed motion), one evaluation
    /// of f instead of two, and a first step of the scale the last interval found.
    fn keep_step<S: OdeSystem>(
        &mut self,
        system: &S,
        (t, y, t_end): IntervalStart,
    ) -> StepResult<()> {
        self.start_at(t, y, t_end);
        system.rhs(t, y, &mut self.k[0]);
        self.counts.rhs_evaluations += 1;
        Ok(())
    }

    fn reset<S: OdeSystem>(&mut self, system: &S, t: f64, y: &[f64], t_end: f64) -> StepResult<()> {
        self.start_at(t, y, t_end);
        // Leaves f(t, y) in k[0], ready for the first step.
        self.ctrl.h = self.initial_step(system);
        self.counts.rhs_evaluations += 2;
        Ok(())
    }

    /// The state, the step size and f there (k[0], the final stage of the last accepted
    /// step) carry over: it saves the two evaluations of f a reset makes.
    fn continue_to(&mut self, t_end: f64) {
        self.ctrl.extend_to(t_end);
    }

    fn step<S: OdeSystem>(&mut self, system: &S) -> StepResult<StepOutcome> {
        let h = self.ctrl.next_attempt()?;
        self.stages(system, h);
        let err = self.error_norm(h);
        let (accepted, h_new) = self.control(err, h);
        self.ctrl.h = h_new;
        if !accepted {
            self.ctrl.last = false;
            self.counts.rejected += 1;
            return Ok(StepOutcome::Rejected);
        }
        self.counts.accepted += 1;
        self.accept(h);
        Ok(StepOutcome::Accepted)
    }

    fn interpolate(&self, t: f64, out: &mut [f64]) {
        if t == self.ctrl.t_prev {
            out.copy_from_slice(&self.start_value);
            return;
        }
        let theta = self.ctrl.fraction_of_last_step(t);
        let theta1 = 1.0 - theta;
        let [c0, c1, c2, c3, c4] = &self.cont;
        for (i, o) in out.iter_mut().enumerate() {
            let r = c3[i] + c4[i] * theta1;
            let r = c2[i] + r * theta;
            let r = c1[i] + r * theta1;
            *o = c0[i] + r * theta;
        }
    }
}
