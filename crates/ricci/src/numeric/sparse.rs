//! Sparse linear solves with faer, the only place the library factorizes sparse matrices.
//!
//! * [`SymmetricSolver`] — symmetric matrices with a fixed pattern (lower triangle, CSC,
//!   [`LowerCsc`]): AMD ordering and the symbolic Cholesky factorization are computed once
//!   and reused for every numeric factorization (LLᵀ for positive definite matrices such as
//!   the E² and H² Hessians of the flows, LDLᵀ for the indefinite S² Hessian).
//!   Single-threaded factorization (DESIGN.md §2 measured no gain from two threads on this
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
use faer::sparse::linalg::cholesky::{
    factorize_symbolic_cholesky, CholeskySymbolicParams, LdltRef, LltRef, SymbolicCholesky,
    SymmetricOrdering,
};
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

/// A reusable sparse symmetric factorization for one sparsity pattern (lower triangle).
pub struct SymmetricSolver {
    n: usize,
    col_ptr: Vec<u32>,
    row_idx: Vec<u32>,
    symbolic: SymbolicCholesky<u32>,
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
        let pattern = pattern.into();
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
        let symbolic = factorize_symbolic_cholesky(
            sym,
            Side::Lower,
            SymmetricOrdering::Amd,
            CholeskySymbolicParams::default(),
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
        Ok(SymmetricSolver {
            n,
            col_ptr,
            row_idx,
            symbolic,
            l_values: vec![0.0; len],
            mem,
            factored: Factored::None,
            factor_nnz: len,
        })
    }

    /// Dimension of the matrix.
    pub fn n(&self) -> usize {
        self.n
    }

    /// Numeric LLᵀ factorization of the matrix with the pattern's lower-triangle `values`.
    /// Returns false if the matrix is not numerically positive definite.
    pub fn factor_llt(&mut self, values: &[f64]) -> bool {
        let a = SparseColMatRef::new(
            SymbolicSparseColMatRef::new_checked(
                self.n,
                self.n,
                &self.col_ptr,
                None,
                &self.row_idx,
            ),
            values,
        );
        let stack = MemStack::new(&mut self.mem);
        let ok = self
            .symbolic
            .factorize_numeric_llt(
                &mut self.l_values,
                a,
                Side::Lower,
                LltRegularization::default(),
                Par::Seq,
                stack,
                Default::default(),
            )
            .is_ok();
        super::simd::clear_upper_state_here();
        self.factored = if ok { Factored::Llt } else { Factored::None };
        ok
    }

    /// Numeric LDLᵀ factorization (symmetric indefinite, no pivoting beyond the fill-reducing
    /// ordering). Returns false on a zero pivot.
    pub fn factor_ldlt(&mut self, values: &[f64]) -> bool {
        let a = SparseColMatRef::new(
            SymbolicSparseColMatRef::new_checked(
                self.n,
                self.n,
                &self.col_ptr,
                None,
                &self.row_idx,
            ),
            values,
        );
        let stack = MemStack::new(&mut self.mem);
        let ok = self
            .symbolic
            .factorize_numeric_ldlt(
                &mut self.l_values,
                a,
                Side::Lower,
                LdltRegularization::default(),
                Par::Seq,
                stack,
                Default::default(),
            )
            .is_ok();
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

/// A one-shot sparse Cholesky factorization LLᵀ of a symmetric positive definite matrix
/// (faer's supernodal factorization, which may run dense kernels on the pool's threads).
pub struct Cholesky {
    llt: faer::sparse::linalg::solvers::Llt<usize, f64>,
}

impl Cholesky {
    /// Factorize `a` (its lower triangle is read); the error is faer's, for the caller's
    /// message (the matrix is not numerically positive definite).
    pub fn factor(
        a: faer::sparse::SparseColMatRef<'_, usize, f64>,
    ) -> std::result::Result<Cholesky, faer::sparse::linalg::LltError> {
        let llt = a.sp_cholesky(Side::Lower);
        super::simd::clear_upper_state();
        Ok(Cholesky { llt: llt? })
    }

    /// Solve in place for the columns of `rhs`.
    pub fn solve_in_place(&self, rhs: faer::MatMut<'_, f64>) {
        use faer::linalg::solvers::Solve;
        self.llt.solve_in_place(rhs);
        super::simd::clear_upper_state();
    }
}
