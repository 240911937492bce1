//! The Hodge star on harmonic 1-forms, as a matrix on the cohomology (paper 002 §4.2.2,
//! "conjugate harmonic 1-form"; Gu–Yau 2003 §4).
//!
//! For a basis `ζ_1 … ζ_2g` of harmonic 1-forms two matrices carry everything:
//! * the **energy Gram matrix** `G_kl = ∫ ⟨ζ_k, ζ_l⟩ dA = Σ_e w_e ζ_k(e) ζ_l(e)` (the forms are
//!   constant on each face, so the integral is exact with the cotangent weights), symmetric
//!   positive definite;
//! * the **wedge (cup product) matrix** `W_kl = ∫ ζ_k ∧ ζ_l = Σ_f ½ (a₁b₂ − a₂b₁)` (`a₁, a₂`
//!   the values of `ζ_k` on the first two half-edges of face `f`); it depends only on the
//!   cohomology classes and equals the intersection form of their periods exactly.
//!
//! Since `⟨β, *α⟩ dA = α ∧ β`, the harmonic form nearest to `*ζ_k` in the energy norm is
//! `Σ_l S_lk ζ_l` with `G S = Wᵀ = −W`: **`S = −G⁻¹ W`** (Gu–Yau's least-squares conjugate).
//! In the smooth limit `S² = −1`; on a mesh `S` is `G`-skew, so its eigenvalues are `±iμ_k`
//! with `μ_k ≈ 1`, and `‖S² + 1‖` measures the discretization error of the conformal
//! structure. The **complex structure** `J = S (−S²)^{-1/2}` (same eigenvectors, `μ_k ↦ 1`)
//! satisfies `J² = −1` exactly and keeps `W J` symmetric positive definite, so the period
//! matrix built from it is exactly symmetric with positive definite imaginary part
//! (Riemann's bilinear relations); it is computed by the Newton iteration
//! `J ← (J − J⁻¹)/2`, which sends `iμ ↦ i(μ + 1/μ)/2 → i` quadratically.

use super::cochain::on_halfedge;
use super::small::{self, Matrix};
use crate::error::{Error, Result};
use crate::mesh::Mesh;

/// `G_kl = Σ_e w_e ζ_k(e) ζ_l(e)`.
pub fn energy_gram(weights: &[f64], forms: &[Vec<f64>]) -> Matrix {
    let n = forms.len();
    let mut g = vec![vec![0.0; n]; n];
    for k in 0..n {
        for l in k..n {
            let s: f64 = weights
                .iter()
                .zip(&forms[k])
                .zip(&forms[l])
                .map(|((w, a), b)| w * a * b)
                .sum();
            g[k][l] = s;
            g[l][k] = s;
        }
    }
    g
}

/// `W_kl = ∫ ζ_k ∧ ζ_l` (exact cup product on the faces).
pub fn wedge_matrix(mesh: &Mesh, forms: &[Vec<f64>]) -> Matrix {
    let n = forms.len();
    let mut vals = vec![[0.0f64; 2]; n];
    let mut w = vec![vec![0.0; n]; n];
    for f in 0..mesh.n_faces() as u32 {
        for (k, form) in forms.iter().enumerate() {
            vals[k] = [
                on_halfedge(mesh, form, 3 * f),
                on_halfedge(mesh, form, 3 * f + 1),
            ];
        }
        for k in 0..n {
            for l in (k + 1)..n {
                let x = 0.5 * (vals[k][0] * vals[l][1] - vals[k][1] * vals[l][0]);
                w[k][l] += x;
                w[l][k] -= x;
            }
        }
    }
    w
}

/// The least-squares Hodge star on the basis: `S = −G⁻¹ W`.
pub fn star_matrix(gram: &Matrix, wedge: &Matrix) -> Result<Matrix> {
    let ginv = small::inverse(gram, "energy Gram")?;
    let mut s = small::mul(&ginv, wedge);
    for r in &mut s {
        for x in r {
            *x = -*x;
        }
    }
    Ok(s)
}

/// `max |S² + 1|`.
pub fn star_defect(s: &Matrix) -> f64 {
    let s2 = small::mul(s, s);
    let mut m = s2.clone();
    for (i, r) in m.iter_mut().enumerate() {
        r[i] += 1.0;
    }
    m.iter().flatten().map(|x| x.abs()).fold(0.0, f64::max)
}

/// The complex structure `J = S (−S²)^{-1/2}` (module docs), with the number of Newton
/// iterations used. Errors when 60 iterations do not bring `‖J² + 1‖` below 1e-13.
pub fn complex_structure(s: &Matrix) -> Result<(Matrix, usize)> {
    let mut j = s.clone();
    for it in 0..60 {
        if star_defect(&j) < 1e-13 {
            return Ok((j, it));
        }
        let inv = small::inverse(&j, "Hodge star")?;
        for (r, ri) in j.iter_mut().zip(&inv) {
            for (x, y) in r.iter_mut().zip(ri) {
                *x = 0.5 * (*x - y);
            }
        }
    }
    Err(Error::numerical(format!(
        "the complex structure iteration did not converge in 60 steps (‖J² + 1‖ = {:.1e})",
        star_defect(&j)
    )))
}
