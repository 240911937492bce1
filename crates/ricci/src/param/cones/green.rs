//! Green's functions of the cotangent Laplacian of a closed surface, for cone placement
//! (Soliman–Slepčev–Crane, "Optimal cone singularities for conformal flattening", 2018, §3–4:
//! the linearised log scale factor of a cone set is `u = w₀ + Σ_c k_c g_c + const`).
//!
//! With one factorization of the (pinned) Laplacian, `g_c` solves `L g_c = δ_c − a/A` and
//! `w₀` solves `L w₀ = −(K⁰ − 2πχ a/A)` (`a` the vertex areas, `A` their sum; both with zero
//! area mean). For cones `C` with curvatures `k` (`Σ k = 2πχ`) the flat-except-at-`C` metric
//! has `L u = −K⁰ + Σ_c k_c δ_c`, i.e. `u = w₀ + Σ_c k_c g_c` up to a constant. Two choices of
//! `k` are solved as `(|C| + 1)²` dense systems:
//!
//! * **Dirichlet** (Ben-Chen–Gotsman–Bunin 2008; BFF's CETM strategy): `u_c = 0` at every
//!   cone — the curvature the cones take when the rest is flattened with `u` pinned at them;
//! * **least squares** (SSC 2018 with the positions fixed): the `k` of least area-weighted
//!   `‖u − ū‖²`.
//!
//! Each new cone costs one triangular solve instead of a new factorization.

use super::Laplacian;
use crate::error::{Error, Result};
use crate::numeric::sparse::SymmetricSolver;
use std::collections::HashMap;
use std::f64::consts::PI;

/// Cone curvatures `(vertex, K̄)` and the linearised log scale factor `u` they give.
pub(super) type ConeField = (Vec<(u32, f64)>, Vec<f64>);

/// Factorization, `w₀`, and the Green's functions computed so far.
pub(super) struct GreenBasis {
    n: usize,
    solver: SymmetricSolver,
    pin: usize,
    used: Vec<bool>,
    pub area: Vec<f64>,
    total_area: f64,
    pub chi: f64,
    pub w0: Vec<f64>,
    columns: HashMap<u32, Vec<f64>>,
    /// Cached `g_aᵀ M g_b` (key `(min, max)`), `g_aᵀ M w₀` and `w₀ᵀ M w₀`.
    gram: HashMap<(u32, u32), f64>,
    gram_w0: HashMap<u32, f64>,
    w0_norm2: f64,
}

impl GreenBasis {
    /// Factorize `lap` with one vertex pinned (`solver`: the symbolic analysis of its
    /// pattern, [`super::laplacian_system`]); `k0` the input's angle defects, `chi` the Euler
    /// characteristic, `used[v]` false for isolated vertices.
    pub fn new(
        lap: &Laplacian,
        k0: &[f64],
        chi: f64,
        used: Vec<bool>,
        mut solver: SymmetricSolver,
    ) -> Result<GreenBasis> {
        let n = lap.n;
        let scale = lap.diag.iter().map(|&i| lap.values[i]).fold(0.0, f64::max);
        let penalty = 1e10 * scale.max(1e-300);
        let pin = (0..n).find(|&v| used[v]).unwrap_or(0);
        let mut vals = lap.values.clone();
        for v in 0..n {
            if v == pin || !used[v] {
                vals[lap.diag[v]] += penalty;
            }
        }
        if !solver.factor_llt(&vals) && !solver.factor_ldlt(&vals) {
            return Err(Error::numerical(
                "the cotangent Laplacian could not be factorized for cone placement",
            ));
        }
        let total_area: f64 = lap.area.iter().sum();
        let mut g = GreenBasis {
            n,
            solver,
            pin,
            used,
            area: lap.area.clone(),
            total_area,
            chi,
            w0: Vec::new(),
            columns: HashMap::new(),
            gram: HashMap::new(),
            gram_w0: HashMap::new(),
            w0_norm2: 0.0,
        };
        let rhs: Vec<f64> = (0..n)
            .map(|v| -(k0[v] - 2.0 * PI * chi * g.area[v] / total_area))
            .collect();
        g.w0 = g.solve_zero_mean(rhs);
        g.w0_norm2 = (0..n).map(|v| g.area[v] * g.w0[v] * g.w0[v]).sum();
        Ok(g)
    }

