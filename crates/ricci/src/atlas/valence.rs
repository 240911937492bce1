//! Step 2 of the atlas (paper 000 §4 Step 2): the valence surgery around the cones. Intrinsic,
//! metric-preserving edge splits and flips ([`crate::metric::refine::Refiner`]) give the
//! vertices near a cone valence ≥ 6 without touching the cut loops, so that the flat target is
//! admissible (Chow–Luo) and the cone's neighbourhood is well shaped for the splines.

use crate::error::Result;
use crate::mesh::{Mesh, NONE};
use crate::metric::refine::Refiner;
use crate::metric::Geometry;
use serde::Serialize;
use std::collections::VecDeque;

/// Give the one-ring neighbours of every cone valence ≥ `min`: in rounds, split the longest
/// link edge of each such neighbour that avoids the cones and the `protected` edges (vertex
/// pairs, smaller first). Returns the refinement and the number of splits.
pub fn raise_ring_valence(
    refined: crate::metric::refine::Refined,
    cones: &[(u32, f64)],
    min: usize,
    protected: &std::collections::HashSet<(u32, u32)>,
) -> Result<(crate::metric::refine::Refined, usize)> {
    let mut refined = refined;
    let mut total = 0;
    for _round in 0..16 {
        let m = &refined.mesh;
        let is_cone = |x: u32| cones.iter().any(|c| c.0 == x);
        let mut todo: Vec<(u32, u32)> = Vec::new();
        for &(v, _) in cones {
            for w in m.vertex_neighbors(v) {
                if m.is_boundary_vertex(w) || is_cone(w) || m.valence(w) >= min {
                    continue;
                }
                let mut best: Option<(f64, (u32, u32))> = None;
                for f in m.vertex_faces(w) {
                    let t = m.face(f);
                    if t.iter().any(|&x| is_cone(x)) {
                        continue;
                    }
                    let i = t.iter().position(|&x| x == w).unwrap_or(0);
                    let (a, b) = (t[(i + 1) % 3], t[(i + 2) % 3]);
                    let key = (a.min(b), a.max(b));
                    if protected.contains(&key) || todo.contains(&key) {
                        continue;
                    }
                    let e = m.face_edges_opposite(f)[i];
                    let l = refined.lengths[e as usize];
                    if best.is_none_or(|b| l > b.0) {
                        best = Some((l, key));
                    }
                }
                if let Some((_, key)) = best {
                    todo.push(key);
                }
            }
        }
        if todo.is_empty() {
            break;
        }
        let mut r = Refiner::resume(refined, Geometry::Euclidean)?;
        for (a, b) in todo {
            if r.split_between(a, b).is_some() {
                total += 1;
            }
        }
        refined = r.finish()?;
    }
    Ok((refined, total))
}

/// What [`flip_ring_valence`] did.
#[derive(Debug, Clone, Copy, Default, Serialize)]
pub struct RingValenceWork {
    pub flips: usize,
    pub splits: usize,
    pub rounds: usize,
    /// Whether every vertex within the rings reached valence ≥ 6 (false: the work bound was
    /// reached, or no flip or split applied; the count left is in
    /// [`super::RefinementReport::low_valence_after`]).
    pub complete: bool,
}

