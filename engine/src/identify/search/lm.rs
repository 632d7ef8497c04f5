//! A bounded Levenberg-Marquardt least-squares solver, written as an argmin [`Solver`].
//!
//! argmin ships no Levenberg-Marquardt. This one follows Marquardt's scaled form as presented
//! by Madsen, Nielsen and Tingleff ("Methods for non-linear least squares problems", 2004):
//! solve (JᵀJ + μ D) δ = -Jᵀr with D = diag(JᵀJ) (Marquardt's scaling, which makes the step
//! invariant to the units of the parameters), accept the step when the actual reduction is a
//! positive fraction of the reduction the linear model predicts, and update μ by Nielsen's rule.
//! Box bounds are kept by projecting each trial point onto the box (a projected LM step); the
//! predicted reduction is evaluated for the projected step, so the gain ratio stays honest.
//!
//! The problem supplies the residual vector through argmin's [`Operator`] and its Jacobian
//! through [`Jacobian`]. A residual vector with a non-finite entry (e.g. a simulation that
//! failed for the trial parameters) is treated as an infinitely bad trial and rejected.

use super::normal_equations::NormalEquations;
use crate::identify::values::outcome::TerminationReason;
use argmin::core::{
    Error, IterState, Jacobian, Operator, Problem, Solver, State,
    TerminationReason as ArgminReason, TerminationStatus, KV,
};
use nalgebra::{DMatrix, DVector};
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::Arc;

/// The argmin state used by [`LevenbergMarquardt`].
pub type LmState = IterState<DVector<f64>, (), DMatrix<f64>, (), DVector<f64>, f64>;

/// A run still this many times above the cost another run of the same fit converged to is
/// abandoned (its residual RMS is more than 1.4 times the other's: it cannot be the best fit
/// short of a descent far larger than any it has made since its screening).
pub const OUTPACE_FACTOR: f64 = 2.0;

/// The lowest cost any of a group of concurrent runs has converged to, shared between them
/// (+inf until one converges), or a cost the fitted model is known to reach (a nested law's
/// fit); a run is held to it only after `grace` iterations of its own.
#[derive(Debug)]
pub struct Pace {
    best: AtomicU64,
    grace: u64,
}

impl Default for Pace {
    fn default() -> Self {
        Self::with_grace(0)
    }
}

impl Pace {
    /// A pace that holds each run to it after `grace` iterations.
    pub fn with_grace(grace: u64) -> Self {
        Self {
            best: AtomicU64::new(f64::INFINITY.to_bits()),
            grace,
        }
    }

    /// Records a converged (or reachable) cost.
    pub fn converged_at(&self, cost: f64) {
        if cost.is_finite() && cost >= 0.0 {
            self.best.fetch_min(cost.to_bits(), Ordering::Relaxed);
        }
    }

    /// The lowest converged cost so far.
    pub fn best(&self) -> f64 {
        f64::from_bits(self.best.load(Ordering::Relaxed))
    }
}

/// The damping (relative to diag(JᵀJ)) of the Gauss-Newton step whose predicted decrease
/// [`LevenbergMarquardt::cost_resolution`] is judged against: small enough to leave the
/// step undamped, large enough to keep a nearly singular system solvable.
pub const GAUSS_NEWTON_DAMPING: f64 = 1e-10;

/// The damping of the first iteration, relative to diag(JᵀJ) (Marquardt's scaling): a pure
/// number, so a fit's path does not depend on the unit of its residuals. Small, so the first
/// step is nearly Gauss-Newton's; a rejected step doubles its way up from there at the cost of
/// one residual evaluation each. Nielsen's absolute start (1e-3 times the largest diagonal of
/// JᵀJ) made a force fit weighted by 1/noise start with a damping of about 1e5 relative: a
/// Dahl fit to a damper stroke spent ten of its sixteen iterations taking the damping down,
/// a factor of three per accepted step.
pub const INITIAL_DAMPING: f64 = 1e-5;

/// The residuals at the initial parameters are not finite: the run cannot start (its caller,
/// which knows the problem, says where they stop being finite).
#[derive(Debug, Clone, Copy, PartialEq, Eq, thiserror::Error)]
#[error("the residuals at the initial parameters are not finite")]
pub struct NonFiniteStart;

/// Bounded Levenberg-Marquardt.
#[derive(Debug, Clone)]
pub struct LevenbergMarquardt {
    lower: DVector<f64>,
    upper: DVector<f64>,
    /// Stop when the largest scaled gradient component falls below this.
    pub gtol: f64,
    /// Stop when a step changes no parameter by more than xtol relative.
    pub xtol: f64,
    /// Stop when an accepted step reduces the cost by less than ftol relative.
    pub ftol: f64,
    /// The damping of the first iteration (the step solves (JᵀJ + mu diag(JᵀJ)) d = -Jᵀr,
    /// Marquardt's scaling).
    pub initial_damping: f64,
    /// Stop when the cost fell by less than this fraction over the last `stall_window`
    /// accepted steps. For noisy data a relative change of 1e-6 is far below the statistical
    /// spread of the cost itself (about sqrt(2/n) relative for n residuals), so iterating on
    /// only moves the parameters inside their confidence region.
    pub stall_tol: f64,
    /// Accepted steps over which stagnation is judged.
    pub stall_window: usize,
    /// Stop when the Gauss-Newton step promises less than this decrease of the cost
    /// (absolute; `None`: never). For a run whose cost is wanted only to a given precision
    /// (a profile step, judged against a rise of the cost).
    pub cost_resolution: Option<f64>,
    /// Stop when the Gauss-Newton step would move the parameters by less than this many
    /// standard errors (their joint Mahalanobis distance, estimated from the residuals' variance
    /// at the current point; `None`: never).
    pub standard_error_resolution: Option<f64>,
    history: Vec<f64>,
    /// Largest change of any parameter in one step (a trust-region cap: a step that would
    /// move further is shortened along its direction).
    pub max_step: f64,
    /// Coordinates whose step cap grows with their magnitude: `max_step` times
    /// max(1, |p_i|) (linear coordinates, whose scale is fixed at the start: a parameter that
    /// has moved to many times its scale may still move by a multiple of itself).
    pub relative_step: Vec<bool>,
    mu: f64,
    nu: f64,
    residuals: DVector<f64>,
    jacobian: DMatrix<f64>,
    /// The normal equations of `jacobian` and `residuals`, kept across rejected steps (which
    /// change neither).
    normal: Option<Arc<NormalEquations>>,
    cost: f64,
    converged: Option<TerminationReason>,
    /// Whether the last trial point could not be evaluated (non-finite residuals: a
    /// simulation that failed or ran into its work budget).
    trial_failed: bool,
    /// Converged costs of the other runs of the fit: the run stops when it falls behind
    /// them by [`OUTPACE_FACTOR`].
    pub pace: Option<Arc<Pace>>,
}

