//! Fairing of DMS splines (paper 000 §5, eq. 14, Fig. 13): the constraints that tie each
//! triangle's control points to its neighbours' blossoms, and the projection of control points
//! onto them (see the parent module [`super`] for the formulas and the method).

use faer::sparse::{SparseColMat, Triplet};
use faer::Mat;

use crate::error::{Error, Result};
use crate::numeric::sparse::Cholesky;
use crate::spline::error::SplineError;

use super::super::dms::multi_indices;
use super::SplineSpace;

/// One fairing constraint `c̃[single] − Σ_b weights[b] c̃[target * nb + b] = 0`.
#[derive(Debug, Clone)]
pub struct Constraint {
    /// Global index of the constrained control point (of triangle `I`).
    pub single: u32,
    /// The neighbouring triangle `J` whose B-patch blossom it must equal.
    pub target: u32,
    /// Blossom weights of `J`'s control points (one per β of `J`).
    pub weights: Vec<f64>,
}

/// The constraints of paper 000 eq. 14 for fairness parameter `r` (`0 ≤ r ≤ n − 1`), for
/// both orientations of every interior edge (the shared-control-point rows, `β_o = 0`, once).
pub fn fairness_constraints<S: SplineSpace + ?Sized>(
    space: &S,
    r: usize,
) -> Result<Vec<Constraint>> {
    let n = space.degree();
    if r >= n {
        return Err(SplineError::FairnessOutOfRange { r, degree: n }.into());
    }
    let nb = space.per_triangle();
    let mut out = Vec::new();
    for (fi, fj, o) in space.neighbour_pairs() {
        for (k, beta) in multi_indices(n).into_iter().enumerate() {
            if beta[o] > r {
                continue;
            }
            // With β_o = 0 the constraint only involves the edge's knots and says that the
            // two triangles share this control point: the same equation as the opposite
            // orientation's, so it is imposed once (from the lower face index).
            if beta[o] == 0 && fi > fj {
                continue;
            }
            let mut w = vec![0.0; nb];
            space.blossom_weights_between(fi, beta, fj, &mut w);
            out.push(Constraint {
                single: (fi as usize * nb + k) as u32,
                target: fj,
                weights: w,
            });
        }
    }
    Ok(out)
}

/// Residuals `A c` of the constraints (`dim` numbers per constraint).
pub fn constraint_residuals<S: SplineSpace + ?Sized>(
    space: &S,
    cons: &[Constraint],
    control: &[f64],
    dim: usize,
) -> Vec<f64> {
    let nb = space.per_triangle();
    let mut r = vec![0.0; cons.len() * dim];
    for (i, c) in cons.iter().enumerate() {
        for d in 0..dim {
            let mut s = control[c.single as usize * dim + d];
            for (b, w) in c.weights.iter().enumerate() {
                s -= w * control[(c.target as usize * nb + b) * dim + d];
            }
            r[i * dim + d] = s;
        }
    }
    r
}

/// What [`fair`] did.
#[derive(Debug, Clone, serde::Serialize)]
pub struct FairingReport {
    pub fairness: usize,
    pub constraints: usize,
    /// `max_i |A_i c̃| / (‖A_i‖₁ max |c|)`: constraint residual relative to the size of its terms.
    pub max_constraint_residual: f64,
    /// Requested tolerance for the above.
    pub tolerance: f64,
    /// `sqrt(mean ‖c̃ − c‖²)` over control points.
    pub rms_change: f64,
    /// Objective of eq. 14, `Σ ‖c̃ − c‖²`.
    pub objective: f64,
    /// Largest number of preconditioned CG steps (over coordinates).
    pub refinement_steps: usize,
    pub converged: bool,
}

