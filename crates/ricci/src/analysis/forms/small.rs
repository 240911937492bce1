//! Small dense matrices (`2g × 2g`, `g × g`) of the period computations, solved with faer.

use crate::error::{Error, Result};
use faer::linalg::solvers::{DenseSolveCore, Solve};
use faer::Mat;

/// A row-major small matrix.
pub type Matrix = Vec<Vec<f64>>;

pub(crate) fn to_faer(a: &Matrix) -> Mat<f64> {
    let n = a.len();
    let m = a.first().map_or(0, |r| r.len());
    Mat::from_fn(n, m, |i, j| a[i][j])
}

pub(crate) fn from_faer(a: &Mat<f64>) -> Matrix {
    (0..a.nrows())
        .map(|i| (0..a.ncols()).map(|j| a[(i, j)]).collect())
        .collect()
}

/// `A B`.
pub fn mul(a: &Matrix, b: &Matrix) -> Matrix {
    let r = from_faer(&(to_faer(a) * to_faer(b)));
    crate::numeric::simd::clear_upper_state_here();
    r
}

/// `Aᵀ`.
pub fn transpose(a: &Matrix) -> Matrix {
    let m = a.first().map_or(0, |r| r.len());
    (0..m).map(|j| a.iter().map(|r| r[j]).collect()).collect()
}

/// `A⁻¹` by LU with partial pivoting; errors when `A` is singular to working precision.
pub fn inverse(a: &Matrix, what: &str) -> Result<Matrix> {
    let f = to_faer(a);
    let n = f.nrows();
    let lu = f.partial_piv_lu();
    let inv = lu.inverse();
    crate::numeric::simd::clear_upper_state_here();
    let r = from_faer(&inv);
    // Check A A⁻¹ = I (LU does not report singularity).
    let id = mul(a, &r);
    let err = (0..n)
        .flat_map(|i| (0..n).map(move |j| (i, j)))
        .map(|(i, j)| (id[i][j] - if i == j { 1.0 } else { 0.0 }).abs())
        .fold(0.0, f64::max);
    if err.is_nan() || err >= 1e-6 {
        return Err(Error::numerical(format!(
            "the {what} matrix is singular (‖A A⁻¹ − I‖ = {err:.1e})"
        )));
    }
    Ok(r)
}

/// Solve `A x = b`.
pub fn solve(a: &Matrix, b: &[f64]) -> Vec<f64> {
    let f = to_faer(a);
    let rhs = Mat::from_fn(b.len(), 1, |i, _| b[i]);
    let x = f.partial_piv_lu().solve(rhs);
    crate::numeric::simd::clear_upper_state_here();
    (0..b.len()).map(|i| x[(i, 0)]).collect()
}

/// The eigenvalues of a symmetric matrix, ascending.
pub fn symmetric_eigenvalues(a: &Matrix) -> Result<Vec<f64>> {
    let f = to_faer(a);
    let r = f
        .self_adjoint_eigenvalues(faer::Side::Lower)
        .map_err(|e| Error::numerical(format!("symmetric eigenvalues failed: {e:?}")));
    crate::numeric::simd::clear_upper_state_here();
    r
}

/// `max |A − B|`.
pub fn max_diff(a: &Matrix, b: &Matrix) -> f64 {
    a.iter()
        .zip(b)
        .flat_map(|(r, s)| r.iter().zip(s).map(|(x, y)| (x - y).abs()))
        .fold(0.0, f64::max)
}

/// The `n × n` identity.
pub fn identity(n: usize) -> Matrix {
    (0..n)
        .map(|i| (0..n).map(|j| f64::from(u8::from(i == j))).collect())
        .collect()
}

/// Eigenvalues (ascending) and eigenvectors (`vectors[k]` belongs to `values[k]`) of a
/// symmetric matrix.
pub fn symmetric_eigen(a: &Matrix) -> Result<(Vec<f64>, Vec<Vec<f64>>)> {
    let f = to_faer(a);
    let evd = f
        .self_adjoint_eigen(faer::Side::Lower)
        .map_err(|e| Error::numerical(format!("symmetric eigendecomposition failed: {e:?}")))?;
    let n = a.len();
    let s = evd.S().column_vector();
    let u = evd.U();
    let values = (0..n).map(|k| s[k]).collect();
    let vectors = (0..n)
        .map(|k| (0..n).map(|i| u[(i, k)]).collect())
        .collect();
    crate::numeric::simd::clear_upper_state_here();
    Ok((values, vectors))
}
