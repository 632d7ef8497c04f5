//! The fitting problem: parameters in, the weighted residuals of every record out.
//!
//! What the residuals are comes from a [`Residuals`] producer (the velocity response by
//! default); the problem maps the solver's coordinates to a model, an oscillator and the
//! per-record nuisance values, and concatenates the producer's residuals over the records.
//! It implements argmin's [`Operator`] (residuals) and [`Jacobian`], so any argmin
//! least-squares solver can drive it; ours is [`crate::identify::search::LevenbergMarquardt`].
//! The Jacobian's columns come from the producer where it has them in closed form
//! ([`Residuals::jacobian_columns`]: the force domain's law columns from one replay with
//! sensitivities, its offsets' and the balance's linear terms), mapped from physical to
//! internal coordinates by dp/du; every other column is a forward difference.

use super::residuals::{Evaluation, JacobianColumns, RecordCase, Residuals};
use super::simulated_response::SimulatedResponse;
use super::step_allowance::StepAllowance;
use crate::error::{EngineError, IntegrationFailure};
use crate::identify::values::layout::{FreeParam, ParamKind};
use crate::identify::values::nuisance::NuisanceValues;
use crate::identify::values::search::RobustLoss;
use crate::oscillator::Oscillator;
use crate::record::Record;
use crate::simulate::SimOptions;
use argmin::core::{Error, Jacobian, Operator};
use frictionid_models::FrictionModel;
use nalgebra::{DMatrix, DVector};
use rayon::prelude::*;
use std::sync::atomic::{AtomicU64, AtomicUsize, Ordering};
use std::sync::{Arc, Mutex};

/// Relative forward-difference step in internal coordinates. The ODE engine's default
/// tolerances (rtol 1e-10) leave ~1e-10 relative noise in the residuals, so a step of 1e-6
/// balances truncation against that noise (error ~ 1e-4 of the derivative).
pub(crate) const FD_STEP: f64 = 1e-6;

/// The residual function of a fit, generic over what produces the residuals.
pub struct FitProblem<R: Residuals = SimulatedResponse> {
    /// The oscillator with its fixed values.
    pub oscillator: Oscillator,
    /// The model with its fixed values.
    pub model: Box<dyn FrictionModel>,
    /// The records (shared by the problems of a multi-start fit).
    pub records: Arc<[Record]>,
    /// The free parameters.
    pub layout: Vec<FreeParam>,
    /// What produces the residuals.
    pub residuals: Arc<R>,
    /// Simulation options.
    pub sim: SimOptions,
    /// Simulate records (and Jacobian columns) in parallel.
    pub parallel: bool,
    /// The loss the solver minimises: its residuals and Jacobian rows are the loss's
    /// transform of the producer's ([`RobustLoss`]; least squares unless told).
    loss: RobustLoss,
    simulations: AtomicU64,
    last_error: Mutex<Option<String>>,
    /// The step allowance of the simulations, per record ([`StepAllowance`]).
    allowance: StepAllowance,
    /// The last point `apply` evaluated, reused by `jacobian` at the same point.
    cache: Mutex<Option<Evaluated>>,
    /// The last physical Jacobian and residuals, by point: the identifiability check and the
    /// statistics both ask for them at the optimum.
    physical_cache: Mutex<Option<PhysicalJacobian>>,
}

/// A physical point with the Jacobian and residuals there.
type PhysicalJacobian = (Vec<f64>, DMatrix<f64>, DVector<f64>);

/// The Jacobian's columns in internal coordinates that a producer gave in closed form, one
/// per free parameter (`None`: a difference quotient's).
type ClosedFormColumns = Vec<Option<DVector<f64>>>;

/// What `apply` evaluated at its last point, for `jacobian` there.
struct Evaluated {
    /// The point, in internal coordinates.
    u: DVector<f64>,
    /// The producer's residuals there (before the loss's transform).
    residuals: DVector<f64>,
    /// The closed-form columns evaluated with the residuals, where the producer gave both
    /// from one evaluation.
    columns: Option<ClosedFormColumns>,
    /// Whether the solver asked for the Jacobian at the point: it took the step there.
    linearised: bool,
}

/// The state of the world for one parameter vector.
pub struct Realised {
    /// The oscillator.
    pub oscillator: Oscillator,
    /// The model.
    pub model: Box<dyn FrictionModel>,
    /// Nuisance values per record.
    pub nuisance: Vec<NuisanceValues>,
}