impl LevenbergMarquardt {
    /// A solver for parameters in the box [lower, upper] (use ±inf for no bound).
    pub fn new(lower: DVector<f64>, upper: DVector<f64>) -> Self {
        Self {
            lower,
            upper,
            gtol: 1e-10,
            xtol: 1e-8,
            ftol: 1e-9,
            initial_damping: INITIAL_DAMPING,
            max_step: f64::INFINITY,
            relative_step: Vec::new(),
            stall_tol: 1e-6,
            stall_window: 10,
            cost_resolution: None,
            standard_error_resolution: None,
            history: Vec::new(),
            mu: 0.0,
            nu: 2.0,
            residuals: DVector::zeros(0),
            jacobian: DMatrix::zeros(0, 0),
            normal: None,
            cost: f64::INFINITY,
            converged: None,
            trial_failed: false,
            pace: None,
        }
    }

    fn project(&self, p: &DVector<f64>) -> DVector<f64> {
        DVector::from_iterator(
            p.len(),
            p.iter()
                .zip(self.lower.iter().zip(self.upper.iter()))
                .map(|(&x, (&lo, &hi))| x.max(lo).min(hi)),
        )
    }

    /// The largest component of the projected gradient, scaled by the diagonal of JᵀJ, so
    /// that a parameter held at a bound by a gradient pushing outwards does not count.
    fn scaled_gradient_norm(&self, p: &DVector<f64>, g: &DVector<f64>, diag: &[f64]) -> f64 {
        let mut worst: f64 = 0.0;
        for i in 0..p.len() {
            let at_lower = p[i] <= self.lower[i] && g[i] > 0.0;
            let at_upper = p[i] >= self.upper[i] && g[i] < 0.0;
            if at_lower || at_upper {
                continue;
            }
            let s = diag[i].sqrt().max(1e-300);
            worst = worst.max(g[i].abs() / s);
        }
        worst / (2.0 * self.cost).sqrt().max(1e-300)
    }
}

fn half_sq(r: &DVector<f64>) -> f64 {
    if r.iter().all(|x| x.is_finite()) {
        0.5 * r.norm_squared()
    } else {
        f64::INFINITY
    }
}

impl<O> Solver<O, LmState> for LevenbergMarquardt
where
    O: Operator<Param = DVector<f64>, Output = DVector<f64>>
        + Jacobian<Param = DVector<f64>, Jacobian = DMatrix<f64>>,
{
    fn name(&self) -> &str {
        "Levenberg-Marquardt (bounded, Nielsen damping)"
    }

    fn init(
        &mut self,
        problem: &mut Problem<O>,
        mut state: LmState,
    ) -> Result<(LmState, Option<KV>), Error> {
        let p0 = state
            .take_param()
            .ok_or_else(|| Error::msg("Levenberg-Marquardt needs an initial parameter vector"))?;
        if p0.len() != self.lower.len() || p0.len() != self.upper.len() {
            return Err(Error::msg("parameter and bound vectors differ in length"));
        }
        let p0 = self.project(&p0);
        let r = problem.apply(&p0)?;
        let cost = half_sq(&r);
        if !cost.is_finite() {
            return Err(NonFiniteStart.into());
        }
        let j = problem.jacobian(&p0)?;
        self.mu = self.initial_damping;
        self.nu = 2.0;
        self.residuals = r;
        self.jacobian = j;
        self.normal = None;
        self.cost = cost;
        self.converged = None;
        self.trial_failed = false;
        self.history.clear();
        Ok((state.param(p0).cost(cost), None))
    }

    fn next_iter(
        &mut self,
        problem: &mut Problem<O>,
        mut state: LmState,
    ) -> Result<(LmState, Option<KV>), Error> {
        let p = state
            .take_param()
            .ok_or_else(|| Error::msg("Levenberg-Marquardt lost its parameter vector"))?;
        if let Some(best) = self.outpaced_by(state.get_iter()) {
            self.converged = Some(TerminationReason::Outpaced {
                best,
                cost: self.cost,
            });
            return Ok((state.param(p).cost(self.cost), None));
        }
        if self.stagnated() {
            self.converged = Some(TerminationReason::Stagnation {
                tolerance: self.stall_tol,
                window: self.stall_window,
            });
            return Ok((state.param(p).cost(self.cost), None));
        }
        let normal = self.normal_equations();
        if self.scaled_gradient_norm(&p, &normal.g, &normal.diag) < self.gtol {
            self.converged = Some(TerminationReason::GradientBelowTolerance);
            return Ok((state.param(p).cost(self.cost), None));
        }
        if let Some(reason) = self.resolved(&p, &normal) {
            self.converged = Some(reason);
            return Ok((state.param(p).cost(self.cost), None));
        }
        let Some(delta) = self.damped_step(&p, &normal) else {
            self.raise_damping();
            return Ok((state.param(p).cost(self.cost), None));
        };
        let trial = self.project(&(&p + &delta));
        let step = &trial - &p;
        let small_step = step
            .iter()
            .zip(p.iter())
            .all(|(s, x)| s.abs() <= self.xtol * (x.abs() + self.xtol));
        if small_step {
            self.converged = Some(TerminationReason::StepBelowTolerance);
            return Ok((state.param(p).cost(self.cost), None));
        }
        let r_new = problem.apply(&trial)?;
        let cost_new = half_sq(&r_new);
        self.trial_failed = !cost_new.is_finite();
        // Predicted reduction of the linear model for the projected step.
        let predicted = normal.predicted_reduction(&step);
        let actual = self.cost - cost_new;
        let rho = if predicted > 0.0 {
            actual / predicted
        } else {
            -1.0
        };
        if cost_new.is_finite() && rho > 0.0 {
            self.accept(r_new, cost_new, actual, rho);
            self.jacobian = problem.jacobian(&trial)?;
            self.normal = None;
            Ok((state.param(trial).cost(cost_new), None))
        } else {
            self.raise_damping();
            if self.mu > 1e20 {
                self.converged = Some(TerminationReason::DampingLimit);
            }
            Ok((state.param(p).cost(self.cost), None))
        }
    }

    fn terminate(&mut self, _state: &LmState) -> TerminationStatus {
        match &self.converged {
            Some(why) => TerminationStatus::Terminated(ArgminReason::SolverExit(why.to_string())),
            None => TerminationStatus::NotTerminated,
        }
    }
}