/// Paper 000 §4 Step 2 (ii): every vertex within `rings` edge-rings of a cone gets valence
/// ≥ 6, by **intrinsic edge flips** ([`Refiner::flip`]) combined with intrinsic splits, both
/// metric-preserving. Greedy, in rounds (ring distances recomputed each round, kept up to
/// date within it; nearest vertices first): for a vertex `w` below 6, flip an edge `(a, b)`
/// opposite `w` (face `(w, a, b)`, replaced by `(w, x)`) when that keeps `a` and `b` at
/// valence ≥ 6 if they lie within the rings (≥ 5 otherwise), the edge is neither a
/// `protected` edge (the cut loops) nor at a cone, `x` is not a cone, and the flip is
/// intrinsically legal (strictly convex quad); among such flips the one leaving the most
/// spare valence, then the shortest new edge. Otherwise split (midpoint) an edge opposite
/// `w` to make room: the one whose endpoints and far vertex `x` lie farthest from the cones,
/// then the longest, so that the new valence-4 vertex lies outside the rings when `w` is on
/// the last ring and the deficit moves outwards otherwise. The new vertices just outside the
/// rings are then raised to valence 5 by flips where one is allowed (no splits there).
///
/// Why 5 and not 4 outside the rings: a valence-4 vertex whose four Thurston intersection
/// angles are clamped to π/2 fails the Chow–Luo condition (paper 000 eq. 7) of a flat target
/// by exactly 0, and the flat flow then refuses the target; the split vertices just outside
/// the rings are such vertices. Splits stop at edges shorter than 1e-6 of the longest.
///
/// At most `max_ops` flips and splits; a round that changes nothing ends the search.
/// Vertex ids are kept (new vertices appended), so the cut loops stay edge paths: a flip
/// never crosses an edge other than the one it removes, and protected edges are never split.
pub fn flip_ring_valence(
    refined: crate::metric::refine::Refined,
    cones: &[(u32, f64)],
    rings: usize,
    protected: &std::collections::HashSet<(u32, u32)>,
    max_ops: usize,
) -> Result<(crate::metric::refine::Refined, RingValenceWork)> {
    let mut work = RingValenceWork::default();
    if rings == 0 || cones.is_empty() {
        work.complete = true;
        return Ok((refined, work));
    }
    let n0 = refined.mesh.n_vertices() as u32;
    let mut r = Refiner::resume(refined, Geometry::Euclidean)?;
    let is_cone = |x: u32| cones.iter().any(|c| c.0 == x);
    let key = |a: u32, b: u32| (a.min(b), a.max(b));
    // Splits stop at edges shorter than 1e-6 of the longest (the metric stays well resolved).
    let min_len = 1e-6
        * (0..r.n_faces() as u32 * 3)
            .map(|h| r.length(h))
            .fold(0.0, f64::max);
    for _round in 0..4 * max_ops.max(1) {
        let mut dist = refiner_ring_distances(&r, cones, rings + 1);
        let mut low: Vec<u32> = (0..r.n_vertices() as u32)
            .filter(|&w| {
                let d = dist[w as usize];
                let target = if d <= rings { 6 } else { 5 };
                d >= 1
                    && (d <= rings || (d == rings + 1 && w >= n0))
                    && !r.is_boundary_vertex(w)
                    && r.valence(w) < target
            })
            .collect();
        if low.is_empty() {
            break;
        }
        if work.flips + work.splits >= max_ops {
            break;
        }
        work.rounds += 1;
        let ops_before = work.flips + work.splits;
        low.sort_by_key(|&w| (dist[w as usize], w));
        for w in low {
            if work.flips + work.splits >= max_ops {
                break;
            }
            let inside = dist[w as usize] <= rings;
            let target = if inside { 6 } else { 5 };
            while r.valence(w) < target && work.flips + work.splits < max_ops {
                let depth = |v: u32| dist.get(v as usize).copied().unwrap_or(usize::MAX);
                let need = |v: u32| if depth(v) <= rings { 6 } else { 5 };
                let mut best_flip: Option<((i64, f64), u32)> = None;
                let mut best_split: Option<((usize, f64), u32)> = None;
                for h in r.link(w) {
                    let (a, b) = r.endpoints(h);
                    if is_cone(a) || is_cone(b) || protected.contains(&key(a, b)) {
                        continue;
                    }
                    let x = r.opposite_across(h);
                    let l = r.length(h);
                    // The new vertex of a split lies next to a, b, w and x; prefer a, b, x
                    // far out, where its valence 4 can later be raised by a flip.
                    let far = depth(a).min(depth(b)).min(x.map_or(usize::MAX, depth));
                    if l > min_len && best_split.is_none_or(|s| (far, l) > s.0) {
                        best_split = Some(((far, l), h));
                    }
                    let Some(x) = x else {
                        continue;
                    };
                    if x == w || is_cone(x) || r.halfedge(w, x).is_some() {
                        continue;
                    }
                    let sa = r.valence(a) as i64 - 1 - need(a);
                    let sb = r.valence(b) as i64 - 1 - need(b);
                    if sa < 0 || sb < 0 {
                        continue;
                    }
                    let Ok(new_len) = r.flip_length(h) else {
                        continue;
                    };
                    let score = (sa.min(sb), -new_len / l);
                    if best_flip.is_none_or(|f| score > f.0) {
                        best_flip = Some((score, h));
                    }
                }
                if let Some((_, h)) = best_flip {
                    let x = r.opposite_across(h).unwrap_or(NONE);
                    r.flip(h)?;
                    work.flips += 1;
                    // The new edge (w, x) can only bring x closer.
                    let dw = depth(w);
                    if let Some(dx) = dist.get_mut(x as usize) {
                        *dx = (*dx).min(dw + 1);
                    }
                } else if let Some(((far, _), h)) = best_split.filter(|_| inside) {
                    r.split(h, 0.5);
                    work.splits += 1;
                    dist.push(far.min(depth(w)).saturating_add(1));
                } else {
                    break;
                }
            }
        }
        if work.flips + work.splits == ops_before {
            // Nothing more can be done (every remaining vertex is stuck).
            break;
        }
    }
    let dist = refiner_ring_distances(&r, cones, rings);
    work.complete = (0..r.n_vertices() as u32).all(|w| {
        let d = dist[w as usize];
        d == 0 || d > rings || r.is_boundary_vertex(w) || r.valence(w) >= 6
    });
    Ok((r.finish()?, work))
}

/// Edge-ring distance from the cones over a [`Refiner`]'s current connectivity, up to
/// `limit` (farther vertices get `usize::MAX`).
fn refiner_ring_distances(r: &Refiner, cones: &[(u32, f64)], limit: usize) -> Vec<usize> {
    let mut d = vec![usize::MAX; r.n_vertices()];
    let mut q = VecDeque::new();
    for &(v, _) in cones {
        if (v as usize) < d.len() {
            d[v as usize] = 0;
            q.push_back(v);
        }
    }
    while let Some(v) = q.pop_front() {
        if d[v as usize] >= limit {
            continue;
        }
        for w in r.neighbors(v) {
            if d[w as usize] == usize::MAX {
                d[w as usize] = d[v as usize] + 1;
                q.push_back(w);
            }
        }
    }
    d
}

/// Vertices within `rings` edge-rings of the cones (the cones excluded).
pub(super) fn rings_around(mesh: &Mesh, cones: &[(u32, f64)], rings: usize) -> Vec<u32> {
    let mut d = vec![usize::MAX; mesh.n_vertices()];
    let mut q = VecDeque::new();
    for &(v, _) in cones {
        if (v as usize) < d.len() {
            d[v as usize] = 0;
            q.push_back(v);
        }
    }
    let mut out = Vec::new();
    while let Some(v) = q.pop_front() {
        if d[v as usize] >= rings {
            continue;
        }
        for w in mesh.vertex_neighbors(v) {
            if d[w as usize] == usize::MAX {
                d[w as usize] = d[v as usize] + 1;
                out.push(w);
                q.push_back(w);
            }
        }
    }
    out
}
