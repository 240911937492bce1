//! Fairing of DMS splines (paper 000 §5, eq. 14, Fig. 13): the constraints that tie each
//! triangle's control points to its neighbours' blossoms, and the projection of control points
//! onto them (see the parent module [`super`] for the formulas and the method).

use std::collections::BTreeMap;

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
    let tolerance = 1e-10;
    if m == 0 {
        return Ok((
            control.to_vec(),
            FairingReport {
                fairness: r,
                constraints: 0,
                max_constraint_residual: 0.0,
                tolerance,
                rms_change: 0.0,
                objective: 0.0,
                refinement_steps: 0,
                converged: true,
            },
        ));
    }
    let sys = ConstraintSystem::new(&cons, nb, nc, control);
    let (trip, diag_max) = normal_triplets(&cons, nb, space.n_triangles());
    // Factor A Aᵀ + shift·I; a shift that is too small for the rounding errors of the
    // factorisation spoils the preconditioner, so it grows until the iteration converges.
    let mut best: Option<(Vec<f64>, f64, usize)> = None;
    for shift_rel in [1e-10, 1e-8, 1e-6, 1e-4] {
        let shift = shift_rel * diag_max;
        let mut t2 = trip.clone();
        for i in 0..m {
            t2.push(Triplet::new(i, i, shift));
        }
        let aat = SparseColMat::<usize, f64>::try_new_from_triplets(m, m, &t2)
            .map_err(|e| Error::numerical(format!("fairing: could not assemble A Aᵀ ({e:?})")))?;
        drop(t2);
        let Ok(llt) = Cholesky::factor(aat.as_ref()) else {
            continue;
        };
        let (x, worst, steps) = sys.project(&llt, control, dim, tolerance);
        let better = best.as_ref().is_none_or(|b| worst < b.1);
        if better && worst.is_finite() {
            best = Some((x, worst, steps));
        }
        if best.as_ref().is_some_and(|b| b.1 <= tolerance) {
            break;
        }
    }
    let Some((x, worst, steps)) = best else {
        return Err(Error::numerical(
            "fairing: the Cholesky factorisation of A Aᵀ failed for every diagonal shift",
        ));
    };
    if !worst.is_finite() {
        return Err(Error::numerical(
            "fairing: the constrained least-squares solve produced non-finite values",
        ));
    }
    let objective: f64 = x.iter().zip(control).map(|(a, b)| (a - b) * (a - b)).sum();
    Ok((
        x,
        FairingReport {
            fairness: r,
            constraints: m,
            max_constraint_residual: worst,
            tolerance,
            rms_change: (objective / nc as f64).sqrt(),
            objective,
            refinement_steps: steps,
            converged: worst <= tolerance,
        },
    ))
}

