//! frictionid from Python: a PyO3 module over the engine's `Spec`, jobs and report values.
//!
//! Thin by design (see docs/architecture.md): every function turns Python dicts into the same
//! `Spec` a TOML configuration becomes, calls the same job the CLI calls, and converts the
//! same report value to Python (its report.json form through `json.loads`, plus numpy arrays
//! for the series report.json leaves out). Nothing here computes a result.
//!
//! - [`convert`]: Python objects to serde_json values and f64 vectors, and back.
//! - [`inputs`]: the spec and the records from dicts.
//! - [`outputs`]: report values to dicts with arrays.
//! - [`errors`]: `ValueError` for bad input, `frictionid.FitError` for a failed fit.
//! - [`api`]: the module's functions.
//! - [`run`]: a configuration file run as the CLI runs it.
//! - [`campaign`]: campaigns, one group a task for any executor.
//! - [`export`]: a fitted law as C, Rust or Python source, or a compensation table.

#[path = "../../cli/src/allocator.rs"]
mod allocator;

pub mod api;
pub mod campaign;
pub mod convert;
pub mod errors;
pub mod export;
pub mod inputs;
pub mod outputs;
pub mod run;

use pyo3::prelude::*;

/// The native module `frictionid._native`; the Python package `frictionid` re-exports it.
#[pymodule]
fn _native(m: &Bound<'_, PyModule>) -> PyResult<()> {
    allocator::keep_freed_memory();
    m.add("FitError", m.py().get_type::<errors::FitError>())?;
    m.add_function(wrap_pyfunction!(api::models, m)?)?;
    m.add_function(wrap_pyfunction!(api::simulate, m)?)?;
    m.add_function(wrap_pyfunction!(api::fit, m)?)?;
    m.add_function(wrap_pyfunction!(api::compare, m)?)?;
    m.add_function(wrap_pyfunction!(api::energy, m)?)?;
    m.add_function(wrap_pyfunction!(api::plan, m)?)?;
    m.add_function(wrap_pyfunction!(run::run, m)?)?;
    m.add_function(wrap_pyfunction!(export::export, m)?)?;
    m.add_function(wrap_pyfunction!(campaign::campaign_plan, m)?)?;
    m.add_function(wrap_pyfunction!(campaign::campaign_group, m)?)?;
    m.add_function(wrap_pyfunction!(campaign::campaign_assemble, m)?)?;
    Ok(())
}
