//! The property refits: how the uncertainty of the oscillator's known properties (m, c,
//! k, N; one standard deviation each) propagates into the fitted parameters, beside the
//! data's own standard error.
//!
//! The sensitivity of the optimum to a property q is taken by refits at q + sigma and
//! q - sigma (central difference, started from the optimum): the component of parameter
//! theta is |theta(q + sigma) - theta(q - sigma)| / 2. The total standard error is the root
//! sum of squares of the data component and every property component; the 95 % interval
//! follows from the total.
//!
//! This module computes; the fit ([`crate::identify::fit`]) hands it the closure that refits.

use super::stats::t_quantile_975;
use crate::error::EngineError;
use crate::identify::values::fit_options::FitOptions;
use crate::identify::values::result::{FitResult, FittedParam};
use crate::identify::values::search::fits_directly;
use crate::identify::values::target_options::FitDomain;
use crate::identify::values::uncertainty::{PropertyUncertainty, StdErrorComponents};
use crate::oscillator::Oscillator;
use frictionid_models::FrictionModel;

/// Adds the property components to every free parameter of `result` (fitted on `osc` with
/// `opts_in`) and makes its standard error and interval the totals. Each component comes
/// from two calls of `refit` (the oscillator with one property moved by plus and minus its
/// standard deviation, the fitted model to start from, the refit's options: one start from
/// the fitted values, no guess, no progress). Properties that the fit itself varies are
/// skipped.
pub(crate) fn add_property_uncertainty(
    result: &mut FitResult,
    osc: &Oscillator,
    opts_in: &FitOptions,
    refit: impl Fn(
        &Oscillator,
        &(dyn FrictionModel + 'static),
        &FitOptions,
    ) -> Result<FitResult, EngineError>,
) -> Result<(), EngineError> {
    let sigma = opts_in.uncertainty;
    sigma.validate()?;
    let opts = refit_options(opts_in, result.fitted_model.as_ref());
    let mut components: Vec<StdErrorComponents> = result
        .parameters
        .iter()
        .map(|p| StdErrorComponents {
            data: p.std_error,
            ..StdErrorComponents::default()
        })
        .collect();
    for (property, s) in sigma.properties() {
        if s <= 0.0 || opts_in.params.oscillator.contains(&property) {
            continue;
        }
        let at = |by: f64| {
            refit(
                &property.shifted(osc, by),
                result.fitted_model.as_ref(),
                &opts,
            )
        };
        let (up, down) = (at(s)?, at(-s)?);
        for (c, p) in components.iter_mut().zip(&result.parameters) {
            if let (Some(a), Some(b)) = (up.value(&p.name), down.value(&p.name)) {
                c.set(property, ((a - b) / 2.0).abs());
            }
        }
    }
    let tq = t_quantile_975(result.samples.saturating_sub(result.free_parameters));
    for (p, c) in result.parameters.iter_mut().zip(components) {
        if p.free {
            set_total(p, c, tq);
        }
    }
    Ok(())
}

/// The options of a refit of `fitted` from its optimum: no uncertainty budget, no guess, one
/// start, no progress; a static law along the measured motion needs no global search from
/// there (its default, see `Search::resolve`), so it searches locally.
pub(crate) fn refit_options(opts: &FitOptions, fitted: &dyn FrictionModel) -> FitOptions {
    let simulated = opts.target.domain != FitDomain::Force;
    let local = opts.search.strategy.is_none() && fits_directly(fitted, simulated);
    let mut refit = opts.clone();
    refit.uncertainty = PropertyUncertainty::default();
    refit.params.guess = false;
    refit.search = opts.search.one_start(local);
    refit.hooks = opts.hooks.quiet();
    refit
}

fn set_total(p: &mut FittedParam, c: StdErrorComponents, tq: f64) {
    p.std_error = c.total();
    p.ci95 = p.std_error.map(|s| [p.value - tq * s, p.value + tq * s]);
    p.std_error_components = Some(c);
}