/// Paper 000's fairing (module docs) of control points with `dim` coordinates each.
///
/// The projection `c̃ = argmin ‖c̃ − c‖²` subject to `A c̃ = 0` is computed by the augmented
/// Lagrangian method on the primal unknowns: with `H = I + μ AᵀA` (one sparse Cholesky
/// factorization, `nc × nc`),
///
/// `H c̃_k = c − Aᵀ λ_k`,  `λ_{k+1} = λ_k + μ A c̃_k`,
///
/// whose fixed point is the KKT point `c̃ = c − Aᵀ λ`, `A c̃ = 0`. Each step divides the
/// constraint residual along a singular direction σ of `A` by `1 + μσ²`, so with
/// `μ = 10⁸ / max diag(AᵀA)` the well-conditioned systems (degree 3 with `r = 1`, degree 4 with
/// `r ≤ 1`) reach [`FAIRING_TOLERANCE`] in 2–3 steps. Larger `r` (degree 4 with `r ≥ 2`,
/// `r = n − 1`) ties rows of control points that are nearly dependent: `A` has a continuum of
/// tiny singular values and the residual falls slowly or not at all (kitten, degree 4, `r = 2`:
/// 9.5e-6 after one step, 2.1e-6 after 30; the demo surface at degree 4, `r = 2`: 1.2e-4). The iteration stops at the tolerance, after [`FAIRING_MAX_STEPS`]
/// steps, or when 8 steps did not halve the residual. If it is then above 1 % of the tolerance,
/// conjugate gradients on the dual `A Aᵀ y = A c`, preconditioned by the same factorization
/// (Woodbury), continue from the multipliers (degree 5 with `r = 3, 4` on a planar grid: 33 / 74
/// steps in all, where the plain iteration stalls at 7e-7), until a round of 40 steps no longer
/// halves the residual. The report says whether the tolerance was reached.
///
/// (Before: conjugate gradients on the dual `A Aᵀ y = A c`, preconditioned by a shifted
/// Cholesky factorization of the `m × m` matrix `A Aᵀ` — about twice as many rows as control
/// points and much denser; on kitten at degree 4 it ran for more than 20 minutes at 5.4 GB.)
pub fn fair<S: SplineSpace + ?Sized>(
    space: &S,
    control: &[f64],
    dim: usize,
    r: usize,
) -> Result<(Vec<f64>, FairingReport)> {
    let nc = space.n_control_points();
    if control.len() != nc * dim {
        return Err(Error::input(format!(
            "fairing: {} numbers given for {nc} control points of dimension {dim}",
            control.len()
        )));
    }
    let cons = fairness_constraints(space, r)?;
    let nb = space.per_triangle();
    let m = cons.len();
    let tolerance = FAIRING_TOLERANCE;
    let report = |x: &[f64], worst: f64, steps: usize| {
        let objective: f64 = x.iter().zip(control).map(|(a, b)| (a - b) * (a - b)).sum();
        FairingReport {
            fairness: r,
            constraints: m,
            max_constraint_residual: worst,
            tolerance,
            rms_change: (objective / nc as f64).sqrt(),
            objective,
            refinement_steps: steps,
            converged: worst <= tolerance,
        }
    };
    if m == 0 {
        return Ok((control.to_vec(), report(control, 0.0, 0)));
    }
    let sys = ConstraintSystem::new(&cons, nb, nc, control);
    let pf = PenaltyFactor::new(&cons, nb, nc, space.n_triangles())?;
    let (mut x, mut worst, mut steps, lambda) =
        sys.augmented_lagrangian(&pf, control, dim, tolerance);
    if worst > 1e-2 * tolerance && worst.is_finite() {
        // The plain iteration is linear and slows down where `A` is ill-conditioned; conjugate
        // gradients on the dual, preconditioned by the same factorization, from its multipliers.
        let (x2, worst2, steps2) = sys.refine_by_dual_pcg(&pf, control, dim, &lambda, tolerance);
        steps += steps2;
        if worst2 < worst {
            (x, worst) = (x2, worst2);
        }
    }
    if !worst.is_finite() {
        return Err(Error::numerical(
            "fairing: the constrained least-squares solve produced non-finite values",
        ));
    }
    let rep = report(&x, worst, steps);
    Ok((x, rep))
}

/// The penalty matrix `H = I + μ AᵀA` of [`fair`] (lower triangle) with its sparse Cholesky
/// factorization and the weight `μ = 10⁸ / max diag(AᵀA)`.
struct PenaltyFactor {
    llt: Cholesky,
    h: SparseColMat<usize, f64>,
    mu: f64,
}

