//! The flow's map on the input's own faces when no cut on the input edges that the flat
//! triangulation `T` kept reaches every cone: the **developing map** of the flat cone metric
//! along an arbitrary input-edge cut, from the common subdivision.
//!
//! The common subdivision (Gillespie–Springborn–Crane 2021 §5) carries the exact map, but
//! its sheets follow a cut on `T`'s edges. Every input face is the union of its pieces; moved
//! rigidly across `T`'s cut where it crosses the face, they give the face's three corners in
//! one chart of the flat metric ([`face_charts`]). The input surface is then opened along a
//! cut graph on any of its edges through every cone ([`super::seams::cut_graph`]) and the
//! face charts are glued face to face across the uncut edges by rigid motions ([`develop`]);
//! the opened surface is a disk with no cone inside, so the result does not depend on the
//! order (the developing map of a flat metric, Thurston 1997 §3.4). The transition across a
//! cut arc is the holonomy of the cones beyond it — a rigid motion by construction.
//!
//! The input faces of this map may fold where `T` flipped input edges; the least-squares
//! conformal refinement of [`super::lscm`] (same cones, seam rotations and boundary) then
//! unfolds them, and the map is written on the input faces only when nothing folds and its
//! qc p95 is no larger than the subdivision's ([`input_map`]).

use super::ladder::unresolved_triangles;
use super::lscm::improve;
use super::seams::cut_graph;
use super::transfer::{folded_faces, SubdivisionChart};
use crate::analysis::distortion::uv_stats;
use crate::error::{Error, Result};
use crate::mesh::Mesh;
use std::collections::VecDeque;

type C = [f64; 2];

/// The rigid motion `x ↦ p1 + R (x − p2)` with `R` the rotation taking `q2 − p2` to
/// `q1 − p1`; `None` for a zero-length edge.
fn motion(p1: C, q1: C, p2: C, q2: C) -> Option<impl Fn(C) -> C> {
    let a = [q1[0] - p1[0], q1[1] - p1[1]];
    let b = [q2[0] - p2[0], q2[1] - p2[1]];
    let (na, nb) = (a[0].hypot(a[1]), b[0].hypot(b[1]));
    if !(na > 0.0 && nb > 0.0 && na.is_finite() && nb.is_finite()) {
        return None;
    }
    // R = (a / |a|) · conj(b / |b|).
    let r = [
        (a[0] * b[0] + a[1] * b[1]) / (na * nb),
        (a[1] * b[0] - a[0] * b[1]) / (na * nb),
    ];
    Some(move |x: C| {
        let d = [x[0] - p2[0], x[1] - p2[1]];
        [
            p1[0] + r[0] * d[0] - r[1] * d[1],
            p1[1] + r[0] * d[1] + r[1] * d[0],
        ]
    })
}

/// The corners `3f + i` of every face of `mesh` in one chart of the flat metric: the face's
/// pieces on the common subdivision `sub`, each moved rigidly onto a neighbouring piece
/// across the sub-edge they share (module docs).
fn face_charts(mesh: &Mesh, sub: &SubdivisionChart) -> Result<Vec<C>> {
    let nf = mesh.n_faces();
    let mut start = vec![0usize; nf + 1];
    for &f in &sub.input_face {
        start[f as usize + 1] += 1;
    }
    for f in 0..nf {
        start[f + 1] += start[f];
    }
    let mut next = start.clone();
    let mut order = vec![0usize; sub.input_face.len()];
    for (t, &f) in sub.input_face.iter().enumerate() {
        order[next[f as usize]] = t;
        next[f as usize] += 1;
    }
    let mut out = vec![[f64::NAN; 2]; 3 * nf];
    let mut placed: Vec<Option<[C; 3]>> = Vec::new();
    for f in 0..nf {
        let pieces = &order[start[f]..start[f + 1]];
        let raw = |t: usize| -> [C; 3] {
            [
                sub.corner_uv[3 * t],
                sub.corner_uv[3 * t + 1],
                sub.corner_uv[3 * t + 2],
            ]
        };
        placed.clear();
        placed.resize(pieces.len(), None);
        if let Some(&t0) = pieces.first() {
            placed[0] = Some(raw(t0));
        }
        // Breadth first over the pieces; k² over a face's k pieces (k is small).
        let mut queue = VecDeque::from([0usize]);
        while let Some(i) = queue.pop_front() {
            let ti = sub.triangles[pieces[i]];
            let ui = placed[i].expect("queued pieces are placed");
            for j in 0..pieces.len() {
                if placed[j].is_some() {
                    continue;
                }
                let tj = sub.triangles[pieces[j]];
                let shared: Vec<(usize, usize)> = (0..3)
                    .filter_map(|a| tj.iter().position(|&w| w == ti[a]).map(|b| (a, b)))
                    .collect();
                if shared.len() < 2 {
                    continue;
                }
                let (a0, b0) = shared[0];
                let (a1, b1) = shared[1];
                let uj = raw(pieces[j]);
                let Some(m) = motion(ui[a0], ui[a1], uj[b0], uj[b1]) else {
                    continue;
                };
                placed[j] = Some([m(uj[0]), m(uj[1]), m(uj[2])]);
                queue.push_back(j);
            }
        }
        for i in 0..3 {
            let v = mesh.he_origin((3 * f + i) as u32);
            let at = pieces.iter().zip(&placed).find_map(|(&t, p)| {
                let c = sub.triangles[t].iter().position(|&w| w == v)?;
                p.map(|p| p[c])
            });
            out[3 * f + i] = at.ok_or_else(|| {
                Error::numerical(format!(
                    "input face {f}: its pieces on the common subdivision do not reach its \
                     vertex {v}"
                ))
            })?;
        }
    }
    Ok(out)
}

