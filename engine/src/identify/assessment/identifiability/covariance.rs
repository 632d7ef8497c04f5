//! The covariance of the parameters the records determine.

use super::Standing;
use crate::identify::assessment::stats::{covariance, Covariance};
use nalgebra::DMatrix;

/// The covariance of the determined parameters, marginal over every undetermined parameter
/// whose column keeps JᵀJ invertible (a Stribeck velocity the records leave flat trades with
/// the levels: holding it fixed would understate their errors) and conditional on the rest
/// (a stiffness run to its rigid limit has a vanishing column). The undetermined parameters'
/// rows and columns come back as NaN.
pub fn covariance_of_determined(
    jac: &DMatrix<f64>,
    ssr: f64,
    standings: &[Standing],
) -> Covariance {
    let determined = |j: usize| standings.get(j).is_none_or(Standing::determined);
    let mut keep: Vec<usize> = (0..jac.ncols()).filter(|&j| determined(j)).collect();
    if keep.len() == jac.ncols() {
        return covariance(jac, ssr);
    }
    for j in (0..jac.ncols()).filter(|&j| !determined(j)) {
        let mut with = keep.clone();
        with.push(j);
        with.sort_unstable();
        let cov = covariance(&jac.select_columns(&with), ssr);
        if !cov.singular && cov.std_errors.iter().all(|s| s.is_finite()) {
            keep = with;
        }
    }
    let reduced = covariance(&jac.select_columns(&keep), ssr);
    let p = jac.ncols();
    let mut matrix = DMatrix::from_element(p, p, f64::NAN);
    let mut correlation = DMatrix::from_element(p, p, f64::NAN);
    let mut std_errors = vec![f64::NAN; p];
    let shown: Vec<(usize, usize)> = keep
        .iter()
        .enumerate()
        .filter(|(_, &j)| determined(j))
        .map(|(a, &j)| (a, j))
        .collect();
    for &(a, ja) in &shown {
        std_errors[ja] = reduced.std_errors[a];
        for &(b, jb) in &shown {
            matrix[(ja, jb)] = reduced.matrix[(a, b)];
            correlation[(ja, jb)] = reduced.correlation[(a, b)];
        }
    }
    Covariance {
        matrix,
        std_errors,
        correlation,
        ..reduced
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::identify::values::result::Identifiability;

    #[test]
    fn undetermined_parameters_have_no_standard_error_and_widen_the_rest_where_they_can() {
        let flat = Standing {
            class: Identifiability::NotIdentifiable,
            bound: None,
        };
        let standings = [Standing::DETERMINED, flat];
        // A flat parameter with a column of its own: the determined one's error is marginal
        // over it. JᵀJ = [[2, 1], [1, 2]], its inverse's first entry 2/3, s² = 1 / (3 - 2).
        let traded = DMatrix::from_row_slice(3, 2, &[1.0, 0.0, 0.0, 1.0, 1.0, 1.0]);
        let cov = covariance_of_determined(&traded, 1.0, &standings);
        assert!(cov.std_errors[1].is_nan() && cov.matrix[(0, 1)].is_nan());
        assert!((cov.std_errors[0] - (2.0f64 / 3.0).sqrt()).abs() < 1e-12);
        // A flat parameter whose column vanishes (run to a limit): held where it is. One
        // column [1, 0, 1]: (JᵀJ)^-1 = 1/2, s² = 1 / (3 - 1).
        let vanished = DMatrix::from_row_slice(3, 2, &[1.0, 0.0, 0.0, 0.0, 1.0, 0.0]);
        let cov = covariance_of_determined(&vanished, 1.0, &standings);
        assert!(cov.std_errors[1].is_nan());
        assert!((cov.std_errors[0] - 0.5).abs() < 1e-12);
    }
}
