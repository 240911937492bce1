//! Cut and flat unfolding of the flow's final Δ-complex `T` itself (self-loops and
//! multi-edges allowed), for the UVs on the common subdivision ([`super::transfer`]).
//!
//! * **Cut** (tree–cotree, Eppstein 2003; Erickson–Whittlesey 2005): a maximum spanning tree
//!   of the dual graph weighted by edge length (the tree crosses long edges, so the cut keeps
//!   short ones); the interior edges it does not cross form a graph that contains every
//!   homology generator, and edges hanging at a degree-one vertex that is neither a cone nor
//!   on the boundary are pruned until none is left. Slicing along the rest leaves a disk
//!   (the faces glued along a tree) with every cone on its boundary.
//! * **Unfolding**: the faces are placed one after the other across the tree edges
//!   (breadth first from face 0), each from its edge lengths and its parent's two shared
//!   corners. The metric is flat off the cones, so the corners agree across every uncut edge
//!   up to rounding.

use crate::error::{Error, Result};
use crate::mesh::NONE;
use crate::metric::intrinsic::IntrinsicTriangulation;
use crate::metric::Geometry;

/// Cut edges of `t` (by edge id) through every vertex of `cones` and the handles.
pub(super) fn cut_edges(t: &IntrinsicTriangulation, lengths: &[f64], cones: &[u32]) -> Vec<bool> {
    let ne = t.n_edges();
    let nf = t.n_faces();
    let mut order: Vec<u32> = (0..ne as u32).filter(|&e| !t.is_boundary_edge(e)).collect();
    order.sort_by(|&a, &b| lengths[b as usize].total_cmp(&lengths[a as usize]));
    let mut parent: Vec<u32> = (0..nf as u32).collect();
    fn find(p: &mut [u32], mut x: u32) -> u32 {
        while p[x as usize] != x {
            p[x as usize] = p[p[x as usize] as usize];
            x = p[x as usize];
        }
        x
    }
    let mut cut = vec![false; ne];
    for e in order {
        let h = t.edge_he[e as usize];
        let (f, g) = (h / 3, t.twin[h as usize] / 3);
        let (rf, rg) = (find(&mut parent, f), find(&mut parent, g));
        if rf == rg {
            cut[e as usize] = true;
        } else {
            parent[rf as usize] = rg;
        }
    }
    // Prune edges at degree-one vertices that are neither cones nor on the boundary.
    let nv = t.n_vertices;
    let mut keep = vec![false; nv];
    for &c in cones {
        keep[c as usize] = true;
    }
    for (k, &b) in keep.iter_mut().zip(&t.boundary_vertex) {
        *k |= b;
    }
    let mut incident: Vec<Vec<u32>> = vec![Vec::new(); nv];
    let mut degree = vec![0usize; nv];
    for e in 0..ne as u32 {
        if cut[e as usize] {
            for v in t.edge_vertices(e) {
                incident[v as usize].push(e);
                degree[v as usize] += 1;
            }
        }
    }
    let mut stack: Vec<u32> = (0..nv as u32)
        .filter(|&v| degree[v as usize] == 1 && !keep[v as usize])
        .collect();
    while let Some(v) = stack.pop() {
        if degree[v as usize] != 1 {
            continue;
        }
        let Some(&e) = incident[v as usize].iter().find(|&&e| cut[e as usize]) else {
            continue;
        };
        cut[e as usize] = false;
        for w in t.edge_vertices(e) {
            degree[w as usize] -= 1;
            if degree[w as usize] == 1 && !keep[w as usize] {
                stack.push(w);
            }
        }
    }
    cut
}

/// Third corner `c` of the counter-clockwise triangle `(p, q, c)` with `|pc| = r1`,
/// `|qc| = r2`.
fn apex(p: [f64; 2], q: [f64; 2], r1: f64, r2: f64) -> [f64; 2] {
    let (dx, dy) = (q[0] - p[0], q[1] - p[1]);
    let d = dx.hypot(dy);
    let x = (d * d + r1 * r1 - r2 * r2) / (2.0 * d);
    let y = (r1 * r1 - x * x).max(0.0).sqrt();
    let (ex, ey) = (dx / d, dy / d);
    [p[0] + x * ex - y * ey, p[1] + x * ey + y * ex]
}

/// Flat positions of every corner `3f + i` of `t` (Euclidean edge lengths `lengths`) opened
/// along `cut` (see the module docs).
pub(super) fn unfold(
    t: &IntrinsicTriangulation,
    lengths: &[f64],
    cut: &[bool],
) -> Result<Vec<[f64; 2]>> {
    let nf = t.n_faces();
    let len = |h: u32| lengths[t.edge[h as usize] as usize];
    let mut pos = vec![[f64::NAN; 2]; 3 * nf];
    let mut placed = vec![false; nf];
    if nf == 0 {
        return Ok(pos);
    }
    pos[0] = [0.0, 0.0];
    pos[1] = [len(0), 0.0];
    pos[2] = apex(pos[0], pos[1], len(2), len(1));
    placed[0] = true;
    let mut queue = std::collections::VecDeque::from([0u32]);
    while let Some(f) = queue.pop_front() {
        for i in 0..3 {
            let h = 3 * f + i;
            let g_he = t.twin[h as usize];
            if g_he == NONE || cut[t.edge[h as usize] as usize] || placed[(g_he / 3) as usize] {
                continue;
            }
            let g = g_he / 3;
            // h: a → b in f; g_he: b → a in g; its apex c closes (b, a, c).
            let a = pos[h as usize];
            let b = pos[IntrinsicTriangulation::next(h) as usize];
            let n1 = IntrinsicTriangulation::next(g_he);
            let n2 = IntrinsicTriangulation::prev(g_he);
            pos[g_he as usize] = b;
            pos[n1 as usize] = a;
            pos[n2 as usize] = apex(b, a, len(n2), len(n1));
            placed[g as usize] = true;
            queue.push_back(g);
        }
    }
    if let Some(f) = placed.iter().position(|&p| !p) {
        return Err(Error::numerical(format!(
            "face {f} of the flat triangulation is not reached from face 0 without crossing \
             the cut"
        )));
    }
    if let Some(c) = pos
        .iter()
        .position(|p| !(p[0].is_finite() && p[1].is_finite()))
    {
        return Err(Error::numerical(format!(
            "corner {c} of the flat triangulation has no finite position in the layout"
        )));
    }
    Ok(pos)
}

/// Euclidean edge lengths of `t`'s metric (its `lambda` already holds the final metric).
pub(super) fn lengths(t: &IntrinsicTriangulation) -> Vec<f64> {
    t.lengths(Geometry::Euclidean, &[])
}