impl LevenbergMarquardt {
    /// The normal equations at the current point, formed once per Jacobian.
    fn normal_equations(&mut self) -> Arc<NormalEquations> {
        let (jacobian, residuals) = (&self.jacobian, &self.residuals);
        self.normal
            .get_or_insert_with(|| Arc::new(NormalEquations::new(jacobian, residuals)))
            .clone()
    }

    /// The Jacobian and residuals at the current (best) point: the solver only moves to a
    /// point of lower cost, and linearises there before it decides to stop.
    pub fn linearisation(&self) -> (&DMatrix<f64>, &DVector<f64>) {
        (&self.jacobian, &self.residuals)
    }

    /// The same, moved out of the solver at the end of its run.
    pub fn into_linearisation(self) -> (DMatrix<f64>, DVector<f64>) {
        (self.jacobian, self.residuals)
    }

    /// The typed reason of the last run's convergence (`None` while running, or when it was
    /// stopped from outside, e.g. by the iteration limit).
    pub fn termination(&self) -> Option<&TerminationReason> {
        self.converged.as_ref()
    }

    /// The converged cost of another run that this run, at iteration `iteration`, is
    /// [`OUTPACE_FACTOR`] times above: after the pace's grace, or at once when its last
    /// trial point could not be evaluated. The grace is for a run that is descending; one
    /// whose trial failed stands still, and with its step at the solver's cap
    /// ([`LevenbergMarquardt::max_step`]) more damping tries the same point again until the
    /// damped step falls below the cap, each try a simulation run into its work budget (on
    /// the FMM fixture, four of Dahl's five screened starts spent their whole grace so).
    fn outpaced_by(&self, iteration: u64) -> Option<f64> {
        let pace = self.pace.as_ref()?;
        let best = pace.best();
        let held = iteration >= pace.grace || self.trial_failed;
        (held && self.cost > OUTPACE_FACTOR * best).then_some(best)
    }

    /// Whether the cost fell by less than `stall_tol` relative over the last `stall_window`
    /// accepted steps.
    fn stagnated(&self) -> bool {
        if self.history.len() <= self.stall_window {
            return false;
        }
        let then = self.history[self.history.len() - 1 - self.stall_window];
        then - self.cost <= self.stall_tol * self.cost
    }

    /// The largest change of coordinate `i` (at `p_i`) in one step.
    fn step_cap(&self, i: usize, p_i: f64) -> f64 {
        if self.relative_step.get(i).copied().unwrap_or(false) {
            self.max_step * p_i.abs().max(1.0)
        } else {
            self.max_step
        }
    }

    /// The damped, length-capped step; `None` when a damped system is not positive definite.
    /// Parameters held at a bound by a gradient pointing outwards stay put; the damped normal
    /// equations are solved for the others only. The step is shortened along its direction
    /// by [`LevenbergMarquardt::cap_excess`] when that exceeds 1.
    ///
    /// A parameter at a bound whose gradient points inwards may still have a step pointing
    /// outwards (its correlations with the others ask for it). The projection onto the box
    /// keeps it at its bound, and the others move as if it had moved: a step the linear model
    /// itself may predict to raise the cost. Raising the damping is no remedy (the model is
    /// not at fault, the projection is), and costs one rejected trial per doubling until the
    /// damping, not the model, sets the step. So when the projected step promises no
    /// decrease, the system is solved again with those parameters fixed at their bounds:
    /// that step minimises the damped model over the others, so it promises a decrease
    /// (Bertsekas' projected Newton method fixes bound parameters the same way: "Projected
    /// Newton methods for optimization problems with simple constraints", SIAM J. Control
    /// Optim. 20, 1982). A step that promises a decrease is kept as it is.
    fn damped_step(&self, p: &DVector<f64>, normal: &NormalEquations) -> Option<DVector<f64>> {
        let free = self.free_coordinates(p, &normal.g);
        let delta = self.capped(p, Self::solve_free(normal, self.mu, &free, p.len())?);
        let step = self.project(&(p + &delta)) - p;
        if normal.predicted_reduction(&step) > 0.0 {
            return Some(delta);
        }
        let inside: Vec<usize> = free
            .iter()
            .copied()
            .filter(|&i| !self.pushed_out(p, &delta, i))
            .collect();
        if inside.len() == free.len() {
            return Some(delta);
        }
        Some(self.capped(p, Self::solve_free(normal, self.mu, &inside, p.len())?))
    }

