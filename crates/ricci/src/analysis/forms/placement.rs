//! Holomorphic 1-forms with zeros at chosen vertices (paper 002 §4.2.4, "zero points
//! allocation", eq. 26–27).
//!
//! A form `ω = Σ λ_i ω_i` vanishes at `p` when its value there is 0: one complex linear
//! condition on `λ ∈ C^g`. With `n ≤ g − 1` points the forms vanishing at all of them form a
//! space of complex dimension `≥ g − n ≥ 1` (Riemann–Roch; exactly `g − n` for points in
//! general position), so up to `g − 1` zeros can be placed exactly; the remaining
//! `2g − 2 − n` are then determined by the conformal structure. As in the paper, the form
//! minimizes `Σ_k |ω(p_k)|²`, here under the normalization `‖Re ω‖² = 1` (Dirichlet
//! energy), i.e. the smallest generalized eigenvector; more than `g − 1` points give the
//! least-squares compromise (reported by the residual).
//!
//! The value of a discrete form at a vertex `v` (the paper's formula is garbled in the text)
//! is the area-weighted mean of its face vectors around `v`, each rotated into a common
//! tangent frame at `v` (the angle of a face's first edge at `v` is the cumulative corner
//! angle scaled by `2π / Σθ`, the frame of a cone of angle `Σθ` opened flat).

use super::cochain::on_halfedge;
use super::small::{self, Matrix};
use super::{HolomorphicForm, HolomorphicForms};
use crate::error::{Error, Result};
use crate::layout::isometry::Complex;
use crate::mesh::Mesh;
use std::f64::consts::PI;

/// The value of the face-constant field of the closed form `w` at vertex `v` in the common
/// tangent frame at `v`, as `(x, y)`.
pub(crate) fn vertex_value(mesh: &Mesh, lengths: &[f64], w: &[f64], v: u32) -> Result<[f64; 2]> {
    if v as usize >= mesh.n_vertices() || mesh.is_isolated(v) {
        return Err(Error::input(format!(
            "vertex {v} is not a vertex of the surface"
        )));
    }
    if mesh.is_boundary_vertex(v) {
        return Err(Error::input(format!("vertex {v} lies on the boundary")));
    }
    let h0 = mesh.vertex_halfedge(v);
    let mut items = Vec::new();
    let mut psi = 0.0;
    let mut h = h0;
    for _ in 0..=mesh.valence(v) {
        let f = h / 3;
        let i = h % 3;
        let hs = mesh.face_halfedges(f);
        // Lengths of the edges from the corner at v: along h (to v_{i+1}) and back (v_{i+2}).
        let a = lengths[mesh.he_edge(h) as usize];
        let b = lengths[mesh.he_edge(hs[((i + 1) % 3) as usize]) as usize];
        let c = lengths[mesh.he_edge(hs[((i + 2) % 3) as usize]) as usize];
        let cos = ((a * a + c * c - b * b) / (2.0 * a * c)).clamp(-1.0, 1.0);
        let theta = cos.acos();
        // Field in the frame with h along +x: w·(a, 0) = ω(h), w·(c cos θ, c sin θ) = −ω(prev h).
        let wh = on_halfedge(mesh, w, h);
        let wp = -on_halfedge(mesh, w, mesh.he_prev(h));
        let wx = wh / a;
        let wy = (wp - wx * c * theta.cos()) / (c * theta.sin());
        let area = 0.5 * a * c * theta.sin();
        items.push((psi, [wx, wy], area));
        psi += theta;
        h = mesh.he_twin(mesh.he_prev(h));
        if h == h0 {
            break;
        }
    }
    let scale = 2.0 * PI / psi;
    let (mut x, mut y, mut total) = (0.0, 0.0, 0.0);
    for (p, [wx, wy], area) in items {
        let (s, c) = (p * scale).sin_cos();
        x += area * (c * wx - s * wy);
        y += area * (s * wx + c * wy);
        total += area;
    }
    Ok([x / total, y / total])
}

