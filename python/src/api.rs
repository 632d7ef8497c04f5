//! The module's functions: dicts in, the engine's job, a dict out with the report's text
//! forms beside it (`(dict, texts)`, see [`crate::outputs::texts`]).
//!
//! Simulations and fits run with the GIL released, on a worker thread, while the calling
//! thread watches for signals; Ctrl-C stops the fit at its next solver iteration (see
//! [`run_job`]) and raises `KeyboardInterrupt`.

use crate::convert::{serialized, to_f64_vec, to_json};
use crate::errors::{engine_error, job_error, value_error};
use crate::inputs;
use crate::outputs::{compare_output, energy_output, fit_output, simulate_output, WithTexts};
use frictionid_engine::identify::require_oscillator;
use frictionid_engine::jobs::{compare_job, energy_job, fit_job, simulate_report};
use frictionid_engine::record::TimeBase;
use frictionid_engine::report::ModelsReport;
use frictionid_engine::simulate::{simulate as simulate_trajectory, Initial};
use frictionid_engine::spec::{Hooks, IntegratorSpec, ModelSpec};
use frictionid_engine::{Axis, Spec};
use frictionid_models::FrictionModel;
use pyo3::exceptions::PyRuntimeError;
use pyo3::prelude::*;
use pyo3::types::PyString;
use std::any::Any;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc::{self, RecvTimeoutError};
use std::sync::Arc;
use std::time::{Duration, Instant};

/// How often the calling thread looks for Ctrl-C while a job runs.
const SIGNAL_POLL: Duration = Duration::from_millis(50);

/// The unwinding payload that stops a cancelled fit (never a crash: caught in [`run_job`]).
struct Cancelled;

/// Hooks whose progress callback stops the fit once `cancel` is set. The engine's progress
/// hook cannot return an error, so the callback unwinds with [`Cancelled`] through
/// `resume_unwind` (which prints nothing); the worker thread catches it.
fn cancellable_hooks(cancel: Arc<AtomicBool>) -> Hooks {
    Hooks {
        progress: Some(Arc::new(move |_| {
            if cancel.load(Ordering::Relaxed) {
                std::panic::resume_unwind(Box::new(Cancelled));
            }
        })),
        ..Hooks::default()
    }
}

/// Why a worker thread ended without a result.
fn lost_worker(payload: Box<dyn Any + Send>) -> PyErr {
    let msg = payload
        .downcast_ref::<&str>()
        .map(|s| s.to_string())
        .or_else(|| payload.downcast_ref::<String>().cloned())
        .unwrap_or_default();
    PyRuntimeError::new_err(format!("internal error: {msg} (please report this)"))
}

/// Runs `job` on a worker thread with the GIL released; the calling thread checks for
/// signals every [`SIGNAL_POLL`]. On Ctrl-C the job is cancelled (it ends at its next solver
/// iteration) and the signal's exception (`KeyboardInterrupt`) raised at once.
pub fn run_job<T: Send + 'static>(
    py: Python<'_>,
    job: impl FnOnce(Hooks) -> PyResult<T> + Send + 'static,
) -> PyResult<T> {
    let cancel = Arc::new(AtomicBool::new(false));
    let hooks = cancellable_hooks(cancel.clone());
    let (tx, rx) = mpsc::channel();
    std::thread::spawn(move || {
        let outcome = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| job(hooks)));
        let _ = tx.send(outcome);
    });
    // A Mutex makes the receiver shareable with the GIL-free closure (it is never contended).
    let rx = std::sync::Mutex::new(rx);
    let wait = || match rx.lock() {
        Ok(r) => r.recv_timeout(SIGNAL_POLL),
        Err(_) => Err(RecvTimeoutError::Disconnected),
    };
    loop {
        match py.detach(wait) {
            Ok(Ok(result)) => return result,
            Ok(Err(payload)) => return Err(lost_worker(payload)),
            Err(RecvTimeoutError::Disconnected) => {
                return Err(PyRuntimeError::new_err(
                    "internal error: the worker thread ended",
                ))
            }
            Err(RecvTimeoutError::Timeout) => {
                if let Err(signal) = py.check_signals() {
                    // The worker stops at its next solver iteration; the caller need not
                    // wait for it (one iteration of a stiff model can take seconds).
                    cancel.store(true, Ordering::Relaxed);
                    return Err(signal);
                }
            }
        }
    }
}

