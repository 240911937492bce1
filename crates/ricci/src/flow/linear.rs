//! Sparse symmetric solves for Newton's method with faer: AMD ordering and the symbolic
//! Cholesky factorization are computed once from the Hessian's pattern and reused for every
//! numeric factorization (LLᵀ for the positive definite E² and H² Hessians, LDLᵀ for the
//! indefinite S² Hessian). Single-threaded factorization (DESIGN.md §2 measured no gain from
//! two threads on this machine).

use crate::error::{Error, Result};
use crate::metric::HessianPattern;
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
    /// Symbolic analysis (AMD ordering, elimination tree, supernodes) of `pattern`.
    pub fn new(pattern: &HessianPattern) -> Result<SymmetricSolver> {
        let n = pattern.n();
        let col_ptr = pattern.col_ptr.clone();
        let row_idx = pattern.row_idx.clone();
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
        crate::simd::clear_upper_state_here();
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
        crate::simd::clear_upper_state_here();
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
        crate::simd::clear_upper_state_here();
    }
}
