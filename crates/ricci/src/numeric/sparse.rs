//! Sparse linear solves with faer, the only place the library factorizes sparse matrices.
//!
//! * [`SymmetricSolver`] — symmetric matrices with a fixed pattern (lower triangle, CSC,
//!   [`LowerCsc`]): AMD ordering and the symbolic Cholesky factorization are computed once
//!   and reused for every numeric factorization (LLᵀ for positive definite matrices such as
//!   the E² and H² Hessians of the flows, LDLᵀ for the indefinite S² Hessian). The pattern
//!   in the factor's order is built once per analysis (`Permuted`), so a numeric
//!   factorization only scatters the values into it.
//!   Single-threaded factorization (docs/DESIGN.md §2 measured no gain from two threads on this
//!   machine).
//! * [`SparseLu`] — general square matrices assembled from triplets with the same pattern at
//!   every call: the symbolic LU analysis is computed once.
//! * [`Cholesky`] — one-shot sparse Cholesky LLᵀ of a symmetric positive definite matrix
//!   assembled from triplets (faer's supernodal factorization), solved for several
//!   right-hand sides.
//!
//! faer's dense kernels inside these factorizations leave the upper halves of the AVX
//! registers dirty; every factorization and solve here ends with `vzeroupper`
//! ([`super::simd`]), so callers never have to.

use crate::error::{Error, Result};
use faer::dyn_stack::{MemBuffer, MemStack, StackReq};
use faer::linalg::cholesky::ldlt::factor::LdltRegularization;
use faer::linalg::cholesky::llt::factor::LltRegularization;
use faer::perm::PermRef;
use faer::sparse::linalg::cholesky::{
    factorize_symbolic_cholesky, supernodal, CholeskySymbolicParams, LdltRef, LltRef,
    SymbolicCholesky, SymbolicCholeskyRaw, SymmetricOrdering,
};
use faer::sparse::linalg::SupernodalThreshold;
use faer::sparse::{SparseColMatRef, SymbolicSparseColMatRef};
use faer::{Conj, MatMut, Par, Side};

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Factored {
    None,
    Llt,
    Ldlt,
}

/// The pattern of the lower triangle of a symmetric `n × n` matrix in compressed sparse
/// columns: the rows of column `j` are `row_idx[col_ptr[j]..col_ptr[j + 1]]`, and a matrix
/// with this pattern is given by its values in the same order.
#[derive(Debug, Clone, Copy)]
pub struct LowerCsc<'a> {
    pub n: usize,
    pub col_ptr: &'a [u32],
    pub row_idx: &'a [u32],
}

/// The matrix with lower-triangle pattern `(col_ptr, row_idx)` and `values` (checked by
/// [`SymmetricSolver::new`] and the callers).
fn lower<'a>(
    n: usize,
    col_ptr: &'a [u32],
    row_idx: &'a [u32],
    values: &'a [f64],
) -> SparseColMatRef<'a, u32, f64> {
    SparseColMatRef::new(
        SymbolicSparseColMatRef::new_checked(n, n, col_ptr, None, row_idx),
        values,
    )
}

/// Always the supernodal factorization (faer's default picks simplicial below 40 flops per
/// factor nonzero). The Hessians of the conformal flow on meshes of 35–50 k vertices lie near
/// that switch and, as their pattern grows with the flips, went simplicial or supernodal from
/// one Newton step to the next; supernodal was the faster there, and for the Laplacian of the
/// cone placement (`ricci param --cones 8 --seams free`, seahorse2_100K and camel: 3–5 % less
/// CPU time for the whole command than faer's default, 2 % less than a switch at 20;
/// BENCHMARKS.md, session 14 spd16). Both are exact factorizations of the same matrix.
const SUPERNODAL_THRESHOLD: SupernodalThreshold = SupernodalThreshold::FORCE_SUPERNODAL;

/// The lower triangle of the permuted matrix `P A Pᵀ` in the factor's order (columns with
/// unsorted rows, as the supernodal factorization reads them), and where each of `A`'s
/// lower-triangle values goes in it: built once per pattern, so a factorization only scatters
/// the values (faer's own route permutes the whole pattern every time).
struct Permuted {
    col_ptr: Vec<u32>,
    row_idx: Vec<u32>,
    /// `slot[k]`: position in `values` of `A`'s `k`-th stored value.
    slot: Vec<u32>,
    values: Vec<f64>,
}

