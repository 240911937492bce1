//! The forms of a double computed on a σ-symmetric triangulation, so that the discretization
//! itself commutes with the reflection (paper 003 §2; issue 17).
//!
//! The closed-surface pipeline computes the harmonic forms on the cut's refined mesh `R`,
//! whose refinement (the valence raised at the base vertex, chord edges split along the loops)
//! is not σ-symmetric: the period matrix of the reflected basis then equals `−Ω̄` only to the
//! discretization's asymmetry. Here the forms are recomputed on the working triangulation `W`
//! (the intrinsic Delaunay triangulation of the double — σ-symmetric, since `σ` is an isometry
//! and the Delaunay triangulation is unique up to ties; checked face by face, not assumed):
//!
//! 1. `σ` on `W`'s vertices: the double's `σ`, extended to vertices the simplicial
//!    conversion inserted by propagation across faces, then checked (every face maps to a
//!    face with reversed orientation and equal edge lengths).
//! 2. The closed forms `ζ_k` of `R` (dual to the canonical loops) restricted to `W`: `R` only
//!    splits `W`'s edges and faces, so every edge of `W` is a path of `R` along which `ζ_k`
//!    is summed; the classes (periods) do not change.
//! 3. Harmonic projection, Hodge star, complex structure and period matrix on `W`
//!    ([`super::forms_of_closed`]): `σ^*` preserves the cotangent weights and the energy and
//!    reverses the wedge product exactly, so the star anticommutes with `σ^*`.
//! 4. `σ^*` on the harmonic forms of `W`, expressed in their basis (`σ^*ζ_k = Σ_m C_mk ζ_m`,
//!    Gram solve, residual reported): `N = Cᵀ` is the reflection on homology, with no loop
//!    mapped.
//! 5. The forms carried back to `R` by linear interpolation on the faces of `W` (a `W`-form is
//!    the differential of a linear function on each face; `R`'s vertices lie on `W`'s faces at
//!    known barycentric coordinates): closed, same periods, constant on every face of `W`, so
//!    the zeros (indices) and the energies are those of `W`.

use super::cochain::on_halfedge;
use super::small::{self, Matrix};
use super::{forms_of_closed, hodge, HolomorphicForm, HolomorphicForms};
use crate::error::{Error, Result};
use crate::mesh::{Mesh, NONE};
use crate::metric::refine::Refined;
use crate::progress::Progress;
use std::collections::HashMap;

/// `σ` on the working triangulation and the reflection on homology computed there.
#[derive(Debug, Clone)]
pub(crate) struct Symmetric {
    /// `σ_* γ_l = Σ_k N_kl γ_k` before rounding.
    pub n: Matrix,
    /// `max_k |σ^*ζ_k − Σ_m C_mk ζ_m| / max |ζ_k|` on `W` (0 up to rounding when `σ` is a
    /// symmetry of the discretization).
    pub residual: f64,
}

/// `σ` on the vertices of the closed mesh `w` extended from `known` (`σ` of its first
/// vertices) across faces, if it is an orientation-reversing isometry of `(w, lengths)`;
/// `None` otherwise.
pub(crate) fn extend_symmetry(w: &Mesh, lengths: &[f64], known: &[u32]) -> Option<Vec<u32>> {
    let nv = w.n_vertices();
    if known.len() > nv {
        return None;
    }
    let mut sig = vec![NONE; nv];
    sig[..known.len()].copy_from_slice(known);
    loop {
        let mut changed = false;
        for h in 0..w.n_halfedges() as u32 {
            let (a, b) = (w.he_origin(h), w.he_tip(h));
            let c = w.he_tip(w.he_next(h));
            let (sa, sb) = (sig[a as usize], sig[b as usize]);
            if sa == NONE || sb == NONE || sig[c as usize] != NONE {
                continue;
            }
            let g = w.halfedge_between(sb, sa)?;
            sig[c as usize] = w.he_tip(w.he_next(g));
            changed = true;
        }
        if !changed {
            break;
        }
    }
    let mut hit = vec![false; nv];
    for &s in &sig {
        if s == NONE || s as usize >= nv || std::mem::replace(&mut hit[s as usize], true) {
            return None;
        }
    }
    for h in 0..w.n_halfedges() as u32 {
        let (a, b) = (w.he_origin(h), w.he_tip(h));
        let c = w.he_tip(w.he_next(h));
        let g = w.halfedge_between(sig[b as usize], sig[a as usize])?;
        if w.he_tip(w.he_next(g)) != sig[c as usize] {
            return None;
        }
        let (x, y) = (
            lengths[w.he_edge(h) as usize],
            lengths[w.he_edge(g) as usize],
        );
        if (x - y).abs() > 1e-9 * x.max(y) {
            return None;
        }
    }
    Some(sig)
}

