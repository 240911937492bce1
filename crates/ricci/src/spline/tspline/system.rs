//! The normal equations of the T-spline fit over one T-mesh, assembled once per T-mesh
//! (paper 003 §3.3: `(AᵀA + λF) P = Aᵀp`, see [`super::fit`]).
//!
//! The thin-plate Gram matrix `F` depends on the T-mesh only, and the pattern of `AᵀA` lies in
//! that of `F` (two blending functions nonzero at a data point are both nonzero on the Bézier
//! element holding it, hence at its Gauss points). So [`FitSystem::new`] integrates `F` once and
//! stores it in compressed columns; every refit of a parameter-correction round only refills the
//! values of `AᵀA` on that pattern (in parallel over fixed chunks of data points, summed in
//! chunk order: the result does not depend on the number of threads) and runs the conjugate
//! gradients, warm-started from the previous control points (or, when they do not converge in
//! their budget on an ill-conditioned domain, a sparse Cholesky solve). A data pair outside the pattern
//! (possible only through rounding at element sides) widens the pattern once; nothing is lost.

use super::bezier::elements;
use super::surface::{Jet, TBasis};
use crate::error::{Error, Result};
use faer::dyn_stack::{MemBuffer, MemStack};
use faer::matrix_free::conjugate_gradient::{
    conjugate_gradient, conjugate_gradient_scratch, CgParams,
};
use faer::matrix_free::IdentityPrecond;
use faer::sparse::{SparseColMat, SparseColMatRef, SymbolicSparseColMatRef, Triplet};
use faer::{Mat, Par};
use rayon::prelude::*;

const GAUSS: [(f64, f64); 4] = [
    (0.069_431_844_202_973_71, 0.173_927_422_568_726_93),
    (0.330_009_478_207_571_87, 0.326_072_577_431_273_07),
    (0.669_990_521_792_428_1, 0.326_072_577_431_273_07),
    (0.930_568_155_797_026_3, 0.173_927_422_568_726_93),
];

/// Data points per chunk of the parallel assembly (fixed, so that the sums do not depend on
/// the number of threads).
const CHUNK: usize = 1024;

/// The fairness matrix of a T-mesh and the sparsity pattern of the fit's normal equations.
pub(crate) struct FitSystem {
    pub basis: TBasis,
    fair: SparseColMat<usize, f64>,
    tr_f: f64,
    /// Solve by sparse Cholesky without trying the conjugate gradients first: set by the
    /// caller once they failed on an earlier system of the same fit, and by [`Self::solve`]
    /// when they fail.
    pub direct: bool,
}

/// What one solve returns: the control points, CG iterations and relative residual.
pub(crate) type Solved = (Vec<[f64; 3]>, usize, f64);

/// The data term on the pattern: values of `Σ w B_i B_j`, the right-hand side `Σ w B_i p`.
struct Data {
    vals: Vec<f64>,
    rhs: Vec<[f64; 3]>,
    missing: Vec<(usize, usize)>,
}

impl FitSystem {
    /// Integrates the thin-plate Gram matrix over the Bézier elements (4×4 Gauss points each;
    /// per element the Gauss sum is taken in a dense block over the element's functions: one
    /// triplet per pair and element, not per pair and Gauss point).
    pub fn new(basis: TBasis) -> Result<FitSystem> {
        let n = basis.len();
        if n == 0 {
            return Err(Error::input("the T-mesh has no anchors"));
        }
        // elements in fixed chunks in parallel, their triplets concatenated in order
        let elems = elements(&basis);
        let fair: Vec<Triplet<usize, usize, f64>> = elems
            .par_chunks(256)
            .map(|chunk| fair_triplets(&basis, chunk))
            .collect::<Vec<_>>()
            .concat();
        let fair = assemble(n, &fair)?;
        let tr_f = diagonal(fair.as_ref()).iter().sum();
        Ok(FitSystem {
            basis,
            fair,
            tr_f,
            direct: false,
        })
    }

