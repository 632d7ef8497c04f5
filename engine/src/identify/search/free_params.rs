//! From options to a fit's free parameters: checks the names and bounds the options give,
//! picks the starting model (data-driven guess or as given) and lays out the free model,
//! oscillator and nuisance parameters with their bounds and starting values.

use crate::axis::Axis;
use crate::energy::EnergyOptions;
use crate::error::EngineError;
use crate::identify::problem::residuals::Residuals;
use crate::identify::values::layout::{FreeParam, ParamKind};
use crate::identify::values::levels::FrictionLevels;
use crate::identify::values::nuisance::{non_model_bound_keys, NuisanceKind};
use crate::identify::values::param_options::ParamOptions;
use crate::oscillator::{Oscillator, OscillatorProperty};
use crate::record::Record;
use frictionid_models::{FrictionModel, GuessHint, ParamInfo};

fn unknown_name(kind: &str, name: &str, valid: &[String]) -> EngineError {
    let hint = frictionid_models::suggest::did_you_mean(name, valid.iter().map(String::as_str));
    EngineError::InvalidInput(format!(
        "{kind} `{name}` is not a parameter{hint}; valid: {}",
        valid.join(", ")
    ))
}

/// The free parameters of a fit, the model carrying the fixed values and where to start.
pub struct Layout {
    /// The model at its starting values (fixed parameters as given).
    pub start_model: Box<dyn FrictionModel>,
    /// The free parameters, in solver order.
    pub params: Vec<FreeParam>,
    /// Their starting physical values.
    pub start: Vec<f64>,
    /// Whether the law's levels are coefficients or forces (bounded by the data).
    pub levels: FrictionLevels,
}

impl Layout {
    /// Number of free model parameters (not oscillator or nuisance).
    pub fn n_model_free(&self) -> usize {
        self.params
            .iter()
            .filter(|f| matches!(f.kind, ParamKind::Model(_)))
            .count()
    }

    fn push(&mut self, param: FreeParam, start: f64) {
        self.params.push(param);
        self.start.push(start);
    }

    /// `point` projected into every free parameter's domain ([`FreeParam::project`]; the
    /// fit's own start where a value has no nearest valid one): where a search may start.
    pub fn projected(&self, point: &[f64]) -> Vec<f64> {
        self.params
            .iter()
            .zip(point)
            .zip(&self.start)
            .map(|((f, &x), &start)| f.project(x, start))
            .collect()
    }

