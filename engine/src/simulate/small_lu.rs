//! LU factors with partial pivoting of the small dense matrices of a stiff step (the iteration
//! matrix E = I / (gamma h) - J of Rodas4, 3 to about 20 unknowns), factored and solved in
//! buffers that live as long as the stepper.
//!
//! The operations are those of nalgebra's `LU` in the same order (its pivot choice: the first
//! largest |a| in the column; its scaling of a column by the reciprocal of the pivot; its
//! rank-one updates a_rk - a_ik l_r column by column; its triangular solves), so the results
//! are the same to the bit. What goes is the cost around them: nalgebra's dynamic matrices
//! allocate E and its factors at every step and walk views for every column, which made the
//! factor and the six solves of a Rodas4 step a quarter of a stiff LuGre fit's time.

/// LU factors of an n x n matrix, row-major, with the row swaps of the factorisation.
#[derive(Debug, Clone)]
pub(crate) struct SmallLu {
    n: usize,
    /// L below the diagonal (unit diagonal implied) and U on and above it, row-major.
    lu: Vec<f64>,
    /// Row swaps (i, pivot row) in the order they were made.
    swaps: Vec<(usize, usize)>,
    invertible: bool,
}

impl SmallLu {
    /// Room for the factors of an `n` x `n` matrix.
    pub(super) fn new(n: usize) -> Self {
        Self {
            n,
            lu: vec![0.0; n * n],
            swaps: Vec::with_capacity(n),
            invertible: false,
        }
    }

    /// Factors E = diag I - M (`m` row-major, n x n); whether E is invertible (no zero
    /// pivot). Off the diagonal the entries are 0 - m_ij, as a caller forming E would.
    /// Inlined, dispatching on `m`'s length: a caller whose slice has a size known when
    /// compiling gets the unrolled elimination of that size (a stiff LuGre fit spent a tenth
    /// of its time in the general loops); the operations and their order are the same for
    /// every size.
    #[inline(always)]
    pub(super) fn factor_shifted(&mut self, diag: f64, m: &[f64]) -> bool {
        match m.len() {
            4 => self.factor_sized(diag, m, 2),
            9 => self.factor_sized(diag, m, 3),
            16 => self.factor_sized(diag, m, 4),
            25 => self.factor_sized(diag, m, 5),
            _ => self.factor_sized(diag, m, self.n),
        }
    }

    /// [`SmallLu::factor_shifted`] for an `n` x `n` matrix (not invertible when the sizes of
    /// `m` and the factors differ from it).
    #[inline(always)]
    fn factor_sized(&mut self, diag: f64, m: &[f64], n: usize) -> bool {
        self.swaps.clear();
        self.invertible = false;
        if n == 0 || n != self.n || m.len() != n * n {
            return false;
        }
        let lu = &mut self.lu[..n * n];
        for (i, (row, m_row)) in lu.chunks_exact_mut(n).zip(m.chunks_exact(n)).enumerate() {
            for (j, (e, &mij)) in row.iter_mut().zip(m_row).enumerate() {
                *e = if i == j { diag } else { 0.0 } - mij;
            }
        }
        eliminate(lu, n, &mut self.swaps);
        self.invertible = (0..n).all(|i| lu[i * n + i] != 0.0);
        self.invertible
    }

    /// Solves A x = b in place (b holds x on return); leaves b unchanged when A is singular.
    /// Inlined, dispatching on `b`'s length: a caller whose slice has a size known when
    /// compiling gets the unrolled substitution of that size.
    #[inline(always)]
    pub(super) fn solve(&self, b: &mut [f64]) {
        if !self.invertible || b.len() != self.n {
            return;
        }
        for &(i, piv) in &self.swaps {
            b.swap(i, piv);
        }
        match b.len() {
            2 => substitute(&self.lu, 2, b),
            3 => substitute(&self.lu, 3, b),
            4 => substitute(&self.lu, 4, b),
            5 => substitute(&self.lu, 5, b),
            n => substitute(&self.lu, n, b),
        }
    }
}

/// Gaussian elimination with partial pivoting of the n x n matrix `lu` (row-major), in
/// place, recording the row swaps: for each column the first row with the largest |a| at or
/// below the diagonal, the column below scaled by the pivot's reciprocal, then the rank-one
/// update column by column.
#[inline(always)]
fn eliminate(lu: &mut [f64], n: usize, swaps: &mut Vec<(usize, usize)>) {
    let lu = &mut lu[..n * n];
    for i in 0..n {
        let mut piv = i;
        let mut largest = lu[i * n + i].abs();
        for r in i + 1..n {
            let size = lu[r * n + i].abs();
            if size > largest {
                largest = size;
                piv = r;
            }
        }
        let diag = lu[piv * n + i];
        if diag == 0.0 {
            // A zero column below the diagonal: nothing to eliminate.
            continue;
        }
        if piv != i {
            swaps.push((i, piv));
            for j in 0..n {
                lu.swap(i * n + j, piv * n + j);
            }
        }
        let inv_diag = 1.0 / diag;
        for r in i + 1..n {
            lu[r * n + i] *= inv_diag;
        }
        for k in i + 1..n {
            let pivot_row_k = lu[i * n + k];
            for r in i + 1..n {
                lu[r * n + k] -= pivot_row_k * lu[r * n + i];
            }
        }
    }
}

/// Solves L y = b (unit lower triangle) and then U x = y, in place, with the n x n factors
/// `lu`.
#[inline(always)]
fn substitute(lu: &[f64], n: usize, b: &mut [f64]) {
    let lu = &lu[..n * n];
    let b = &mut b[..n];
    for i in 0..n.saturating_sub(1) {
        let coeff = b[i];
        for r in i + 1..n {
            b[r] -= coeff * lu[r * n + i];
        }
    }
    for i in (0..n).rev() {
        let coeff = b[i] / lu[i * n + i];
        b[i] = coeff;
        for r in 0..i {
            b[r] -= coeff * lu[r * n + i];
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::{DMatrix, DVector};
    use rand::rngs::StdRng;
    use rand::{Rng, SeedableRng};

    /// Factors and solves like nalgebra's LU to the bit, on random matrices of the sizes a
    /// stiff step meets (with pivoting forced by small diagonals), and on a singular one.
    #[test]
    fn matches_nalgebra_lu_bit_for_bit() {
        let mut rng = StdRng::seed_from_u64(7);
        for n in 1..=12 {
            // 2..=5 take the unrolled paths, the others the general loops.
            for trial in 0..20 {
                let mut a: Vec<f64> = (0..n * n).map(|_| rng.random_range(-1.0..1.0)).collect();
                if trial % 2 == 0 {
                    (0..n).for_each(|i| a[i * n + i] *= 1e-3);
                }
                let b: Vec<f64> = (0..n).map(|_| rng.random_range(-1.0..1.0)).collect();
                let mut small = SmallLu::new(n);
                // E = 0 I - M with M = -A: the matrix A itself.
                let m: Vec<f64> = a.iter().map(|x| -x).collect();
                assert!(small.factor_shifted(0.0, &m));
                let mut x = b.clone();
                small.solve(&mut x);
                let reference = DMatrix::from_row_slice(n, n, &a).lu();
                assert!(reference.is_invertible());
                let mut y = DVector::from_vec(b);
                reference.solve_mut(&mut y);
                let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
                assert_eq!(bits(&x), bits(y.as_slice()), "n {n}, trial {trial}");
            }
        }
        let mut singular = SmallLu::new(2);
        assert!(!singular.factor_shifted(0.0, &[0.0, 0.0, -1.0, -1.0]));
    }
}