/// A holomorphic form of the basis' span with zeros at `vertices` (module docs): the complex
/// coefficients `λ` (normalized: `‖Re ω‖² = 1`), the form, and the residual
/// `max_k |ω(p_k)| / max_v |ω(v)|`-type relative size `√(Σ|ω(p_k)|²) / ‖ω‖`.
pub fn form_with_zeros(
    h: &HolomorphicForms,
    vertices: &[u32],
) -> Result<(Vec<Complex>, HolomorphicForm, f64)> {
    let g = h.genus;
    if vertices.is_empty() {
        return Err(Error::input("no zero position was given"));
    }
    if vertices.len() > g {
        return Err(Error::input(format!(
            "{} zero positions given; a genus-{g} surface allows at most {} (at most g − 1 exactly)",
            vertices.len(),
            g
        )));
    }
    let (mesh, lengths) = (h.mesh(), h.lengths());
    // Columns: c = (Re λ_1, Im λ_1, …); Re(λ ω_i) = Re λ Re ω_i − Im λ Im ω_i.
    let n = 2 * g;
    let mut rows: Vec<Vec<f64>> = Vec::new();
    for &v in vertices {
        if v as usize >= mesh.n_vertices() {
            return Err(Error::input(format!(
                "zero position {v} is not a vertex (the surface has {} vertices)",
                mesh.n_vertices()
            )));
        }
        let mut rx = vec![0.0; n];
        let mut ry = vec![0.0; n];
        for (i, w) in h.basis.iter().enumerate() {
            let re = vertex_value(mesh, lengths, &w.re, v)?;
            let im = vertex_value(mesh, lengths, &w.im, v)?;
            rx[2 * i] = re[0];
            ry[2 * i] = re[1];
            rx[2 * i + 1] = -im[0];
            ry[2 * i + 1] = -im[1];
        }
        rows.push(rx);
        rows.push(ry);
    }
    let mut m: Matrix = vec![vec![0.0; n]; n];
    for r in &rows {
        for i in 0..n {
            for j in 0..n {
                m[i][j] += r[i] * r[j];
            }
        }
    }
    // Energy of Re ω in the coordinates c.
    let parts: Vec<&Vec<f64>> = h.basis.iter().flat_map(|w| [&w.re, &w.im]).collect();
    let mut e: Matrix = vec![vec![0.0; n]; n];
    for i in 0..n {
        for j in i..n {
            let s: f64 = h
                .weights
                .iter()
                .zip(parts[i])
                .zip(parts[j])
                .map(|((w, a), b)| w * a * b)
                .sum();
            let sign = if (i % 2 == 1) ^ (j % 2 == 1) {
                -1.0
            } else {
                1.0
            };
            e[i][j] = sign * s;
            e[j][i] = sign * s;
        }
    }
    // E^{-1/2} M E^{-1/2}, smallest eigenvector.
    let (ev, evec) = small::symmetric_eigen(&e)?;
    if ev[0].is_nan() || ev[0] <= 0.0 {
        return Err(Error::numerical(
            "the energy of the basis is not positive definite",
        ));
    }
    let mut eh: Matrix = vec![vec![0.0; n]; n];
    for k in 0..n {
        let s = 1.0 / ev[k].sqrt();
        for i in 0..n {
            for j in 0..n {
                eh[i][j] += s * evec[k][i] * evec[k][j];
            }
        }
    }
    let b = small::mul(&small::mul(&eh, &m), &eh);
    let (bv, bvec) = small::symmetric_eigen(&b)?;
    let c: Vec<f64> = (0..n)
        .map(|i| (0..n).map(|j| eh[i][j] * bvec[0][j]).sum())
        .collect();
    let lambda: Vec<Complex> = (0..g)
        .map(|i| Complex::new(c[2 * i], c[2 * i + 1]))
        .collect();
    let form = h.combination(&lambda);
    Ok((lambda, form, bv[0].max(0.0).sqrt()))
}