    /// `delta` divided by its [`LevenbergMarquardt::cap_excess`] when that exceeds 1.
    fn capped(&self, p: &DVector<f64>, mut delta: DVector<f64>) -> DVector<f64> {
        let over = self.cap_excess(p, &delta);
        if over > 1.0 {
            delta /= over;
        }
        delta
    }

    /// Whether coordinate `i` sits at a bound that `delta` pushes it across (the projection
    /// keeps it there).
    fn pushed_out(&self, p: &DVector<f64>, delta: &DVector<f64>, i: usize) -> bool {
        (p[i] <= self.lower[i] && delta[i] < 0.0) || (p[i] >= self.upper[i] && delta[i] > 0.0)
    }

    /// How many times its cap the step `delta` would move the coordinate it moves furthest
    /// (relative to its cap), leaving out the coordinates at a bound that `delta` pushes
    /// outwards; dividing `delta` by it (when above 1) shortens the step along its direction
    /// until no coordinate it moves moves further than its cap.
    ///
    /// The projection onto the box keeps a coordinate at its bound when the step pushes it
    /// outwards: it does not move, however long its share of `delta`, and must not shorten
    /// the step. Counting it lets a parameter at its bound, whose Gauss-Newton share points
    /// far outside the box (its correlations with the others ask for it, while its gradient
    /// points inwards, so it is not held), scale every step down by that share: it stays at
    /// its bound and the others move by a small fraction of their step at each iteration,
    /// an accepted step the linear model predicts well (gain ratio 1), so the damping only
    /// falls, and the run crawls until that parameter's gradient turns outwards. A
    /// 16-parameter GMS fit to a driven axis crawled so through all of its 200 iterations,
    /// the cost falling 1 % per step, that share 250 times its cap; from the same start it
    /// now converges in 45. A coordinate inside the box still counts, even where its bound
    /// lies within its cap: the shortened step crosses fewer bounds, and the projection of
    /// the full step, bent at the bounds it crosses, may promise no decrease at all.
    fn cap_excess(&self, p: &DVector<f64>, delta: &DVector<f64>) -> f64 {
        (0..p.len())
            .filter(|&i| !self.pushed_out(p, delta, i))
            .map(|i| delta[i].abs() / self.step_cap(i, p[i]))
            .fold(0.0, f64::max)
    }

    /// Why the run stops on what the Gauss-Newton step at `p` promises (its gain computed
    /// once): it moves the parameters by less than the standard-error resolution, or it
    /// decreases the cost by less than the cost resolution.
    fn resolved(&self, p: &DVector<f64>, normal: &NormalEquations) -> Option<TerminationReason> {
        let by_errors = self
            .standard_error_resolution
            .and_then(|fraction| Some((fraction, self.standard_error_gain(p.len(), fraction)?)));
        if by_errors.is_none() && self.cost_resolution.is_none() {
            return None;
        }
        let gain = self.gauss_newton_gain(p, normal)?;
        if let Some((fraction, limit)) = by_errors {
            if gain >= 0.0 && gain < limit {
                return Some(TerminationReason::WithinStandardErrors { fraction });
            }
        }
        let resolution = self.cost_resolution?;
        (gain < resolution).then_some(TerminationReason::WithinResolution { resolution })
    }

    /// The Gauss-Newton gain below which the step moves `n` parameters by less than
    /// `fraction` standard errors: the gain delta' JᵀJ delta / 2 is half the step's squared
    /// Mahalanobis distance times the residual variance 2 cost / (m - n). `None` without
    /// degrees of freedom.
    fn standard_error_gain(&self, n: usize, fraction: f64) -> Option<f64> {
        let dof = self.residuals.len().checked_sub(n).filter(|&d| d > 0)?;
        let variance = 2.0 * self.cost / dof as f64;
        Some(0.5 * fraction * fraction * variance)
    }

    /// The decrease of the cost the linear model predicts for the Gauss-Newton step (damping
    /// [`GAUSS_NEWTON_DAMPING`], no length cap) projected onto the bounds: what is left to
    /// gain near `p` as far as the model knows; `None` when it cannot be solved.
    fn gauss_newton_gain(&self, p: &DVector<f64>, normal: &NormalEquations) -> Option<f64> {
        let delta = self.step_with_damping(p, normal, GAUSS_NEWTON_DAMPING)?;
        let step = self.project(&(p + delta)) - p;
        Some(normal.predicted_reduction(&step))
    }

    /// The step solving the damped normal equations with damping `mu`, uncapped. Parameters
    /// held at a bound by a gradient pointing outwards stay put; the system is solved for
    /// the others only.
    fn step_with_damping(
        &self,
        p: &DVector<f64>,
        normal: &NormalEquations,
        mu: f64,
    ) -> Option<DVector<f64>> {
        let free = self.free_coordinates(p, &normal.g);
        Self::solve_free(normal, mu, &free, p.len())
    }

    /// The coordinates not held at a bound by a gradient `g` pointing outwards.
    fn free_coordinates(&self, p: &DVector<f64>, g: &DVector<f64>) -> Vec<usize> {
        (0..p.len())
            .filter(|&i| {
                !((p[i] <= self.lower[i] && g[i] > 0.0) || (p[i] >= self.upper[i] && g[i] < 0.0))
            })
            .collect()
    }