impl Permuted {
    /// `inverse[i]`: the position of original index `i` (identity when `None`).
    fn new(n: usize, col_ptr: &[u32], row_idx: &[u32], inverse: Option<&[u32]>) -> Permuted {
        let at = |i: u32| inverse.map_or(i, |p| p[i as usize]);
        let nnz = row_idx.len();
        // Entry (r, c) of the lower triangle goes to column min(P r, P c), row max.
        let mut count = vec![0u32; n + 1];
        for c in 0..n {
            let pc = at(c as u32);
            for &r in &row_idx[col_ptr[c] as usize..col_ptr[c + 1] as usize] {
                count[pc.min(at(r)) as usize + 1] += 1;
            }
        }
        for j in 0..n {
            count[j + 1] += count[j];
        }
        let out_ptr = count.clone();
        let mut out_row = vec![0u32; nnz];
        let mut slot = vec![0u32; nnz];
        for c in 0..n {
            let pc = at(c as u32);
            for k in col_ptr[c] as usize..col_ptr[c + 1] as usize {
                let pr = at(row_idx[k]);
                let j = pc.min(pr) as usize;
                let s = count[j];
                count[j] += 1;
                out_row[s as usize] = pc.max(pr);
                slot[k] = s;
            }
        }
        Permuted {
            col_ptr: out_ptr,
            row_idx: out_row,
            slot,
            values: vec![0.0; nnz],
        }
    }

    /// The permuted matrix with `A`'s lower-triangle `values` (in `A`'s pattern order).
    fn matrix(&mut self, n: usize, values: &[f64]) -> SparseColMatRef<'_, u32, f64> {
        for (&s, &v) in self.slot.iter().zip(values) {
            self.values[s as usize] = v;
        }
        SparseColMatRef::new(
            SymbolicSparseColMatRef::new_unsorted_checked(n, n, &self.col_ptr, None, &self.row_idx),
            &self.values,
        )
    }
}

/// A reusable sparse symmetric factorization for one sparsity pattern (lower triangle).
pub struct SymmetricSolver {
    n: usize,
    col_ptr: Vec<u32>,
    row_idx: Vec<u32>,
    symbolic: SymbolicCholesky<u32>,
    /// The pattern in the factor's order (supernodal analyses; `None`: faer's own route).
    permuted: Option<Permuted>,
    l_values: Vec<f64>,
    mem: MemBuffer,
    factored: Factored,
    /// Number of nonzeros of the factor (for reports).
    pub factor_nnz: usize,
}