impl PenaltyFactor {
    /// Assemble and factor `H` for the constraints `cons` (`nb` control points per triangle,
    /// `nc` in all, `nf` triangles).
    fn new(cons: &[Constraint], nb: usize, nc: usize, nf: usize) -> Result<Self> {
        let (trip, diag_max) = penalty_triplets(cons, nb, nc, nf);
        let mu = 1e8 / diag_max.max(1e-300);
        let trip: Vec<Triplet<usize, usize, f64>> = trip
            .into_iter()
            .map(|t| {
                let v = if t.row == t.col {
                    1.0 + mu * t.val
                } else {
                    mu * t.val
                };
                Triplet::new(t.row, t.col, v)
            })
            .collect();
        let h = SparseColMat::<usize, f64>::try_new_from_triplets(nc, nc, &trip).map_err(|e| {
            Error::numerical(format!("fairing: could not assemble I + μAᵀA ({e:?})"))
        })?;
        drop(trip);
        let llt = Cholesky::factor(h.as_ref()).map_err(|e| {
            Error::numerical(format!(
                "fairing: the Cholesky factorisation of I + μAᵀA failed ({e:?})"
            ))
        })?;
        Ok(PenaltyFactor { llt, h, mu })
    }

    /// `H⁻¹ b` for the columns of `b` (in place) with one step of iterative refinement,
    /// `x ← x + H⁻¹ (b − H x)`: `H = I + μAᵀA` has condition number about μ‖A‖², and without
    /// the step the solve's rounding (about ε·μ relative, mostly in the null space of `A`) moves
    /// the faired points off the closest feasible point by about 1e-8. `r` is scratch space
    /// (reshaped to `b`'s shape when it differs).
    fn solve_refined(&self, mut b: faer::MatMut<'_, f64>, r: &mut Mat<f64>) {
        let (n, k) = (b.nrows(), b.ncols());
        if r.nrows() != n || r.ncols() != k {
            *r = Mat::zeros(n, k);
        }
        r.as_mut().copy_from(b.as_ref());
        self.llt.solve_in_place(b.as_mut());
        let h = self.h.as_ref();
        let sym = h.symbolic();
        let (cp, ri, val) = (sym.col_ptr(), sym.row_idx(), h.val());
        for c in 0..k {
            for j in 0..n {
                let xj = b[(j, c)];
                for q in cp[j]..cp[j + 1] {
                    let i = ri[q];
                    r[(i, c)] -= val[q] * xj;
                    if i != j {
                        r[(j, c)] -= val[q] * b[(i, c)];
                    }
                }
            }
        }
        self.llt.solve_in_place(r.as_mut());
        for c in 0..k {
            for j in 0..n {
                b[(j, c)] += r[(j, c)];
            }
        }
    }
}

/// Relative constraint residual the fairing aims at (see [`FairingReport`]).
pub const FAIRING_TOLERANCE: f64 = 1e-10;
/// Budget of augmented-Lagrangian steps of [`fair`].
pub const FAIRING_MAX_STEPS: usize = 60;

/// The lower triangle of `AᵀA` as triplets (duplicates are summed by faer; they come in a fixed
/// order, so the sums are reproducible) and its largest diagonal entry. Row `i` of `A` is
/// `e_single − Σ_b w_b e_{target·nb + b}`: its outer product gives a dense `nb × nb` block on
/// the target triangle (accumulated per triangle), `−w_b` between the single and the target's
/// points (different triangles), and 1 on the single's diagonal.
fn penalty_triplets(
    cons: &[Constraint],
    nb: usize,
    nc: usize,
    nf: usize,
) -> (Vec<Triplet<usize, usize, f64>>, f64) {
    let mut block = vec![0.0; nf * nb * nb];
    let mut diag = vec![0.0; nc];
    let mut trip: Vec<Triplet<usize, usize, f64>> = Vec::with_capacity(cons.len() * nb);
    for c in cons {
        let t = c.target as usize;
        let blk = &mut block[t * nb * nb..(t + 1) * nb * nb];
        for a in 0..nb {
            for b in 0..=a {
                blk[a * nb + b] += c.weights[a] * c.weights[b];
            }
        }
        diag[c.single as usize] += 1.0;
        for (b, &w) in c.weights.iter().enumerate() {
            if w != 0.0 {
                let (i, j) = (c.single as usize, t * nb + b);
                let (i, j) = if i >= j { (i, j) } else { (j, i) };
                trip.push(Triplet::new(i, j, -w));
            }
        }
    }
    for t in 0..nf {
        for a in 0..nb {
            diag[t * nb + a] += block[t * nb * nb + a * nb + a];
            for b in 0..a {
                let v = block[t * nb * nb + a * nb + b];
                if v != 0.0 {
                    trip.push(Triplet::new(t * nb + a, t * nb + b, v));
                }
            }
        }
    }
    let diag_max = diag.iter().copied().fold(0.0f64, f64::max);
    for (k, &d) in diag.iter().enumerate() {
        trip.push(Triplet::new(k, k, d));
    }
    (trip, diag_max)
}

