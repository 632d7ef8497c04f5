//! From information to predictions and a choice: the predicted standard errors of a set of
//! records ([`predicted_std`]), the design criteria ([`Criterion`]: D on the named
//! parameters, A on their relative variances) and the search over sets ([`choose`]:
//! exhaustive while the sets are few, greedy with exchanges otherwise).

use nalgebra::{DMatrix, SymmetricEigen};
use serde::{Deserialize, Serialize};

/// Most sets an exhaustive search evaluates; more and the search is greedy.
pub const EXHAUSTIVE_SETS: u128 = 20_000;

/// Eigenvalues of the relative information below this fraction of the largest are taken as
/// zero (a direction no record informs).
const NULL_EIGENVALUE: f64 = 1e-10;

/// What a design minimises.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize)]
pub enum Criterion {
    /// D-optimality on the named parameters: the determinant of their covariance (the
    /// volume of their confidence ellipsoid; all free parameters when none are named).
    #[default]
    D,
    /// A-optimality on the named parameters: the sum of their relative variances.
    A,
}

/// How a set was found.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum SearchKind {
    /// Every set evaluated.
    Exhaustive,
    /// Greedy additions, then exchanges while one improves the criterion.
    Greedy,
}

/// The chosen set.
#[derive(Debug, Clone, PartialEq)]
pub struct Choice {
    /// Candidate indices, ascending.
    pub indices: Vec<usize>,
    /// How it was found.
    pub search: SearchKind,
    /// Sets evaluated.
    pub evaluated: usize,
}

/// The relative information S = D F D, D = diag(|value|) (1 where a value is 0): the
/// information about ln p, in which the criteria and the rank are judged.
pub fn relative(info: &DMatrix<f64>, values: &[f64]) -> DMatrix<f64> {
    let scale: Vec<f64> = values
        .iter()
        .map(|v| if *v != 0.0 { v.abs() } else { 1.0 })
        .collect();
    DMatrix::from_fn(info.nrows(), info.ncols(), |i, j| {
        info[(i, j)] * scale[i] * scale[j]
    })
}

/// The predicted standard error of each parameter from the information `info` about
/// parameters at `values`: sqrt(diag(F^-1)), `None` for a parameter that a direction with no
/// information moves (a rank-deficient information).
pub fn predicted_std(info: &DMatrix<f64>, values: &[f64]) -> Vec<Option<f64>> {
    let n = values.len();
    let s = relative(info, values);
    if n == 0 || !s.iter().all(|x| x.is_finite()) {
        return vec![None; n];
    }
    let eig = SymmetricEigen::new(s);
    let top = eig.eigenvalues.amax();
    let mut variance = vec![0.0; n];
    let mut unreached = vec![top <= 0.0; n];
    for (k, &lambda) in eig.eigenvalues.iter().enumerate() {
        let v = eig.eigenvectors.column(k);
        if lambda <= NULL_EIGENVALUE * top {
            for (i, u) in unreached.iter_mut().enumerate() {
                *u |= v[i].abs() > 1e-3;
            }
        } else {
            for (i, var) in variance.iter_mut().enumerate() {
                *var += v[i] * v[i] / lambda;
            }
        }
    }
    (0..n)
        .map(|i| {
            let scale = if values[i] != 0.0 {
                values[i].abs()
            } else {
                1.0
            };
            (!unreached[i]).then(|| variance[i].sqrt() * scale)
        })
        .collect()
}

/// The criterion's value for information `info` (smaller is better): ln det of the
/// relative covariance of the `targets` (D) or the sum of their relative variances (A). A
/// small ridge keeps a rank-deficient information comparable (and far behind).
pub fn criterion_value(
    criterion: Criterion,
    info: &DMatrix<f64>,
    values: &[f64],
    targets: &[usize],
) -> f64 {
    let mut s = relative(info, values);
    let n = s.nrows();
    let ridge = 1e-12 * s.diagonal().amax().max(1e-300);
    for i in 0..n {
        s[(i, i)] += ridge;
    }
    let Some(cov) = s.cholesky().map(|c| c.inverse()) else {
        return f64::INFINITY;
    };
    match criterion {
        Criterion::D => {
            let block = DMatrix::from_fn(targets.len(), targets.len(), |a, b| {
                cov[(targets[a], targets[b])]
            });
            match block.cholesky() {
                Some(c) => 2.0 * c.l().diagonal().iter().map(|d| d.ln()).sum::<f64>(),
                None => f64::INFINITY,
            }
        }
        Criterion::A => targets.iter().map(|&t| cov[(t, t)]).sum(),
    }
}

/// The number of sets of `k` among `n`.
fn sets(n: usize, k: usize) -> u128 {
    let k = k.min(n - k.min(n));
    (0..k).fold(1u128, |acc, i| {
        acc.saturating_mul((n - i) as u128) / (i as u128 + 1)
    })
}