    /// The damped normal equations (damping `mu`) solved for the coordinates `free`, the
    /// other coordinates' step 0 (`n` in all); `None` when not positive definite.
    fn solve_free(
        normal: &NormalEquations,
        mu: f64,
        free: &[usize],
        n: usize,
    ) -> Option<DVector<f64>> {
        let (a, g, diag) = (&normal.a, &normal.g, &normal.diag);
        let m = free.len();
        let mut lhs = DMatrix::zeros(m, m);
        let mut rhs = DVector::zeros(m);
        for (r, &i) in free.iter().enumerate() {
            rhs[r] = -g[i];
            for (c, &k) in free.iter().enumerate() {
                lhs[(r, c)] = a[(i, k)];
            }
            lhs[(r, r)] += mu * diag[i];
        }
        let reduced = lhs.cholesky()?.solve(&rhs);
        let mut delta = DVector::zeros(n);
        for (r, &i) in free.iter().enumerate() {
            delta[i] = reduced[r];
        }
        Some(delta)
    }

    /// Takes an accepted step: new residuals and cost, Nielsen's damping decrease.
    fn accept(&mut self, r_new: DVector<f64>, cost_new: f64, actual: f64, rho: f64) {
        let old = self.cost;
        self.history.push(old);
        self.residuals = r_new;
        self.cost = cost_new;
        self.mu *= (1.0_f64 / 3.0).max(1.0 - (2.0 * rho - 1.0).powi(3));
        self.nu = 2.0;
        if actual <= self.ftol * old {
            self.converged = Some(TerminationReason::CostReductionBelowTolerance);
        }
    }

    /// Rejects a step: more damping.
    fn raise_damping(&mut self) {
        self.mu *= self.nu;
        self.nu *= 2.0;
    }
}

/// The typed reason a run of `solver` stopped with argmin status `status`, given the run's
/// iteration limit.
pub fn termination_reason(
    solver: &LevenbergMarquardt,
    status: &TerminationStatus,
    max_iterations: u64,
) -> TerminationReason {
    match (status, solver.termination()) {
        (TerminationStatus::Terminated(ArgminReason::MaxItersReached), _) => {
            TerminationReason::IterationLimit {
                limit: max_iterations,
            }
        }
        (TerminationStatus::Terminated(ArgminReason::SolverExit(_)), Some(reason)) => {
            reason.clone()
        }
        (other, _) => TerminationReason::Other {
            text: other.to_string(),
        },
    }
}

/// Reads the state's best parameter and cost.
pub fn best(state: &LmState) -> Option<(DVector<f64>, f64)> {
    state
        .get_best_param()
        .map(|p| (p.clone(), state.get_best_cost()))
}

#[cfg(test)]
mod tests {
    use super::*;
    use argmin::core::Executor;

    /// Rosenbrock as least squares: r = (10 (y - x^2), 1 - x), minimum at (1, 1).
    struct Rosenbrock;
    impl Operator for Rosenbrock {
        type Param = DVector<f64>;
        type Output = DVector<f64>;
        fn apply(&self, p: &DVector<f64>) -> Result<DVector<f64>, Error> {
            Ok(DVector::from_vec(vec![
                10.0 * (p[1] - p[0] * p[0]),
                1.0 - p[0],
            ]))
        }
    }
    impl Jacobian for Rosenbrock {
        type Param = DVector<f64>;
        type Jacobian = DMatrix<f64>;
        fn jacobian(&self, p: &DVector<f64>) -> Result<DMatrix<f64>, Error> {
            Ok(DMatrix::from_row_slice(
                2,
                2,
                &[-20.0 * p[0], 10.0, -1.0, 0.0],
            ))
        }
    }

    fn run<O>(problem: O, p0: Vec<f64>, lo: Vec<f64>, hi: Vec<f64>) -> (LmState, TerminationReason)
    where
        O: Operator<Param = DVector<f64>, Output = DVector<f64>>
            + Jacobian<Param = DVector<f64>, Jacobian = DMatrix<f64>>,
    {
        run_with(problem, p0, lo, hi, INITIAL_DAMPING)
    }

    fn run_with<O>(
        problem: O,
        p0: Vec<f64>,
        lo: Vec<f64>,
        hi: Vec<f64>,
        initial_damping: f64,
    ) -> (LmState, TerminationReason)
    where
        O: Operator<Param = DVector<f64>, Output = DVector<f64>>
            + Jacobian<Param = DVector<f64>, Jacobian = DMatrix<f64>>,
    {
        let mut solver = LevenbergMarquardt::new(DVector::from_vec(lo), DVector::from_vec(hi));
        solver.initial_damping = initial_damping;
        // Exact (zero-residual) problems: tolerances far below the defaults for noisy data.
        solver.xtol = 1e-13;
        solver.ftol = 1e-15;
        let res = Executor::new(problem, solver)
            .configure(|s| s.param(DVector::from_vec(p0)).max_iters(500))
            .run()
            .unwrap();
        let reason = termination_reason(&res.solver, &res.state().termination_status, 500);
        (res.state().clone(), reason)
    }

    /// Rosenbrock from (-1.2, 1) (cost 12.1) racing runs that converged at `best`.
    fn race_rosenbrock(best: f64) -> (u64, TerminationReason) {
        race_rosenbrock_after(best, 0)
    }

    /// The same, held to the pace only after `grace` iterations.
    fn race_rosenbrock_after(best: f64, grace: u64) -> (u64, TerminationReason) {
        let pace = Arc::new(Pace::with_grace(grace));
        pace.converged_at(best);
        let (state, reason) = rosenbrock_with(|solver| solver.pace = Some(pace));
        (state.get_iter(), reason)
    }

    /// Rosenbrock from (-1.2, 1), unbounded, by a default solver that `configure` adjusts.
    fn rosenbrock_with(
        configure: impl FnOnce(&mut LevenbergMarquardt),
    ) -> (LmState, TerminationReason) {
        let inf = f64::INFINITY;
        let mut solver = LevenbergMarquardt::new(
            DVector::from_vec(vec![-inf; 2]),
            DVector::from_vec(vec![inf; 2]),
        );
        configure(&mut solver);
        let res = Executor::new(Rosenbrock, solver)
            .configure(|s| s.param(DVector::from_vec(vec![-1.2, 1.0])).max_iters(500))
            .run()
            .unwrap();
        let reason = termination_reason(&res.solver, &res.state().termination_status, 500);
        (res.state().clone(), reason)
    }

