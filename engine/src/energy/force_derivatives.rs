//! The force's derivatives in a law's parameters along a replayed motion, and the rows they
//! are made of: the force's own parameter gradient plus its state gradient times the states'
//! sensitivities, however those were computed (the exact steps of `model_force`, the
//! integrated sensitivities of `integrated_sensitivities`).

use crate::record::{ConditionColumns, NormalForce};
use frictionid_models::{Derivatives, FrictionModel, ParamGradients};

/// The model's force at some samples of a replayed motion and its derivatives with respect to
/// every model parameter there
/// ([`force_derivatives_along`](crate::energy::force_derivatives_along)).
#[derive(Debug, Clone, PartialEq)]
pub struct ForceDerivatives {
    /// The force at each requested sample \[N\].
    pub force: Vec<f64>,
    /// dF/dp at each requested sample, one row of `n_params` entries per sample (parameters in
    /// `FrictionModel::params` order).
    pub gradient: Vec<f64>,
    /// For each parameter, whether its entries are given (the others' are NaN: the law has no
    /// closed form of its sensitivity).
    pub given: Vec<bool>,
}

impl ForceDerivatives {
    /// Room for the rows of `samples` samples of `np` parameters, every parameter given.
    pub(crate) fn for_samples(samples: usize, np: usize) -> Self {
        Self {
            force: Vec::with_capacity(samples),
            gradient: vec![0.0; samples * np],
            given: vec![true; np],
        }
    }

    /// The derivative of the force at requested sample `k` with respect to parameter `j`.
    pub fn at(&self, k: usize, j: usize) -> f64 {
        self.gradient[k * self.given.len() + j]
    }

    /// Each parameter's column over the first `samples` requested samples (`None` for a
    /// parameter whose entries are not given): the rows read once, in the order they are
    /// stored (a column read on its own would stride through every row of the gradient).
    pub fn columns(&self, samples: usize) -> Vec<Option<Vec<f64>>> {
        let np = self.given.len();
        let mut columns: Vec<Option<Vec<f64>>> = self
            .given
            .iter()
            .map(|&given| given.then(|| Vec::with_capacity(samples)))
            .collect();
        if np == 0 {
            return columns;
        }
        for row in self.gradient.chunks_exact(np).take(samples) {
            for (column, &entry) in columns.iter_mut().zip(row) {
                if let Some(column) = column {
                    column.push(entry);
                }
            }
        }
        columns
    }
}

/// The states and their sensitivities along a replay, and the force's derivatives from them.
pub(crate) struct SensitivityReplay<'a> {
    model: &'a dyn FrictionModel,
    gradients: &'a dyn ParamGradients,
    derivatives: Derivatives<'a>,
    pub(crate) z: Vec<f64>,
    /// dz/dp, n_states x n_params row-major.
    pub(crate) sens: Vec<f64>,
    df_dz: Vec<f64>,
}

impl<'a> SensitivityReplay<'a> {
    /// Relaxed states without sensitivities, for `np` parameters.
    pub(crate) fn new(
        model: &'a dyn FrictionModel,
        gradients: &'a dyn ParamGradients,
        derivatives: Derivatives<'a>,
        np: usize,
    ) -> Self {
        let ns = model.n_states();
        Self {
            model,
            gradients,
            derivatives,
            z: vec![0.0; ns],
            sens: vec![0.0; ns * np],
            df_dz: vec![0.0; ns],
        }
    }

    /// The force at velocity `v`, normal force `normal` and conditions `at` with the current
    /// states, its total derivatives dF/dp + dF/dz dz/dp written into `row`.
    pub(crate) fn derivatives_at(
        &mut self,
        v: f64,
        normal: f64,
        at: &[f64],
        row: &mut [f64],
    ) -> f64 {
        self.gradients
            .force_param_gradient_in(v, &self.z, normal, at, row);
        self.derivatives
            .force_gradient(v, &self.z, normal, &mut self.df_dz);
        let np = row.len();
        for (s, &d) in self.df_dz.iter().enumerate() {
            for (r, &dz) in row.iter_mut().zip(&self.sens[s * np..(s + 1) * np]) {
                *r += d * dz;
            }
        }
        self.model.force_in(v, &self.z, normal, at)
    }
}

/// A replay's samples: their velocities, normal force and the conditions the law reads.
pub(crate) struct ReplayedSamples<'a> {
    pub v: &'a [f64],
    pub normal: &'a NormalForce,
    pub conditions: &'a ConditionColumns<'a>,
}

/// Walks a replay over every sample of `at` in turn: `advance(i, replay)` moves the states
/// and their sensitivities in `replay` over the interval ending at sample i (i >= 1; `None`
/// stops the walk), and the rows of the requested `samples` (ascending) are written into
/// `out` as the walk passes them. `None` when an advance failed.
pub(crate) fn walk_rows(
    replay: &mut SensitivityReplay<'_>,
    at: ReplayedSamples<'_>,
    samples: &[usize],
    out: &mut ForceDerivatives,
    mut advance: impl FnMut(usize, &mut SensitivityReplay<'_>) -> Option<()>,
) -> Option<()> {
    let np = out.given.len();
    let mut values = vec![0.0; at.conditions.len()];
    let mut next = samples.iter().enumerate().peekable();
    for i in 0..at.v.len() {
        if i > 0 {
            advance(i, replay)?;
        }
        while let Some((k, _)) = next.next_if(|(_, &s)| s == i) {
            let row = &mut out.gradient[k * np..(k + 1) * np];
            at.conditions.fill(i, &mut values);
            out.force
                .push(replay.derivatives_at(at.v[i], at.normal.at(i), &values, row));
        }
    }
    Some(())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The columns read in one pass over the rows hold each entry as `at` gives it, for the
    /// samples asked for only, and none for a parameter whose entries are not given.
    #[test]
    fn columns_hold_each_entry_as_at_gives_it() {
        let (samples, np) = (7, 3);
        let mut d = ForceDerivatives::for_samples(samples, np);
        for (i, g) in d.gradient.iter_mut().enumerate() {
            *g = (i as f64 * 0.731).sin();
        }
        d.given[1] = false;
        let columns = d.columns(5);
        assert_eq!(columns.len(), np);
        assert_eq!(columns[1], None);
        for j in [0, 2] {
            let want: Vec<f64> = (0..5).map(|k| d.at(k, j)).collect();
            assert_eq!(columns[j].as_ref(), Some(&want), "column {j}");
        }
        assert!(ForceDerivatives::for_samples(4, 0).columns(4).is_empty());
    }
}
