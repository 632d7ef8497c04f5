//! The Fisher information of one record about the free parameters at the assumed point:
//! J^T W J, from the velocity-domain fit's own residual Jacobian (the simulated response of
//! [`SimulatedResponse`] differentiated by [`FitProblem::jacobian_physical`], the columns a
//! fit's statistics read), W the inverse covariance of the noise (white, or AR(1) with a
//! lag-one correlation), and each record's own nuisance parameters (offset, release shift,
//! x0) marginalised out: what is left is the information about the shared parameters (the
//! law's and the oscillator's), which adds over records.

use crate::energy::EnergyOptions;
use crate::error::EngineError;
use crate::identify::problem::{FitProblem, ProblemParts, SimulatedResponse};
use crate::identify::search::build_layout;
use crate::identify::values::layout::{FreeParam, ParamKind};
use crate::identify::values::param_options::ParamOptions;
use crate::oscillator::Oscillator;
use crate::record::{Channel, Record};
use crate::simulate::SimOptions;
use frictionid_models::FrictionModel;
use nalgebra::DMatrix;
use std::sync::Arc;

/// The assumed point and what a fit would free: the law and oscillator at their assumed
/// values, the fit's parameter options (its free set and nuisance parameters) and the
/// simulation options.
pub struct Assumed<'a> {
    /// The oscillator.
    pub oscillator: Oscillator,
    /// The law at its assumed values.
    pub model: &'a (dyn FrictionModel + 'static),
    /// What a fit frees (the guess is not used: the layout starts at the assumed values).
    pub params: ParamOptions,
    /// The simulation options of the fit.
    pub sim: SimOptions,
}

/// The shared free parameters (the law's and the oscillator's) at the assumed point.
#[derive(Debug, Clone, PartialEq)]
pub struct Shared {
    /// Their layout entries (name, unit, kind).
    pub params: Vec<FreeParam>,
    /// Their assumed values.
    pub values: Vec<f64>,
}

/// A record's information about the shared parameters.
#[derive(Debug, Clone, PartialEq)]
pub struct RecordInformation {
    /// The shared parameters, in the matrix's order.
    pub shared: Shared,
    /// J^T W J with the record's nuisance parameters marginalised.
    pub matrix: DMatrix<f64>,
}

/// The information of `record` (its velocity noise level given or estimated) at the
/// assumed point, with noise of lag-one correlation `correlation`.
pub fn record_information(
    assumed: &Assumed<'_>,
    record: Record,
    correlation: f64,
) -> Result<RecordInformation, EngineError> {
    let sigma = record
        .noise_level(Channel::Velocity)
        .filter(|s| s.is_finite() && *s > 0.0)
        .ok_or_else(|| EngineError::Record {
            record: record.name.clone(),
            reason: "no velocity channel with a noise level to plan from".into(),
        })?;
    let records: Arc<[Record]> = Arc::from(vec![record]);
    let po = ParamOptions {
        guess: false,
        ..assumed.params.clone()
    };
    let residuals =
        SimulatedResponse::for_records(&records, po.velocity_offset, po.time_shift, po.x0)?;
    let layout = build_layout(
        &assumed.oscillator,
        assumed.model,
        &records,
        &residuals,
        &po,
        &EnergyOptions::default(),
    )?;
    let start = layout.start.clone();
    let problem = FitProblem::new(
        Arc::new(residuals),
        ProblemParts {
            oscillator: assumed.oscillator,
            model: layout.start_model,
            records,
            layout: layout.params.clone(),
            sim: assumed.sim,
            parallel: false,
        },
    );
    let (jacobian, _) = problem.jacobian_physical(&start)?;
    let whitened = whiten(jacobian, correlation) / sigma;
    let full = whitened.transpose() * &whitened;
    let n_shared = layout
        .params
        .iter()
        .take_while(|f| !matches!(f.kind, ParamKind::Nuisance { .. }))
        .count();
    Ok(RecordInformation {
        shared: Shared {
            params: layout.params[..n_shared].to_vec(),
            values: start[..n_shared].to_vec(),
        },
        matrix: marginal(&full, n_shared),
    })
}

/// The rows of `j` whitened for AR(1) noise of lag-one correlation `rho` (the first row as
/// it is, then (j_i - rho j_{i-1}) / sqrt(1 - rho^2)): J^T R^-1 J = W^T W.
pub fn whiten(j: DMatrix<f64>, rho: f64) -> DMatrix<f64> {
    if rho == 0.0 || j.nrows() < 2 {
        return j;
    }
    let gain = 1.0 / (1.0 - rho * rho).sqrt();
    let mut out = j.clone();
    for i in 1..j.nrows() {
        let row = (j.row(i) - j.row(i - 1) * rho) * gain;
        out.set_row(i, &row);
    }
    out
}

/// The information about the first `n` parameters of `full` with the others marginalised
/// (the Schur complement A - B C^+ B^T).
pub fn marginal(full: &DMatrix<f64>, n: usize) -> DMatrix<f64> {
    let m = full.nrows();
    if n >= m {
        return full.clone();
    }
    let a = full.view((0, 0), (n, n)).into_owned();
    let b = full.view((0, n), (n, m - n)).into_owned();
    let c = full.view((n, n), (m - n, m - n)).into_owned();
    let eps = 1e-12 * c.diagonal().amax().max(f64::MIN_POSITIVE);
    match c.pseudo_inverse(eps) {
        Ok(c_inv) => a - &b * c_inv * b.transpose(),
        Err(_) => a,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Whitening an AR(1) series' covariance gives the identity: W R W^T = I.
    #[test]
    fn whitening_inverts_the_ar1_covariance() {
        let (n, rho) = (6, 0.7);
        let r = DMatrix::from_fn(n, n, |i, j| rho_pow(rho, i.abs_diff(j)));
        let w = whiten(DMatrix::identity(n, n), rho);
        let id = &w * r * w.transpose();
        assert!((id - DMatrix::identity(n, n)).amax() < 1e-12);
    }

    fn rho_pow(rho: f64, k: usize) -> f64 {
        rho.powi(k as i32)
    }

    /// The Schur complement is the inverse of the covariance's shared block.
    #[test]
    fn marginal_information_inverts_the_covariance_block() {
        let f = DMatrix::from_row_slice(3, 3, &[4.0, 1.0, 0.5, 1.0, 3.0, 0.2, 0.5, 0.2, 2.0]);
        let cov = f.clone().try_inverse().unwrap();
        let block = cov.view((0, 0), (2, 2)).into_owned().try_inverse().unwrap();
        assert!((marginal(&f, 2) - block).amax() < 1e-12);
    }
}
