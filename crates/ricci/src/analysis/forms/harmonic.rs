//! Harmonic 1-forms: the harmonic representative of a closed 1-form's cohomology class
//! (paper 002 §4.2.2, "Hodge decomposition": `ω + df` with `δ(ω + df) = 0`).
//!
//! On a triangle mesh with a Euclidean metric (edge lengths) the codifferential is the one of
//! the cotangent weights `w_e = (cot α + cot β)/2` (α, β the angles opposite `e`):
//! `(δω)_i = Σ_{h: i→j} w_e ω(h)`. The harmonic representative `ω + du` solves the cotangent
//! Laplace equation `L u = δω` (L positive semidefinite with the constants as kernel, made
//! definite by fixing `u` at vertex 0), which is the minimiser of the Dirichlet energy
//! `Σ_e w_e (ω + du)_e²` over the class. L is the Dirichlet energy of piecewise linear
//! functions, positive semidefinite on any triangulation; on an intrinsic Delaunay
//! triangulation its weights are also non-negative (discrete maximum principle, Bobenko–
//! Springborn 2007), the reason the default working triangulation is Delaunay.

use super::cochain::on_halfedge;
use crate::error::{Error, Result};
use crate::mesh::Mesh;
use crate::numeric::sparse::Cholesky;
use faer::sparse::{SparseColMat, Triplet};
use faer::Mat;

/// The cotangent weight `(cot α + cot β)/2` of every edge (α, β the angles opposite it; one
/// term on boundary edges), from the Euclidean edge lengths. Errors on a face whose lengths
/// violate the triangle inequality.
pub(crate) fn cotan_weights(mesh: &Mesh, lengths: &[f64]) -> Result<Vec<f64>> {
    if lengths.len() != mesh.n_edges() {
        return Err(Error::input(format!(
            "{} edge lengths given for a mesh with {} edges",
            lengths.len(),
            mesh.n_edges()
        )));
    }
    let mut w = vec![0.0; mesh.n_edges()];
    for f in 0..mesh.n_faces() as u32 {
        let es = mesh.face_edges_opposite(f);
        let l = es.map(|e| lengths[e as usize]);
        let cots = face_cotangents(l).ok_or_else(|| {
            Error::numerical(format!(
                "face {f} is degenerate (edge lengths {:.3e}, {:.3e}, {:.3e} violate the triangle inequality)",
                l[0], l[1], l[2]
            ))
        })?;
        for i in 0..3 {
            w[es[i] as usize] += 0.5 * cots[i];
        }
    }
    Ok(w)
}

/// Cotangents of the angles of the Euclidean triangle with sides `l` (`l[i]` opposite vertex
/// `i`), `None` when it is degenerate.
pub fn face_cotangents(l: [f64; 3]) -> Option<[f64; 3]> {
    let [a, b, c] = l;
    let s = 0.5 * (a + b + c);
    let area2 = s * (s - a) * (s - b) * (s - c);
    if area2.is_nan() || area2 <= 0.0 || !area2.is_finite() {
        return None;
    }
    let four_area = 4.0 * area2.sqrt();
    Some([
        (b * b + c * c - a * a) / four_area,
        (c * c + a * a - b * b) / four_area,
        (a * a + b * b - c * c) / four_area,
    ])
}

/// `(δω)_v = Σ_{h: v→·} w_e ω(h)` at every vertex (zero for a harmonic form).
pub fn codifferential(mesh: &Mesh, weights: &[f64], w: &[f64]) -> Vec<f64> {
    let mut d = vec![0.0; mesh.n_vertices()];
    for e in 0..mesh.n_edges() as u32 {
        let h = mesh.edge_halfedge(e);
        let x = weights[e as usize] * w[e as usize];
        d[mesh.he_origin(h) as usize] += x;
        d[mesh.he_tip(h) as usize] -= x;
    }
    d
}

/// The cotangent Laplacian of a mesh factored once (vertex 0 fixed), projecting closed
/// 1-forms to their harmonic representatives.
pub struct HarmonicProjector {
    weights: Vec<f64>,
    chol: Cholesky,
    n: usize,
}

impl HarmonicProjector {
    /// Assemble and factor the cotangent Laplacian with vertex 0 removed.
    pub fn new(mesh: &Mesh, weights: &[f64]) -> Result<HarmonicProjector> {
        let n = mesh.n_vertices();
        if n < 2 {
            return Err(Error::input("the mesh needs at least two vertices"));
        }
        let m = n - 1;
        let mut trip = Vec::with_capacity(4 * mesh.n_edges());
        for e in 0..mesh.n_edges() as u32 {
            let [a, b] = mesh.edge_vertices(e);
            let x = weights[e as usize];
            if a == b {
                continue;
            }
            for (i, j, v) in [(a, a, x), (b, b, x), (a, b, -x), (b, a, -x)] {
                if i > 0 && j > 0 {
                    trip.push(Triplet::new(i as usize - 1, j as usize - 1, v));
                }
            }
        }
        let a = SparseColMat::<usize, f64>::try_new_from_triplets(m, m, &trip)
            .map_err(|e| Error::numerical(format!("cotangent Laplacian assembly failed: {e:?}")))?;
        let chol = Cholesky::factor(a.as_ref()).map_err(|e| {
            Error::numerical(format!(
                "the cotangent Laplacian is not positive definite after fixing vertex 0 ({e:?}); \
                 is the mesh connected?"
            ))
        })?;
        Ok(HarmonicProjector {
            weights: weights.to_vec(),
            chol,
            n,
        })
    }

    /// The harmonic representatives `ω_k + du_k` of the closed forms `forms` (one solve with
    /// several right-hand sides).
    pub fn project(&self, mesh: &Mesh, forms: &[Vec<f64>]) -> Vec<Vec<f64>> {
        let k = forms.len();
        let m = self.n - 1;
        let mut rhs = Mat::<f64>::zeros(m, k);
        for (c, w) in forms.iter().enumerate() {
            let d = codifferential(mesh, &self.weights, w);
            for i in 1..self.n {
                rhs[(i - 1, c)] = d[i];
            }
        }
        self.chol.solve_in_place(rhs.as_mut());
        forms
            .iter()
            .enumerate()
            .map(|(c, w)| {
                let u = |v: u32| {
                    if v == 0 {
                        0.0
                    } else {
                        rhs[(v as usize - 1, c)]
                    }
                };
                (0..mesh.n_edges() as u32)
                    .map(|e| {
                        let h = mesh.edge_halfedge(e);
                        w[e as usize] + u(mesh.he_tip(h)) - u(mesh.he_origin(h))
                    })
                    .collect()
            })
            .collect()
    }
}

/// `max_v |(δω)_v| / max_v Σ_e w_e |ω_e|`: the relative harmonicity residual of a form.
pub fn harmonic_residual(mesh: &Mesh, weights: &[f64], w: &[f64]) -> f64 {
    let d = codifferential(mesh, weights, w);
    let mut scale = vec![0.0f64; mesh.n_vertices()];
    for e in 0..mesh.n_edges() as u32 {
        let h = mesh.edge_halfedge(e);
        let x = (weights[e as usize] * on_halfedge(mesh, w, h)).abs();
        scale[mesh.he_origin(h) as usize] += x;
        scale[mesh.he_tip(h) as usize] += x;
    }
    let s = scale.iter().cloned().fold(0.0, f64::max);
    if s == 0.0 {
        return 0.0;
    }
    d.iter().map(|x| x.abs()).fold(0.0, f64::max) / s
}