/// What a fit problem is built from, apart from its residual producer.
pub struct ProblemParts {
    /// The oscillator with its fixed values.
    pub oscillator: Oscillator,
    /// The model with its fixed values.
    pub model: Box<dyn FrictionModel>,
    /// The records.
    pub records: Arc<[Record]>,
    /// The free parameters.
    pub layout: Vec<FreeParam>,
    /// Simulation options.
    pub sim: SimOptions,
    /// Evaluate records and Jacobian columns in parallel.
    pub parallel: bool,
}

impl<R: Residuals> FitProblem<R> {
    /// A problem over `parts.layout` with residuals from `residuals`; the model and
    /// oscillator carry the fixed values.
    pub fn new(residuals: Arc<R>, parts: ProblemParts) -> Self {
        Self {
            allowance: StepAllowance::new(parts.records.len()),
            oscillator: parts.oscillator,
            model: parts.model,
            records: parts.records,
            layout: parts.layout,
            residuals,
            sim: parts.sim,
            parallel: parts.parallel,
            loss: RobustLoss::linear(),
            simulations: AtomicU64::new(0),
            last_error: Mutex::new(None),
            cache: Mutex::new(None),
            physical_cache: Mutex::new(None),
        }
    }

    /// The same problem minimising `loss` (`[fit.options] loss`).
    pub fn with_loss(self, loss: RobustLoss) -> Self {
        Self { loss, ..self }
    }

    /// The loss the solver minimises.
    pub fn loss(&self) -> RobustLoss {
        self.loss
    }

    /// `r` through the loss's transform.
    fn robust(&self, mut r: DVector<f64>) -> DVector<f64> {
        if !self.loss.is_linear() {
            r.iter_mut().for_each(|x| *x = self.loss.residual(*x));
        }
        r
    }

    /// The Jacobian `j` of the residuals `r0` as the loss's transform sees it: each row times
    /// the transform's derivative there (the weights at the point, as iteratively reweighted
    /// least squares).
    fn robust_rows(&self, mut j: DMatrix<f64>, r0: &DVector<f64>) -> DMatrix<f64> {
        if !self.loss.is_linear() {
            for (i, &r) in r0.iter().enumerate() {
                j.row_mut(i).scale_mut(self.loss.derivative(r));
            }
        }
        j
    }

    /// Number of residuals (over all records).
    pub fn n_residuals(&self) -> usize {
        self.residual_counts().iter().sum()
    }

    /// Each record's number of residuals, in record order.
    pub fn residual_counts(&self) -> Vec<usize> {
        self.records
            .iter()
            .enumerate()
            .map(|(i, r)| self.residuals.residual_count(i, r))
            .collect()
    }

    /// Each record's span in the concatenated residuals.
    pub fn record_ranges(&self) -> Vec<std::ops::Range<usize>> {
        let mut at = 0;
        self.residual_counts()
            .into_iter()
            .map(|n| {
                at += n;
                at - n..at
            })
            .collect()
    }

    /// Simulations run so far.
    pub fn simulations(&self) -> u64 {
        self.simulations.load(Ordering::Relaxed)
    }

    /// The last simulation failure, if any.
    pub fn last_error(&self) -> Option<String> {
        self.last_error.lock().ok().and_then(|g| g.clone())
    }

    /// Physical values of the free parameters at internal coordinates `u`.
    pub fn physical(&self, u: &DVector<f64>) -> Vec<f64> {
        self.layout
            .iter()
            .zip(u.iter())
            .map(|(f, &x)| f.to_physical(x))
            .collect()
    }

    /// Internal coordinates of physical values.
    pub fn internal(&self, p: &[f64]) -> DVector<f64> {
        DVector::from_iterator(
            p.len(),
            self.layout.iter().zip(p).map(|(f, &x)| f.to_internal(x)),
        )
    }

