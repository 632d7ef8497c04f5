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
    pub fn new(n: usize) -> Self {
        Self {
            n,
            lu: vec![0.0; n * n],
            swaps: Vec::with_capacity(n),
            invertible: false,
        }
    }

    /// Factors E = diag I - M (`m` row-major, n x n); whether E is invertible (no zero
    /// pivot). Off the diagonal the entries are 0 - m_ij, as a caller forming E would.
    pub fn factor_shifted(&mut self, diag: f64, m: &[f64]) -> bool {
        let n = self.n;
        for (i, (row, m_row)) in self.lu.chunks_mut(n).zip(m.chunks(n)).enumerate() {
            for (j, (e, &mij)) in row.iter_mut().zip(m_row).enumerate() {
                *e = if i == j { diag } else { 0.0 } - mij;
            }
        }
        self.swaps.clear();
        match n {
            2 => self.eliminate_fixed::<2>(),
            3 => self.eliminate_fixed::<3>(),
            4 => self.eliminate_fixed::<4>(),
            5 => self.eliminate_fixed::<5>(),
            _ => self.eliminate(),
        }
        self.invertible = (0..n).all(|i| self.at(i, i) != 0.0);
        self.invertible
    }

    /// Gaussian elimination with partial pivoting of the matrix in `lu`, in place.
    fn eliminate(&mut self) {
        for i in 0..self.n {
            let piv = self.pivot_row(i);
            let diag = self.at(piv, i);
            if diag == 0.0 {
                // A zero column below the diagonal: nothing to eliminate.
                continue;
            }
            if piv != i {
                self.swaps.push((i, piv));
                self.swap_rows(i, piv);
            }
            self.eliminate_below(i, diag);
        }
    }

    /// [`SmallLu::eliminate`] for a size known when compiling: the same operations in the
    /// same order, the loops unrolled and free of bounds checks (a stiff LuGre fit spent a
    /// tenth of its time in the general loops).
    fn eliminate_fixed<const N: usize>(&mut self) {
        let lu = &mut self.lu[..N * N];
        for i in 0..N {
            let mut piv = i;
            let mut largest = lu[i * N + i].abs();
            for r in i + 1..N {
                let size = lu[r * N + i].abs();
                if size > largest {
                    largest = size;
                    piv = r;
                }
            }
            let diag = lu[piv * N + i];
            if diag == 0.0 {
                continue;
            }
            if piv != i {
                self.swaps.push((i, piv));
                for j in 0..N {
                    lu.swap(i * N + j, piv * N + j);
                }
            }
            let inv_diag = 1.0 / diag;
            for r in i + 1..N {
                lu[r * N + i] *= inv_diag;
            }
            for k in i + 1..N {
                let pivot_row_k = lu[i * N + k];
                for r in i + 1..N {
                    lu[r * N + k] -= pivot_row_k * lu[r * N + i];
                }
            }
        }
    }

    /// Solves A x = b in place (b holds x on return); leaves b unchanged when A is singular.
    pub fn solve(&self, b: &mut [f64]) {
        if !self.invertible || b.len() != self.n {
            return;
        }
        for &(i, piv) in &self.swaps {
            b.swap(i, piv);
        }
        match self.n {
            2 => substitute::<2>(&self.lu, b),
            3 => substitute::<3>(&self.lu, b),
            4 => substitute::<4>(&self.lu, b),
            5 => substitute::<5>(&self.lu, b),
            _ => {
                self.forward_substitute(b);
                self.back_substitute(b);
            }
        }
    }

    fn at(&self, i: usize, j: usize) -> f64 {
        self.lu[i * self.n + j]
    }

    /// The first row at or below `i` with the largest |a| in column `i`.
    fn pivot_row(&self, i: usize) -> usize {
        let mut best = i;
        let mut largest = self.at(i, i).abs();
        for r in i + 1..self.n {
            let size = self.at(r, i).abs();
            if size > largest {
                largest = size;
                best = r;
            }
        }
        best
    }

    fn swap_rows(&mut self, i: usize, piv: usize) {
        let n = self.n;
        for j in 0..n {
            self.lu.swap(i * n + j, piv * n + j);
        }
    }

    /// One step of Gaussian elimination below the pivot `diag` at (i, i).
    fn eliminate_below(&mut self, i: usize, diag: f64) {
        let n = self.n;
        let inv_diag = 1.0 / diag;
        for r in i + 1..n {
            self.lu[r * n + i] *= inv_diag;
        }
        for k in i + 1..n {
            let pivot_row_k = self.lu[i * n + k];
            for r in i + 1..n {
                self.lu[r * n + k] -= pivot_row_k * self.lu[r * n + i];
            }
        }
    }

    /// Solves L y = b (unit lower triangle) in place.
    fn forward_substitute(&self, b: &mut [f64]) {
        for i in 0..self.n.saturating_sub(1) {
            let coeff = b[i];
            for (r, br) in b.iter_mut().enumerate().skip(i + 1) {
                *br -= coeff * self.at(r, i);
            }
        }
    }

    /// Solves U x = y in place.
    fn back_substitute(&self, b: &mut [f64]) {
        for i in (0..self.n).rev() {
            let coeff = b[i] / self.at(i, i);
            b[i] = coeff;
            for (r, br) in b.iter_mut().enumerate().take(i) {
                *br -= coeff * self.at(r, i);
            }
        }
    }
}

/// [`SmallLu::forward_substitute`] then [`SmallLu::back_substitute`] for a size known when
/// compiling (the same operations in the same order).
fn substitute<const N: usize>(lu: &[f64], b: &mut [f64]) {
    let lu = &lu[..N * N];
    let b = &mut b[..N];
    for i in 0..N - 1 {
        let coeff = b[i];
        for r in i + 1..N {
            b[r] -= coeff * lu[r * N + i];
        }
    }
    for i in (0..N).rev() {
        let coeff = b[i] / lu[i * N + i];
        b[i] = coeff;
        for r in 0..i {
            b[r] -= coeff * lu[r * N + i];
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