    #[test]
    fn a_run_far_behind_a_converged_one_is_abandoned_at_once() {
        let (iterations, reason) = race_rosenbrock(1.0);
        assert_eq!(iterations, 1);
        let TerminationReason::Outpaced { best, cost } = reason else {
            panic!("not outpaced: {reason:?}");
        };
        // The starting cost, 0.5 ((10 (1 - 1.44))^2 + 2.2^2).
        assert!((cost - 12.1).abs() < 1e-12 && best == 1.0, "{cost} {best}");
        assert!(!reason.is_converged());
    }

    #[test]
    fn a_pace_with_grace_lets_a_run_take_its_first_iterations() {
        let (iterations, reason) = race_rosenbrock_after(1e-30, 3);
        assert_eq!(iterations, 4, "{reason:?}");
        let TerminationReason::Outpaced { cost, .. } = reason else {
            panic!("not outpaced: {reason:?}");
        };
        // Three iterations took it below its starting cost.
        assert!(cost < 12.1, "{cost}");
    }

    /// r = p - 10, which cannot be evaluated beyond p = 1 (a trial point whose simulation
    /// fails).
    struct Walled;
    impl Operator for Walled {
        type Param = DVector<f64>;
        type Output = DVector<f64>;
        fn apply(&self, p: &DVector<f64>) -> Result<DVector<f64>, Error> {
            let r = if p[0] > 1.0 { f64::NAN } else { p[0] - 10.0 };
            Ok(DVector::from_vec(vec![r]))
        }
    }
    impl Jacobian for Walled {
        type Param = DVector<f64>;
        type Jacobian = DMatrix<f64>;
        fn jacobian(&self, _p: &DVector<f64>) -> Result<DMatrix<f64>, Error> {
            Ok(DMatrix::from_element(1, 1, 1.0))
        }
    }

    /// Within its grace a run that descends goes on (above), but one whose trial point cannot
    /// be evaluated is held to the pace at once: from p = 0 (cost 50) the Gauss-Newton step
    /// to 10 fails (iteration 0), and the run is abandoned at its next iteration instead of
    /// retrying with more damping for the rest of its grace.
    #[test]
    fn a_run_whose_trial_fails_is_held_to_the_pace_within_its_grace() {
        let pace = Arc::new(Pace::with_grace(5));
        pace.converged_at(1.0);
        let inf = f64::INFINITY;
        let mut solver =
            LevenbergMarquardt::new(DVector::from_vec(vec![-inf]), DVector::from_vec(vec![inf]));
        solver.pace = Some(pace);
        let res = Executor::new(Walled, solver)
            .configure(|s| s.param(DVector::from_vec(vec![0.0])).max_iters(50))
            .run()
            .unwrap();
        let reason = termination_reason(&res.solver, &res.state().termination_status, 50);
        assert_eq!(res.state().get_iter(), 2, "{reason:?}");
        let TerminationReason::Outpaced { cost, best } = reason else {
            panic!("not outpaced: {reason:?}");
        };
        assert_eq!((cost, best), (50.0, 1.0));
    }

    #[test]
    fn a_run_within_the_factor_of_the_others_runs_to_convergence() {
        let (_, reason) = race_rosenbrock(12.1 / OUTPACE_FACTOR);
        assert!(reason.is_converged(), "{reason:?}");
    }

    #[test]
    fn the_pace_keeps_the_lowest_finite_converged_cost() {
        let pace = Pace::default();
        assert_eq!(pace.best(), f64::INFINITY);
        for cost in [3.0, 1.0, f64::NAN, 2.0, -1.0, f64::INFINITY] {
            pace.converged_at(cost);
        }
        assert_eq!(pace.best(), 1.0);
    }

    /// Rosenbrock with its residuals (and Jacobian) in another unit: times the factor held.
    struct Scaled(f64);
    impl Operator for Scaled {
        type Param = DVector<f64>;
        type Output = DVector<f64>;
        fn apply(&self, p: &DVector<f64>) -> Result<DVector<f64>, Error> {
            Ok(Rosenbrock.apply(p)? * self.0)
        }
    }
    impl Jacobian for Scaled {
        type Param = DVector<f64>;
        type Jacobian = DMatrix<f64>;
        fn jacobian(&self, p: &DVector<f64>) -> Result<DMatrix<f64>, Error> {
            Ok(Rosenbrock.jacobian(p)? * self.0)
        }
    }

    /// A relative damping start is a pure number: the path does not depend on the residuals'
    /// unit (with Nielsen's largest-diagonal rule a force fit weighted by 1/noise would start
    /// with 1e4 times the damping of the same fit in other units).
    #[test]
    fn the_path_does_not_depend_on_the_unit_of_the_residuals() {
        let inf = f64::INFINITY;
        let path = |scale: f64| {
            let (s, reason) = run_with(
                Scaled(scale),
                vec![-1.2, 1.0],
                vec![-inf; 2],
                vec![inf; 2],
                1e-2,
            );
            let p = best(&s).unwrap().0;
            (s.get_iter(), p, reason)
        };
        let (iterations, p, reason) = path(1.0);
        assert!(reason.is_converged(), "{reason:?}");
        for scale in [1e-3, 1e4] {
            let (n, q, _) = path(scale);
            assert_eq!(n, iterations, "scale {scale}");
            assert!((&q - &p).amax() < 1e-12, "scale {scale}: {q} against {p}");
        }
    }