impl SymmetricSolver {
    /// Symbolic analysis (AMD ordering, elimination tree, supernodes) of `pattern` (a
    /// [`LowerCsc`], or anything that converts to one, such as a Hessian pattern).
    pub fn new<'a>(pattern: impl Into<LowerCsc<'a>>) -> Result<SymmetricSolver> {
        SymmetricSolver::analyse(pattern.into(), None)
    }

    /// As [`SymmetricSolver::new`] with a given fill-reducing permutation instead of a new
    /// AMD ordering (`forward[i]`: the original index at position `i`; `inverse` its
    /// inverse), typically [`SymmetricSolver::ordering`] of a solver for a slightly smaller
    /// pattern: the AMD ordering is most of the symbolic analysis, and a pattern that grew
    /// by a few entries is still ordered well by its predecessor's permutation.
    pub fn with_ordering<'a>(
        pattern: impl Into<LowerCsc<'a>>,
        forward: &[u32],
        inverse: &[u32],
    ) -> Result<SymmetricSolver> {
        let pattern = pattern.into();
        let n = pattern.n;
        let valid = forward.len() == n
            && inverse.len() == n
            && forward
                .iter()
                .enumerate()
                .all(|(i, &p)| (p as usize) < n && inverse[p as usize] as usize == i);
        if !valid {
            return Err(Error::numerical(format!(
                "the ordering is not a permutation of 0..{n} with its inverse"
            )));
        }
        SymmetricSolver::analyse(pattern, Some((forward, inverse)))
    }

    /// The fill-reducing permutation of the symbolic analysis as `(forward, inverse)`
    /// (`None` when faer kept the identity).
    pub fn ordering(&self) -> Option<(Vec<u32>, Vec<u32>)> {
        let (f, i) = self.symbolic.perm()?.arrays();
        Some((f.to_vec(), i.to_vec()))
    }

    fn analyse(
        pattern: LowerCsc<'_>,
        ordering: Option<(&[u32], &[u32])>,
    ) -> Result<SymmetricSolver> {
        let n = pattern.n;
        if pattern.col_ptr.len() != n + 1
            || pattern.col_ptr[n] as usize != pattern.row_idx.len()
            || pattern.col_ptr.windows(2).any(|w| w[0] > w[1])
            || pattern.row_idx.iter().any(|&r| r as usize >= n)
        {
            return Err(Error::numerical(format!(
                "the sparse pattern is not a valid {n}×{n} CSC pattern"
            )));
        }
        let col_ptr = pattern.col_ptr.to_vec();
        let row_idx = pattern.row_idx.to_vec();
        let sym = SymbolicSparseColMatRef::new_checked(n, n, &col_ptr, None, &row_idx);
        let order = match ordering {
            Some((f, i)) => SymmetricOrdering::Custom(PermRef::new_checked(f, i, n)),
            None => SymmetricOrdering::Amd,
        };
        let symbolic = factorize_symbolic_cholesky(
            sym,
            Side::Lower,
            order,
            CholeskySymbolicParams {
                supernodal_flop_ratio_threshold: SUPERNODAL_THRESHOLD,
                ..Default::default()
            },
        )
        .map_err(|e| Error::numerical(format!("symbolic Cholesky factorization failed: {e:?}")))?;
        let par = Par::Seq;
        let req = StackReq::any_of(&[
            symbolic.factorize_numeric_llt_scratch::<f64>(par, Default::default()),
            symbolic.factorize_numeric_ldlt_scratch::<f64>(par, Default::default()),
            symbolic.solve_in_place_scratch::<f64>(1, par),
        ]);
        let mem = MemBuffer::try_new(req)
            .map_err(|_| Error::numerical("out of memory for the Cholesky workspace"))?;
        let len = symbolic.len_val();
        let permuted = match symbolic.raw() {
            SymbolicCholeskyRaw::Supernodal(_) => Some(Permuted::new(
                n,
                &col_ptr,
                &row_idx,
                symbolic.perm().map(|p| p.arrays().1),
            )),
            SymbolicCholeskyRaw::Simplicial(_) => None,
        };
        Ok(SymmetricSolver {
            n,
            col_ptr,
            row_idx,
            symbolic,
            permuted,
            l_values: vec![0.0; len],
            mem,
            factored: Factored::None,
            factor_nnz: len,
        })
    }

    /// Numeric LLᵀ factorization of the matrix with the pattern's lower-triangle `values`.
    /// Returns false if the matrix is not numerically positive definite (or `values` does not
    /// fit the pattern).
    pub fn factor_llt(&mut self, values: &[f64]) -> bool {
        if values.len() != self.row_idx.len() {
            self.factored = Factored::None;
            return false;
        }
        let stack = MemStack::new(&mut self.mem);
        let ok = match (&mut self.permuted, self.symbolic.raw()) {
            (Some(p), SymbolicCholeskyRaw::Supernodal(sym)) => {
                supernodal::factorize_supernodal_numeric_llt(
                    &mut self.l_values,
                    p.matrix(self.n, values),
                    LltRegularization::default(),
                    sym,
                    Par::Seq,
                    stack,
                    Default::default(),
                )
                .is_ok()
            }
            _ => self
                .symbolic
                .factorize_numeric_llt(
                    &mut self.l_values,
                    lower(self.n, &self.col_ptr, &self.row_idx, values),
                    Side::Lower,
                    LltRegularization::default(),
                    Par::Seq,
                    stack,
                    Default::default(),
                )
                .is_ok(),
        };
        super::simd::clear_upper_state_here();
        self.factored = if ok { Factored::Llt } else { Factored::None };
        ok
    }

    /// Numeric LDLᵀ factorization (symmetric indefinite, no pivoting beyond the fill-reducing
    /// ordering). Returns false on a zero pivot.
    pub fn factor_ldlt(&mut self, values: &[f64]) -> bool {
        if values.len() != self.row_idx.len() {
            self.factored = Factored::None;
            return false;
        }
        let stack = MemStack::new(&mut self.mem);
        let ok = match (&mut self.permuted, self.symbolic.raw()) {
            (Some(p), SymbolicCholeskyRaw::Supernodal(sym)) => {
                supernodal::factorize_supernodal_numeric_ldlt(
                    &mut self.l_values,
                    p.matrix(self.n, values),
                    LdltRegularization::default(),
                    sym,
                    Par::Seq,
                    stack,
                    Default::default(),
                )
                .is_ok()
            }
            _ => self
                .symbolic
                .factorize_numeric_ldlt(
                    &mut self.l_values,
                    lower(self.n, &self.col_ptr, &self.row_idx, values),
                    Side::Lower,
                    LdltRegularization::default(),
                    Par::Seq,
                    stack,
                    Default::default(),
                )
                .is_ok(),
        };
        super::simd::clear_upper_state_here();
        self.factored = if ok { Factored::Ldlt } else { Factored::None };
        ok && self.l_values.iter().all(|x| x.is_finite())
    }

    /// Solve in place with the last factorization.
    pub fn solve(&mut self, rhs: &mut [f64]) {
        debug_assert_eq!(rhs.len(), self.n);
        let stack = MemStack::new(&mut self.mem);
        let x = MatMut::from_column_major_slice_mut(rhs, self.n, 1);
        match self.factored {
            Factored::Llt => LltRef::new(&self.symbolic, &self.l_values).solve_in_place_with_conj(
                Conj::No,
                x,
                Par::Seq,
                stack,
            ),
            Factored::Ldlt => LdltRef::new(&self.symbolic, &self.l_values)
                .solve_in_place_with_conj(Conj::No, x, Par::Seq, stack),
            Factored::None => {}
        }
        super::simd::clear_upper_state_here();
    }
}

