//! Which parameters a fit varies and where they start: the model's free parameters and
//! their bounds (`[fit] free`, `bounds`), the data-driven guess (`[fit.options] guess`), the
//! oscillator properties fitted with the model (`oscillator`) and the per-record nuisance
//! parameters (`velocity_offset`, `time_shift`, `x0`).

use super::nuisance::non_model_bound_keys;
use super::option_keys::option_keys;
use super::options::OscillatorParam;
use std::collections::BTreeMap;

/// Which parameters a fit varies, their bounds and starts (the search floor lays them out).
#[derive(Debug, Clone, PartialEq)]
pub struct ParamOptions {
    /// Model parameters to fit, by name; `None`: every parameter not fixed by default.
    pub free: Option<Vec<String>>,
    /// Bounds by parameter name (model parameters, `mass`, `damping`, `stiffness`, `offset`,
    /// `shift`, `x0` in metres); default: the model's physical bounds, none for an offset, a
    /// quarter of the natural period for a shift, 20 % of each record's x0 for x0.
    pub bounds: BTreeMap<String, (f64, f64)>,
    /// Data-driven initial values for the free model parameters (from the half-cycle energy
    /// estimate), except those named in `keep_initial`.
    pub guess: bool,
    /// Free parameters whose initial value is the model's current value even when guessing.
    /// Not a key: the parameters the `[model]` table gives.
    pub keep_initial: Vec<String>,
    /// Oscillator properties to fit.
    pub oscillator: Vec<OscillatorParam>,
    /// Fit a velocity offset per record.
    pub velocity_offset: bool,
    /// Fit a release-time shift per record.
    pub time_shift: bool,
    /// Fit the release displacement x0 of each record, starting from its given value.
    pub x0: bool,
}

impl Default for ParamOptions {
    fn default() -> Self {
        Self {
            free: None,
            bounds: BTreeMap::new(),
            guess: true,
            keep_initial: Vec::new(),
            oscillator: Vec::new(),
            velocity_offset: false,
            time_shift: false,
            x0: false,
        }
    }
}

option_keys!(ParamOptions {
    fit: ["free" => free, "bounds" => bounds],
    options: [
        "oscillator" => oscillator,
        "velocity_offset" => velocity_offset,
        "time_shift" => time_shift,
        "x0" => x0,
        "guess" => guess,
    ],
});

impl ParamOptions {
    /// These options for a model whose parameters are `names`: the free list, the bounds and
    /// the kept initial values of parameters it does not have are dropped (the nuisance and
    /// oscillator bounds are kept), as `compare` fits every model with one set of options.
    pub fn for_model(&self, names: &[String]) -> Self {
        let other_keys = non_model_bound_keys();
        let mut o = self.clone();
        o.free = self
            .free
            .as_ref()
            .map(|f| f.iter().filter(|n| names.contains(n)).cloned().collect());
        o.bounds
            .retain(|k, _| names.contains(k) || other_keys.contains(&k.as_str()));
        o.keep_initial.retain(|k| names.contains(k));
        o
    }

    /// The options of a simpler law fitted on the way (a stage, a rigid limit): every
    /// parameter the law does not fix by default free, from its data-driven guess, the
    /// model's bounds its own, the nuisance bounds kept, the oscillator fixed.
    pub fn for_simpler_law(&self) -> Self {
        let keys = non_model_bound_keys();
        Self {
            free: None,
            bounds: self
                .bounds
                .iter()
                .filter(|(k, _)| keys.contains(&k.as_str()))
                .map(|(k, b)| (k.clone(), *b))
                .collect(),
            guess: true,
            keep_initial: Vec::new(),
            oscillator: Vec::new(),
            ..self.clone()
        }
    }
}