/// The set of `k` candidates (of the informations `each`, added to `base`) that minimises
/// `score`: every set while there are at most [`EXHAUSTIVE_SETS`], else greedy with
/// exchanges.
pub fn choose(
    each: &[DMatrix<f64>],
    base: &DMatrix<f64>,
    k: usize,
    score: &dyn Fn(&DMatrix<f64>) -> f64,
) -> Choice {
    let n = each.len();
    let k = k.min(n);
    let total = |set: &[usize]| set.iter().fold(base.clone(), |acc, &i| acc + &each[i]);
    if sets(n, k) <= EXHAUSTIVE_SETS {
        let mut best = (f64::INFINITY, (0..k).collect::<Vec<_>>());
        let mut evaluated = 0;
        for_each_set(n, k, &mut |set| {
            evaluated += 1;
            let value = score(&total(set));
            if value < best.0 {
                best = (value, set.to_vec());
            }
        });
        return Choice {
            indices: best.1,
            search: SearchKind::Exhaustive,
            evaluated,
        };
    }
    greedy(n, k, &total, score)
}

/// Greedy additions, then single exchanges while one improves the score.
fn greedy(
    n: usize,
    k: usize,
    total: &dyn Fn(&[usize]) -> DMatrix<f64>,
    score: &dyn Fn(&DMatrix<f64>) -> f64,
) -> Choice {
    let mut set: Vec<usize> = Vec::with_capacity(k);
    let mut evaluated = 0;
    let try_set = |s: &[usize], evaluated: &mut usize| {
        *evaluated += 1;
        score(&total(s))
    };
    while set.len() < k {
        let mut best = (f64::INFINITY, None);
        for c in (0..n).filter(|c| !set.contains(c)) {
            let mut trial = set.clone();
            trial.push(c);
            let value = try_set(&trial, &mut evaluated);
            if best.1.is_none() || value < best.0 {
                best = (value, Some(c));
            }
        }
        match best.1 {
            Some(c) => set.push(c),
            None => break,
        }
    }
    let mut current = try_set(&set, &mut evaluated);
    for _ in 0..(4 * k) {
        let mut improved = false;
        for slot in 0..set.len() {
            for c in 0..n {
                if set.contains(&c) {
                    continue;
                }
                let mut trial = set.clone();
                trial[slot] = c;
                let value = try_set(&trial, &mut evaluated);
                if value < current {
                    (current, set, improved) = (value, trial, true);
                }
            }
        }
        if !improved {
            break;
        }
    }
    set.sort_unstable();
    Choice {
        indices: set,
        search: SearchKind::Greedy,
        evaluated,
    }
}

/// Calls `f` with every ascending set of `k` indices below `n`.
fn for_each_set(n: usize, k: usize, f: &mut dyn FnMut(&[usize])) {
    let mut set: Vec<usize> = (0..k).collect();
    if k > n {
        return;
    }
    loop {
        f(&set);
        let Some(i) = (0..k).rev().find(|&i| set[i] < n - k + i) else {
            return;
        };
        set[i] += 1;
        for j in i + 1..k {
            set[j] = set[j - 1] + 1;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A diagonal information gives 1 / sqrt(F_ii); a null direction leaves its parameters
    /// unreached and the others as they are.
    #[test]
    fn standard_errors_of_full_and_deficient_information() {
        let f = DMatrix::from_diagonal(&nalgebra::DVector::from_vec(vec![4.0, 100.0]));
        let s = predicted_std(&f, &[1.0, 0.1]);
        assert!((s[0].unwrap() - 0.5).abs() < 1e-12 && (s[1].unwrap() - 0.1).abs() < 1e-12);
        let f = DMatrix::from_row_slice(3, 3, &[4.0, 0.0, 0.0, 0.0, 1.0, 1.0, 0.0, 1.0, 1.0]);
        let s = predicted_std(&f, &[1.0, 1.0, 1.0]);
        assert!((s[0].unwrap() - 0.5).abs() < 1e-9);
        assert_eq!((s[1], s[2]), (None, None));
    }

    /// Exhaustive and greedy searches find the two most informative of five records when
    /// the informations are diagonal (each record informs one parameter, or both).
    #[test]
    fn searches_pick_the_most_informative_pair() {
        let d = |a: f64, b: f64| DMatrix::from_diagonal(&nalgebra::DVector::from_vec(vec![a, b]));
        let each = vec![
            d(1.0, 0.0),
            d(0.0, 1.0),
            d(5.0, 0.0),
            d(0.0, 5.0),
            d(1.0, 1.0),
        ];
        let base = DMatrix::zeros(2, 2);
        let score = |f: &DMatrix<f64>| criterion_value(Criterion::D, f, &[1.0, 1.0], &[0, 1]);
        let exhaustive = choose(&each, &base, 2, &score);
        assert_eq!(exhaustive.indices, vec![2, 3]);
        assert_eq!(exhaustive.evaluated, 10);
        let greedy = greedy(
            5,
            2,
            &|s: &[usize]| s.iter().fold(base.clone(), |a, &i| a + &each[i]),
            &score,
        );
        assert_eq!(greedy.indices, vec![2, 3]);
        assert_eq!(sets(40, 5), 658_008);
    }
}