    /// Builds the oscillator, model and nuisance values for physical parameters `p`.
    pub fn realise(&self, p: &[f64]) -> Result<Realised, EngineError> {
        let mut osc = self.oscillator;
        let mut model = self.model.clone();
        let mut values = model.params();
        let mut nuisance = vec![NuisanceValues::default(); self.records.len()];
        for (f, &x) in self.layout.iter().zip(p) {
            match f.kind {
                ParamKind::Model(i) => {
                    if let Some(v) = values.get_mut(i) {
                        *v = x;
                    }
                }
                ParamKind::Property(property) => property.set(&mut osc, x),
                ParamKind::Nuisance { kind, record } => {
                    if let Some(n) = nuisance.get_mut(record) {
                        n.set(kind, x);
                    }
                }
            }
        }
        model.set_params(&values)?;
        osc.validate()?;
        Ok(Realised {
            oscillator: osc,
            model,
            nuisance,
        })
    }

    /// The values a producer evaluates at for the realised `world`.
    pub fn evaluation<'a>(&'a self, world: &'a Realised) -> Evaluation<'a> {
        Evaluation::new(
            &world.oscillator,
            world.model.as_ref(),
            &self.sim,
            &self.simulations,
        )
        .with_step_allowance(&self.allowance)
    }

    /// The prediction of record `r`'s measured series at `world`.
    pub fn predict_record(&self, world: &Realised, r: usize) -> Result<Vec<f64>, EngineError> {
        if r >= self.records.len() {
            return Err(EngineError::InvalidInput(format!("no record {r}")));
        }
        self.residuals
            .predict(&self.evaluation(world), self.case(world, r))
    }

    /// Weighted residuals of every record at physical parameters `p`, concatenated.
    pub fn residuals_at(&self, p: &[f64]) -> Result<DVector<f64>, EngineError> {
        let world = self.realise(p)?;
        // The lowest index of a record that failed: the evaluation reports the first error
        // in record order, so a later record's simulation is stopped (or not started) once
        // an earlier one failed (a trial point too stiff for the step allowance costs one
        // record's failure instead of three); the outcome is the same.
        let failed = AtomicUsize::new(usize::MAX);
        let at = self.evaluation(&world).with_failures(&failed);
        let run = |r: usize| -> Result<Vec<f64>, EngineError> {
            if at.superseded(r) {
                return Err(IntegrationFailure::Halted { time: 0.0 }.into());
            }
            let residuals = self.residuals.residuals(&at, self.case(&world, r));
            if residuals.is_err() {
                failed.fetch_min(r, Ordering::Relaxed);
            }
            residuals
        };
        let parts: Vec<Result<Vec<f64>, EngineError>> = self.per_record(run);
        if parts.len() == 1 {
            // One record: its residuals as they are (a long record's are not copied).
            let only = parts.into_iter().next().unwrap_or_else(|| Ok(Vec::new()))?;
            return Ok(DVector::from_vec(only));
        }
        let mut out = Vec::with_capacity(self.n_residuals());
        for part in parts {
            out.extend(part?);
        }
        Ok(DVector::from_vec(out))
    }

    fn residuals_or_nan(&self, u: &DVector<f64>) -> DVector<f64> {
        match self.residuals_at(&self.physical(u)) {
            Ok(r) => r,
            Err(e) => {
                if let Ok(mut g) = self.last_error.lock() {
                    *g = Some(e.to_string());
                }
                DVector::from_element(self.n_residuals(), f64::NAN)
            }
        }
    }

    /// The Jacobian of the residuals in internal coordinates: the producer's closed-form
    /// columns where it gives them, forward differences (stepping inwards at an upper bound)
    /// for the others.
    pub fn jacobian_internal(&self, u: &DVector<f64>, r0: &DVector<f64>) -> DMatrix<f64> {
        self.completed_jacobian(u, r0, self.analytic_columns(u, r0))
    }

    /// The Jacobian at `u` from the producer's closed-form columns `analytic`, forward
    /// differences from the residuals `r0` there (stepping inwards at an upper bound) for the
    /// columns it did not give.
    fn completed_jacobian(
        &self,
        u: &DVector<f64>,
        r0: &DVector<f64>,
        analytic: ClosedFormColumns,
    ) -> DMatrix<f64> {
        let n = self.layout.len();
        if n == 0 {
            return DMatrix::zeros(r0.len(), 0);
        }
        let column = |j: usize| -> DVector<f64> {
            if let Some(c) = &analytic[j] {
                return c.clone();
            }
            let (_, hi) = self.layout[j].internal_bounds();
            let h = self.fd_step(u, j);
            self.difference_column(u, r0, j, if u[j] + h > hi { -h } else { h })
        };
        let cols: Vec<DVector<f64>> = if self.worth_threads() && n > 1 {
            (0..n).into_par_iter().map(column).collect()
        } else {
            (0..n).map(column).collect()
        };
        DMatrix::from_columns(&cols)
    }

