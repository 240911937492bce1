//! The most uniform global conformal parameterization (paper 002 §4.2.1, eq. 18–19): the
//! holomorphic form `ω = Σ λ_i ω_i` whose conformal net spreads the parameter area most evenly.
//!
//! The parameter area of face `f` is `a_f(λ) = ∫_f Re ω ∧ Im ω` (exact on the face-constant
//! forms, a quadratic form in the real coordinates `c = (Re λ₁, Im λ₁, …)`); the paper fixes
//! the total `A(λ) = Σ a_f` to the surface area `S` and minimizes
//! `E(λ) = Σ_f (a_f − S_f)²`. Here the constraint is built in by scaling,
//! `r_f(c) = a_f(c)·S/A(c) − S_f`, which is invariant under `λ ↦ tλ` (t ∈ C \ {0}), and
//! `Σ r_f²` is minimized by Levenberg–Marquardt from several starts (each basis form and their
//! sum; the energy is quartic with several local minima, as the paper notes), reported as
//! `E / Σ S_f²`.

use super::cochain::on_halfedge;
use super::harmonic::face_cotangents;
use super::small::{self, Matrix};
use super::{HolomorphicForm, HolomorphicForms};
use crate::error::{Error, Result};
use crate::layout::isometry::Complex;
use serde::Serialize;

/// The result of [`uniform_combination`].
#[derive(Debug, Clone, Serialize)]
pub struct UniformCombination {
    /// `λ`, scaled so that the parameter area equals the surface area.
    #[serde(skip)]
    pub coefficients: Vec<Complex>,
    /// `E / Σ S_f²` at the optimum.
    pub energy: f64,
    /// The same for `ω₁` (area scaled to `S`), for comparison.
    pub energy_first_form: f64,
    pub iterations: usize,
    /// Whether the best start stopped on a small relative decrease (1e-10) rather than on the
    /// iteration budget.
    pub converged: bool,
}

struct Faces {
    n: usize,
    /// Per face: R1, R2, M1, M2 (each `n` coefficients).
    coef: Vec<f64>,
    area: Vec<f64>,
}

impl Faces {
    fn new(h: &HolomorphicForms) -> Result<Faces> {
        let (mesh, lengths) = (h.mesh(), h.lengths());
        let g = h.genus;
        let n = 2 * g;
        let nf = mesh.n_faces();
        let mut coef = vec![0.0; nf * 4 * n];
        let mut area = vec![0.0; nf];
        for f in 0..nf as u32 {
            let hs = mesh.face_halfedges(f);
            let l = mesh.face_edges_opposite(f).map(|e| lengths[e as usize]);
            if face_cotangents(l).is_none() {
                return Err(Error::numerical(format!("face {f} is degenerate")));
            }
            let s = 0.5 * (l[0] + l[1] + l[2]);
            area[f as usize] = (s * (s - l[0]) * (s - l[1]) * (s - l[2])).sqrt();
            let base = f as usize * 4 * n;
            for (i, w) in h.basis.iter().enumerate() {
                for (q, &he) in [hs[0], hs[1]].iter().enumerate() {
                    let re = on_halfedge(mesh, &w.re, he);
                    let im = on_halfedge(mesh, &w.im, he);
                    // Re(λω) = Re λ Re ω − Im λ Im ω; Im(λω) = Re λ Im ω + Im λ Re ω.
                    coef[base + q * n + 2 * i] = re;
                    coef[base + q * n + 2 * i + 1] = -im;
                    coef[base + (2 + q) * n + 2 * i] = im;
                    coef[base + (2 + q) * n + 2 * i + 1] = re;
                }
            }
        }
        Ok(Faces { n, coef, area })
    }

    /// Per face `a_f` and, if asked, its gradient.
    fn eval(&self, c: &[f64], f: usize, grad: Option<&mut [f64]>) -> f64 {
        let n = self.n;
        let b = &self.coef[f * 4 * n..(f + 1) * 4 * n];
        let dot = |k: usize| -> f64 { (0..n).map(|j| b[k * n + j] * c[j]).sum() };
        let (r1, r2, m1, m2) = (dot(0), dot(1), dot(2), dot(3));
        if let Some(gr) = grad {
            for j in 0..n {
                gr[j] = 0.5 * (b[j] * m2 + b[3 * n + j] * r1 - b[n + j] * m1 - b[2 * n + j] * r2);
            }
        }
        0.5 * (r1 * m2 - r2 * m1)
    }

    /// `Σ r_f² / Σ S_f²`.
    fn energy(&self, c: &[f64]) -> f64 {
        let nf = self.area.len();
        let a: Vec<f64> = (0..nf).map(|f| self.eval(c, f, None)).collect();
        let total: f64 = a.iter().sum();
        let s: f64 = self.area.iter().sum();
        let s2: f64 = self.area.iter().map(|x| x * x).sum();
        a.iter()
            .zip(&self.area)
            .map(|(af, sf)| (af * s / total - sf).powi(2))
            .sum::<f64>()
            / s2
    }
}