    /// The law's checks (`check`: its bounds, then [`FrictionModel::validate`]) on `model`'s
    /// fixed parameters; the free ones start projected into their domain, so they are checked
    /// at their declared defaults.
    pub fn validate_fixed(&self, model: &(dyn FrictionModel + 'static)) -> Result<(), EngineError> {
        let mut checked = frictionid_models::clone_model(model);
        let info = checked.param_info();
        let mut values = checked.params();
        for f in &self.params {
            if let ParamKind::Model(i) = f.kind {
                if let (Some(v), Some(p)) = (values.get_mut(i), info.get(i)) {
                    *v = p.default;
                }
            }
        }
        checked.set_params(&values)?;
        // A fixed level read as a force (a 20 N Coulomb level without a normal force) is
        // checked as the coefficient a simulation scales it to, not against the bound of 10.
        match self.levels.scaled_for_simulation(checked.as_ref()) {
            Some((scaled, _)) => scaled.check(),
            None => checked.check(),
        }?;
        Ok(())
    }
}

/// Builds the starting model and the free-parameter layout from the options (the guess
/// analysing the records with `energy`), with the nuisance parameters `residuals` adds to
/// every record.
pub fn build_layout<R: Residuals + ?Sized>(
    osc: &Oscillator,
    model: &(dyn FrictionModel + 'static),
    records: &[Record],
    residuals: &R,
    opts: &ParamOptions,
    energy: &EnergyOptions,
) -> Result<Layout, EngineError> {
    let info = model.param_info();
    let names: Vec<String> = info.iter().map(|p| p.name.clone()).collect();
    check_bounds(opts, &names)?;
    let free = free_model_indices(&info, &names, opts)?;
    if let Some(k) = opts.keep_initial.iter().find(|k| !names.contains(k)) {
        return Err(unknown_name("initial value", k, &names));
    }
    let levels = residuals.friction_levels();
    let mut layout = Layout {
        start_model: starting_model(model, opts, &free, || residuals.hint(osc, records, energy))?,
        params: Vec::new(),
        start: Vec::new(),
        levels,
    };
    let values = layout.start_model.params();
    for &i in &free {
        let (param, x) = model_param(&info[i], i, values[i], opts, (levels, osc.axis))?;
        layout.push(param, x);
    }
    for &q in &opts.oscillator {
        check_property_exists(osc, q)?;
        let (param, x) = oscillator_param(osc, q, opts);
        layout.push(param, x);
    }
    for (r, rec) in records.iter().enumerate() {
        for &kind in residuals.nuisance() {
            let (param, x) = nuisance_param(kind, r, rec, osc, opts);
            layout.push(param, x);
        }
    }
    Ok(layout)
}

/// Every bound names a parameter (model, oscillator or nuisance) and has lower < upper.
fn check_bounds(opts: &ParamOptions, model_names: &[String]) -> Result<(), EngineError> {
    let mut valid = model_names.to_vec();
    valid.extend(non_model_bound_keys().into_iter().map(String::from));
    if let Some(b) = opts.bounds.keys().find(|b| !valid.contains(b)) {
        return Err(unknown_name("bound", b, &valid));
    }
    for (k, &(lo, hi)) in &opts.bounds {
        if lo.is_nan() || hi.is_nan() || lo >= hi {
            return Err(EngineError::InvalidInput(format!(
                "bounds of `{k}` must satisfy lower < upper, got [{lo}, {hi}]"
            )));
        }
    }
    Ok(())
}

/// Indices of the free model parameters, sorted: the options' list (oscillator names are
/// allowed and skipped) or every parameter not fixed by default.
fn free_model_indices(
    info: &[ParamInfo],
    names: &[String],
    opts: &ParamOptions,
) -> Result<Vec<usize>, EngineError> {
    let Some(list) = &opts.free else {
        return Ok((0..info.len())
            .filter(|&i| !info[i].fixed_by_default)
            .collect());
    };
    let mut idx = Vec::new();
    for name in list {
        match names.iter().position(|n| n == name) {
            Some(i) if !idx.contains(&i) => idx.push(i),
            Some(_) => {}
            None if OscillatorProperty::parse(name).is_some() => {}
            None => return Err(unknown_name("free parameter", name, names)),
        }
    }
    idx.sort_unstable();
    Ok(idx)
}

/// The model at its starting values: the data-driven guess (from `hint`) for the free
/// parameters (unless kept), the given values for the others.
fn starting_model(
    model: &(dyn FrictionModel + 'static),
    opts: &ParamOptions,
    free: &[usize],
    hint: impl FnOnce() -> GuessHint,
) -> Result<Box<dyn FrictionModel>, EngineError> {
    let mut start_model = frictionid_models::clone_model(model);
    if opts.guess && !free.is_empty() {
        let given = model.params();
        if let Some(staging) = start_model.staging() {
            staging.apply_guess(&hint());
        }
        let mut values = start_model.params();
        for (i, p) in model.param_info().iter().enumerate() {
            if !free.contains(&i) || opts.keep_initial.contains(&p.name) {
                values[i] = given[i];
            }
        }
        start_model.set_params(&values)?;
    }
    Ok(start_model)
}

/// A free model parameter: log coordinates for a strictly positive one, its bounds from the
/// options within the law's domain ([`law_domain`]), else the model's (a level read as a
/// force: from the data, see [`FrictionLevels`]); the start projected into them
/// ([`FreeParam::project`], the law's default where the value has no nearest valid one).
fn model_param(
    p: &ParamInfo,
    index: usize,
    value: f64,
    opts: &ParamOptions,
    (levels, axis): (FrictionLevels, Axis),
) -> Result<(FreeParam, f64), EngineError> {
    let (lo, hi) = match opts.bounds.get(&p.name) {
        Some(&(lo, hi)) => within_domain(p, (lo, hi), levels)?,
        None => levels.bounds(p),
    };
    let log = p.lower_exclusive && p.lower == 0.0 && lo >= 0.0;
    let param = |start: f64| FreeParam {
        log,
        ..FreeParam::linear(
            p.name.clone(),
            &levels.unit(p, axis),
            ParamKind::Model(index),
            (lo, hi),
            start,
            1.0,
        )
    };
    let x = param(p.default).project(value, p.default);
    Ok((param(x), x))
}

/// The law's domain of `p`: its declared bounds, without the upper one for a level read as a
/// force (whose declared bounds are a coefficient's).
fn law_domain(p: &ParamInfo, levels: FrictionLevels) -> (f64, f64) {
    if levels.are_forces() && FrictionLevels::is_level(p) {
        (p.lower, f64::INFINITY)
    } else {
        (p.lower, p.upper)
    }
}

/// The bounds `(lo, hi)` the options give `p`, within the law's domain: a search beyond it
/// would evaluate the law where it is not defined. An error when they do not meet it.
fn within_domain(
    p: &ParamInfo,
    (lo, hi): (f64, f64),
    levels: FrictionLevels,
) -> Result<(f64, f64), EngineError> {
    let (d_lo, d_hi) = law_domain(p, levels);
    let (lo_in, hi_in) = (lo.max(d_lo), hi.min(d_hi));
    let empty = lo_in > hi_in || (p.lower_exclusive && hi_in <= d_lo);
    if empty {
        return Err(EngineError::InvalidInput(format!(
            "[fit] bounds of `{}` = [{lo}, {hi}] lie outside its domain {}{d_lo}, {d_hi}]",
            p.name,
            if p.lower_exclusive { "(" } else { "[" },
        )));
    }
    Ok((lo_in, hi_in))
}

/// A fitted property is one a fit may vary, and a restoring law's parameter (the gravity
/// moment) needs a law that has it (the pendulum): otherwise its start would be undefined.
fn check_property_exists(osc: &Oscillator, q: OscillatorProperty) -> Result<(), EngineError> {
    if !q.is_fitted() {
        let fitted: Vec<&str> = OscillatorProperty::FITTED.map(|p| p.key()).to_vec();
        return Err(EngineError::InvalidInput(format!(
            "[fit.options] oscillator: `{}` cannot be fitted; fitted properties: {}",
            q.key(),
            fitted.join(", ")
        )));
    }
    if let (None, Some(table)) = (q.value(osc), q.restoring_table()) {
        return Err(EngineError::InvalidInput(format!(
            "[fit.options] oscillator: `{}` is fitted, but the restoring law `{}` has \
             none; set [oscillator] restoring = {table}",
            q.key(),
            osc.restoring.name()
        )));
    }
    Ok(())
}

/// A free oscillator property, named as reports name it on the axis (a rotary axis's mass
/// is its `inertia`, bounded under either name): the strictly positive ones in log
/// coordinates, the others linear (see [`OscillatorProperty::domain`]).
fn oscillator_param(
    osc: &Oscillator,
    q: OscillatorProperty,
    opts: &ParamOptions,
) -> (FreeParam, f64) {
    let current = q.value(osc).unwrap_or(f64::NAN);
    let log = q.log_coordinates();
    let name = q.name_on(osc.axis);
    let (lo, hi) = opts
        .bounds
        .get(q.key())
        .or_else(|| opts.bounds.get(name))
        .copied()
        .unwrap_or(q.default_bounds());
    let mut f = FreeParam::linear(
        name.to_string(),
        &q.unit_on(osc.axis),
        ParamKind::Property(q),
        (lo, hi),
        current,
        q.typical(osc),
    );
    f.log = log;
    let floor = if log { f64::MIN_POSITIVE } else { lo };
    (f, current.clamp(lo.max(floor), hi))
}

/// A nuisance parameter of record `r`, named `<key>[<record>]`.
fn nuisance_param(
    kind: NuisanceKind,
    r: usize,
    rec: &Record,
    osc: &Oscillator,
    opts: &ParamOptions,
) -> (FreeParam, f64) {
    let b = opts
        .bounds
        .get(kind.key())
        .copied()
        .unwrap_or_else(|| kind.default_bounds(rec, osc));
    let param = FreeParam::linear(
        format!("{}[{}]", kind.key(), rec.name),
        &osc.axis.unit(kind.unit()),
        ParamKind::Nuisance { kind, record: r },
        b,
        kind.start(rec),
        kind.typical(),
    );
    (param, kind.start(rec).clamp(b.0, b.1))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Fitting a gravity moment on the linear spring is an error naming the key and the law to
    /// set; on a pendulum it is accepted.
    #[test]
    fn a_gravity_moment_is_fitted_only_on_a_law_that_has_one() {
        let spring = Oscillator::fmm();
        let e = check_property_exists(&spring, OscillatorProperty::GravityMoment).unwrap_err();
        let text = e.to_string();
        assert!(text.contains("`gravity_moment`"), "{text}");
        assert!(text.contains("pendulum"), "{text}");
        assert!(check_property_exists(&spring, OscillatorProperty::Stiffness).is_ok());
        let pendulum: crate::axis::Restoring =
            serde_json::from_value(serde_json::json!({"type": "pendulum", "gravity_moment": 2.0}))
                .unwrap();
        let osc = Oscillator {
            restoring: pendulum,
            ..Oscillator::fmm()
        };
        assert!(check_property_exists(&osc, OscillatorProperty::GravityMoment).is_ok());
    }

    /// The normal force is an oscillator property a fit reads but never varies.
    #[test]
    fn the_normal_force_is_refused_as_a_fitted_property() {
        let e = check_property_exists(&Oscillator::fmm(), OscillatorProperty::NormalForce)
            .unwrap_err()
            .to_string();
        assert!(e.contains("`normal_force` cannot be fitted"), "{e}");
    }
}