/// A sparse LU factorization of square matrices assembled from triplets, with the symbolic
/// analysis (ordering, elimination structure) computed at the first factorization and reused
/// while the triplets keep the same pattern in the same order.
#[derive(Default)]
pub struct SparseLu {
    symbolic: Option<faer::sparse::linalg::solvers::SymbolicLu<u32>>,
    lu: Option<faer::sparse::linalg::solvers::Lu<u32, f64>>,
}

impl SparseLu {
    pub fn new() -> SparseLu {
        SparseLu::default()
    }

    /// Factorize the `n × n` matrix with entries `(row, col, value)` (duplicates are summed).
    /// Returns false when the matrix cannot be assembled or is numerically singular.
    pub fn factor(&mut self, n: usize, triplets: &[faer::sparse::Triplet<u32, u32, f64>]) -> bool {
        use faer::sparse::linalg::solvers::{Lu, SymbolicLu};
        self.lu = None;
        let Ok(a) = faer::sparse::SparseColMat::<u32, f64>::try_new_from_triplets(n, n, triplets)
        else {
            return false;
        };
        if self.symbolic.is_none() {
            self.symbolic = SymbolicLu::try_new(a.symbolic()).ok();
        }
        let Some(symbolic) = self.symbolic.clone() else {
            return false;
        };
        self.lu = Lu::try_new_with_symbolic(symbolic, a.as_ref()).ok();
        super::simd::clear_upper_state();
        self.lu.is_some()
    }

    /// Solve in place with the last factorization (no-op without one).
    pub fn solve(&self, x: &mut [f64]) {
        use faer::linalg::solvers::SolveCore;
        if let Some(lu) = &self.lu {
            let n = x.len();
            lu.solve_in_place_with_conj(Conj::No, MatMut::from_column_major_slice_mut(x, n, 1));
            super::simd::clear_upper_state();
        }
    }
}

/// A one-shot sparse Cholesky factorization LLᵀ (LLᴴ for complex `T`) of a symmetric (Hermitian)
/// positive definite matrix (faer's supernodal factorization, which may run dense kernels on
/// the pool's threads).
pub struct Cholesky<T: faer::traits::ComplexField = f64> {
    llt: faer::sparse::linalg::solvers::Llt<usize, T>,
}

impl<T: faer::traits::ComplexField> Cholesky<T> {
    /// Factorize `a` (its lower triangle is read); the error is faer's, for the caller's
    /// message (the matrix is not numerically positive definite).
    pub fn factor(
        a: faer::sparse::SparseColMatRef<'_, usize, T>,
    ) -> std::result::Result<Cholesky<T>, faer::sparse::linalg::LltError> {
        let llt = a.sp_cholesky(Side::Lower);
        super::simd::clear_upper_state();
        Ok(Cholesky { llt: llt? })
    }

