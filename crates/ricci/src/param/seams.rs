//! The cut graph of a parametrization: the edges along which a surface is opened to a disk
//! so that every cone lies on the boundary (Gu–Yau 2003 §4, Erickson–Whittlesey 2005 for the
//! greedy system of loops, and the cone paths of Sawhney–Crane 2017 §6.3).
//!
//! * A shortest-path forest `P` over the **allowed** edges (edges the cut may use) from the
//!   roots — every boundary vertex when the surface has a boundary, otherwise the first cone
//!   (or vertex 0).
//! * A maximum spanning tree of the dual graph over the edges not in `P`, weighted by the
//!   length of the loop each edge closes with `P` (`d(a) + l_ab + d(b)`), with the edges that
//!   are not allowed first (weight +∞: they must stay uncut). The `2g + b − 1` edges left
//!   over (Euler) close the shortest greedy loops of Erickson–Whittlesey.
//! * `P` plus the leftovers, pruned: edges hanging at a degree-one vertex that is not a cone
//!   are removed until none is left (boundary edges count for the degree and are never cut).
//!
//! What remains is a cut graph through every cone and every homology generator; slicing along
//! it leaves a disk. Edges that are not allowed enter `P` only where nothing else reaches
//! (their length plus the total length of all edges) and are normally pruned; when one would have to stay cut the function
//! says so.

use crate::error::{Error, Result};
use crate::mesh::{Mesh, NONE};
use crate::numeric::dijkstra::Dijkstra;
use rayon::slice::ParallelSliceMut;

/// Cut edges (`cut[e]`) of `mesh` with `lengths`; `allowed[e]` says which edges may be cut;
/// `cones` must all end up on the cut (or the boundary).
pub(crate) fn cut_graph(
    mesh: &Mesh,
    lengths: &[f64],
    allowed: &[bool],
    cones: &[u32],
) -> Result<Vec<bool>> {
    let n = mesh.n_vertices();
    let ne = mesh.n_edges();
    let is_cone = {
        let mut c = vec![false; n];
        for &v in cones {
            c[v as usize] = true;
        }
        c
    };
    let penalty: f64 = 1.0 + lengths.iter().sum::<f64>();
    let mut dj = Dijkstra::new(n);
    let boundary = mesh.has_boundary();
    if boundary {
        for v in 0..n as u32 {
            if mesh.is_boundary_vertex(v) {
                dj.offer(v, 0.0, NONE);
            }
        }
    } else {
        let root = cones
            .first()
            .copied()
            .or_else(|| (0..n as u32).find(|&v| !mesh.is_isolated(v)))
            .ok_or_else(|| Error::input("the mesh has no faces"))?;
        dj.offer(root, 0.0, NONE);
    }
    dj.run(
        |v| {
            mesh.outgoing(v)
                .filter(move |&h| !mesh.is_boundary_edge(mesh.he_edge(h)))
                .map(move |h| {
                    let e = mesh.he_edge(h) as usize;
                    // Edges the cut may not use only where nothing else reaches (pruned
                    // away below unless a cone needs them).
                    let w = if allowed[e] { 0.0 } else { penalty };
                    (mesh.he_tip(h), lengths[e] + w)
                })
        },
        |_, _| false,
    );
    let mut in_tree = vec![false; ne];
    let mut dist = vec![0.0; n];
    for v in 0..n as u32 {
        if mesh.is_isolated(v) {
            continue;
        }
        let d = dj.dist(v);
        if !d.is_finite() {
            return Err(Error::numerical(format!(
                "vertex {v} cannot be reached from the cut's root"
            )));
        }
        dist[v as usize] = d;
        let p = dj.pred(v);
        if p != NONE {
            let h = mesh
                .halfedge_between(p, v)
                .ok_or_else(|| Error::numerical("shortest-path tree edge missing"))?;
            in_tree[mesh.he_edge(h) as usize] = true;
        }
    }
    // Dual maximum spanning tree (Kruskal) over the edges not in P.
    let mut order: Vec<(f64, u32)> = (0..ne as u32)
        .filter(|&e| !in_tree[e as usize] && !mesh.is_boundary_edge(e))
        .map(|e| {
            let [a, b] = mesh.edge_vertices(e);
            let w = if allowed[e as usize] {
                dist[a as usize] + dist[b as usize] + lengths[e as usize]
            } else {
                f64::INFINITY
            };
            (w, e)
        })
        .collect();
    // Heaviest first, ties by edge id (the order of a stable sort of the edges by weight).
    order.par_sort_unstable_by(|x, y| y.0.total_cmp(&x.0).then(x.1.cmp(&y.1)));
    let mut parent: Vec<u32> = (0..mesh.n_faces() as u32).collect();
    fn find(p: &mut [u32], mut x: u32) -> u32 {
        while p[x as usize] != x {
            p[x as usize] = p[p[x as usize] as usize];
            x = p[x as usize];
        }
        x
    }
    let mut cut = in_tree.clone();
    for &(_, e) in &order {
        let h = mesh.edge_halfedge(e);
        let (f, g) = (mesh.he_face(h), mesh.he_face(mesh.he_twin(h)));
        let (rf, rg) = (find(&mut parent, f), find(&mut parent, g));
        if rf != rg {
            parent[rf as usize] = rg;
        } else {
            if !allowed[e as usize] {
                let [a, b] = mesh.edge_vertices(e);
                return Err(Error::numerical(format!(
                    "the cut would need edge {e} ({a}–{b}), which the final triangulation \
                     flipped away"
                )));
            }
            cut[e as usize] = true;
        }
    }
    // Prune.
    let mut degree = vec![0u32; n];
    for e in 0..ne as u32 {
        if cut[e as usize] || mesh.is_boundary_edge(e) {
            let [a, b] = mesh.edge_vertices(e);
            degree[a as usize] += 1;
            degree[b as usize] += 1;
        }
    }
    let mut stack: Vec<u32> = (0..n as u32)
        .filter(|&v| degree[v as usize] == 1 && !is_cone[v as usize])
        .collect();
    while let Some(v) = stack.pop() {
        if degree[v as usize] != 1 || is_cone[v as usize] {
            continue;
        }
        let Some(h) = mesh.outgoing(v).find(|&h| cut[mesh.he_edge(h) as usize]) else {
            continue;
        };
        let e = mesh.he_edge(h) as usize;
        cut[e] = false;
        degree[v as usize] -= 1;
        let w = mesh.he_tip(h);
        degree[w as usize] -= 1;
        if degree[w as usize] == 1 && !is_cone[w as usize] {
            stack.push(w);
        }
    }
    if let Some(e) = (0..ne).find(|&e| cut[e] && !allowed[e]) {
        let [a, b] = mesh.edge_vertices(e as u32);
        return Err(Error::numerical(format!(
            "the cut would need edge {e} ({a}–{b}), which the final triangulation flipped away"
        )));
    }
    Ok(cut)
}