    /// Position of entry `(i, j)` in the values, if it is in the pattern.
    fn position(sym: SymbolicSparseColMatRef<'_, usize>, i: usize, j: usize) -> Option<usize> {
        let (a, b) = (sym.col_ptr()[j], sym.col_ptr()[j + 1]);
        sym.row_idx()[a..b].binary_search(&i).ok().map(|k| a + k)
    }

    fn data(&self, points: &[[f64; 3]], params: &[[f64; 2]], weights: &[f64]) -> Data {
        let sym = self.fair.symbolic();
        let nnz = self.fair.val().len();
        let n = self.basis.len();
        let chunks: Vec<Data> = (0..points.len().div_ceil(CHUNK))
            .into_par_iter()
            .map(|c| {
                let mut d = Data {
                    vals: vec![0.0; nnz],
                    rhs: vec![[0.0; 3]; n],
                    missing: Vec::new(),
                };
                let mut buf = Vec::new();
                for k in c * CHUNK..((c + 1) * CHUNK).min(points.len()) {
                    let (p, uv) = (points[k], params[k]);
                    let w = weights.get(k).copied().unwrap_or(1.0);
                    self.basis.eval(uv[0], uv[1], &mut buf);
                    for &(i, ji) in &buf {
                        for t in 0..3 {
                            d.rhs[i][t] += w * ji[0] * p[t];
                        }
                        for &(j, jj) in &buf {
                            match Self::position(sym, i, j) {
                                Some(q) => d.vals[q] += w * ji[0] * jj[0],
                                None => d.missing.push((i, j)),
                            }
                        }
                    }
                }
                d
            })
            .collect();
        let mut out = Data {
            vals: vec![0.0; nnz],
            rhs: vec![[0.0; 3]; n],
            missing: Vec::new(),
        };
        for d in chunks {
            out.vals.iter_mut().zip(&d.vals).for_each(|(a, b)| *a += b);
            for (a, b) in out.rhs.iter_mut().zip(&d.rhs) {
                for t in 0..3 {
                    a[t] += b[t];
                }
            }
            out.missing.extend(d.missing);
        }
        out
    }

    /// Adds the entries `pairs` (value 0 in `F`) to the pattern.
    fn widen(&mut self, pairs: &[(usize, usize)]) -> Result<()> {
        let sym = self.fair.symbolic();
        let mut trip = Vec::with_capacity(self.fair.val().len() + pairs.len());
        for j in 0..sym.ncols() {
            for q in sym.col_ptr()[j]..sym.col_ptr()[j + 1] {
                trip.push(Triplet::new(sym.row_idx()[q], j, self.fair.val()[q]));
            }
        }
        trip.extend(pairs.iter().map(|&(i, j)| Triplet::new(i, j, 0.0)));
        self.fair = assemble(self.basis.len(), &trip)?;
        Ok(())
    }

