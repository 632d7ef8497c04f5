//! The Gauss-Newton quantities of a Levenberg-Marquardt iteration: JᵀJ, the gradient Jᵀr and
//! Marquardt's scaling diagonal.
//!
//! The products are summed in the order nalgebra's `Jᵀ * J` sums them (the fits of laws with
//! internal states are sensitive to the last bit: a different order moved the LuGre and Dahl
//! fits of the five-model compare onto slower paths, 2.0 -> 2.6-2.9 s), without its
//! transposed copy of J: up to [`GEMV_SIZE`] columns (or rows) nalgebra sums every product in row
//! order, which [`row_order_products`] does in one pass over the rows; for more columns it
//! hands a strided view of Jᵀ to matrixmultiply's blocked product, which gives the same
//! values whatever the strides of its operands.

use nalgebra::{DMatrix, DMatrixView, DVector, Dyn};

/// Up to this many columns or rows of J nalgebra's product sums in row order (its `gemm`
/// hands larger products to matrixmultiply).
const GEMV_SIZE: usize = 5;

/// JᵀJ, Jᵀr and the scaling diagonal at the current point.
#[derive(Debug)]
pub(super) struct NormalEquations {
    pub(super) a: DMatrix<f64>,
    pub(super) g: DVector<f64>,
    pub(super) diag: Vec<f64>,
}

impl NormalEquations {
    /// The normal equations of the Jacobian `j` and residuals `r`.
    pub(super) fn new(j: &DMatrix<f64>, r: &DVector<f64>) -> Self {
        let (a, g) = match (j.nrows(), j.ncols()) {
            // One free parameter (a Coulomb mu): two dot products; no residuals: zeros.
            (0, _) | (_, 1) => (j.tr_mul(j), j.tr_mul(r)),
            (n, p) if p <= GEMV_SIZE || n <= GEMV_SIZE => row_order_products(j, r),
            _ => (transposed_view(j) * j, row_order_gradient(j, r)),
        };
        let diag: Vec<f64> = (0..a.nrows())
            .map(|i| a[(i, i)].max(1e-12 * (1.0 + a[(i, i)])))
            .collect();
        Self { a, g, diag }
    }

    /// The decrease of the cost the linear model predicts for `step`.
    pub(super) fn predicted_reduction(&self, step: &DVector<f64>) -> f64 {
        -(step.dot(&self.g)) - 0.5 * step.dot(&(&self.a * step))
    }
}

/// Jᵀ as a view of J's storage (no copy), for matrixmultiply's product (which reads it
/// through its strides).
fn transposed_view(j: &DMatrix<f64>) -> DMatrixView<'_, f64, Dyn, Dyn> {
    DMatrixView::from_slice_with_strides(j.as_slice(), j.ncols(), j.nrows(), j.nrows(), 1)
}

/// J's columns as slices.
fn columns(j: &DMatrix<f64>) -> Vec<&[f64]> {
    let n = j.nrows();
    (0..j.ncols())
        .map(|c| &j.as_slice()[c * n..(c + 1) * n])
        .collect()
}

/// Jᵀr, each entry summed over the rows in order from the first row's term, as nalgebra's
/// `gemv` sums it.
fn row_order_gradient(j: &DMatrix<f64>, r: &DVector<f64>) -> DVector<f64> {
    let columns = columns(j);
    let mut g: Vec<f64> = columns.iter().map(|column| column[0] * r[0]).collect();
    for (k, &rk) in r.iter().enumerate().skip(1) {
        for (gc, column) in g.iter_mut().zip(&columns) {
            *gc += column[k] * rk;
        }
    }
    DVector::from_vec(g)
}

/// JᵀJ and Jᵀr, each entry summed over the rows in order from the first row's term (one pass
/// over the rows), with fixed-size accumulators up to [`GEMV_SIZE`] columns.
fn row_order_products(j: &DMatrix<f64>, r: &DVector<f64>) -> (DMatrix<f64>, DVector<f64>) {
    match j.ncols() {
        2 => fixed_row_order_products::<2>(j, r),
        3 => fixed_row_order_products::<3>(j, r),
        4 => fixed_row_order_products::<4>(j, r),
        5 => fixed_row_order_products::<5>(j, r),
        _ => (j.transpose() * j, row_order_gradient(j, r)),
    }
}

/// [`row_order_products`] for `P` columns and at least one row.
fn fixed_row_order_products<const P: usize>(
    j: &DMatrix<f64>,
    r: &DVector<f64>,
) -> (DMatrix<f64>, DVector<f64>) {
    let columns = columns(j);
    let row_at = |k: usize| -> [f64; P] { std::array::from_fn(|c| columns[c][k]) };
    let first = row_at(0);
    let mut a: [[f64; P]; P] =
        std::array::from_fn(|c| std::array::from_fn(|d| first[c] * first[d]));
    let mut g: [f64; P] = std::array::from_fn(|c| first[c] * r[0]);
    for (k, &rk) in r.iter().enumerate().skip(1) {
        let row = row_at(k);
        for c in 0..P {
            for d in c..P {
                a[c][d] += row[c] * row[d];
            }
            g[c] += row[c] * rk;
        }
    }
    let jtj = DMatrix::from_fn(P, P, |c, d| a[c.min(d)][c.max(d)]);
    (jtj, DVector::from_fn(P, |c, _| g[c]))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A Jacobian whose products round differently in every summation order.
    fn jacobian(rows: usize, cols: usize) -> (DMatrix<f64>, DVector<f64>) {
        let value = |i: usize, c: usize| ((i * 7919 + c * 104_729) as f64 * 0.618_033_988_75).sin();
        let j = DMatrix::from_fn(rows, cols, |i, c| value(i, c) * 10f64.powi(c as i32 - 2));
        let r = DVector::from_fn(rows, |i, _| value(i, cols) * 3.7);
        (j, r)
    }

    /// To the bit, the products nalgebra's transposed copy gives, for every column count.
    #[test]
    fn the_products_are_those_of_the_transposed_copy_to_the_bit() {
        for cols in 1..=9 {
            for rows in [0, 1, 2, 5, 6, 17, 1000] {
                let (j, r) = jacobian(rows, cols);
                let jt = j.transpose();
                let normal = NormalEquations::new(&j, &r);
                if cols == 1 || rows == 0 {
                    assert_eq!(normal.a, j.tr_mul(&j));
                    continue;
                }
                assert_eq!(normal.a, &jt * &j, "{rows} x {cols}");
                assert_eq!(normal.g, &jt * &r, "{rows} x {cols}");
            }
        }
    }
}
