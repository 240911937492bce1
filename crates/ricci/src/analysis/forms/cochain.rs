//! Discrete 1-forms (1-cochains) on the edges of a closed triangle mesh, and the closed
//! 1-form Poincaré dual to a simple edge loop (paper 002 §4.2.1: "a closed 1-form whose
//! integral along a closed curve counts its crossings with the loop").
//!
//! A 1-form is stored per edge: `w[e]` is its integral along the half-edge
//! [`Mesh::edge_halfedge`]`(e)`; the opposite half-edge carries `−w[e]`. It is **closed** when
//! its integral around every face vanishes, and its cohomology class is then determined by its
//! periods, the integrals along the loops of a homology basis.
//!
//! The dual of a simple loop `γ` is `d` of the function that is 1 on the *left* copy of `γ`'s
//! vertices (the surface cut open along `γ`) and 0 elsewhere: on a half-edge leaving a vertex
//! of `γ` into the fan strictly to the left of `γ` the function starts at 1, on every other
//! half-edge (right fan, along `γ`, away from `γ`) it starts at 0. It is closed (locally it is
//! `d` of a function), integer valued, vanishes on `γ` itself and on every edge away from `γ`,
//! and its integral along a closed path counts signed crossings with `γ`.

use crate::error::{Error, Result};
use crate::mesh::Mesh;
use std::collections::HashSet;

/// The value of the 1-form `w` (per edge) on half-edge `h`.
#[inline]
pub fn on_halfedge(mesh: &Mesh, w: &[f64], h: u32) -> f64 {
    let e = mesh.he_edge(h);
    if mesh.edge_halfedge(e) == h {
        w[e as usize]
    } else {
        -w[e as usize]
    }
}

/// The integral of `w` along a path of half-edges.
pub fn period(mesh: &Mesh, w: &[f64], halfedges: &[u32]) -> f64 {
    halfedges.iter().map(|&h| on_halfedge(mesh, w, h)).sum()
}

/// `max_f |∮_{∂f} w|`: zero (up to rounding) for a closed form.
pub fn closedness_defect(mesh: &Mesh, w: &[f64]) -> f64 {
    (0..mesh.n_faces() as u32)
        .map(|f| {
            mesh.face_halfedges(f)
                .iter()
                .map(|&h| on_halfedge(mesh, w, h))
                .sum::<f64>()
                .abs()
        })
        .fold(0.0, f64::max)
}

/// The closed 1-form dual to the simple closed edge loop `halfedges` (see the module docs).
/// Errors when the path is not closed or repeats a vertex.
pub fn loop_dual(mesh: &Mesh, halfedges: &[u32]) -> Result<Vec<f64>> {
    let n = halfedges.len();
    if n < 2 {
        return Err(Error::input(format!(
            "a loop of {n} half-edge(s) cannot carry a dual 1-form"
        )));
    }
    let mut seen = HashSet::with_capacity(n);
    let mut left: HashSet<u32> = HashSet::new();
    for k in 0..n {
        let h_in = halfedges[(k + n - 1) % n];
        let h_out = halfedges[k];
        if mesh.is_boundary_halfedge(h_out) || mesh.is_boundary_halfedge(h_in) {
            return Err(Error::input(format!(
                "the loop runs along the boundary at half-edge {h_out}"
            )));
        }
        let v = mesh.he_origin(h_out);
        if mesh.he_tip(h_in) != v {
            return Err(Error::input(format!(
                "the loop is not a closed path: half-edge {h_in} does not end where {h_out} starts"
            )));
        }
        if !seen.insert(v) {
            return Err(Error::input(format!(
                "the loop passes twice through vertex {v}; a dual 1-form needs a simple loop"
            )));
        }
        let back = mesh.he_twin(h_in);
        // Counter-clockwise from h_out to the way back: the fan on the left of the loop.
        let mut g = h_out;
        let budget = mesh.valence(v) + 1;
        let mut steps = 0;
        loop {
            g = mesh.he_twin(mesh.he_prev(g));
            if g == back {
                break;
            }
            if mesh.is_boundary_halfedge(g) || steps > budget {
                return Err(Error::input(format!(
                    "the fan of vertex {v} is not closed; the loop must lie in the interior"
                )));
            }
            left.insert(g);
            steps += 1;
        }
    }
    let mut w = vec![0.0; mesh.n_edges()];
    for e in 0..mesh.n_edges() as u32 {
        let h = mesh.edge_halfedge(e);
        let start = f64::from(u8::from(left.contains(&h)));
        let end = f64::from(u8::from(left.contains(&mesh.he_twin(h))));
        w[e as usize] = end - start;
    }
    Ok(w)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::generate::torus;

    #[test]
    fn dual_of_a_torus_loop_is_closed_and_counts_crossings() {
        let s = torus(1.0, 0.4, 12).unwrap();
        let m = &s.mesh;
        let lengths = s.edge_lengths();
        let cut = crate::cut::canonical_cut(
            m,
            &crate::metric::IntrinsicMetric::new(
                crate::metric::Geometry::Euclidean,
                lengths.to_vec(),
            ),
            None,
            &Default::default(),
            &mut crate::progress::NoProgress,
        )
        .unwrap();
        let rm = &cut.refined.mesh;
        let a = &cut.loops[0].halfedges;
        let b = &cut.loops[1].halfedges;
        let wa = loop_dual(rm, a).unwrap();
        let wb = loop_dual(rm, b).unwrap();
        assert!(closedness_defect(rm, &wa) == 0.0 && closedness_defect(rm, &wb) == 0.0);
        // Its own loop: 0; the partner crosses once (sign by orientation), and the two
        // crossing numbers are opposite (the intersection form is antisymmetric).
        assert_eq!(period(rm, &wa, a), 0.0);
        let ab = period(rm, &wa, b);
        let ba = period(rm, &wb, a);
        assert_eq!(ab.abs(), 1.0);
        assert_eq!(ab, -ba);
    }
}