    /// `x` with `L x = rhs` (rows of the pin and of isolated vertices ignored), shifted to
    /// zero area mean.
    fn solve_zero_mean(&mut self, mut x: Vec<f64>) -> Vec<f64> {
        for (v, y) in x.iter_mut().enumerate() {
            if v == self.pin || !self.used[v] {
                *y = 0.0;
            }
        }
        self.solver.solve(&mut x);
        let m = self.mean(&x);
        for (y, &u) in x.iter_mut().zip(&self.used) {
            *y = if u { *y - m } else { 0.0 };
        }
        x
    }

    /// The adjoint `φ = L⁺ M (u − ū)` (zero area mean) of a field `u`: `φ_v` is the
    /// derivative of `½‖u − ū‖²_M` with respect to curvature added at `v`
    /// (`∂/∂k_v` of `u = w₀ + Σ k g` is `g_v`, and `g_vᵀ M ũ = φ_v`; Soliman–Slepčev–Crane
    /// 2018 §4). At least-squares curvatures `φ` is equal at every cone (the multiplier of
    /// `Σ k = 2πχ`); where it differs most from that value a new cone lowers the energy most
    /// to first order.
    pub fn adjoint(&mut self, u: &[f64]) -> Vec<f64> {
        let m = self.mean(u);
        let rhs: Vec<f64> = (0..self.n)
            .map(|v| {
                if self.used[v] {
                    self.area[v] * (u[v] - m)
                } else {
                    0.0
                }
            })
            .collect();
        self.solve_zero_mean(rhs)
    }

    /// Area-weighted mean.
    pub fn mean(&self, x: &[f64]) -> f64 {
        (0..self.n).map(|v| x[v] * self.area[v]).sum::<f64>() / self.total_area
    }

    /// Area-weighted `σ(2x)` (the spread of the log area ratio `2u`).
    pub fn sigma_2x(&self, x: &[f64]) -> f64 {
        let m = self.mean(x);
        let s: f64 = (0..self.n)
            .map(|v| self.area[v] * (x[v] - m) * (x[v] - m))
            .sum();
        2.0 * (s / self.total_area).max(0.0).sqrt()
    }

    /// The Green's function of vertex `c` (computed once, then cached).
    pub fn column(&mut self, c: u32) -> &[f64] {
        if !self.columns.contains_key(&c) {
            let a = self.total_area;
            let rhs: Vec<f64> = (0..self.n)
                .map(|v| f64::from(u8::from(v == c as usize)) - self.area[v] / a)
                .collect();
            let g = self.solve_zero_mean(rhs);
            self.columns.insert(c, g);
        }
        &self.columns[&c]
    }

    /// `u = w₀ + Σ k_c g_c` (zero area mean).
    pub fn field(&mut self, cones: &[(u32, f64)]) -> Vec<f64> {
        let mut u = self.w0.clone();
        for &(c, k) in cones {
            let g = self.column(c);
            for (x, y) in u.iter_mut().zip(g) {
                *x += k * y;
            }
        }
        u
    }

    /// Cone curvatures with `u = 0` at every cone (module docs), and the field `u` (zero at
    /// the cones).
    pub fn dirichlet(&mut self, cones: &[u32]) -> Result<ConeField> {
        let m = cones.len();
        let mut a = vec![vec![0.0; m + 1]; m + 1];
        let mut rhs = vec![0.0; m + 1];
        for (j, &c) in cones.iter().enumerate() {
            let g = self.column(c).to_vec();
            for (i, &d) in cones.iter().enumerate() {
                a[i][j] = g[d as usize];
            }
        }
        for (i, &d) in cones.iter().enumerate() {
            a[i][m] = 1.0;
            a[m][i] = 1.0;
            rhs[i] = -self.w0[d as usize];
        }
        rhs[m] = 2.0 * PI * self.chi;
        let x = crate::analysis::forms::small::solve(&a, &rhs);
        self.finish(cones, &x, true)
    }

    /// `g_aᵀ M g_b`, computed once.
    fn gram(&mut self, a: u32, b: u32) -> f64 {
        let key = (a.min(b), a.max(b));
        if let Some(&v) = self.gram.get(&key) {
            return v;
        }
        self.column(a);
        self.column(b);
        let (x, y) = (&self.columns[&a], &self.columns[&b]);
        let v: f64 = x
            .iter()
            .zip(y)
            .zip(&self.area)
            .map(|((p, q), w)| p * q * w)
            .sum();
        self.gram.insert(key, v);
        v
    }

