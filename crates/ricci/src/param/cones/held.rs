//! Cone placement on a surface **with boundary** held at `u = 0` (the disk of `--seams free`,
//! module docs of [`super`]) from one factorization.
//!
//! `A = L + P` is the cotangent Laplacian with a large diagonal penalty `p` on the held
//! vertices (boundary and isolated). Holding cones `C` too is the matrix `A + p E Eᵀ` (`E` the
//! unit columns of `C`), whose solutions follow from `A`'s by the Sherman–Morrison–Woodbury
//! identity
//!
//! ```text
//! (A + p E Eᵀ)⁻¹ r = A⁻¹ r − G (I/p + G_CC)⁻¹ (A⁻¹ r)_C,    G = A⁻¹ E,  G_CC = Eᵀ A⁻¹ E,
//! ```
//!
//! so each new cone costs one triangular solve (its column `g_c = A⁻¹ e_c`) and a `|C| × |C|`
//! dense solve instead of a numeric factorization of `A + p E Eᵀ` — the same linear system,
//! solved in another order (equal up to rounding). The least-squares curvatures at the chosen
//! positions ([`HeldBasis::least_squares`]) use the same `A⁻¹ r₀` and columns.

use super::{ConeBudget, ConePlacement, Laplacian};
use crate::error::{Error, Result};
use crate::numeric::sparse::SymmetricSolver;
use std::collections::HashMap;
use std::f64::consts::PI;

/// The factorization of `L + P` (penalty on `held`), `A⁻¹ r₀` and the cone columns so far.
pub(super) struct HeldBasis<'a> {
    lap: &'a Laplacian,
    k0: &'a [f64],
    solver: SymmetricSolver,
    /// Boundary or isolated vertices (held at `u = 0`, never cones).
    held: Vec<bool>,
    used: Vec<bool>,
    penalty: f64,
    total_area: f64,
    /// `A⁻¹ r₀`, `r₀ = −K⁰` off the held vertices, 0 on them.
    u0: Vec<f64>,
    columns: HashMap<u32, Vec<f64>>,
}

/// `x` solving the dense `m × m` system `a x = b` (Gaussian elimination, partial pivoting).
fn dense_solve(mut a: Vec<Vec<f64>>, b: &[f64], what: &str) -> Result<Vec<f64>> {
    let k = b.len();
    for (row, &y) in a.iter_mut().zip(b) {
        row.push(y);
    }
    for col in 0..k {
        let p = (col..k)
            .max_by(|&x, &y| a[x][col].abs().total_cmp(&a[y][col].abs()))
            .unwrap_or(col);
        a.swap(col, p);
        let d = a[col][col];
        if d.abs() < 1e-300 || !d.is_finite() {
            return Err(Error::numerical(format!(
                "{what}: singular normal equations"
            )));
        }
        let pivot = a[col].clone();
        for (r, row) in a.iter_mut().enumerate() {
            if r != col {
                let f = row[col] / d;
                for (x, y) in row[col..].iter_mut().zip(&pivot[col..]) {
                    *x -= f * y;
                }
            }
        }
    }
    Ok((0..k).map(|i| a[i][k] / a[i][i]).collect())
}