/// `E / Σ S_f²` of the form `Σ λ_i ω_i` (area scaled to the surface's).
pub fn area_distortion(h: &HolomorphicForms, lambda: &[Complex]) -> Result<f64> {
    if lambda.len() != h.genus {
        return Err(Error::input(format!(
            "{} coefficients given for genus {}",
            lambda.len(),
            h.genus
        )));
    }
    let faces = Faces::new(h)?;
    let c: Vec<f64> = lambda.iter().flat_map(|l| [l.re, l.im]).collect();
    Ok(faces.energy(&c))
}

/// Minimize the area distortion over the holomorphic forms (module docs); `max_iterations`
/// per start.
pub fn uniform_combination(
    h: &HolomorphicForms,
    max_iterations: usize,
) -> Result<(UniformCombination, HolomorphicForm)> {
    let faces = Faces::new(h)?;
    let n = faces.n;
    let nf = faces.area.len();
    let s: f64 = faces.area.iter().sum();
    let mut starts: Vec<Vec<f64>> = (0..h.genus)
        .map(|i| {
            let mut c = vec![0.0; n];
            c[2 * i] = 1.0;
            c
        })
        .collect();
    starts.push((0..n).map(|k| f64::from(u8::from(k % 2 == 0))).collect());
    let first_energy = faces.energy(&starts[0]);
    let mut best: Option<(f64, Vec<f64>, usize, bool)> = None;
    let mut grad = vec![0.0; n];
    for start in starts {
        let mut c = start;
        let mut e = faces.energy(&c);
        let mut mu = 1e-3;
        let (mut it, mut converged) = (0, false);
        while it < max_iterations {
            it += 1;
            // Residuals r_f = a_f S / A − S_f and their gradients.
            let a: Vec<f64> = (0..nf).map(|f| faces.eval(&c, f, None)).collect();
            let total: f64 = a.iter().sum();
            let mut ga = vec![0.0; n];
            let mut grads = vec![0.0; nf * n];
            for f in 0..nf {
                faces.eval(&c, f, Some(&mut grad));
                grads[f * n..(f + 1) * n].copy_from_slice(&grad);
                for j in 0..n {
                    ga[j] += grad[j];
                }
            }
            let mut jtj: Matrix = vec![vec![0.0; n]; n];
            let mut jtr = vec![0.0; n];
            for f in 0..nf {
                let r = a[f] * s / total - faces.area[f];
                let jf: Vec<f64> = (0..n)
                    .map(|j| s * (grads[f * n + j] * total - a[f] * ga[j]) / (total * total))
                    .collect();
                for i in 0..n {
                    jtr[i] += jf[i] * r;
                    for j in 0..n {
                        jtj[i][j] += jf[i] * jf[j];
                    }
                }
            }
            let diag: Vec<f64> = (0..n).map(|i| jtj[i][i]).collect();
            let dmax = diag.iter().cloned().fold(0.0, f64::max).max(1e-300);
            let mut accepted = false;
            for _ in 0..30 {
                let mut m = jtj.clone();
                for i in 0..n {
                    m[i][i] += mu * (diag[i] + 1e-12 * dmax);
                }
                let rhs: Vec<f64> = jtr.iter().map(|x| -x).collect();
                let d = small::solve(&m, &rhs);
                let trial: Vec<f64> = c.iter().zip(&d).map(|(x, y)| x + y).collect();
                let et = faces.energy(&trial);
                if et.is_finite() && et < e {
                    let norm = trial.iter().map(|x| x * x).sum::<f64>().sqrt();
                    let rel = (e - et) / e.max(1e-300);
                    c = trial.iter().map(|x| x / norm).collect();
                    e = et;
                    mu = (mu / 3.0).max(1e-12);
                    accepted = true;
                    if rel < 1e-10 {
                        converged = true;
                    }
                    break;
                }
                mu *= 4.0;
            }
            if !accepted || converged {
                converged = true;
                break;
            }
        }
        if best.as_ref().is_none_or(|b| e < b.0) {
            best = Some((e, c, it, converged));
        }
    }
    let (energy, c, iterations, converged) =
        best.ok_or_else(|| Error::numerical("no start for the area optimization"))?;
    // Scale λ so that the parameter area is S.
    let total: f64 = (0..nf).map(|f| faces.eval(&c, f, None)).sum();
    let t = (s / total.abs().max(1e-300)).sqrt();
    let lambda: Vec<Complex> = (0..h.genus)
        .map(|i| Complex::new(t * c[2 * i], t * c[2 * i + 1]))
        .collect();
    let form = h.combination(&lambda);
    Ok((
        UniformCombination {
            coefficients: lambda,
            energy,
            energy_first_form: first_energy,
            iterations,
            converged,
        },
        form,
    ))
}