    /// A run wanted only to a cost resolution stops once the Gauss-Newton step promises
    /// less, before the full convergence tests would, and within about that resolution of
    /// the minimum (0 for Rosenbrock: near it the linear model's promise is the cost left).
    #[test]
    fn a_run_wanted_to_a_resolution_stops_when_the_model_promises_less() {
        let inf = f64::INFINITY;
        let (full, _) = run(Rosenbrock, vec![-1.2, 1.0], vec![-inf; 2], vec![inf; 2]);
        let resolution = 1e-4;
        let (state, reason) = rosenbrock_with(|solver| solver.cost_resolution = Some(resolution));
        assert_eq!(reason, TerminationReason::WithinResolution { resolution });
        assert!(reason.is_converged());
        let cost = state.get_best_cost();
        assert!(cost < 2.0 * resolution, "{cost}");
        assert!(
            state.get_iter() < full.get_iter(),
            "{} vs {}",
            state.get_iter(),
            full.get_iter()
        );
    }

    /// A linear least-squares problem r = J (p - p*) whose Hessian JᵀJ = [[1, 999],
    /// [999, 1e6]] couples a soft parameter p0 (bounded below by 0) with a stiff one p1
    /// (correlation 0.999), the unconstrained optimum p* = (-1000, 20) outside the box.
    struct CoupledAtBound;
    impl CoupledAtBound {
        const OPTIMUM: [f64; 2] = [-1000.0, 20.0];
        fn j() -> DMatrix<f64> {
            DMatrix::from_row_slice(2, 2, &[1.0, 999.0, 0.0, 1999f64.sqrt()])
        }
    }
    impl Operator for CoupledAtBound {
        type Param = DVector<f64>;
        type Output = DVector<f64>;
        fn apply(&self, p: &DVector<f64>) -> Result<DVector<f64>, Error> {
            Ok(Self::j() * (p - DVector::from_row_slice(&Self::OPTIMUM)))
        }
    }
    impl Jacobian for CoupledAtBound {
        type Param = DVector<f64>;
        type Jacobian = DMatrix<f64>;
        fn jacobian(&self, _p: &DVector<f64>) -> Result<DMatrix<f64>, Error> {
            Ok(Self::j())
        }
    }

    /// From (0, 15), p0 at its bound: its gradient points into the box (1000 - 999 * 5 < 0),
    /// so it is not held, but its Gauss-Newton step is -1000, far outside. The projection
    /// keeps it at 0 whatever that step, so it must not shorten the step under the cap of
    /// 2: p1 reaches the face's minimum in a few capped steps. Shortened by p0's share
    /// (t = 2/1000), p1 moved 0.2 % of its way per iteration and the run used up 500
    /// iterations. The oracle: on the face p0 = 0 the cost is least at p1 = 20 - 999 * 1000
    /// / 1e6 = 19.001, where the gradient 1000 - 999 * 0.999 > 0 holds p0 at its bound.
    #[test]
    fn a_parameter_stopped_by_its_bound_does_not_shorten_the_capped_step() {
        let (p, reason, iterations) = run_coupled_at_bound(15.0, 500);
        assert!(reason.is_converged(), "{reason:?}");
        assert!(iterations <= 10, "{iterations} iterations");
        assert_eq!(p[0], 0.0, "{p}");
        assert!((p[1] - 19.001).abs() < 1e-9, "{p}");
    }

    /// [`CoupledAtBound`] from (0, `p1`) with p0 >= 0, a step cap of 2 and tight tolerances,
    /// for at most `iterations`: the best point, why it stopped and the iterations run.
    fn run_coupled_at_bound(p1: f64, iterations: u64) -> (DVector<f64>, TerminationReason, u64) {
        let mut solver = LevenbergMarquardt::new(
            DVector::from_vec(vec![0.0, f64::NEG_INFINITY]),
            DVector::from_vec(vec![f64::INFINITY; 2]),
        );
        solver.max_step = 2.0;
        (solver.xtol, solver.ftol) = (1e-13, 1e-15);
        let res = Executor::new(CoupledAtBound, solver)
            .configure(|s| {
                s.param(DVector::from_vec(vec![0.0, p1]))
                    .max_iters(iterations)
            })
            .run()
            .unwrap();
        let reason = termination_reason(&res.solver, &res.state().termination_status, iterations);
        (best(res.state()).unwrap().0, reason, res.state().get_iter())
    }

    /// From (0, 18.5) p0's gradient still points into the box (1000 - 999 * 1.5 < 0) and its
    /// Gauss-Newton step far out of it; p1's step of 1.5 is within the cap, but projected
    /// (p0 kept at 0) the step promises an increase of the cost (the linear model's decrease
    /// -999 * 1000 * 1.5 + 1e6 * 1.5² / 2 < 0). Solved again with p0 fixed, the first step
    /// takes p1 to the face's minimum 19.001 (to the first damping's 1e-5 relative);
    /// raising the damping instead spent a rejected trial per doubling from 1e-5 to about 1.
    #[test]
    fn a_projected_step_that_promises_no_decrease_is_solved_again_without_the_bound_parameter() {
        let run = |iterations: u64| {
            let (p, reason, _) = run_coupled_at_bound(18.5, iterations);
            (p, reason)
        };
        let (first, _) = run(1);
        assert_eq!(first[0], 0.0, "{first}");
        assert!((first[1] - 19.001).abs() < 1e-4, "{first}");
        let (p, reason) = run(500);
        assert!(reason.is_converged(), "{reason:?}");
        assert_eq!(p[0], 0.0, "{p}");
        assert!((p[1] - 19.001).abs() < 1e-9, "{p}");
    }

    #[test]
    fn finds_the_rosenbrock_minimum() {
        let inf = f64::INFINITY;
        let (s, reason) = run(Rosenbrock, vec![-1.2, 1.0], vec![-inf; 2], vec![inf; 2]);
        let (p, cost) = best(&s).unwrap();
        assert!(
            (p[0] - 1.0).abs() < 1e-8 && (p[1] - 1.0).abs() < 1e-8,
            "{p}"
        );
        assert!(cost < 1e-20);
        assert!(reason.is_converged(), "{reason:?}");
    }

