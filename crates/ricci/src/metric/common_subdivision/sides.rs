//! Input edges that join the same two vertices, told apart by their **side** (a Δ-complex
//! input: the input metric's Delaunay triangulation `T_iso` of camelhead's double has pairs of
//! edges that are mirror images under the double's reflection σ — the same ends, the same
//! length, the same log Penner coordinate — so neither the ends nor `λ` choose between them).
//!
//! The input edges leaving a vertex `a` are disjoint curves from `a`, so they leave it in the
//! same cyclic order in the input triangulation and in `T`. In `T` that order is read off the
//! normal coordinates: turning around `a` through its corners, an edge of `T` that is an input
//! edge (normal coordinate −1), then the arcs that leave `a` through the opposite side of the
//! corner, in the order of their places on that side (from the corner's next vertex on). Each
//! of them is followed to its far end. In the input the order is its own rotation at `a`. The
//! two cyclic lists of far ends are matched by rotation; where exactly one rotation matches,
//! every input edge leaving `a` is known by where it leaves `a` in `T`. A symmetric order (two
//! rotations match) is refused, not guessed. No lengths and no perturbation enter: this is
//! what Gillespie–Sharp–Crane's roundabouts (2021, §3.3) record, recomputed at the vertices
//! that need it instead of kept through the flips.

use super::input::InputComplex;
use super::normal::TriangleArcs;
use super::trace::walk;
use super::Tri;
use crate::error::{Error, Result};
use crate::mesh::NONE;
use std::collections::HashMap;

/// Where an input edge leaves a vertex of `T`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub(super) enum Leaving {
    /// Along the half-edge of `T` leaving the vertex (an input edge, normal coordinate −1).
    Along(u32),
    /// The `k`-th arc leaving corner `3f + m` through the opposite side (counted from the
    /// corner's next vertex).
    Arc(u32, u32),
}

/// The input half-edges leaving vertex `a` of `T` by where they leave it (module docs);
/// `out` is a half-edge of `T` leaving `a`.
pub(super) fn match_at_vertex<M: InputComplex>(
    mesh: &M,
    tri: &Tri,
    normal: &[i32],
    arcs: &[TriangleArcs],
    a: u32,
    out: u32,
) -> Result<HashMap<Leaving, u32>> {
    let in_t = leaving_in_t(tri, normal, arcs, a, out)?;
    let in_input = mesh.rotation(a)?;
    let d = in_t.len();
    if in_input.len() != d {
        return Err(Error::numerical(format!(
            "{} input edges leave vertex {a} in the intrinsic triangulation, {} in the input",
            d,
            in_input.len()
        )));
    }
    let far_input: Vec<u32> = in_input
        .iter()
        .map(|&h| mesh.edge_vertices(mesh.he_edge(h)))
        .zip(&in_input)
        .map(|([v0, v1], &h)| {
            // The far end of h: its edge's other vertex (no loops, module input).
            if mesh.edge_halfedge(mesh.he_edge(h)) == h {
                v1
            } else {
                v0
            }
        })
        .collect();
    let shifts: Vec<usize> = (0..d)
        .filter(|&s| (0..d).all(|k| in_t[k].1 == far_input[(k + s) % d]))
        .collect();
    let [s] = shifts[..] else {
        return Err(Error::numerical(format!(
            "the input edges leaving vertex {a} match the intrinsic triangulation's in {} \
             rotations, so edges with the same ends are not told apart by side",
            shifts.len()
        )));
    };
    Ok((0..d).map(|k| (in_t[k].0, in_input[(k + s) % d])).collect())
}

/// The input edges leaving vertex `a` in `T`, in the rotation `h, twin(prev(h)), …` from `out`:
/// where each leaves and its far end.
fn leaving_in_t(
    tri: &Tri,
    normal: &[i32],
    arcs: &[TriangleArcs],
    a: u32,
    out: u32,
) -> Result<Vec<(Leaving, u32)>> {
    let budget: usize = normal.iter().map(|&n| n.max(0) as usize).sum();
    let mut list = Vec::new();
    let mut h = out;
    for _ in 0..tri.n_halfedges() {
        if normal[tri.edge[h as usize] as usize] == -1 {
            list.push((Leaving::Along(h), tri.tip(h)));
        }
        let (f, m) = (h / 3, (h % 3) as usize);
        let j = (m + 1) % 3;
        let side = 3 * f + j as u32;
        for k in 0..arcs[f as usize].through[j] {
            let q = arcs[f as usize].corner[j] + k;
            let tw = tri.twin[side as usize];
            if tw == NONE {
                return Err(Error::numerical(format!(
                    "an input edge leaves vertex {a} through a boundary edge"
                )));
            }
            let n = normal[tri.edge[side as usize] as usize] as u32;
            let (_, end) = walk(tri, normal, arcs, tw, n - 1 - q, budget)?;
            list.push((Leaving::Arc(h, k), tri.origin[end as usize]));
        }
        h = tri.twin[Tri::prev(h) as usize];
        if h == NONE {
            return Err(Error::numerical(format!(
                "vertex {a} is on the boundary of the intrinsic triangulation"
            )));
        }
        if h == out {
            return Ok(list);
        }
    }
    Err(Error::numerical(format!(
        "the half-edges around vertex {a} of the intrinsic triangulation do not close up"
    )))
}

/// Where the input edge traced along `first` (its first step: the half-edge of `T` it crosses
/// and its place there, as [`walk`] takes them) leaves `start`, the corner it starts at.
pub(super) fn leaving_corner(
    tri: &Tri,
    normal: &[i32],
    arcs: &[TriangleArcs],
    start: u32,
    first: (u32, u32),
) -> Result<Leaving> {
    let x = tri.twin[first.0 as usize];
    let (f, m) = (start / 3, (start % 3) as usize);
    let j = (m + 1) % 3;
    let n = normal[tri.edge[first.0 as usize] as usize];
    if x != 3 * f + j as u32 || n <= first.1 as i32 {
        return Err(Error::numerical(format!(
            "a traced input edge does not leave corner {start} through its opposite side"
        )));
    }
    let q = n as u32 - 1 - first.1;
    let c = &arcs[f as usize];
    match q.checked_sub(c.corner[j]) {
        Some(k) if k < c.through[j] => Ok(Leaving::Arc(start, k)),
        _ => Err(Error::numerical(format!(
            "a traced input edge is not among the arcs leaving corner {start}"
        ))),
    }
}