    /// Least squares with thin-plate fairness at the parameters `params`: `λ = smoothing ·
    /// tr(AᵀA)/tr(F)`, symmetric Jacobi scaling, conjugate gradients from `guess` to the
    /// relative residual `cg_tolerance`; when they do not reach it in `cg_max_iterations`,
    /// sparse Cholesky of the same system (iterations reported as `cg_max_iterations`, the
    /// residual measured), and with [`Self::direct`] sparse Cholesky only (0 iterations).
    #[allow(clippy::too_many_arguments)]
    pub fn solve(
        &mut self,
        points: &[[f64; 3]],
        params: &[[f64; 2]],
        weights: &[f64],
        smoothing: f64,
        guess: Option<&[[f64; 3]]>,
        cg_tolerance: f64,
        cg_max_iterations: usize,
    ) -> Result<Solved> {
        let n = self.basis.len();
        let mut data = self.data(points, params, weights);
        if !data.missing.is_empty() {
            let mut pairs = std::mem::take(&mut data.missing);
            pairs.sort_unstable();
            pairs.dedup();
            self.widen(&pairs)?;
            data = self.data(points, params, weights);
        }
        let sym = self.fair.symbolic();
        let data_diag = diagonal(SparseColMatRef::new(sym, &data.vals));
        let fair_diag = diagonal(self.fair.as_ref());
        let tr_a: f64 = data_diag.iter().sum();
        let lambda = if self.tr_f > 0.0 {
            smoothing * tr_a / self.tr_f
        } else {
            0.0
        };
        let diag: Vec<f64> = (0..n)
            .map(|i| data_diag[i] + lambda * fair_diag[i])
            .collect();
        if let Some(i) = diag.iter().position(|&d| !(d > 0.0)) {
            return Err(Error::numerical(format!(
                "the fitting system has an empty row for control point {i} (no data and no fairness)"
            )));
        }
        let s: Vec<f64> = diag.iter().map(|d| 1.0 / d.sqrt()).collect();
        let mut vals = data.vals;
        for j in 0..n {
            for q in sym.col_ptr()[j]..sym.col_ptr()[j + 1] {
                let i = sym.row_idx()[q];
                vals[q] = (vals[q] + lambda * self.fair.val()[q]) * s[i] * s[j];
            }
        }
        let k = SparseColMatRef::new(sym, &vals);
        let rhs = Mat::<f64>::from_fn(n, 3, |i, d| data.rhs[i][d] * s[i]);
        // unknowns y = D^{1/2} x
        let mut x = Mat::<f64>::zeros(n, 3);
        if let Some(g) = guess {
            for i in 0..n.min(g.len()) {
                for d in 0..3 {
                    x[(i, d)] = g[i][d] / s[i];
                }
            }
        }
        if self.direct {
            x = direct_solve(k, &rhs, cg_tolerance, cg_max_iterations)?;
            let resid = relative_residual(k, &x, &rhs);
            return Ok((unscale(&x, &s)?, 0, resid));
        }
        let precond = IdentityPrecond { dim: n };
        let params_cg = CgParams {
            rel_tolerance: cg_tolerance,
            max_iters: cg_max_iterations,
            ..Default::default()
        };
        let mut mem = MemBuffer::new(conjugate_gradient_scratch(precond, k, 3, Par::Seq));
        let info = conjugate_gradient(
            x.as_mut(),
            precond,
            k,
            rhs.as_ref(),
            params_cg,
            |_| {},
            Par::Seq,
            MemStack::new(&mut mem),
        );
        let (iters, resid) = match info {
            Ok(i) => (i.iter_count, i.rel_residual),
            // Ill-conditioned (e.g. the decimated knight's genus-0 domain, whose limbs the
            // conformal map shrinks by orders of magnitude): the sparse Cholesky factorization
            // of the same scaled system, its residual measured.
            Err(_) => {
                self.direct = true;
                x = direct_solve(k, &rhs, cg_tolerance, cg_max_iterations)?;
                (cg_max_iterations, relative_residual(k, &x, &rhs))
            }
        };
        Ok((unscale(&x, &s)?, iters, resid))
    }
}

/// The control points `x_i · s_i` of the scaled unknowns; an error if one is not finite.
fn unscale(x: &Mat<f64>, s: &[f64]) -> Result<Vec<[f64; 3]>> {
    let control: Vec<[f64; 3]> = (0..s.len())
        .map(|i| [x[(i, 0)] * s[i], x[(i, 1)] * s[i], x[(i, 2)] * s[i]])
        .collect();
    if control.iter().any(|c| c.iter().any(|x| !x.is_finite())) {
        return Err(Error::numerical(
            "the T-spline fit produced non-finite control points",
        ));
    }
    Ok(control)
}