    /// The columns the producer gives in closed form at `u` (internal coordinates), `None` for
    /// the others: all `None` when it gives none, when the residuals `r0` there are not finite
    /// (a failed evaluation, whose columns the differences make NaN) or when it fails.
    fn analytic_columns(&self, u: &DVector<f64>, r0: &DVector<f64>) -> ClosedFormColumns {
        let n = self.layout.len();
        if !self.residuals.has_jacobian() || r0.iter().any(|r| !r.is_finite()) {
            return vec![None; n];
        }
        let p = self.physical(u);
        let Ok(world) = self.realise(&p) else {
            return vec![None; n];
        };
        let at = self.evaluation(&world);
        let record = |r: usize| -> Option<JacobianColumns> {
            let columns = self
                .residuals
                .jacobian_columns(&at, self.case(&world, r), &self.layout)
                .ok()?;
            self.fits_record(r, &columns).then_some(columns)
        };
        let parts: Vec<Option<JacobianColumns>> = self.per_record(record);
        let Some(parts) = parts.into_iter().collect::<Option<Vec<_>>>() else {
            return vec![None; n];
        };
        self.internal_columns(&parts, &p, r0.len())
    }

    /// The records' closed-form columns `parts` (physical, in record order) at physical `p`
    /// concatenated into columns of `len` residuals in internal coordinates.
    fn internal_columns(
        &self,
        parts: &[JacobianColumns],
        p: &[f64],
        len: usize,
    ) -> ClosedFormColumns {
        (0..self.layout.len())
            .map(|j| {
                let mut column = Vec::with_capacity(len);
                for part in parts {
                    column.extend_from_slice(part[j].as_ref()?);
                }
                // d r / d u = d r / d p * d p / d u, with d u / d p = internal_derivative.
                let dp_du = 1.0 / self.layout[j].internal_derivative(p[j]);
                Some(DVector::from_vec(column) * dp_du)
            })
            .collect()
    }

    /// The residuals at physical `p` (internal `u`) with the closed-form Jacobian columns
    /// there, from one evaluation per record, where the producer gives them together
    /// ([`Residuals::residuals_with_columns`]) and every record's residuals are finite; `None`
    /// otherwise (the caller evaluates them apart, and reports any failure).
    fn evaluated_together(&self, p: &[f64]) -> Option<(DVector<f64>, ClosedFormColumns)> {
        if !self.residuals.has_jacobian() {
            return None;
        }
        let world = self.realise(p).ok()?;
        let at = self.evaluation(&world);
        let record = |r: usize| -> Option<(Vec<f64>, JacobianColumns)> {
            let (residuals, columns) = self
                .residuals
                .residuals_with_columns(&at, self.case(&world, r), &self.layout)
                .ok()??;
            let sound = residuals.len() == self.residuals.residual_count(r, &self.records[r])
                && residuals.iter().all(|x| x.is_finite())
                && self.fits_record(r, &columns);
            sound.then_some((residuals, columns))
        };
        let parts: Vec<Option<(Vec<f64>, JacobianColumns)>> = self.per_record(record);
        let (residuals, columns): (Vec<Vec<f64>>, Vec<JacobianColumns>) = parts
            .into_iter()
            .collect::<Option<Vec<_>>>()?
            .into_iter()
            .unzip();
        let residuals = DVector::from_vec(residuals.concat());
        let columns = self.internal_columns(&columns, p, residuals.len());
        Some((residuals, columns))
    }

    /// The residuals at `u` (NaN where the evaluation failed) and, when `together`, the
    /// closed-form columns evaluated with them where the producer gives both at once.
    fn evaluate(
        &self,
        u: &DVector<f64>,
        together: bool,
    ) -> (DVector<f64>, Option<ClosedFormColumns>) {
        if together {
            if let Some((r, columns)) = self.evaluated_together(&self.physical(u)) {
                return (r, Some(columns));
            }
        }
        (self.residuals_or_nan(u), None)
    }

