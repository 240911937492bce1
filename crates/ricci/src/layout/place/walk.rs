//! The order in which [`super::layout_from`] places the faces: a Dijkstra over the dual graph
//! whose cost bounds the growth of rounding errors along the placement (needles are crossed
//! along their length), with the tree's levels for the level-parallel composition of frames.

use crate::mesh::{Mesh, NONE};

/// The order of [`super::layout_from`]'s walk.
pub(super) struct Walk {
    /// `(g, t)`: face `g` placed from its parent across `t` (a half-edge of `g`; the parent
    /// is the face of its twin), parents first.
    pub(super) steps: Vec<(u32, u32)>,
    /// The indices in `steps` of the faces at each depth of the tree (depth 1 first: faces
    /// whose parent is the seed).
    pub(super) levels: Vec<Vec<u32>>,
    /// `(k, i)`: vertex `k` placed by the face of `steps[i]` (its corner opposite `t`).
    pub(super) placements: Vec<(u32, u32)>,
    /// The largest breadth-first depth of a vertex.
    pub(super) depth: u32,
}

/// The walk of [`super::layout_from`] from `seed`. Error-growth estimate per vertex: placing k from
/// the edge (i, j) multiplies the error of the edge's direction by about max(l_ik, l_jk)/l_ij,
/// so needles (e.g. from refinement fans) are crossed along their length, not across; the
/// order is a Dijkstra on cost = Σ ln(1 + max(l_ik, l_jk)/l_ij), i.e. breadth first on
/// well-shaped meshes. Each vertex is placed by the first face that reaches it.
pub(super) fn walk(mesh: &Mesh, lengths: &[f64], seed: u32) -> Walk {
    use std::cmp::Reverse;
    use std::collections::BinaryHeap;
    let nv = mesh.n_vertices();
    let nf = mesh.n_faces();
    let len = |h: u32| lengths[mesh.he_edge(h) as usize];
    let mut placed = vec![false; nv];
    let mut cost = vec![f64::INFINITY; nv];
    let mut vdepth = vec![0u32; nv];
    let mut done = vec![false; nf];
    let mut level = vec![0u32; nf];
    let mut heap: BinaryHeap<(Reverse<u64>, u32, u32)> = BinaryHeap::with_capacity(nf);
    let mut w = Walk {
        steps: Vec::with_capacity(nf),
        levels: Vec::new(),
        placements: Vec::with_capacity(nv),
        depth: 0,
    };
    done[seed as usize] = true;
    for v in mesh.face(seed) {
        placed[v as usize] = true;
        cost[v as usize] = 0.0;
    }
    // Heap entries: (cost, face g, half-edge t of g whose ends are placed); the parent is the
    // face across t.
    let push =
        |f: u32, heap: &mut BinaryHeap<(Reverse<u64>, u32, u32)>, cost: &[f64], done: &[bool]| {
            for h in mesh.face_halfedges(f) {
                let t = mesh.he_twin(h);
                let g = mesh.he_face(t);
                if g == NONE || done[g as usize] {
                    continue;
                }
                let (i, j) = (mesh.he_origin(t), mesh.he_tip(t));
                let amp =
                    len(mesh.he_next(t)).max(len(mesh.he_prev(t))) / len(t).max(f64::MIN_POSITIVE);
                let c = cost[i as usize].max(cost[j as usize]) + (1.0 + amp).ln();
                heap.push((Reverse(c.to_bits()), g, t));
            }
        };
    push(seed, &mut heap, &cost, &done);
    while let Some((_, g, t)) = heap.pop() {
        if done[g as usize] {
            continue;
        }
        done[g as usize] = true;
        let i = w.steps.len() as u32;
        w.steps.push((g, t));
        let lg = level[mesh.he_face(mesh.he_twin(t)) as usize] + 1;
        level[g as usize] = lg;
        if w.levels.len() < lg as usize {
            w.levels.push(Vec::new());
        }
        w.levels[lg as usize - 1].push(i);
        let tn = mesh.he_next(t);
        let k = mesh.he_tip(tn);
        if !placed[k as usize] {
            let (a, b) = (mesh.he_origin(t), mesh.he_tip(t));
            placed[k as usize] = true;
            w.placements.push((k, i));
            let amp = len(tn).max(len(mesh.he_prev(t))) / len(t).max(f64::MIN_POSITIVE);
            cost[k as usize] = cost[a as usize].max(cost[b as usize]) + (1.0 + amp).ln();
            vdepth[k as usize] = vdepth[a as usize].max(vdepth[b as usize]) + 1;
            w.depth = w.depth.max(vdepth[k as usize]);
        }
        push(g, &mut heap, &cost, &done);
    }
    w
}