/// Every registered friction model with its parameters' units on `axis` (`"linear"`, the
/// default, or `"rotary"`): what `frictionid models --json [--axis rotary]` prints.
#[pyfunction]
#[pyo3(signature = (axis = "linear"))]
pub fn models<'py>(py: Python<'py>, axis: &str) -> PyResult<Bound<'py, PyAny>> {
    let axis: Axis = axis
        .parse()
        .map_err(|e| value_error(format!("models: {e}")))?;
    serialized(py, &ModelsReport::on_axis(axis))
}

/// Integrator options and initial internal states from `simulate`'s `options` dict.
fn simulate_options(
    options: Option<&Bound<'_, PyAny>>,
) -> PyResult<(IntegratorSpec, Option<Vec<f64>>)> {
    let mut json = match options {
        Some(o) if !o.is_none() => to_json(o, "options")?,
        _ => serde_json::json!({}),
    };
    let z0 = json
        .as_object_mut()
        .and_then(|o| o.remove("z0"))
        .map(serde_json::from_value::<Vec<f64>>)
        .transpose()
        .map_err(|e| value_error(format!("options: z0: {e}")))?;
    let integrator =
        serde_json::from_value(json).map_err(|e| value_error(format!("options: {e}")))?;
    Ok((integrator, z0))
}

/// One free vibration released at `x0` (and `v0`), sampled at the times `t`.
#[pyfunction]
#[pyo3(signature = (oscillator, model, x0, t, v0 = 0.0, options = None))]
pub fn simulate<'py>(
    py: Python<'py>,
    oscillator: &Bound<'py, PyAny>,
    model: &Bound<'py, PyAny>,
    x0: f64,
    t: &Bound<'py, PyAny>,
    v0: f64,
    options: Option<&Bound<'py, PyAny>>,
) -> PyResult<WithTexts<'py>> {
    let stage = inputs::oscillator(oscillator)?;
    require_oscillator(&stage.unknown, stage.oscillator.axis, "simulate")
        .map_err(|e| value_error(e.to_string()))?;
    let osc = stage.oscillator;
    let model = inputs::model(model)?.model;
    let times = TimeBase::new(to_f64_vec(t, "t")?).map_err(|e| value_error(format!("t: {e}")))?;
    let (integrator, z0) = simulate_options(options)?;
    let init = Initial { x0, v0, z0 };
    let t_end = times.as_slice().last().copied().unwrap_or(0.0);
    let report = py.detach(|| {
        let started = Instant::now();
        let sim = integrator.sim_options();
        simulate_trajectory(&osc, model.as_ref(), &init, t_end, times.as_slice(), &sim).map(
            |traj| {
                simulate_report(
                    osc,
                    model.clone(),
                    &init,
                    traj,
                    started.elapsed().as_secs_f64(),
                )
            },
        )
    });
    simulate_output(py, &report.map_err(engine_error)?)
}

/// The spec of `fit`, `compare` and `energy` from their dicts.
fn spec_from(
    oscillator: &Bound<'_, PyAny>,
    model: Option<ModelSpec>,
    fit: Option<&Bound<'_, PyAny>>,
    energy: Option<&Bound<'_, PyAny>>,
) -> PyResult<Spec> {
    inputs::spec(
        inputs::oscillator(oscillator)?,
        model,
        inputs::fit_spec(fit)?,
        inputs::energy_spec(energy)?,
    )
}

/// The model fitted to `records`: report.json's structure plus the fitted series.
#[pyfunction]
#[pyo3(signature = (oscillator, model, records, fit = None))]
pub fn fit<'py>(
    py: Python<'py>,
    oscillator: &Bound<'py, PyAny>,
    model: &Bound<'py, PyAny>,
    records: &Bound<'py, PyAny>,
    fit: Option<&Bound<'py, PyAny>>,
) -> PyResult<WithTexts<'py>> {
    let spec = model_spec(oscillator, model, fit)?;
    let records = inputs::records(records)?;
    let report = run_job(py, move |hooks| {
        fit_job(&spec, &records, &hooks).map_err(job_error)
    })?;
    fit_output(py, &report)
}

/// The spec of `fit` and `plan`: the oscillator, the model dict and the fit's options.
fn model_spec(
    oscillator: &Bound<'_, PyAny>,
    model: &Bound<'_, PyAny>,
    fit: Option<&Bound<'_, PyAny>>,
) -> PyResult<Spec> {
    spec_from(oscillator, Some(inputs::model(model)?), fit, None)
}