    /// Record `r` as the producer evaluates it at `world`.
    fn case<'a>(&'a self, world: &'a Realised, r: usize) -> RecordCase<'a> {
        RecordCase {
            index: r,
            record: &self.records[r],
            nuisance: &world.nuisance[r],
        }
    }

    /// Whether a producer's `columns` for record `r` are whole: one per free parameter, each
    /// as long as the record's residuals.
    fn fits_record(&self, r: usize, columns: &JacobianColumns) -> bool {
        let len = self.residuals.residual_count(r, &self.records[r]);
        let fits = |c: &Option<Vec<f64>>| c.as_ref().is_none_or(|c| c.len() == len);
        columns.len() == self.layout.len() && columns.iter().all(fits)
    }

    /// `f` of every record index, in record order: on rayon's pool where simulations should
    /// go to other threads and there is more than one record.
    fn per_record<T: Send>(&self, f: impl Fn(usize) -> T + Sync + Send) -> Vec<T> {
        if self.worth_threads() && self.records.len() > 1 {
            (0..self.records.len()).into_par_iter().map(f).collect()
        } else {
            (0..self.records.len()).map(f).collect()
        }
    }

    /// Whether simulations should go to other threads: allowed, and the records are not so
    /// light that the hand-over costs more than the work.
    fn worth_threads(&self) -> bool {
        self.parallel
            && !self
                .allowance
                .is_light(self.records.iter().map(|r| r.time().len()))
    }

    /// The forward-difference step of parameter `j` at `u` (internal coordinates).
    pub fn fd_step(&self, u: &DVector<f64>, j: usize) -> f64 {
        FD_STEP * u[j].abs().max(1.0)
    }

    /// The difference quotient of the residuals along parameter `j` with step `h` (either
    /// sign), from the residuals `r0` at `u`.
    pub fn difference_column(
        &self,
        u: &DVector<f64>,
        r0: &DVector<f64>,
        j: usize,
        h: f64,
    ) -> DVector<f64> {
        let mut moved = u.clone();
        moved[j] += h;
        (self.residuals_or_nan(&moved) - r0) / h
    }

    /// The Jacobian with respect to the physical parameters (for the statistics), and the
    /// residuals at `p`; computed once per point.
    pub fn jacobian_physical(
        &self,
        p: &[f64],
    ) -> Result<(DMatrix<f64>, DVector<f64>), EngineError> {
        let cached = self.physical_cache.lock().ok().and_then(|c| {
            c.as_ref()
                .filter(|(at, _, _)| at.as_slice() == p)
                .map(|(_, j, r)| (j.clone(), r.clone()))
        });
        if let Some(hit) = cached {
            return Ok(hit);
        }
        let (j, r0) = self.compute_jacobian_physical(p)?;
        if let Ok(mut c) = self.physical_cache.lock() {
            *c = Some((p.to_vec(), j.clone(), r0.clone()));
        }
        Ok((j, r0))
    }

    /// Takes the Jacobian `jac` (internal coordinates) and residuals `r` a solver run of this
    /// problem's twin computed at `u`, as the physical Jacobian there (saves recomputing it).
    pub fn adopt_linearisation(&self, u: &DVector<f64>, jac: DMatrix<f64>, r: DVector<f64>) {
        let p = self.physical(u);
        let physical = self.to_physical_columns(jac, &p);
        if let Ok(mut c) = self.physical_cache.lock() {
            *c = Some((p, physical, r));
        }
    }

    /// The physical Jacobian and the residuals at `p` for their last reader: taken out of the
    /// cache (not copied) when it holds them, else computed and not kept. On a long record
    /// each is as large as the record's samples.
    pub fn take_jacobian_physical(
        &self,
        p: &[f64],
    ) -> Result<(DMatrix<f64>, DVector<f64>), EngineError> {
        let kept = self.physical_cache.lock().ok().and_then(|mut c| {
            let hit = c.as_ref().is_some_and(|(at, _, _)| at.as_slice() == p);
            hit.then(|| c.take()).flatten()
        });
        match kept {
            Some((_, j, r)) => Ok((j, r)),
            None => self.compute_jacobian_physical(p),
        }
    }