    #[test]
    fn respects_bounds() {
        // The unconstrained minimum (1, 1) is outside x <= 0.5: the bounded minimum of
        // 100 (y - x^2)^2 + (1 - x)^2 on x <= 0.5 is at x = 0.5, y = 0.25.
        let inf = f64::INFINITY;
        let (s, reason) = run(Rosenbrock, vec![-1.2, 1.0], vec![-inf; 2], vec![0.5, inf]);
        let (p, _) = best(&s).unwrap();
        assert!((p[0] - 0.5).abs() < 1e-12, "{p}");
        assert!((p[1] - 0.25).abs() < 1e-8, "{p}");
        assert!(reason.is_converged(), "{reason:?}");
    }

    /// Exponential decay y = a exp(-b t) from exact data: recovers a and b exactly.
    struct Decay {
        t: Vec<f64>,
        y: Vec<f64>,
    }
    impl Operator for Decay {
        type Param = DVector<f64>;
        type Output = DVector<f64>;
        fn apply(&self, p: &DVector<f64>) -> Result<DVector<f64>, Error> {
            Ok(DVector::from_iterator(
                self.t.len(),
                self.t
                    .iter()
                    .zip(&self.y)
                    .map(|(t, y)| p[0] * (-p[1] * t).exp() - y),
            ))
        }
    }
    impl Jacobian for Decay {
        type Param = DVector<f64>;
        type Jacobian = DMatrix<f64>;
        fn jacobian(&self, p: &DVector<f64>) -> Result<DMatrix<f64>, Error> {
            let mut j = DMatrix::zeros(self.t.len(), 2);
            for (i, t) in self.t.iter().enumerate() {
                let e = (-p[1] * t).exp();
                j[(i, 0)] = e;
                j[(i, 1)] = -p[0] * t * e;
            }
            Ok(j)
        }
    }

    #[test]
    fn fits_an_exponential_decay_exactly() {
        let t: Vec<f64> = (0..50).map(|i| i as f64 * 0.1).collect();
        let y = t.iter().map(|t| 3.0 * (-0.7 * t).exp()).collect();
        let inf = f64::INFINITY;
        let (s, _) = run(Decay { t, y }, vec![1.0, 3.0], vec![0.0; 2], vec![inf; 2]);
        let (p, _) = best(&s).unwrap();
        assert!(
            (p[0] - 3.0).abs() < 1e-9 && (p[1] - 0.7).abs() < 1e-9,
            "{p}"
        );
    }

    /// An exponential decay with noise: residuals y_i - a exp(-b t_i).
    struct NoisyDecay;
    impl NoisyDecay {
        fn samples() -> impl Iterator<Item = (f64, f64)> {
            (0..200).map(|i| {
                let t = i as f64 * 0.02;
                let noise = 0.05 * ((i * 7919) as f64 * 0.618_033_988_75).sin();
                (t, 2.0 * (-1.3 * t).exp() + noise)
            })
        }
    }
    impl Operator for NoisyDecay {
        type Param = DVector<f64>;
        type Output = DVector<f64>;
        fn apply(&self, p: &DVector<f64>) -> Result<DVector<f64>, Error> {
            Ok(DVector::from_iterator(
                200,
                Self::samples().map(|(t, y)| y - p[0] * (-p[1] * t).exp()),
            ))
        }
    }
    impl Jacobian for NoisyDecay {
        type Param = DVector<f64>;
        type Jacobian = DMatrix<f64>;
        fn jacobian(&self, p: &DVector<f64>) -> Result<DMatrix<f64>, Error> {
            let rows: Vec<f64> = Self::samples()
                .flat_map(|(t, _)| {
                    let e = (-p[1] * t).exp();
                    [-e, p[0] * t * e]
                })
                .collect();
            Ok(DMatrix::from_row_slice(200, 2, &rows))
        }
    }

    /// A run stopped by the standard-error resolution ends within that many standard errors
    /// of the optimum the same solver reaches at tolerances near machine precision, measured
    /// in the covariance s² (JᵀJ)⁻¹ there, and needs no more iterations to get there.
    #[test]
    fn a_run_within_the_standard_error_resolution_stops_that_close_to_the_optimum() {
        let inf = f64::INFINITY;
        let solve = |resolution: Option<f64>| {
            let mut solver = LevenbergMarquardt::new(
                DVector::from_vec(vec![-inf; 2]),
                DVector::from_vec(vec![inf; 2]),
            );
            solver.standard_error_resolution = resolution;
            if resolution.is_none() {
                (solver.xtol, solver.ftol, solver.gtol) = (1e-15, 1e-16, 1e-16);
            }
            let res = Executor::new(NoisyDecay, solver)
                .configure(|s| s.param(DVector::from_vec(vec![0.5, 5.0])).max_iters(200))
                .run()
                .unwrap();
            let reason = termination_reason(&res.solver, &res.state().termination_status, 200);
            (best(res.state()).unwrap().0, res.state().get_iter(), reason)
        };
        let (optimum, exact_iterations, _) = solve(None);
        let (p, iterations, reason) = solve(Some(0.01));
        assert_eq!(
            reason,
            TerminationReason::WithinStandardErrors { fraction: 0.01 }
        );
        assert!(
            iterations <= exact_iterations,
            "{iterations} > {exact_iterations}"
        );
        let j = NoisyDecay.jacobian(&optimum).unwrap();
        let r = NoisyDecay.apply(&optimum).unwrap();
        let variance = r.norm_squared() / (200.0 - 2.0);
        let d = &p - &optimum;
        let distance = ((d.transpose() * (j.transpose() * &j) * &d)[(0, 0)] / variance).sqrt();
        assert!(
            distance < 0.01,
            "{distance} standard errors from the optimum"
        );
        assert!(
            distance > 0.0,
            "stopped at the optimum itself: the test judges nothing"
        );
    }
}