    /// `g_aᵀ M w₀`, computed once.
    fn gram_w0(&mut self, a: u32) -> f64 {
        if let Some(&v) = self.gram_w0.get(&a) {
            return v;
        }
        self.column(a);
        let x = &self.columns[&a];
        let v: f64 = x
            .iter()
            .zip(&self.w0)
            .zip(&self.area)
            .map(|((p, q), w)| p * q * w)
            .sum();
        self.gram_w0.insert(a, v);
        v
    }

    /// The area-weighted `σ(2u)` of [`GreenBasis::least_squares`]' field, from the cached
    /// inner products alone (`u = w₀ + Σ k g` has zero area mean, so
    /// `σ² = (w₀ᵀMw₀ + 2 Σ k_c g_cᵀMw₀ + Σ k_a k_b g_aᵀMg_b) / A`): no pass over the
    /// vertices once the cones' Green's functions are known.
    pub fn least_squares_sigma(&mut self, cones: &[u32]) -> Result<f64> {
        let m = cones.len();
        let mut a = vec![vec![0.0; m + 1]; m + 1];
        let mut rhs = vec![0.0; m + 1];
        for i in 0..m {
            for j in i..m {
                let d = self.gram(cones[i], cones[j]);
                a[i][j] = d;
                a[j][i] = d;
            }
            a[i][m] = 1.0;
            a[m][i] = 1.0;
            rhs[i] = -self.gram_w0(cones[i]);
        }
        rhs[m] = 2.0 * PI * self.chi;
        let x = crate::analysis::forms::small::solve(&a, &rhs);
        if x.iter().any(|v| !v.is_finite()) {
            return Err(Error::numerical(
                "the cone curvature system is singular (two cones at one vertex?)",
            ));
        }
        let mut s = self.w0_norm2;
        for i in 0..m {
            s -= 2.0 * x[i] * rhs[i];
            for j in 0..m {
                s += x[i] * x[j] * a[i][j];
            }
        }
        Ok(2.0 * (s.max(0.0) / self.total_area).sqrt())
    }

    /// Cone curvatures of least area-weighted `‖u − ū‖²` at fixed positions (module docs).
    pub fn least_squares(&mut self, cones: &[u32]) -> Result<ConeField> {
        let w0 = self.w0.clone();
        let x = self.least_squares_with(&w0, cones, 2.0 * PI * self.chi)?;
        self.finish(cones, &x, false)
    }

    /// The `k` (one per cone, `Σ k = total`) of least area-weighted `‖base + Σ k_c g_c‖²`
    /// (normal equations `[GᵀMG 1; 1ᵀ 0] [k; λ] = [−GᵀM base; total]`).
    pub fn least_squares_with(
        &mut self,
        base: &[f64],
        cones: &[u32],
        total: f64,
    ) -> Result<Vec<f64>> {
        let m = cones.len();
        let gs: Vec<Vec<f64>> = cones.iter().map(|&c| self.column(c).to_vec()).collect();
        let dot = |x: &[f64], y: &[f64]| -> f64 {
            x.iter()
                .zip(y)
                .zip(&self.area)
                .map(|((p, q), w)| p * q * w)
                .sum()
        };
        let mut a = vec![vec![0.0; m + 1]; m + 1];
        let mut rhs = vec![0.0; m + 1];
        for i in 0..m {
            for j in i..m {
                let d = dot(&gs[i], &gs[j]);
                a[i][j] = d;
                a[j][i] = d;
            }
            a[i][m] = 1.0;
            a[m][i] = 1.0;
            rhs[i] = -dot(&gs[i], base);
        }
        rhs[m] = total;
        let mut x = crate::analysis::forms::small::solve(&a, &rhs);
        if x.iter().any(|v| !v.is_finite()) {
            return Err(Error::numerical(
                "the cone curvature system is singular (two cones at one vertex?)",
            ));
        }
        x.truncate(m);
        Ok(x)
    }

    fn finish(&mut self, cones: &[u32], x: &[f64], pin_cones: bool) -> Result<ConeField> {
        if x.iter().any(|v| !v.is_finite()) {
            return Err(Error::numerical(
                "the cone curvature system is singular (two cones at one vertex?)",
            ));
        }
        let k: Vec<(u32, f64)> = cones.iter().zip(x).map(|(&c, &k)| (c, k)).collect();
        let mut u = self.field(&k);
        if pin_cones {
            // The constant that makes u vanish at the cones (the system's last unknown).
            let t = x[cones.len()];
            for (v, y) in u.iter_mut().enumerate() {
                if self.used[v] {
                    *y += t;
                }
            }
        }
        Ok((k, u))
    }
}