    /// Scales the columns of an internal-coordinate Jacobian at physical `p` to physical ones.
    fn to_physical_columns(&self, mut j: DMatrix<f64>, p: &[f64]) -> DMatrix<f64> {
        for (c, f) in self.layout.iter().enumerate() {
            j.column_mut(c).scale_mut(f.internal_derivative(p[c]));
        }
        j
    }

    fn compute_jacobian_physical(
        &self,
        p: &[f64],
    ) -> Result<(DMatrix<f64>, DVector<f64>), EngineError> {
        let u = self.internal(p);
        let (r0, analytic) = match self.evaluated_together(p) {
            Some(both) => both,
            None => {
                let r0 = self.residuals_at(p)?;
                let analytic = self.analytic_columns(&u, &r0);
                (r0, analytic)
            }
        };
        let j = self.robust_rows(self.completed_jacobian(&u, &r0, analytic), &r0);
        Ok((self.to_physical_columns(j, p), self.robust(r0)))
    }
}

/// The Operator and Jacobian a solver drives. Where the producer gives the residuals and the
/// closed-form columns from one evaluation, `apply` evaluates both whenever the solver took its
/// last step (asked for the Jacobian at `apply`'s previous point): a solver that takes its
/// step asks for the Jacobian there next, and one evaluation with sensitivities costs less
/// than a plain one followed by another with sensitivities. After a rejected step, `apply`
/// evaluates the residuals alone.
impl<R: Residuals> Operator for FitProblem<R> {
    type Param = DVector<f64>;
    type Output = DVector<f64>;
    fn apply(&self, u: &DVector<f64>) -> Result<DVector<f64>, Error> {
        let took_last_step = self
            .cache
            .lock()
            .ok()
            .is_none_or(|c| c.as_ref().is_none_or(|e| e.linearised));
        let (r, columns) = self.evaluate(u, took_last_step);
        let out = self.robust(r.clone());
        if let Ok(mut c) = self.cache.lock() {
            *c = Some(Evaluated {
                u: u.clone(),
                residuals: r,
                columns,
                linearised: false,
            });
        }
        Ok(out)
    }
}