/// The solution of `k x = rhs` by sparse Cholesky (`k` symmetric positive definite, both
/// triangles stored), when the conjugate gradients did not reach `cg_tolerance` in
/// `cg_max_iterations`; one sentence when `k` is not numerically positive definite either.
fn direct_solve(
    k: SparseColMatRef<'_, usize, f64>,
    rhs: &Mat<f64>,
    cg_tolerance: f64,
    cg_max_iterations: usize,
) -> Result<Mat<f64>> {
    let chol = crate::numeric::sparse::Cholesky::factor(k).map_err(|_| {
        Error::numerical(format!(
            "the T-spline fitting system ({} control points) could not be solved: the conjugate gradients did not reach the relative residual {cg_tolerance:.0e} in {cg_max_iterations} iterations and its matrix is not numerically positive definite (sparse Cholesky failed)",
            k.nrows()
        ))
    })?;
    let mut x = rhs.clone();
    chol.solve_in_place(x.as_mut());
    Ok(x)
}

/// `‖k x − rhs‖ / ‖rhs‖` (Frobenius norms over the three coordinates).
fn relative_residual(k: SparseColMatRef<'_, usize, f64>, x: &Mat<f64>, rhs: &Mat<f64>) -> f64 {
    let r = k * x - rhs;
    let b = rhs.norm_l2();
    if b > 0.0 {
        r.norm_l2() / b
    } else {
        r.norm_l2()
    }
}

fn assemble(n: usize, trip: &[Triplet<usize, usize, f64>]) -> Result<SparseColMat<usize, f64>> {
    SparseColMat::<usize, f64>::try_new_from_triplets(n, n, trip)
        .map_err(|e| Error::numerical(format!("could not assemble the fitting system: {e:?}")))
}

/// The diagonal of a square matrix in compressed columns (0 where it is not stored).
fn diagonal(m: SparseColMatRef<'_, usize, f64>) -> Vec<f64> {
    let sym = m.symbolic();
    let mut d = vec![0.0; sym.ncols()];
    for (j, dj) in d.iter_mut().enumerate() {
        if let Some(q) = FitSystem::position(sym, j, j) {
            *dj = m.val()[q];
        }
    }
    d
}

/// The thin-plate Gram matrix's contributions of `elems`, one triplet per pair of functions
/// nonzero on an element.
fn fair_triplets(basis: &TBasis, elems: &[[f64; 4]]) -> Vec<Triplet<usize, usize, f64>> {
    let mut fair = Vec::new();
    let mut at: Vec<Vec<(usize, Jet)>> = vec![Vec::new(); GAUSS.len() * GAUSS.len()];
    let mut ids: Vec<usize> = Vec::new();
    for &[u0, u1, v0, v1] in elems {
        ids.clear();
        for (q, buf) in at.iter_mut().enumerate() {
            let (x, y) = (GAUSS[q / GAUSS.len()].0, GAUSS[q % GAUSS.len()].0);
            basis.eval(u0 + x * (u1 - u0), v0 + y * (v1 - v0), buf);
            // the element's functions, in a fixed order, each once
            for &(i, _) in buf.iter() {
                if !ids.contains(&i) {
                    ids.push(i);
                }
            }
        }
        let m = ids.len();
        let mut block = vec![0.0; m * m];
        let area = (u1 - u0) * (v1 - v0);
        for (q, buf) in at.iter().enumerate() {
            let w = GAUSS[q / GAUSS.len()].1 * GAUSS[q % GAUSS.len()].1 * area;
            let local: Vec<usize> = buf
                .iter()
                .map(|(i, _)| ids.iter().position(|x| x == i).unwrap_or(0))
                .collect();
            for (&(_, ji), &a) in buf.iter().zip(&local) {
                for (&(_, jj), &b) in buf.iter().zip(&local) {
                    let e = ji[3] * jj[3] + 2.0 * ji[4] * jj[4] + ji[5] * jj[5];
                    block[a * m + b] += w * e;
                }
            }
        }
        for (a, &i) in ids.iter().enumerate() {
            for (b, &j) in ids.iter().enumerate() {
                fair.push(Triplet::new(i, j, block[a * m + b]));
            }
        }
    }
    fair
}
