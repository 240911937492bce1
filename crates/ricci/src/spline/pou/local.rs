//! Local polynomial approximants of a partition-of-unity surface (the blend of paper 004 §4
//! made to reproduce polynomials, as in Ying–Zorin's manifold constructions).
//!
//! A blend `Σ wᵢ Pᵢ` of constant control points reproduces only constants (Shepard): between
//! the control points it flattens towards weighted averages, and its reflection lines
//! meander on the scale of a few triangles. Each basis therefore carries a local polynomial
//! `Lᵢ(W) = Pᵢ + Qᵢ(W)` of its own chart coordinate `W` (the lift taken to the origin,
//! [`super::atlas::ControlLift::map`]), `Qᵢ` of degree `1` or `2` without constant term,
//! and `F = Σ wᵢ Lᵢ(Wᵢ)`. The coordinate is scaled by `sᵢ = tanh(rᵢ/2)` (the disk's radius
//! in the chart) so the coefficients are of the size of the surface:
//! `Qᵢ = q₁ X + q₂ Y + q₃ X² + q₄ XY + q₅ Y²`, `X + iY = W/sᵢ`.
//!
//! `Qᵢ` is fitted to the mesh around `cᵢ`: weighted least squares of the full polynomial
//! `a₀ + Qᵢ` on the vertex lifts in the disk of `cᵢ` (at least its two-ring), weighted by
//! the basis itself, with a tiny ridge on the non-constant coefficients (degenerate
//! neighbourhoods fall back towards lower degree instead of blowing up). `a₀` is dropped: the
//! constants `Pᵢ` are fitted globally ([`super::fit`]), with `Σ wᵢ Qᵢ` moved to the right-hand
//! side. Everything is a function of the hyperbolic structure only, so `F` stays C∞ and
//! chart independent.

use faer::linalg::solvers::Solve;
use rayon::prelude::*;

use crate::error::{Error, Result};

use super::surface::{bump, PouBasis};

/// Coefficients `q₁..q₅` of `Qᵢ` per coordinate (`[d][k]`).
pub type LocalPolynomial = [[f64; 5]; 3];

/// Number of non-constant monomials of a local polynomial of `degree` (0, 1 or 2).
pub fn local_terms(degree: usize) -> usize {
    match degree {
        0 => 0,
        1 => 2,
        _ => 5,
    }
}

/// Fit the local polynomials of degree `degree` (0: none, 1: affine, 2: quadratic) to the
/// positions of the atlas' vertices (module docs). Returns an empty vector for degree 0.
pub fn local_fits(basis: &PouBasis, degree: usize) -> Result<Vec<LocalPolynomial>> {
    if degree > 2 {
        return Err(Error::input(format!(
            "the local polynomials have degree 0, 1 or 2, not {degree}"
        )));
    }
    if degree == 0 {
        return Ok(Vec::new());
    }
    let atlas = basis.atlas;
    let nt = local_terms(degree);
    let n = nt + 1;
    (0..atlas.mesh.n_vertices())
        .into_par_iter()
        .map(|i| -> Result<LocalPolynomial> {
            let chart = atlas
                .charts
                .get(i)
                .ok_or_else(|| Error::input(format!("no chart for vertex {i}")))?;
            let (sigma, s) = (basis.sigma[i], basis.sigma[i].sqrt());
            let mut ata = faer::Mat::<f64>::zeros(n, n);
            let mut atb = faer::Mat::<f64>::zeros(n, 3);
            let mut points = 0;
            for c in &chart.controls {
                let w = bump(c.z.norm_sqr(), sigma);
                if w <= 0.0 {
                    continue;
                }
                points += 1;
                let (x, y) = (c.z.re / s, c.z.im / s);
                let m = [1.0, x, y, x * x, x * y, y * y];
                let p = atlas.positions[c.vertex as usize];
                for a in 0..n {
                    for b in 0..n {
                        ata[(a, b)] += w * m[a] * m[b];
                    }
                    for d in 0..3 {
                        atb[(a, d)] += w * m[a] * p[d];
                    }
                }
            }
            if points == 0 {
                return Err(Error::numerical(format!(
                    "vertex {i}: no vertex lies in its disk for the local fit"
                )));
            }
            // Ridge on the non-constant terms, relative to the weight of the data.
            let ridge = 1e-6 * ata[(0, 0)];
            for a in 1..n {
                ata[(a, a)] += ridge;
            }
            let x = ata.partial_piv_lu().solve(&atb);
            let mut q = [[0.0; 5]; 3];
            for d in 0..3 {
                for k in 0..nt {
                    q[d][k] = x[(k + 1, d)];
                }
            }
            if q.iter().flatten().any(|v| !v.is_finite()) {
                return Err(Error::numerical(format!(
                    "vertex {i}: the local polynomial fit is singular"
                )));
            }
            Ok(q)
        })
        .collect()
}