/// The models to compare: names (registered models with their defaults) or model dicts.
fn models_to_compare(
    spec: &Spec,
    models: Option<&Bound<'_, PyAny>>,
) -> PyResult<Vec<Box<dyn FrictionModel>>> {
    let Some(list) = models.filter(|m| !m.is_none()) else {
        return spec.models_to_compare(None).map_err(value_error);
    };
    let items = inputs::non_empty_list(
        list,
        "models: expected a list of names or model dicts",
        "no models to compare",
    )?;
    items
        .iter()
        .map(|item| match item.cast::<PyString>() {
            Ok(name) => {
                let request = [name.extract::<String>()?];
                let mut found = spec
                    .models_to_compare(Some(&request))
                    .map_err(value_error)?;
                Ok(found.remove(0))
            }
            Err(_) => Ok(inputs::model(item)?.model),
        })
        .collect()
}

/// Several models fitted to the same records and ranked by AIC.
#[pyfunction]
#[pyo3(signature = (oscillator, models, records, fit = None))]
pub fn compare<'py>(
    py: Python<'py>,
    oscillator: &Bound<'py, PyAny>,
    models: Option<&Bound<'py, PyAny>>,
    records: &Bound<'py, PyAny>,
    fit: Option<&Bound<'py, PyAny>>,
) -> PyResult<WithTexts<'py>> {
    let spec = spec_from(oscillator, None, fit, None)?;
    let models = models_to_compare(&spec, models)?;
    let records = inputs::records(records)?;
    let report = run_job(py, move |hooks| {
        compare_job(&spec, &models, &records, &hooks).map_err(job_error)
    })?;
    compare_output(py, &report)
}

/// The energy-based friction force of every record (Eq. 7) against a reference: the model's
/// force when a model is given, else a fitted Coulomb force.
#[pyfunction]
#[pyo3(signature = (oscillator, records, model = None, options = None))]
pub fn energy<'py>(
    py: Python<'py>,
    oscillator: &Bound<'py, PyAny>,
    records: &Bound<'py, PyAny>,
    model: Option<&Bound<'py, PyAny>>,
    options: Option<&Bound<'py, PyAny>>,
) -> PyResult<WithTexts<'py>> {
    let model = model
        .filter(|m| !m.is_none())
        .map(inputs::model)
        .transpose()?;
    let spec = spec_from(oscillator, model, None, options)?;
    let records = inputs::records(records)?;
    let report = run_job(py, move |hooks| {
        energy_job(&spec, &records, &hooks).map_err(job_error)
    })?;
    energy_output(py, &report)
}

/// Which records to take next, as `frictionid plan` says: `plan` is the `[plan]` table as a
/// dict (candidates released or driven by a multisine; input files, `noise_record` and
/// `prior` are read by `run(config, "plan")`), `records` the records already taken, `fit`
/// what a fit would free. Returns report.json's structure.
#[pyfunction]
#[pyo3(signature = (oscillator, model, plan, records = None, fit = None))]
pub fn plan<'py>(
    py: Python<'py>,
    oscillator: &Bound<'py, PyAny>,
    model: &Bound<'py, PyAny>,
    plan: &Bound<'py, PyAny>,
    records: Option<&Bound<'py, PyAny>>,
    fit: Option<&Bound<'py, PyAny>>,
) -> PyResult<Bound<'py, PyAny>> {
    use frictionid_engine::jobs::{plan_job, PlanInputs};
    use frictionid_engine::spec::PlanSpec;
    let spec = model_spec(oscillator, model, fit)?;
    let plan_spec: PlanSpec = serde_json::from_value(to_json(plan, "plan")?)
        .map_err(|e| value_error(format!("plan: {e}")))?;
    let files = plan_spec.candidates.iter().any(|c| c.input.is_some())
        || plan_spec.noise_record.is_some()
        || plan_spec.prior.is_some();
    if files {
        return Err(value_error(
            "plan: input files, noise_record and prior are read by run(config, \"plan\"); \
             give multisines, velocity_noise and the model here",
        ));
    }
    let taken = match records.filter(|r| !r.is_none()) {
        Some(r) => inputs::records(r)?,
        None => Vec::new(),
    };
    let report = run_job(py, move |_hooks| {
        let given = PlanInputs {
            taken: &taken,
            ..PlanInputs::default()
        };
        plan_job(&spec, &plan_spec, given).map_err(job_error)
    })?;
    serialized(py, &report)
}