/// [`wedge_key`] of every corner `h < mesh.n_corners()`, in one turn around each vertex
/// instead of one per corner: the key of `h` is the key of the next half-edge counter-clockwise
/// unless that one is a cut or boundary edge (then its tip), so each turn labels every corner
/// it passes. Same values as [`wedge_key`] corner by corner.
pub fn wedge_keys(mesh: &Mesh, cut: &[bool]) -> Vec<u32> {
    const UNSET: u32 = u32::MAX - 1;
    let nc = mesh.n_corners();
    let mut key = vec![UNSET; nc];
    let mut path = Vec::new();
    for h in 0..nc as u32 {
        if key[h as usize] != UNSET {
            continue;
        }
        path.clear();
        let mut g = h;
        let k = loop {
            path.push(g);
            let r = mesh.he_twin(mesh.he_prev(g));
            if mesh.is_boundary_halfedge(r) || cut[mesh.he_edge(r) as usize] {
                break mesh.he_tip(r);
            }
            if r == h || path.len() > mesh.n_halfedges() {
                break NONE;
            }
            if key[r as usize] != UNSET {
                break key[r as usize];
            }
            g = r;
        };
        for &p in &path {
            key[p as usize] = k;
        }
    }
    key
}

/// The wedge of corner `h` (an interior half-edge leaving vertex `v`) between the cut or
/// boundary edges at `v`, named by the tip of the first cut or boundary edge met turning
/// counter-clockwise from the corner's face (`NONE` when `v` has none). Two triangulations of
/// the same surface that share the cut and boundary edges name the same wedges alike.
pub fn wedge_key(mesh: &Mesh, h: u32, cut: &[bool]) -> u32 {
    let mut g = mesh.he_twin(mesh.he_prev(h));
    for _ in 0..mesh.n_halfedges() {
        if mesh.is_boundary_halfedge(g) || cut[mesh.he_edge(g) as usize] {
            return mesh.he_tip(g);
        }
        if g == h {
            return NONE;
        }
        g = mesh.he_twin(mesh.he_prev(g));
    }
    NONE
}

#[cfg(test)]
mod tests {
    use super::{wedge_key, wedge_keys};

    /// The one-turn labelling agrees with the corner-by-corner walk on closed and bordered
    /// meshes under arbitrary cut flags (every cut pattern names the same wedges both ways).
    #[test]
    fn wedge_keys_match_wedge_key() {
        for s in [
            crate::mesh::generate::genus(2, 20).unwrap(),
            crate::mesh::generate::pair_of_pants(24).unwrap(),
        ] {
            let mesh = &s.mesh;
            for period in [1usize, 3, 7, 50, usize::MAX] {
                let cut: Vec<bool> = (0..mesh.n_edges()).map(|e| e % period == 1).collect();
                let keys = wedge_keys(mesh, &cut);
                for h in 0..mesh.n_corners() as u32 {
                    assert_eq!(keys[h as usize], wedge_key(mesh, h, &cut), "corner {h}");
                }
            }
        }
    }
}