impl<R: Residuals> Jacobian for FitProblem<R> {
    type Param = DVector<f64>;
    type Jacobian = DMatrix<f64>;
    fn jacobian(&self, u: &DVector<f64>) -> Result<DMatrix<f64>, Error> {
        let cached = self.cache.lock().ok().and_then(|mut c| {
            let e = c.as_mut().filter(|e| &e.u == u)?;
            e.linearised = true;
            Some((e.residuals.clone(), e.columns.take()))
        });
        let (r0, columns) = match cached {
            Some(hit) => hit,
            None => (self.residuals_or_nan(u), None),
        };
        let analytic = columns.unwrap_or_else(|| self.analytic_columns(u, &r0));
        Ok(self.robust_rows(self.completed_jacobian(u, &r0, analytic), &r0))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::exact::coulomb_free_vibration;
    use crate::record::{Channel, TimeBase};
    use crate::simulate::Integrator;
    use frictionid_models::LuGre;

    /// Three velocity records of the exact Coulomb motion (mu 0.24) released from 10, 14 and
    /// 22 mm, 1 s at 1 kHz.
    fn coulomb_records(osc: &Oscillator) -> Vec<Record> {
        let time: Vec<f64> = (0..1000).map(|i| i as f64 * 1e-3).collect();
        [0.010, 0.014, 0.022]
            .iter()
            .map(|&x0| {
                let exact =
                    coulomb_free_vibration(osc, 0.24 * osc.normal_force, x0, &time).unwrap();
                let mut r = Record::from_time_base(
                    format!("{} mm", x0 * 1e3),
                    TimeBase::new(time.clone()).unwrap(),
                )
                .with_channel(Channel::Velocity, exact.v);
                r.x0 = x0;
                r
            })
            .collect()
    }

    /// LuGre's sigma0 free (log), Dopri5 forced, records evaluated one after the other.
    fn stiffness_problem(records: Arc<[Record]>) -> FitProblem {
        let model = LuGre {
            sigma0: 1e5,
            mu_c: 0.24,
            mu_s: 0.24,
            ..LuGre::default()
        };
        let residuals =
            Arc::new(SimulatedResponse::for_records(&records, false, false, false).unwrap());
        let sigma0 = FreeParam {
            log: true,
            ..FreeParam::linear(
                "sigma0".into(),
                "N/m",
                ParamKind::Model(0),
                (1.0, 1e12),
                1e5,
                1e5,
            )
        };
        FitProblem::new(
            residuals,
            ProblemParts {
                oscillator: Oscillator::fmm(),
                model: Box::new(model),
                records,
                layout: vec![sigma0],
                sim: SimOptions {
                    integrator: Integrator::Dopri5,
                    ..SimOptions::default()
                },
                parallel: false,
            },
        )
    }

    /// A damper stroke's Dahl problem (sigma0, the level and the load cell's offset free) and
    /// a point off its truth, in internal coordinates.
    fn dahl_stroke_problem() -> (
        FitProblem<crate::identify::problem::force_along_motion::ForceAlongMotion>,
        DVector<f64>,
    ) {
        use crate::identify::search::strategy::{law_force_problem, offset_stroke};
        let (stroke, osc, opts) = offset_stroke(3.0);
        let records: Arc<[Record]> = vec![stroke].into();
        let truth = frictionid_models::Dahl {
            sigma0: 4e5,
            mu_c: 50.0,
            alpha: 1.0,
        };
        let (problem, start) = law_force_problem(&records, osc, &opts, &truth);
        let away: Vec<f64> = start.iter().map(|x| 0.8 * x + 0.5).collect();
        let u = problem.internal(&away);
        (problem, u)
    }

    /// A trial the solver takes costs one replay: the replay with sensitivities that gives the
    /// Jacobian gives the residuals as well, and they are the plain replay's. The Jacobian
    /// agrees with central differences of the plain residuals.
    #[test]
    fn a_taken_step_costs_one_replay_with_sensitivities() {
        let (problem, u) = dahl_stroke_problem();
        let r = problem.apply(&u).unwrap();
        let j = problem.jacobian(&u).unwrap();
        assert_eq!(problem.simulations(), 1);
        let (plain, _) = dahl_stroke_problem();
        let expected = plain.residuals_at(&plain.physical(&u)).unwrap();
        assert!((&r - &expected).norm() <= 1e-12 * expected.norm());
        for c in 0..u.len() {
            let h = 1e-5 * u[c].abs().max(1.0);
            let at = |step: f64| {
                let mut moved = u.clone();
                moved[c] += step;
                plain.residuals_at(&plain.physical(&moved)).unwrap()
            };
            let central = (at(h) - at(-h)) / (2.0 * h);
            let error = (j.column(c) - &central).norm();
            assert!(error <= 1e-5 * central.norm(), "column {c}: {error}");
        }
    }

    /// After a trial the solver did not take (it asked for no Jacobian there), the next trial
    /// is evaluated without sensitivities; its Jacobian, asked for, then costs its own replay.
    #[test]
    fn after_a_rejected_trial_the_next_is_evaluated_alone() {
        let (problem, u) = dahl_stroke_problem();
        problem.apply(&u).unwrap();
        assert_eq!(problem.simulations(), 1);
        let next = u.map(|x| x * 1.01);
        problem.apply(&next).unwrap();
        assert_eq!(problem.simulations(), 2);
        problem.jacobian(&next).unwrap();
        assert_eq!(problem.simulations(), 3);
    }

    /// Once a record's simulation fails, the records after it in the same evaluation are not
    /// simulated (their outcome no longer matters): the first evaluation, at a soft contact,
    /// sets each record's step allowance, and a trial at a contact a thousand times stiffer
    /// (stability-bound for Dopri5, far over the allowance) fails on the first record and costs
    /// that one simulation, not three. The error is the one the first record alone gives.
    #[test]
    fn an_evaluation_stops_at_the_first_record_that_fails() {
        let records = coulomb_records(&Oscillator::fmm());
        let problem = stiffness_problem(records.clone().into());
        let soft = problem.residuals_at(&[1e5]).unwrap();
        assert!(soft.iter().all(|r| r.is_finite()));
        assert_eq!(problem.simulations(), 3);
        let err = problem.residuals_at(&[1e8]).unwrap_err().to_string();
        assert_eq!(problem.simulations(), 4, "{err}");
        let alone = stiffness_problem(records[..1].to_vec().into());
        alone.residuals_at(&[1e5]).unwrap();
        assert_eq!(err, alone.residuals_at(&[1e8]).unwrap_err().to_string());
    }
}