/// The developing map of the face charts `local` on `mesh` opened along `cut`: one UV per
/// corner, each face glued to a placed neighbour across an uncut edge (module docs).
fn develop(mesh: &Mesh, cut: &[bool], local: &[C]) -> Result<Vec<C>> {
    let nf = mesh.n_faces();
    let mut out = vec![[f64::NAN; 2]; 3 * nf];
    let mut done = vec![false; nf];
    let mut queue = VecDeque::new();
    for seed in 0..nf {
        if done[seed] {
            continue;
        }
        done[seed] = true;
        out[3 * seed..3 * seed + 3].copy_from_slice(&local[3 * seed..3 * seed + 3]);
        queue.push_back(seed);
        while let Some(f) = queue.pop_front() {
            for i in 0..3 {
                let h = (3 * f + i) as u32;
                let e = mesh.he_edge(h);
                if cut[e as usize] || mesh.is_boundary_edge(e) {
                    continue;
                }
                let g = mesh.he_twin(h);
                let gf = g as usize / 3;
                if done[gf] {
                    continue;
                }
                // h: a → b in f; g: b → a in gf.
                let (pa, pb) = (out[h as usize], out[mesh.he_next(h) as usize]);
                let (qb, qa) = (local[g as usize], local[mesh.he_next(g) as usize]);
                let m = motion(pa, pb, qa, qb).ok_or_else(|| {
                    Error::numerical(format!(
                        "input edge {e} has zero length in the flat metric's chart"
                    ))
                })?;
                for j in 0..3 {
                    out[3 * gf + j] = m(local[3 * gf + j]);
                }
                done[gf] = true;
                queue.push_back(gf);
            }
        }
    }
    Ok(out)
}

/// The map on the input's faces of a chart written on the common subdivision `sub`
/// (module docs): the cut (through `cones`, none when `needs_cut` is false and there are no
/// cones), the corner UVs and how many faces the developed map folded before the
/// refinement. `None` when the refinement leaves a face folded or the qc p95 of the input
/// faces would exceed the subdivision's.
pub(super) fn input_map(
    positions: &[[f64; 3]],
    mesh: &Mesh,
    lengths: &[f64],
    cones: &[u32],
    needs_cut: bool,
    sub: &SubdivisionChart,
) -> Option<(Vec<bool>, Vec<C>, usize)> {
    let cut = if needs_cut || !cones.is_empty() {
        cut_graph(mesh, lengths, &vec![true; mesh.n_edges()], cones).ok()?
    } else {
        vec![false; mesh.n_edges()]
    };
    let local = face_charts(mesh, sub).ok()?;
    let uv = develop(mesh, &cut, &local).ok()?;
    let folds = folded_faces(mesh.faces(), &uv);
    let refined = improve(positions, mesh, &cut, cones, &uv, folds);
    let uv = match refined {
        Some(better) => better,
        None if folds == 0 => uv,
        None => return None,
    };
    if unresolved_triangles(mesh.faces(), &uv) > 0 {
        return None;
    }
    let ours = uv_stats(positions, mesh.faces(), &uv).qc_p95;
    let theirs = uv_stats(&sub.positions, &sub.triangles, &sub.corner_uv).qc_p95;
    (ours <= theirs).then_some((cut, uv, folds))
}