/// `σ^*w` for the 1-form `w` on `mesh`: `(σ^*w)(a→b) = w(σa→σb)`.
fn pull_back(mesh: &Mesh, sig: &[u32], w: &[f64]) -> Vec<f64> {
    (0..mesh.n_edges() as u32)
        .map(|e| {
            let [a, b] = mesh.edge_vertices(e);
            mesh.halfedge_between(sig[a as usize], sig[b as usize])
                .map_or(f64::NAN, |h| on_halfedge(mesh, w, h))
        })
        .collect()
}

/// For every vertex of `r` lying on an edge of `w` (inside it): the edge and the fraction of
/// its length from its first vertex.
fn on_edges(r: &Refined, w: &Mesh) -> Vec<Option<(u32, f64)>> {
    let nw = r.original_vertices;
    let mut on: Vec<Option<(u32, f64)>> = vec![None; r.mesh.n_vertices()];
    // The edge of `w` and the fraction at `v` if `v` is on that edge (or one of its ends).
    let at = |on: &[Option<(u32, f64)>], v: u32, e: u32| -> Option<f64> {
        if (v as usize) < nw {
            let [a, b] = w.edge_vertices(e);
            return (v == a).then_some(0.0).or((v == b).then_some(1.0));
        }
        on[v as usize].and_then(|(f, s)| (f == e).then_some(s))
    };
    for (k, s) in r.new_vertices.iter().enumerate() {
        let (a, b) = (s.a, s.b);
        let edge = match (a as usize) < nw {
            true if (b as usize) < nw => w.halfedge_between(a, b).map(|h| w.he_edge(h)),
            true => on[b as usize].map(|x| x.0),
            false => on[a as usize].map(|x| x.0),
        };
        if let Some(e) = edge {
            if let (Some(sa), Some(sb)) = (at(&on, a, e), at(&on, b, e)) {
                on[nw + k] = Some((e, (1.0 - s.t) * sa + s.t * sb));
            }
        }
    }
    on
}

/// The closed 1-form `z` of the refinement `r` of `w` summed along every edge of `w`.
fn restrict(
    r: &Refined,
    w: &Mesh,
    lw: &[f64],
    on: &[Option<(u32, f64)>],
    z: &[f64],
) -> Result<Vec<f64>> {
    let nw = r.original_vertices;
    let mut out = vec![0.0; w.n_edges()];
    let mut covered = vec![0.0; w.n_edges()];
    let rm = &r.mesh;
    for er in 0..rm.n_edges() as u32 {
        let [u, v] = rm.edge_vertices(er);
        let place = |x: u32, e: u32| -> Option<f64> {
            if (x as usize) < nw {
                let [a, b] = w.edge_vertices(e);
                (x == a).then_some(0.0).or((x == b).then_some(1.0))
            } else {
                on[x as usize].and_then(|(f, s)| (f == e).then_some(s))
            }
        };
        let edge = if (u as usize) < nw && (v as usize) < nw {
            w.halfedge_between(u, v).map(|h| w.he_edge(h))
        } else if (u as usize) >= nw {
            on[u as usize].map(|x| x.0)
        } else {
            on[v as usize].map(|x| x.0)
        };
        let Some(e) = edge else { continue };
        let (Some(su), Some(sv)) = (place(u, e), place(v, e)) else {
            continue;
        };
        let sign = if sv > su { 1.0 } else { -1.0 };
        out[e as usize] += sign * z[er as usize];
        covered[e as usize] += r.lengths[er as usize];
    }
    let bad = (0..w.n_edges()).find(|&e| (covered[e] - lw[e]).abs() > 1e-9 * lw[e]);
    if let Some(e) = bad {
        return Err(Error::numerical(format!(
            "edge {e} of the working triangulation is not a path of the cut's refinement"
        )));
    }
    Ok(out)
}

/// Barycentric coordinates of the vertices of `r` in the faces of `w` (memoized).
struct Barycentric<'a> {
    r: &'a Refined,
    w: &'a Mesh,
    memo: HashMap<(u32, u32), Option<[f64; 3]>>,
}

impl Barycentric<'_> {
    fn get(&mut self, f: u32, v: u32) -> Option<[f64; 3]> {
        if let Some(x) = self.memo.get(&(f, v)) {
            return *x;
        }
        let nw = self.r.original_vertices;
        let out = if (v as usize) < nw {
            let hs = self.w.face_halfedges(f);
            hs.iter().position(|&h| self.w.he_origin(h) == v).map(|i| {
                let mut x = [0.0; 3];
                x[i] = 1.0;
                x
            })
        } else {
            let s = self.r.new_vertices[v as usize - nw];
            match (self.get(f, s.a), self.get(f, s.b)) {
                (Some(x), Some(y)) => {
                    Some(std::array::from_fn(|i| (1.0 - s.t) * x[i] + s.t * y[i]))
                }
                _ => None,
            }
        };
        self.memo.insert((f, v), out);
        out
    }
}