    /// Solve in place for the columns of `rhs`.
    pub fn solve_in_place(&self, rhs: faer::MatMut<'_, T>) {
        use faer::linalg::solvers::Solve;
        self.llt.solve_in_place(rhs);
        super::simd::clear_upper_state();
    }
}

/// The lower triangle of a symmetric `n × n` matrix summed from dense blocks on sets of indices
/// (finite-element assembly): the pattern — every pair of one set, and the diagonal — is built
/// once from the sets, then every block's values are added at their places. Memory stays the
/// size of the pattern (a triplet per pair and block held genus3's T-spline fit at 25 MB per
/// solve, a triplet per pair and data point at 0.9 GB).
pub struct BlockAssembly {
    col_ptr: Vec<usize>,
    row_idx: Vec<usize>,
    vals: Vec<f64>,
    /// Values added outside the pattern (a caller's error; [`Self::matrix`] refuses them).
    outside: usize,
}

impl BlockAssembly {
    /// The pattern of the sets `sets` (indices `< n`; one set's pairs are its block's entries).
    pub fn new<'a>(n: usize, sets: impl IntoIterator<Item = &'a [u32]>) -> BlockAssembly {
        let mut cols: Vec<Vec<u32>> = (0..n as u32).map(|j| vec![j]).collect();
        for set in sets {
            for &r in set {
                for &q in set.iter().filter(|&&q| q < r) {
                    if let Some(c) = cols.get_mut(q as usize) {
                        c.push(r);
                    }
                }
            }
        }
        let mut col_ptr = Vec::with_capacity(n + 1);
        let mut row_idx = Vec::new();
        col_ptr.push(0);
        for mut c in cols {
            c.sort_unstable();
            c.dedup();
            row_idx.extend(c.iter().map(|&r| r as usize));
            col_ptr.push(row_idx.len());
        }
        let vals = vec![0.0; row_idx.len()];
        BlockAssembly {
            col_ptr,
            row_idx,
            vals,
            outside: 0,
        }
    }

    /// Adds `v` to entry `(r, q)` (and so to `(q, r)`: only the lower triangle is stored).
    pub fn add(&mut self, r: u32, q: u32, v: f64) {
        let (r, q) = (r.max(q) as usize, r.min(q) as usize);
        let Some(&[a, b]) = self.col_ptr.get(q..q + 2) else {
            self.outside += 1;
            return;
        };
        match self.row_idx[a..b].binary_search(&r) {
            Ok(k) => self.vals[a + k] += v,
            Err(_) => self.outside += 1,
        }
    }

    /// The lower triangle in compressed columns, or the number of values added outside the
    /// pattern.
    pub fn matrix(&self) -> std::result::Result<SparseColMatRef<'_, usize, f64>, usize> {
        if self.outside > 0 {
            return Err(self.outside);
        }
        let n = self.col_ptr.len() - 1;
        let sym = SymbolicSparseColMatRef::new_checked(n, n, &self.col_ptr, None, &self.row_idx);
        Ok(SparseColMatRef::new(sym, &self.vals))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use faer::sparse::Triplet;

    /// Tridiagonal `A = tridiag(−1, d(i), −1)` of size `n`: lower-triangle CSC pattern and
    /// values.
    fn tridiagonal(n: usize, d: impl Fn(usize) -> f64) -> (Vec<u32>, Vec<u32>, Vec<f64>) {
        let (mut col_ptr, mut row_idx, mut values) = (vec![0u32], Vec::new(), Vec::new());
        for j in 0..n {
            row_idx.push(j as u32);
            values.push(d(j));
            if j + 1 < n {
                row_idx.push(j as u32 + 1);
                values.push(-1.0);
            }
            col_ptr.push(row_idx.len() as u32);
        }
        (col_ptr, row_idx, values)
    }

    /// `A x` for the tridiagonal matrix.
    fn apply(d: impl Fn(usize) -> f64, x: &[f64]) -> Vec<f64> {
        let n = x.len();
        (0..n)
            .map(|i| {
                let l = if i > 0 { x[i - 1] } else { 0.0 };
                let r = if i + 1 < n { x[i + 1] } else { 0.0 };
                d(i) * x[i] - l - r
            })
            .collect()
    }

    fn max_error(x: &[f64], y: &[f64]) -> f64 {
        x.iter()
            .zip(y)
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f64::max)
    }

    #[test]
    fn symmetric_solver_reuses_its_analysis_for_definite_and_indefinite_matrices() {
        let n = 50;
        let want: Vec<f64> = (0..n).map(|i| (i as f64 * 0.37).sin()).collect();
        let (col_ptr, row_idx, _) = tridiagonal(n, |_| 0.0);
        let mut s = SymmetricSolver::new(LowerCsc {
            n,
            col_ptr: &col_ptr,
            row_idx: &row_idx,
        })
        .unwrap();
        // Positive definite (diagonal 2.5 > 2), then indefinite (diagonal ±3, eigenvalues of
        // both signs, pivots away from 0) with the same symbolic factorization.
        let definite = |_: usize| 2.5;
        let indefinite = |i: usize| if i.is_multiple_of(2) { 3.0 } else { -3.0 };
        let (_, _, values) = tridiagonal(n, definite);
        assert!(s.factor_llt(&values));
        let mut x = apply(definite, &want);
        s.solve(&mut x);
        let err = max_error(&x, &want);
        assert!(err < 1e-12, "definite: error {err}");
        let (_, _, values) = tridiagonal(n, indefinite);
        assert!(s.factor_ldlt(&values));
        let mut x = apply(indefinite, &want);
        s.solve(&mut x);
        let err = max_error(&x, &want);
        assert!(err < 1e-12, "indefinite: error {err}");
        // LLᵀ refuses the indefinite matrix; a wrong number of values is refused too.
        assert!(!s.factor_llt(&values));
        assert!(!s.factor_llt(&values[1..]));
        // An invalid pattern is an error, not a panic.
        let bad = LowerCsc {
            n: 3,
            col_ptr: &[0, 1, 2],
            row_idx: &[0, 1],
        };
        assert!(SymmetricSolver::new(bad).is_err());
    }

    #[test]
    fn a_given_ordering_is_used_and_bad_orderings_are_refused() {
        let n = 40;
        let d = |i: usize| 2.2 + (i % 3) as f64 * 0.1;
        let want: Vec<f64> = (0..n).map(|i| (i as f64 * 0.61).cos()).collect();
        let (col_ptr, row_idx, values) = tridiagonal(n, d);
        let pattern = LowerCsc {
            n,
            col_ptr: &col_ptr,
            row_idx: &row_idx,
        };
        // A scrambled ordering (i ↦ 7i mod 40 is a bijection): the solve must still be exact,
        // and the solver must report the ordering it was given.
        let forward: Vec<u32> = (0..n as u32).map(|i| (7 * i) % n as u32).collect();
        let mut inverse = vec![0u32; n];
        for (i, &p) in forward.iter().enumerate() {
            inverse[p as usize] = i as u32;
        }
        let mut s = SymmetricSolver::with_ordering(pattern, &forward, &inverse).unwrap();
        assert_eq!(s.ordering(), Some((forward.clone(), inverse.clone())));
        assert!(s.factor_llt(&values));
        let mut x = apply(d, &want);
        s.solve(&mut x);
        let err = max_error(&x, &want);
        assert!(err < 1e-12, "scrambled ordering: error {err}");
        // The ordering of an AMD analysis, reused, gives the same solve.
        let amd = SymmetricSolver::new(pattern).unwrap();
        let (f, i) = amd.ordering().unwrap();
        let mut s = SymmetricSolver::with_ordering(pattern, &f, &i).unwrap();
        assert!(s.factor_llt(&values));
        let mut x = apply(d, &want);
        s.solve(&mut x);
        assert!(max_error(&x, &want) < 1e-12);
        // Not a permutation, or not its inverse, or the wrong length: errors, not panics.
        let mut twice = forward.clone();
        twice[1] = twice[0];
        assert!(SymmetricSolver::with_ordering(pattern, &twice, &inverse).is_err());
        assert!(SymmetricSolver::with_ordering(pattern, &forward, &forward).is_err());
        assert!(SymmetricSolver::with_ordering(pattern, &forward[1..], &inverse).is_err());
    }

    #[test]
    fn sparse_lu_and_cholesky_solve_their_systems() {
        // Non-symmetric 3×3: A = [[4, 1, 0], [2, 5, 1], [0, 3, 6]], x = (1, −2, 3).
        let a = [[4.0, 1.0, 0.0], [2.0, 5.0, 1.0], [0.0, 3.0, 6.0]];
        let want = [1.0, -2.0, 3.0];
        let b: Vec<f64> = (0..3)
            .map(|i| (0..3).map(|j| a[i][j] * want[j]).sum())
            .collect();
        let trip: Vec<Triplet<u32, u32, f64>> = (0..3)
            .flat_map(|i| (0..3).map(move |j| (i, j)))
            .filter(|&(i, j)| a[i][j] != 0.0)
            .map(|(i, j)| Triplet::new(i as u32, j as u32, a[i][j]))
            .collect();
        let mut lu = SparseLu::new();
        for _ in 0..2 {
            assert!(lu.factor(3, &trip));
            let mut x = b.clone();
            lu.solve(&mut x);
            for k in 0..3 {
                assert!((x[k] - want[k]).abs() < 1e-14, "{x:?}");
            }
        }
        // Cholesky of the SPD tridiagonal matrix, two right-hand sides.
        let n = 20;
        let (col_ptr, row_idx, values) = tridiagonal(n, |_| 3.0);
        let mut t = Vec::new();
        for j in 0..n {
            for k in col_ptr[j] as usize..col_ptr[j + 1] as usize {
                let i = row_idx[k] as usize;
                t.push(Triplet::new(i, j, values[k]));
                if i != j {
                    t.push(Triplet::new(j, i, values[k]));
                }
            }
        }
        let m = faer::sparse::SparseColMat::<usize, f64>::try_new_from_triplets(n, n, &t).unwrap();
        let c = Cholesky::factor(m.as_ref()).unwrap();
        let xs: [Vec<f64>; 2] = [
            (0..n).map(|i| i as f64).collect(),
            (0..n).map(|i| (i as f64).cos()).collect(),
        ];
        let mut rhs = faer::Mat::<f64>::zeros(n, 2);
        for (c, x) in xs.iter().enumerate() {
            for (i, v) in apply(|_| 3.0, x).into_iter().enumerate() {
                rhs[(i, c)] = v;
            }
        }
        c.solve_in_place(rhs.as_mut());
        for (c, x) in xs.iter().enumerate() {
            for i in 0..n {
                assert!((rhs[(i, c)] - x[i]).abs() < 1e-12);
            }
        }
    }

    /// Blocks on overlapping index sets: the assembled lower triangle equals faer's triplet
    /// assembly of the same blocks (independently summed), and a value outside is refused.
    #[test]
    fn block_assembly_sums_blocks_like_triplets() {
        let sets: [&[u32]; 4] = [&[0, 3, 5], &[5, 1, 3], &[2], &[4, 0, 1, 3]];
        let value = |k: usize, a: u32, b: u32| {
            1.0 + k as f64 + 0.1 * (a * b) as f64 + 0.01 * (a + b) as f64
        };
        let mut asm = BlockAssembly::new(6, sets.iter().copied());
        let mut t = Vec::new();
        for (k, set) in sets.iter().enumerate() {
            for &a in set.iter() {
                for &b in set.iter() {
                    t.push(Triplet::new(a as usize, b as usize, value(k, a, b)));
                    if a >= b {
                        asm.add(a, b, value(k, a, b));
                    }
                }
            }
        }
        let full =
            faer::sparse::SparseColMat::<usize, f64>::try_new_from_triplets(6, 6, &t).unwrap();
        let m = asm.matrix().unwrap();
        let dense = |i: usize, j: usize| {
            let (i, j) = (i.max(j), i.min(j));
            let (a, b) = (m.symbolic().col_ptr()[j], m.symbolic().col_ptr()[j + 1]);
            (a..b)
                .find(|&k| m.symbolic().row_idx()[k] == i)
                .map_or(0.0, |k| m.val()[k])
        };
        for i in 0..6 {
            for j in 0..6 {
                let want = full.as_ref().get(i, j).copied().unwrap_or(0.0);
                assert!(
                    (dense(i, j) - want).abs() < 1e-14,
                    "({i}, {j}): {} vs {want}",
                    dense(i, j)
                );
            }
        }
        // rows 2 and 4 share no set: outside the pattern
        asm.add(4, 2, 1.0);
        assert_eq!(asm.matrix().err(), Some(1));
    }
}