/// The constraint matrix `A` (rows [`Constraint`]) on one coordinate, with what the projection
/// measures residuals against.
struct ConstraintSystem<'a> {
    cons: &'a [Constraint],
    nb: usize,
    nc: usize,
    /// `1 + ‖w‖₁` per row: residuals are measured relative to the size of their terms,
    /// `|A_i x| / (‖A_i‖₁ max|c|)`.
    row_norm: Vec<f64>,
    /// `max |c|` of the input control points.
    scale: f64,
}

impl<'a> ConstraintSystem<'a> {
    fn new(cons: &'a [Constraint], nb: usize, nc: usize, control: &[f64]) -> Self {
        ConstraintSystem {
            cons,
            nb,
            nc,
            row_norm: cons
                .iter()
                .map(|c| 1.0 + c.weights.iter().map(|w| w.abs()).sum::<f64>())
                .collect(),
            scale: control
                .iter()
                .fold(0.0f64, |a, b| a.max(b.abs()))
                .max(1e-300),
        }
    }

    /// `out = A x`.
    fn apply_a(&self, x: &[f64], out: &mut [f64]) {
        for (i, c) in self.cons.iter().enumerate() {
            let mut s = x[c.single as usize];
            let base = c.target as usize * self.nb;
            for (b, w) in c.weights.iter().enumerate() {
                s -= w * x[base + b];
            }
            out[i] = s;
        }
    }

    /// `out = Aᵀ y`.
    fn apply_at(&self, y: &[f64], out: &mut [f64]) {
        out.fill(0.0);
        for (i, c) in self.cons.iter().enumerate() {
            let v = y[i];
            out[c.single as usize] += v;
            let base = c.target as usize * self.nb;
            for (b, w) in c.weights.iter().enumerate() {
                out[base + b] -= w * v;
            }
        }
    }

    /// The largest relative residual of `r = A x`.
    fn rel_max(&self, r: &[f64]) -> f64 {
        r.iter()
            .zip(&self.row_norm)
            .fold(0.0f64, |a, (v, n)| a.max(v.abs() / n))
            / self.scale
    }