impl<'a> HeldBasis<'a> {
    /// Factorize `lap` with the vertices `held` (boundary) and `!used` (isolated) penalised;
    /// `solver` holds the symbolic analysis of `lap`'s pattern ([`super::laplacian_system`]).
    pub fn new(
        lap: &'a Laplacian,
        k0: &'a [f64],
        held: &[bool],
        used: &[bool],
        mut solver: SymmetricSolver,
    ) -> Result<HeldBasis<'a>> {
        let n = lap.n;
        let held: Vec<bool> = (0..n).map(|v| held[v] || !used[v]).collect();
        let scale = lap.diag.iter().map(|&i| lap.values[i]).fold(0.0, f64::max);
        let penalty = 1e10 * scale.max(1e-300);
        let mut vals = lap.values.clone();
        for v in 0..n {
            if held[v] {
                vals[lap.diag[v]] += penalty;
            }
        }
        if !solver.factor_llt(&vals) && !solver.factor_ldlt(&vals) {
            return Err(Error::numerical(
                "the cotangent Laplacian could not be factorized for cone placement",
            ));
        }
        let mut u0: Vec<f64> = (0..n).map(|v| if held[v] { 0.0 } else { -k0[v] }).collect();
        solver.solve(&mut u0);
        Ok(HeldBasis {
            lap,
            k0,
            solver,
            held,
            used: used.to_vec(),
            penalty,
            total_area: lap.area.iter().sum(),
            u0,
            columns: HashMap::new(),
        })
    }

    /// `g_c = A⁻¹ e_c` (cached).
    fn column(&mut self, c: u32) -> &[f64] {
        if !self.columns.contains_key(&c) {
            let mut x = vec![0.0; self.lap.n];
            x[c as usize] = 1.0;
            self.solver.solve(&mut x);
            self.columns.insert(c, x);
        }
        &self.columns[&c]
    }

    /// The linearised `u` with the held vertices and `cones` at 0 and `L u = −K⁰` elsewhere
    /// (the penalised system, by the Woodbury identity of the module docs).
    fn field(&mut self, cones: &[u32]) -> Result<Vec<f64>> {
        for &c in cones {
            self.column(c);
        }
        let g: Vec<&[f64]> = cones.iter().map(|c| &self.columns[c][..]).collect();
        // The right-hand side is 0 at the cones: A⁻¹r = u₀ − Σ_c r₀_c g_c, r₀_c = −K⁰_c.
        let r0: Vec<f64> = cones.iter().map(|&c| -self.k0[c as usize]).collect();
        let y_at = |i: usize| -> f64 {
            let ci = cones[i] as usize;
            self.u0[ci] - (0..cones.len()).map(|j| r0[j] * g[j][ci]).sum::<f64>()
        };
        let y: Vec<f64> = (0..cones.len()).map(y_at).collect();
        let m: Vec<Vec<f64>> = (0..cones.len())
            .map(|i| {
                (0..cones.len())
                    .map(|j| {
                        g[j][cones[i] as usize] + if i == j { 1.0 / self.penalty } else { 0.0 }
                    })
                    .collect()
            })
            .collect();
        let z = dense_solve(m, &y, "cone placement")?;
        let w: Vec<f64> = r0.iter().zip(&z).map(|(a, b)| a + b).collect();
        let mut u = self.u0.clone();
        for (gj, wj) in g.iter().zip(&w) {
            for (x, gv) in u.iter_mut().zip(gj.iter()) {
                *x -= wj * gv;
            }
        }
        Ok(u)
    }

    /// Linearised `max |2u − mean(2u)|` over the used vertices.
    fn spread(&self, u: &[f64]) -> f64 {
        let n = self.lap.n;
        let a = &self.lap.area;
        let m: f64 = (0..n).map(|v| 2.0 * u[v] * a[v]).sum::<f64>() / self.total_area;
        (0..n)
            .filter(|&v| self.used[v])
            .map(|v| (2.0 * u[v] - m).abs())
            .fold(0.0, f64::max)
    }

    /// The greedy (module docs of [`super`]): a cone where `|u − ū|` is largest, until the
    /// budget is spent; curvatures `K̄_c = K⁰_c + (L u)_c` (`u = 0` at the cones).
    pub fn greedy(&mut self, budget: ConeBudget) -> Result<ConePlacement> {
        let n = self.lap.n;
        let (max_cones, bound) = match budget {
            ConeBudget::Count(c) => (c, -1.0),
            ConeBudget::AreaDistortion { bound, max_cones } => (max_cones, bound),
        };
        let mut blocked = self.held.clone();
        let mut cones: Vec<u32> = Vec::new();
        let mut history = Vec::new();
        let mut u = self.u0.clone();
        while cones.len() < max_cones {
            if bound >= 0.0 && !cones.is_empty() && self.spread(&u) <= bound {
                break;
            }
            let area = &self.lap.area;
            let mean: f64 = (0..n).map(|v| u[v] * area[v]).sum::<f64>() / self.total_area;
            let next = (0..n)
                .filter(|&v| self.used[v] && !blocked[v])
                .max_by(|&a, &b| (u[a] - mean).abs().total_cmp(&(u[b] - mean).abs()));
            let Some(c) = next else { break };
            cones.push(c as u32);
            blocked[c] = true;
            u = self.field(&cones)?;
            history.push(self.spread(&u));
        }
        // Curvature left at the cones: K̄_c = K⁰_c + (L u)_c.
        let lap = self.lap;
        let mut lu = vec![0.0; n];
        for j in 0..n {
            for p in lap.col_ptr[j] as usize..lap.col_ptr[j + 1] as usize {
                let i = lap.row_idx[p] as usize;
                let v = lap.values[p];
                lu[i] += v * u[j];
                if i != j {
                    lu[j] += v * u[i];
                }
            }
        }
        Ok(ConePlacement {
            cones: cones
                .iter()
                .map(|&c| (c, self.k0[c as usize] + lu[c as usize]))
                .collect(),
            distortion_history: history,
        })
    }

    /// Curvatures at `cones` of least area-weighted variance of `u = u₀ + Σ_c K̄_c g_c`
    /// (both shifted to zero area mean), cone angles kept positive (`K̄ ≤ 2π − 0.05`), and the
    /// linearised area-weighted `σ(2u)`. With `ceiling = Some(β)`, no cone's linearised `u(c)`
    /// lies above `ū + β sd(u)` (mean and deviation of the unbounded solution): such cones
    /// are held there and the others' curvatures are least-squares under that condition
    /// (see [`super::CONE_SCALE_CEILING`]).
    pub fn least_squares(
        &mut self,
        cones: &[u32],
        ceiling: Option<f64>,
    ) -> Result<(Vec<(u32, f64)>, f64)> {
        let lap: &'a Laplacian = self.lap;
        let n = lap.n;
        if let Some(&c) = cones
            .iter()
            .find(|&&c| c as usize >= n || self.held[c as usize])
        {
            return Err(Error::input(format!(
                "cone vertex {c} is not an interior vertex of the mesh"
            )));
        }
        let area = &lap.area;
        let total = self.total_area;
        let centred = |x: &[f64]| -> Vec<f64> {
            let m = (0..n).map(|v| x[v] * area[v]).sum::<f64>() / total;
            x.iter().map(|y| y - m).collect()
        };
        let u0 = centred(&self.u0);
        let g: Vec<Vec<f64>> = cones.iter().map(|&c| centred(self.column(c))).collect();
        let dot = |a: &[f64], b: &[f64]| (0..n).map(|v| area[v] * a[v] * b[v]).sum::<f64>();
        let k = cones.len();
        let m: Vec<Vec<f64>> = (0..k)
            .map(|i| (0..k).map(|j| dot(&g[i], &g[j])).collect())
            .collect();
        let b: Vec<f64> = (0..k).map(|i| -dot(&g[i], &u0)).collect();
        let mut x = dense_solve(m.clone(), &b, "cone curvatures")?;
        if let Some(beta) = ceiling {
            x = self.held_below(cones, &m, &b, x, beta)?;
        }
        let x: Vec<f64> = x.into_iter().map(|x| x.min(2.0 * PI - 0.05)).collect();
        let mut u = u0;
        for (gc, xc) in g.iter().zip(&x) {
            for v in 0..n {
                u[v] += xc * gc[v];
            }
        }
        let sigma = 2.0 * (dot(&u, &u) / total).sqrt();
        Ok((cones.iter().copied().zip(x).collect(), sigma))
    }

    /// The least-squares curvatures `x` (normal equations `m x = b`) with every cone whose
    /// linearised `u(c)` lies above `ū + β sd(u)` of the unbounded `x` held there: the normal
    /// equations with those conditions as constraints (a KKT system), until no cone is above
    /// (each round holds at least one more, so at most `|C|` rounds).
    fn held_below(
        &self,
        cones: &[u32],
        m: &[Vec<f64>],
        b: &[f64],
        mut x: Vec<f64>,
        beta: f64,
    ) -> Result<Vec<f64>> {
        let (n, k) = (self.lap.n, cones.len());
        let area = &self.lap.area;
        // u(c) = u₀(c) + Σ_j K̄_j g_j(c), uncentred (the held boundary's u = 0).
        let rows: Vec<Vec<f64>> = cones
            .iter()
            .map(|&c| cones.iter().map(|d| self.columns[d][c as usize]).collect())
            .collect();
        let u_at = |x: &[f64], i: usize| {
            self.u0[cones[i] as usize] + rows[i].iter().zip(x).map(|(a, y)| a * y).sum::<f64>()
        };
        let mut u = self.u0.clone();
        for (c, xc) in cones.iter().zip(&x) {
            for (y, gv) in u.iter_mut().zip(&self.columns[c]) {
                *y += xc * gv;
            }
        }
        let mean = (0..n).map(|v| u[v] * area[v]).sum::<f64>() / self.total_area;
        let var = (0..n).map(|v| (u[v] - mean).powi(2) * area[v]).sum::<f64>() / self.total_area;
        let ceiling = mean + beta * var.sqrt();
        let mut hold = vec![false; k];
        for _ in 0..k {
            let above: Vec<usize> = (0..k)
                .filter(|&i| !hold[i] && u_at(&x, i) > ceiling)
                .collect();
            if above.is_empty() {
                break;
            }
            for i in above {
                hold[i] = true;
            }
            let held: Vec<usize> = (0..k).filter(|&i| hold[i]).collect();
            let size = k + held.len();
            let mut a = vec![vec![0.0; size]; size];
            let mut rhs = b.to_vec();
            for (row, mi) in a.iter_mut().zip(m) {
                row[..k].copy_from_slice(mi);
            }
            for (r, &i) in held.iter().enumerate() {
                for j in 0..k {
                    a[k + r][j] = rows[i][j];
                    a[j][k + r] = rows[i][j];
                }
                rhs.push(ceiling - self.u0[cones[i] as usize]);
            }
            x = dense_solve(a, &rhs, "bounded cone curvatures")?;
            x.truncate(k);
        }
        Ok(x)
    }
}