/// The 1-forms `forms` of `w` carried to its refinement `r` (module docs, step 5).
fn transfer(r: &Refined, w: &Mesh, forms: &[&[f64]]) -> Result<Vec<Vec<f64>>> {
    let rm = &r.mesh;
    let mut bary = Barycentric {
        r,
        w,
        memo: HashMap::new(),
    };
    let mut out = vec![vec![0.0; rm.n_edges()]; forms.len()];
    for e in 0..rm.n_edges() as u32 {
        let h = rm.edge_halfedge(e);
        let f = r.face_origin[rm.he_face(h) as usize];
        let [u, v] = rm.edge_vertices(e);
        let (Some(bu), Some(bv)) = (bary.get(f, u), bary.get(f, v)) else {
            return Err(Error::numerical(format!(
                "vertex {u} or {v} of the cut's refinement is not on face {f} of the working \
                 triangulation"
            )));
        };
        let hs = w.face_halfedges(f);
        for (k, z) in forms.iter().enumerate() {
            let p1 = on_halfedge(w, z, hs[0]);
            let pot = [0.0, p1, p1 + on_halfedge(w, z, hs[1])];
            out[k][e as usize] = (0..3).map(|i| (bv[i] - bu[i]) * pot[i]).sum();
        }
    }
    Ok(out)
}

/// Recompute the forms of the double on its working triangulation (module docs). `sigma` is
/// `σ` on the double's vertices (the working triangulation's first vertices). `Ok(None)` when
/// the working triangulation is not σ-symmetric (the forms are left as they are).
pub(crate) fn symmetrize(
    h: &mut HolomorphicForms,
    sigma: &[u32],
    progress: &mut dyn Progress,
) -> Result<Option<Symmetric>> {
    let (w, lw) = (&h.working.mesh, &h.working.lengths);
    let Some(sig) = extend_symmetry(w, lw, sigma) else {
        return Ok(None);
    };
    let r = &h.cut.refined;
    let on = on_edges(r, w);
    let zeta0 = h
        .harmonic
        .iter()
        .map(|z| restrict(r, w, lw, &on, z))
        .collect::<Result<Vec<_>>>()?;
    let lf = forms_of_closed(w, lw, &zeta0, progress)?;
    let n = 2 * h.genus;
    // σ^*ζ_k in the basis: G c = (⟨ζ_m, σ^*ζ_k⟩)_m.
    let ginv = small::inverse(&lf.gram, "energy Gram")?;
    // Row k of N: the coordinates of σ^*ζ_k (N_kl = ∫_{σγ_l} ζ_k = ∫_{γ_l} σ^*ζ_k).
    let mut nm: Matrix = Vec::with_capacity(n);
    let mut residual: f64 = 0.0;
    for zk in &lf.harmonic {
        let s = pull_back(w, &sig, zk);
        let rhs: Vec<f64> = lf
            .harmonic
            .iter()
            .map(|zm| {
                lf.weights
                    .iter()
                    .zip(zm)
                    .zip(&s)
                    .map(|((x, y), z)| x * y * z)
                    .sum()
            })
            .collect();
        let row: Vec<f64> = ginv
            .iter()
            .map(|gi| gi.iter().zip(&rhs).map(|(a, b)| a * b).sum())
            .collect();
        let scale = zk.iter().fold(0.0f64, |a, x| a.max(x.abs()));
        for (e, se) in s.iter().enumerate() {
            let fit: f64 = row.iter().zip(&lf.harmonic).map(|(c, zm)| c * zm[e]).sum();
            residual = residual.max((se - fit).abs() / scale.max(1e-300));
        }
        nm.push(row);
    }
    // Carry everything to the refined mesh.
    let harmonic_refs: Vec<&[f64]> = lf.harmonic.iter().map(|z| z.as_slice()).collect();
    let harmonic = transfer(r, w, &harmonic_refs)?;
    let combine = |coords: &[f64]| -> Vec<f64> {
        let mut z = vec![0.0; r.mesh.n_edges()];
        for (k, zk) in harmonic.iter().enumerate() {
            for (a, b) in z.iter_mut().zip(zk) {
                *a += coords[k] * b;
            }
        }
        z
    };
    let j = &lf.complex_structure;
    h.basis = lf
        .basis_coordinates
        .iter()
        .map(|x| {
            let jx: Vec<f64> = j
                .iter()
                .map(|row| row.iter().zip(x).map(|(a, b)| a * b).sum())
                .collect();
            HolomorphicForm {
                re: combine(x),
                im: combine(&jx),
            }
        })
        .collect();
    let rep = &mut h.report;
    rep.negative_weights = lf.negative_weights;
    rep.closedness = lf.closedness;
    rep.harmonic_residual = lf.harmonic_residual;
    rep.wedge_integrality = lf.wedge_integrality;
    rep.star_defect = hodge::star_defect(&lf.star);
    rep.raw_asymmetry = lf.raw_asymmetry;
    rep.complex_structure_iterations = lf.iterations;
    h.harmonic = harmonic;
    h.gram = lf.gram;
    h.wedge = lf.wedge;
    h.star = lf.star;
    h.complex_structure = lf.complex_structure;
    h.basis_coordinates = lf.basis_coordinates;
    h.period_matrix = lf.period_matrix;
    Ok(Some(Symmetric { n: nm, residual }))
}