    /// The augmented-Lagrangian steps of [`fair`] (all coordinates at once): the iterate with
    /// the smallest largest relative residual, that residual, the number of steps taken and
    /// the multipliers.
    fn augmented_lagrangian(
        &self,
        pf: &PenaltyFactor,
        control: &[f64],
        dim: usize,
        tolerance: f64,
    ) -> (Vec<f64>, f64, usize, Vec<f64>) {
        let (m, nc, mu) = (self.cons.len(), self.nc, pf.mu);
        let mut lambda = vec![0.0; m * dim];
        let mut best: (Vec<f64>, f64) = (control.to_vec(), f64::INFINITY);
        let mut history: Vec<f64> = Vec::new();
        let (mut tmp, mut col, mut res, mut lam) =
            (vec![0.0; nc], vec![0.0; nc], vec![0.0; m], vec![0.0; m]);
        let mut x = vec![0.0; nc * dim];
        let (mut rhs, mut scratch) = (Mat::<f64>::zeros(nc, dim), Mat::<f64>::zeros(nc, dim));
        // `A c` per coordinate.
        let mut ac = vec![0.0; m * dim];
        for d in 0..dim {
            for k in 0..nc {
                col[k] = control[k * dim + d];
            }
            self.apply_a(&col, &mut res);
            for i in 0..m {
                ac[i * dim + d] = res[i];
            }
        }
        let mut steps = 0;
        while steps < FAIRING_MAX_STEPS {
            steps += 1;
            // In correction form, `c̃ = c − H⁻¹ Aᵀ (λ + μ A c)` (the same step as
            // `H c̃ = c − Aᵀ λ`): the solve's rounding is relative to the correction, so a
            // feasible `c` (r = 0, a polynomial) is left in place to the last bit.
            for d in 0..dim {
                for i in 0..m {
                    lam[i] = lambda[i * dim + d] + mu * ac[i * dim + d];
                }
                self.apply_at(&lam, &mut tmp);
                for k in 0..nc {
                    rhs[(k, d)] = tmp[k];
                }
            }
            pf.solve_refined(rhs.as_mut(), &mut scratch);
            let mut worst: f64 = 0.0;
            for d in 0..dim {
                for k in 0..nc {
                    col[k] = control[k * dim + d] - rhs[(k, d)];
                    x[k * dim + d] = col[k];
                }
                self.apply_a(&col, &mut res);
                worst = worst.max(self.rel_max(&res));
                for i in 0..m {
                    lambda[i * dim + d] += mu * res[i];
                }
            }
            if !worst.is_finite() {
                break;
            }
            if worst < best.1 {
                best.0.copy_from_slice(&x);
                best.1 = worst;
            }
            history.push(worst);
            // Go on to 1 % of the tolerance (steps are cheap next to the factorization): the
            // distance to the closest feasible point is off by about ⟨λ, A c̃⟩, and λ is large
            // where `A` is ill-conditioned (degree 3, r = 2: 3e-8 of the move at the tolerance
            // itself, after 31 steps of rate 0.65).
            if worst <= 1e-2 * tolerance {
                break;
            }
            // Stalled: 8 steps did not halve the residual.
            let n = history.len();
            if n > 8 && history[n - 1] > 0.5 * history[n - 9] {
                break;
            }
        }
        (best.0, best.1, steps, lambda)
    }

    /// [`Self::dual_pcg`] for every coordinate (budget 200 steps each) from the multipliers
    /// `lambda`: the projected points, their largest relative residual and the most steps taken.
    fn refine_by_dual_pcg(
        &self,
        pf: &PenaltyFactor,
        control: &[f64],
        dim: usize,
        lambda: &[f64],
        tolerance: f64,
    ) -> (Vec<f64>, f64, usize) {
        let (m, nc) = (self.cons.len(), self.nc);
        let mut x = control.to_vec();
        let (mut c, mut tmp, mut r) = (vec![0.0; nc], vec![0.0; nc], vec![0.0; m]);
        let mut pre = Preconditioner::new(nc, m);
        let (mut worst, mut steps): (f64, usize) = (0.0, 0);
        for d in 0..dim {
            for k in 0..nc {
                c[k] = control[k * dim + d];
            }
            let y0: Vec<f64> = (0..m).map(|i| lambda[i * dim + d]).collect();
            let (y, it) = self.dual_pcg(pf, &mut pre, &c, y0, tolerance, 200);
            steps = steps.max(it);
            self.apply_at(&y, &mut tmp);
            for k in 0..nc {
                c[k] -= tmp[k];
                x[k * dim + d] = c[k];
            }
            self.apply_a(&c, &mut r);
            worst = worst.max(self.rel_max(&r));
        }
        (x, worst, steps)
    }

