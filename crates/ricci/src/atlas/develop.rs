//! Development of a set of faces of a flat cone surface into the plane (paper 000 §4 Step 5):
//! breadth-first placement across shared edges, one coordinate per surface vertex, never
//! across a singular vertex (faces incident to one are not in the set), with every placement
//! checked.
//!
//! A face is *accepted* into the chart when its third vertex is placed from the shared edge
//! (its two new sides then reproduce the metric exactly up to rounding), or, when all three
//! vertices are already placed, when its three sides reproduce the metric within `tol`
//! (the development closed up consistently). A face whose closure is inconsistent — the
//! region winds around a cone or a boundary hole with non-trivial holonomy — is rejected:
//! the chart stays an embedded-in-pieces development where every pair of faces adjacent in
//! the chart shares the coordinates of its common edge (one coordinate per vertex).

use crate::layout::Space;
use crate::mesh::{Mesh, NONE};
use crate::metric::Euclidean;
use num_complex::Complex64 as C;
use std::collections::{HashMap, VecDeque};

/// A developed chart: faces with the plane coordinates of their corners.
#[derive(Debug, Clone, Default)]
pub struct Development {
    /// Accepted faces, in placement order (the first is the seed).
    pub faces: Vec<u32>,
    /// Corner coordinates of `faces[k]` in the corner order of [`Mesh::face`].
    pub coords: Vec<[[f64; 2]; 3]>,
    /// Faces of the region that were rejected because they did not close up consistently.
    pub rejected: usize,
    /// Largest |(distance in the chart) − (metric length)| over the sides of accepted faces.
    pub max_length_error: f64,
}

/// Develop the faces with `in_region[f]` true, starting from `seed` (which must be in the
/// region), with the flat metric `lengths` (by edge id). `tol` is the absolute tolerance of
/// the closure checks.
pub(crate) fn develop(
    mesh: &Mesh,
    lengths: &[f64],
    in_region: &[bool],
    seed: u32,
    tol: f64,
) -> Development {
    let mut out = Development::default();
    if !in_region.get(seed as usize).copied().unwrap_or(false) {
        return out;
    }
    let len = |h: u32| lengths[mesh.he_edge(h) as usize];
    let mut pos: HashMap<u32, C> = HashMap::new();
    let mut accepted: HashMap<u32, ()> = HashMap::new();
    let [h0, h1, h2] = mesh.face_halfedges(seed);
    let tri = <Euclidean as Space>::seed(len(h0), len(h1), len(h2));
    let fv = mesh.face(seed);
    for i in 0..3 {
        pos.insert(fv[i], tri[i]);
    }
    accepted.insert(seed, ());
    out.faces.push(seed);
    let mut queue = VecDeque::new();
    queue.push_back(seed);
    let mut tried: HashMap<u32, u8> = HashMap::new();
    while let Some(f) = queue.pop_front() {
        for h in mesh.face_halfedges(f) {
            let t = mesh.he_twin(h);
            let g = mesh.he_face(t);
            if g == NONE || !in_region[g as usize] || accepted.contains_key(&g) {
                continue;
            }
            let n = tried.entry(g).or_insert(0);
            *n += 1;
            if *n > 3 {
                continue;
            }
            // g = (i, j, k) counter-clockwise with t = i → j.
            let (i, j) = (mesh.he_origin(t), mesh.he_tip(t));
            let k = mesh.he_tip(mesh.he_next(t));
            let (pi, pj) = (pos[&i], pos[&j]);
            let pk = <Euclidean as Space>::third(
                pi,
                pj,
                len(t),
                len(mesh.he_next(t)),
                len(mesh.he_prev(t)),
            );
            let ok = match pos.get(&k) {
                None => {
                    pos.insert(k, pk);
                    true
                }
                Some(&q) => (q - pk).norm() <= tol,
            };
            if ok {
                accepted.insert(g, ());
                out.faces.push(g);
                queue.push_back(g);
            }
        }
    }
    out.rejected = in_region.iter().filter(|&&b| b).count() - out.faces.len();
    out.coords = out
        .faces
        .iter()
        .map(|&f| {
            let v = mesh.face(f);
            let mut c = [[0.0; 2]; 3];
            for i in 0..3 {
                let p = pos[&v[i]];
                c[i] = [p.re, p.im];
            }
            c
        })
        .collect();
    for (k, &f) in out.faces.iter().enumerate() {
        out.max_length_error =
            out.max_length_error
                .max(face_length_error(mesh, lengths, f, &out.coords[k]));
    }
    out
}

/// Largest |(side in the coordinates) − (metric length)| of face `f`.
pub(crate) fn face_length_error(mesh: &Mesh, lengths: &[f64], f: u32, c: &[[f64; 2]; 3]) -> f64 {
    let hs = mesh.face_halfedges(f);
    let mut err: f64 = 0.0;
    for i in 0..3 {
        let (a, b) = (c[i], c[(i + 1) % 3]);
        let d = ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2)).sqrt();
        err = err.max((d - lengths[mesh.he_edge(hs[i]) as usize]).abs());
    }
    err
}

/// Twice the signed area of a triangle (positive: counter-clockwise).
pub fn signed_area2(c: &[[f64; 2]; 3]) -> f64 {
    (c[1][0] - c[0][0]) * (c[2][1] - c[0][1]) - (c[1][1] - c[0][1]) * (c[2][0] - c[0][0])
}