/// The lower triangle of `A Aᵀ` as triplets (duplicates are summed by faer; the triplets come
/// in a fixed order, so the sums are reproducible) and the largest diagonal entry.
fn normal_triplets(
    cons: &[Constraint],
    nb: usize,
    nf: usize,
) -> (Vec<Triplet<usize, usize, f64>>, f64) {
    // Rows touching each triangle's control points (as target) and rows whose single lies in
    // each triangle.
    let mut by_target: Vec<Vec<u32>> = vec![Vec::new(); nf];
    let mut by_single_face: Vec<Vec<u32>> = vec![Vec::new(); nf];
    let mut by_single: BTreeMap<u32, Vec<u32>> = BTreeMap::new();
    for (i, c) in cons.iter().enumerate() {
        by_target[c.target as usize].push(i as u32);
        by_single_face[c.single as usize / nb].push(i as u32);
        by_single.entry(c.single).or_default().push(i as u32);
    }
    let mut trip: Vec<Triplet<usize, usize, f64>> = Vec::new();
    let push = |a: u32, b: u32, v: f64, trip: &mut Vec<Triplet<usize, usize, f64>>| {
        let (i, j) = if a >= b { (a, b) } else { (b, a) };
        trip.push(Triplet::new(i as usize, j as usize, v));
    };
    let mut diag_max: f64 = 0.0;
    for (i, c) in cons.iter().enumerate() {
        let d = 1.0 + c.weights.iter().map(|w| w * w).sum::<f64>();
        diag_max = diag_max.max(d);
        push(i as u32, i as u32, d, &mut trip);
    }
    for f in 0..nf {
        let rows = &by_target[f];
        // Both rows target f: w_a · w_b.
        for (x, &a) in rows.iter().enumerate() {
            for &b in &rows[..x] {
                let s: f64 = cons[a as usize]
                    .weights
                    .iter()
                    .zip(&cons[b as usize].weights)
                    .map(|(p, q)| p * q)
                    .sum();
                push(a, b, s, &mut trip);
            }
        }
        // Row a's single lies in f, row b targets f: −w_b(local index of a's single).
        for &a in &by_single_face[f] {
            let local = cons[a as usize].single as usize % nb;
            for &b in rows {
                if a != b {
                    push(a, b, -cons[b as usize].weights[local], &mut trip);
                }
            }
        }
    }
    for rows in by_single.values() {
        for (x, &a) in rows.iter().enumerate() {
            for &b in &rows[..x] {
                push(a, b, 1.0, &mut trip);
            }
        }
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

    /// `c − Aᵀ y` with `A Aᵀ y = A c` solved by preconditioned conjugate gradients (the shifted
    /// factorisation `llt` as preconditioner), one coordinate at a time; the projected control
    /// points, the largest relative residual of the result and the most CG steps taken.
    fn project(
        &self,
        llt: &Cholesky,
        control: &[f64],
        dim: usize,
        tolerance: f64,
    ) -> (Vec<f64>, f64, usize) {
        let (m, nc) = (self.cons.len(), self.nc);
        let mut x = control.to_vec();
        let mut steps = 0;
        let mut xc = vec![0.0; nc];
        let mut tmp = vec![0.0; nc];
        for d in 0..dim {
            for k in 0..nc {
                xc[k] = control[k * dim + d];
            }
            let (y, it) = self.pcg(llt, &xc, tolerance);
            steps = steps.max(it);
            self.apply_at(&y, &mut tmp);
            for k in 0..nc {
                x[k * dim + d] = control[k * dim + d] - tmp[k];
            }
        }
        // Report the true residual of the result.
        let mut worst: f64 = 0.0;
        let mut r = vec![0.0; m];
        for d in 0..dim {
            for k in 0..nc {
                xc[k] = x[k * dim + d];
            }
            self.apply_a(&xc, &mut r);
            worst = worst.max(self.rel_max(&r));
        }
        (x, worst, steps)
    }

    /// Restarted PCG on the consistent system `A Aᵀ y = A c` for one coordinate `c`; each
    /// restart recomputes the true residual `A(c − Aᵀ y)`. `y` and the number of steps.
    fn pcg(&self, llt: &Cholesky, c: &[f64], tolerance: f64) -> (Vec<f64>, usize) {
        let m = self.cons.len();
        let precond = |r: &[f64]| -> Vec<f64> {
            let mut z = Mat::<f64>::zeros(m, 1);
            for i in 0..m {
                z[(i, 0)] = r[i];
            }
            llt.solve_in_place(z.as_mut());
            (0..m).map(|i| z[(i, 0)]).collect()
        };
        let dotp = |a: &[f64], b: &[f64]| a.iter().zip(b).map(|(p, q)| p * q).sum::<f64>();
        let mut tmp = vec![0.0; self.nc];
        let mut y = vec![0.0; m];
        let mut it = 0;
        for _restart in 0..4 {
            let mut r = vec![0.0; m];
            self.apply_at(&y, &mut tmp);
            for k in 0..self.nc {
                tmp[k] = c[k] - tmp[k];
            }
            self.apply_a(&tmp, &mut r);
            let mut rmax = self.rel_max(&r);
            if rmax <= tolerance {
                break;
            }
            let mut z = precond(&r);
            let mut p = z.clone();
            let mut rz = dotp(&r, &z);
            let mut q = vec![0.0; m];
            let mut inner = 0;
            while rmax > tolerance && inner < 40 {
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
                z = precond(&r);
                let rz_new = dotp(&r, &z);
                let beta = rz_new / rz;
                rz = rz_new;
                for i in 0..m {
                    p[i] = z[i] + beta * p[i];
                }
            }
        }
        (y, it)
    }
}