    /// `out = μ (I − μ A H⁻¹ Aᵀ) r`, the preconditioner of [`Self::dual_pcg`] (Woodbury:
    /// `(A Aᵀ + I/μ)⁻¹`), in the buffers of `pre`.
    fn precondition(
        &self,
        pf: &PenaltyFactor,
        pre: &mut Preconditioner,
        r: &[f64],
        out: &mut [f64],
    ) {
        let mu = pf.mu;
        self.apply_at(r, &mut pre.t);
        for (k, &t) in pre.t.iter().enumerate() {
            pre.z[(k, 0)] = t;
        }
        pf.solve_refined(pre.z.as_mut(), &mut pre.scratch);
        for (k, t) in pre.t.iter_mut().enumerate() {
            *t = pre.z[(k, 0)];
        }
        self.apply_a(&pre.t, &mut pre.w);
        for ((o, &ri), &wi) in out.iter_mut().zip(r).zip(&pre.w) {
            *o = mu * (ri - mu * wi);
        }
    }

    /// Conjugate gradients on the dual `A Aᵀ y = A c` for one coordinate `c`, from `y`,
    /// preconditioned by `(A Aᵀ + I/μ)⁻¹ = μ (I − μ A H⁻¹ Aᵀ)` (Woodbury, through the primal
    /// factorization of `H`, [`Self::precondition`]), restarted with the true residual
    /// `A (c − Aᵀ y)` every 40 steps; at most `budget` steps, and it stops when a round of 40
    /// did not halve the residual. Returns `y` and the steps taken.
    fn dual_pcg(
        &self,
        pf: &PenaltyFactor,
        pre: &mut Preconditioner,
        c: &[f64],
        mut y: Vec<f64>,
        tolerance: f64,
        budget: usize,
    ) -> (Vec<f64>, usize) {
        let (m, nc) = (self.cons.len(), self.nc);
        let dotp = |a: &[f64], b: &[f64]| a.iter().zip(b).map(|(p, q)| p * q).sum::<f64>();
        let mut tmp = vec![0.0; nc];
        let (mut r, mut z, mut p, mut q) = (vec![0.0; m], vec![0.0; m], vec![0.0; m], vec![0.0; m]);
        let mut it = 0;
        let mut last_restart = f64::INFINITY;
        while it < budget {
            self.apply_at(&y, &mut tmp);
            for k in 0..nc {
                tmp[k] = c[k] - tmp[k];
            }
            self.apply_a(&tmp, &mut r);
            let mut rmax = self.rel_max(&r);
            // Done, or stalled: a round of 40 steps did not halve the residual.
            if rmax <= 1e-2 * tolerance || rmax > 0.5 * last_restart {
                break;
            }
            last_restart = rmax;
            self.precondition(pf, pre, &r, &mut z);
            p.copy_from_slice(&z);
            let mut rz = dotp(&r, &z);
            let mut inner = 0;
            while rmax > 1e-2 * tolerance && inner < 40 && it < budget {
                inner += 1;
                it += 1;
                self.apply_at(&p, &mut tmp);
                self.apply_a(&tmp, &mut q);
                let pq = dotp(&p, &q);
                if !(pq > 0.0) {
                    break;
                }
                let alpha = rz / pq;
                for i in 0..m {
                    y[i] += alpha * p[i];
                    r[i] -= alpha * q[i];
                }
                rmax = self.rel_max(&r);
                self.precondition(pf, pre, &r, &mut z);
                let rz_new = dotp(&r, &z);
                let beta = rz_new / rz;
                rz = rz_new;
                for i in 0..m {
                    p[i] = z[i] + beta * p[i];
                }
            }
            if inner == 0 {
                break;
            }
        }
        (y, it)
    }
}

/// The buffers of [`ConstraintSystem::precondition`], allocated once per [`fair`] call (the
/// preconditioner runs at every conjugate-gradient step).
struct Preconditioner {
    /// `Aᵀ r`, then `H⁻¹ Aᵀ r` (length `nc`).
    t: Vec<f64>,
    /// The right-hand side and solution of the solve (`nc × 1`).
    z: Mat<f64>,
    /// Scratch of [`PenaltyFactor::solve_refined`] (`nc × 1`).
    scratch: Mat<f64>,
    /// `A H⁻¹ Aᵀ r` (length `m`).
    w: Vec<f64>,
}

impl Preconditioner {
    fn new(nc: usize, m: usize) -> Self {
        Preconditioner {
            t: vec![0.0; nc],
            z: Mat::zeros(nc, 1),
            scratch: Mat::zeros(nc, 1),
            w: vec![0.0; m],
        }
    }
}
