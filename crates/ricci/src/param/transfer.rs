//! From the flat intrinsic triangulation `T` of the conformal flow to UVs on the input
//! surface (steps 3–5 of the [module docs](super)): the cut, the flat layout of the opened
//! surface, and the transfer of the layout to the surface.
//!
//! * **On the input's own faces** ([`input_route`]): the cut runs on input edges that `T`
//!   kept, the opened `T` is laid out, and every input corner takes the layout position of
//!   its vertex in the same wedge between cut edges ([`input_face_map`]). The map is exact at
//!   the vertices and linear on input faces; where `T` flipped input edges, an input face's
//!   UV triangle joins points that are not adjacent in `T` and can fold.
//! * **On the common subdivision** of the input and `T` ([`subdivision_route`];
//!   Gillespie–Springborn–Crane 2021 §5, [`crate::metric::common_subdivision`]): the cut runs
//!   on `T`'s own edges (flipped ones included, so every cone is reached), `T` is laid out,
//!   and every piece of the overlay — one input face ∩ one face of `T` — takes the projective
//!   interpolation of its `T` face's layout. The pieces are convex in both charts, so none
//!   folds. Used when the first route folds a face or cannot cut.

use super::seams;
use crate::error::{Error, Result};
use crate::flow::FlowResult;
use crate::layout::place::layout;
use crate::mesh::{Mesh, Surface};
use crate::metric::common_subdivision::CommonSubdivision;
use crate::metric::{Euclidean, Geometry, IntrinsicMetric};
use std::collections::HashMap;
use std::f64::consts::PI;

/// The map of the input's faces into the layout of the opened intrinsic triangulation: one
/// UV per input corner (see the module docs). `t_mesh` is the simplicial mesh of the flow
/// (input vertices first, same ids), `t_cut` its cut flags, `t_uv[3f + i]` the layout
/// position of corner `i` of its face `f`; `cut` are the cut flags of `input`.
pub fn input_face_map(
    input: &Mesh,
    cut: &[bool],
    t_mesh: &Mesh,
    t_cut: &[bool],
    t_uv: &[[f64; 2]],
) -> Result<Vec<[f64; 2]>> {
    let keys = (
        seams::wedge_keys(t_mesh, t_cut),
        seams::wedge_keys(input, cut),
    );
    map_wedges(input, t_mesh, &keys, t_uv)
}

/// [`input_face_map`] from the wedge keys ([`seams::wedge_keys`]) of `T`'s corners and of the
/// input's corners: every input corner takes the position of the first corner of `T` (in
/// corner order) at the same vertex and in the same wedge. Per vertex, the few wedges seen so
/// far are a list (`head[v]`, then `next`), as in the OBJ writer — no hashing.
fn map_wedges(
    input: &Mesh,
    t_mesh: &Mesh,
    (t_keys, keys): &(Vec<u32>, Vec<u32>),
    t_uv: &[[f64; 2]],
) -> Result<Vec<[f64; 2]>> {
    const END: u32 = u32::MAX;
    let nv = input.n_vertices();
    let mut head = vec![END; nv];
    let mut wedges: Vec<(u32, [f64; 2], u32)> = Vec::with_capacity(nv + nv / 4);
    let find = |wedges: &[(u32, [f64; 2], u32)], mut at: u32, key: u32| {
        while at != END && wedges[at as usize].0 != key {
            at = wedges[at as usize].2;
        }
        at
    };
    for h in 0..t_mesh.n_corners() as u32 {
        let v = t_mesh.he_origin(h) as usize;
        if v < nv {
            let key = t_keys[h as usize];
            if find(&wedges, head[v], key) == END {
                wedges.push((key, t_uv[h as usize], head[v]));
                head[v] = (wedges.len() - 1) as u32;
            }
        }
    }
    (0..input.n_corners() as u32)
        .map(|h| {
            let v = input.he_origin(h);
            match find(&wedges, head[v as usize], keys[h as usize]) {
                END => Err(Error::numerical(format!(
                    "input vertex {v} (face {}) has no position in the layout of the intrinsic \
                     triangulation",
                    h / 3
                ))),
                at => Ok(wedges[at as usize].1),
            }
        })
        .collect()
}

/// Flat layout of `mesh` (edge lengths `lengths`) opened along `cut`: the position of every
/// corner `3f + i` (the cut mesh keeps face and half-edge ids).
fn cut_layout(mesh: &Mesh, lengths: &[f64], cut: &[bool]) -> Result<Vec<[f64; 2]>> {
    let (disk, _origin) = crate::cut::slice(mesh, cut)?;
    let mut dl = vec![0.0; disk.n_edges()];
    for h in 0..disk.n_corners() as u32 {
        dl[disk.he_edge(h) as usize] = lengths[mesh.he_edge(h) as usize];
    }
    // One walk from the disk's central face: the flat layout's rounding grows only linearly
    // with the distance from the seed, so the second walk from the boundary's minimax centre
    // that `layout` adds for a disk (for the hyperbolic plane's exponential growth) would only
    // move the chart rigidly (the packing orients it anyway).
    let seed = crate::layout::place::central_face(&disk);
    let lay = layout::<Euclidean>(&disk, &IntrinsicMetric::euclidean(dl), Some(seed))?;
    Ok((0..disk.n_corners() as u32)
        .map(|h| {
            let p = lay.positions[disk.he_origin(h) as usize];
            [p.re, p.im]
        })
        .collect())
}

/// Input edges the cut may use: never flipped by the flow and present once in `T`.
///
/// Edge ids survive flips, so an edge of `T` that was never flipped and still joins its input
/// endpoints is that input edge, and no other input edge joins the same pair (the input's
/// edges are its distinct vertex pairs). The pairs joined more than once are therefore found
/// among the other edges of `T` alone (flipped, or new) — a few, where one table of all of
/// `T`'s edges would hash every one.
fn kept_input_edges(mesh: &Mesh, r: &FlowResult) -> Result<Vec<bool>> {
    let tr = triangulation(r)?;
    let t_mesh = &tr.simplicial.mesh;
    let t = &tr.triangulation;
    let ne = mesh.n_edges();
    let mut flipped = vec![false; ne];
    for &e in &t.flip_log {
        flipped[e as usize] = true;
    }
    let key = |[a, b]: [u32; 2]| (a.min(b), a.max(b));
    // Edge e of T is the input edge e (unflipped, same endpoints).
    let same = |e: u32| {
        (e as usize) < ne.min(t.n_edges())
            && !flipped[e as usize]
            && key(t.edge_vertices(e)) == key(mesh.edge_vertices(e))
    };
    let mut others: HashMap<(u32, u32), u32> = HashMap::new();
    for e in 0..t.n_edges() as u32 {
        if !same(e) {
            *others.entry(key(t.edge_vertices(e))).or_insert(0) += 1;
        }
    }
    Ok((0..ne as u32)
        .map(|e| {
            let pair = key(mesh.edge_vertices(e));
            let count = same(e) as u32 + others.get(&pair).copied().unwrap_or(0);
            !flipped[e as usize] && count == 1 && t_mesh.halfedge_between(pair.0, pair.1).is_some()
        })
        .collect())
}

fn triangulation(r: &FlowResult) -> Result<&crate::flow::IntrinsicResult> {
    r.triangulation
        .as_ref()
        .ok_or_else(|| Error::numerical("the conformal flow returned no triangulation"))
}

/// The metric `lengths` of the flow's simplicial mesh (which may differ from the Δ-complex's
/// own, e.g. after the `--seamless` holonomy fix) per edge of the Δ-complex `T`; `None` when
/// edges were split (then the two meshes' edges differ).
fn simplicial_lengths(tr: &crate::flow::IntrinsicResult, lengths: &[f64]) -> Option<Vec<f64>> {
    let (t, m) = (&tr.triangulation, &tr.simplicial.mesh);
    if tr.simplicial.splits > 0 || lengths.len() != m.n_edges() {
        return None;
    }
    (0..t.n_edges() as u32)
        .map(|e| {
            let [a, b] = t.edge_vertices(e);
            let h = m.halfedge_between(a, b)?;
            Some(lengths[m.he_edge(h) as usize])
        })
        .collect()
}

/// UVs on the input's own faces: the input-edge cut (`None` when `needs_cut` is false) and
/// one UV per input corner (unscaled layout units). Fails when the cut cannot avoid edges the
/// flow flipped away.
pub(super) fn input_route(
    surface: &Surface,
    lengths: &[f64],
    r: &FlowResult,
    cones: &[u32],
    needs_cut: bool,
) -> Result<(Vec<bool>, Vec<[f64; 2]>)> {
    let mesh = &surface.mesh;
    let t_mesh = &triangulation(r)?.simplicial.mesh;
    let cut = if needs_cut {
        let allowed = kept_input_edges(mesh, r)?;
        seams::cut_graph(mesh, lengths, &allowed, cones)?
    } else {
        vec![false; mesh.n_edges()]
    };
    let mut t_cut = vec![false; t_mesh.n_edges()];
    for e in 0..mesh.n_edges() as u32 {
        if cut[e as usize] {
            let [a, b] = mesh.edge_vertices(e);
            let h = t_mesh.halfedge_between(a, b).ok_or_else(|| {
                Error::numerical(format!(
                    "cut edge {a}–{b} is missing in the flat triangulation"
                ))
            })?;
            t_cut[t_mesh.he_edge(h) as usize] = true;
        }
    }
    // The wedges of both meshes' corners depend only on the cuts: found beside the layout.
    let (t_uv, keys) = rayon::join(
        || cut_layout(t_mesh, &r.lengths, &t_cut),
        || {
            (
                seams::wedge_keys(t_mesh, &t_cut),
                seams::wedge_keys(mesh, &cut),
            )
        },
    );
    let uv = map_wedges(mesh, t_mesh, &keys, &t_uv?)?;
    Ok((cut, uv))
}

/// A chart's UVs on the common subdivision of the input and `T` (see the module docs).
pub(super) struct SubdivisionChart {
    /// Points on the input surface (input vertices first, same ids).
    pub positions: Vec<[f64; 3]>,
    pub triangles: Vec<[u32; 3]>,
    /// Input face (of the chart's piece) of every triangle.
    pub input_face: Vec<u32>,
    pub corner_uv: Vec<[f64; 2]>,
    /// Input edges that are also cut edges of `T`.
    pub input_cut: Vec<bool>,
    /// Triangles whose UV triangle is not positive (0 unless the layout itself folds).
    pub flipped: usize,
}

/// UVs on the common subdivision: the cut on `T` itself through the cones and the handles
/// (any edge of `T`, [`super::unfold`]), its unfolding, and the projective interpolation of
/// every piece of the overlay (unscaled layout units).
pub(super) fn subdivision_route(
    surface: &Surface,
    lengths: &[f64],
    r: &FlowResult,
    cones: &[u32],
    needs_cut: bool,
) -> Result<SubdivisionChart> {
    let tr = triangulation(r)?;
    let mesh = &surface.mesh;
    let t = &tr.triangulation;
    // The cut and layout of `T` and the overlay of the input with `T` do not depend on each
    // other: the two run side by side (`rayon::join`).
    let (unfolded, sub) = rayon::join(
        || -> Result<_> {
            let t_len =
                simplicial_lengths(tr, &r.lengths).unwrap_or_else(|| super::unfold::lengths(t));
            let t_cut = if needs_cut {
                super::unfold::cut_edges(t, &t_len, cones)
            } else {
                vec![false; t.n_edges()]
            };
            let t_uv = super::unfold::unfold(t, &t_len, &t_cut)?;
            Ok((t_cut, t_uv))
        },
        || {
            CommonSubdivision::from_triangulation(
                mesh,
                Geometry::Euclidean,
                lengths,
                &tr.triangulation,
                &r.u,
            )
        },
    );
    let (t_cut, t_uv) = unfolded?;
    let sub = sub?;
    let corner_uv = sub.uv(Geometry::Euclidean, &r.u, &t_uv)?;
    let flipped = sub.flipped_triangles(Geometry::Euclidean, &corner_uv);
    let positions = sub.positions(mesh, &surface.positions)?;
    // Edge ids survive flips: an input edge never flipped is the edge of T with its id.
    let mut input_cut = vec![false; mesh.n_edges()];
    input_cut.copy_from_slice(&t_cut[..mesh.n_edges()]);
    for &e in &t.flip_log {
        input_cut[e as usize] = false;
    }
    Ok(SubdivisionChart {
        positions,
        triangles: sub.triangles,
        input_face: sub.input_face,
        corner_uv,
        input_cut,
        flipped,
    })
}

/// Faces of `faces` whose corner UVs (`uv[3f + i]`) are not positively oriented.
pub(super) fn folded_faces(faces: &[[u32; 3]], uv: &[[f64; 2]]) -> usize {
    (0..faces.len())
        .filter(|&f| {
            let q = &uv[3 * f..3 * f + 3];
            let a = (q[1][0] - q[0][0]) * (q[2][1] - q[0][1])
                - (q[2][0] - q[0][0]) * (q[1][1] - q[0][1]);
            a.is_nan() || a <= 0.0
        })
        .count()
}

/// Scale corner UVs (in place) so that the map's total UV area equals the 3D area.
pub(super) fn scale_to_area(positions: &[[f64; 3]], faces: &[[u32; 3]], uv: &mut [[f64; 2]]) {
    use crate::numeric::vec3::{cross, norm, sub};
    let (mut a3, mut a2) = (0.0, 0.0);
    for (f, t) in faces.iter().enumerate() {
        let p = |i: usize| positions[t[i] as usize];
        a3 += 0.5 * norm(cross(sub(p(1), p(0)), sub(p(2), p(0))));
        let q = &uv[3 * f..3 * f + 3];
        a2 += 0.5
            * ((q[1][0] - q[0][0]) * (q[2][1] - q[0][1])
                - (q[2][0] - q[0][0]) * (q[1][1] - q[0][1]));
    }
    if a2 > 0.0 && a3 > 0.0 {
        let s = (a3 / a2).sqrt();
        for q in uv.iter_mut() {
            q[0] *= s;
            q[1] *= s;
        }
    }
}

/// Seam edges of a mesh with corner UVs: interior edges whose two sides' UVs differ by more
/// than `1e-9` of the layout's size (cut edges; after the layout every other edge has equal
/// UVs on both sides up to rounding).
pub(super) fn seam_edges(mesh: &Mesh, uv: &[[f64; 2]]) -> Vec<bool> {
    let mut lo = [f64::INFINITY; 2];
    let mut hi = [f64::NEG_INFINITY; 2];
    for p in uv {
        for k in 0..2 {
            lo[k] = lo[k].min(p[k]);
            hi[k] = hi[k].max(p[k]);
        }
    }
    let tol = 1e-9 * (hi[0] - lo[0]).hypot(hi[1] - lo[1]).max(1e-300);
    let d = |a: [f64; 2], b: [f64; 2]| (a[0] - b[0]).hypot(a[1] - b[1]);
    (0..mesh.n_edges() as u32)
        .map(|e| {
            if mesh.is_boundary_edge(e) {
                return false;
            }
            let h = mesh.edge_halfedge(e);
            let g = mesh.he_twin(h);
            let (pa, pb) = (uv[h as usize], uv[mesh.he_next(h) as usize]);
            let (qb, qa) = (uv[g as usize], uv[mesh.he_next(g) as usize]);
            d(pa, qa) > tol || d(pb, qb) > tol
        })
        .collect()
}

/// Seams of a chart: cut edges, their total 3D length, the largest relative length mismatch
/// of the two sides, the distinct transition rotation angles and their largest distance from
/// a quarter turn.
pub(super) struct SeamReport {
    pub edges: usize,
    pub length: f64,
    pub mismatch: f64,
    pub angles: Vec<f64>,
    pub quarter_turn_error: f64,
}

/// [`SeamReport`] of `mesh` (3D `positions`) with corner UVs `uv` and seam flags `seam`.
pub(super) fn seam_report(
    mesh: &Mesh,
    positions: &[[f64; 3]],
    uv: &[[f64; 2]],
    seam: &[bool],
) -> SeamReport {
    use crate::numeric::vec3::{norm, sub};
    let mut s = SeamReport {
        edges: 0,
        length: 0.0,
        mismatch: 0.0,
        angles: Vec::new(),
        quarter_turn_error: 0.0,
    };
    for e in 0..mesh.n_edges() as u32 {
        if !seam[e as usize] || mesh.is_boundary_edge(e) {
            continue;
        }
        let [a, b] = mesh.edge_vertices(e);
        s.edges += 1;
        s.length += norm(sub(positions[a as usize], positions[b as usize]));
        let h = mesh.edge_halfedge(e);
        let g = mesh.he_twin(h);
        // h: a→b in face h/3; g: b→a.
        let (pa, pb) = (uv[h as usize], uv[mesh.he_next(h) as usize]);
        let (qb, qa) = (uv[g as usize], uv[mesh.he_next(g) as usize]);
        let d1 = [pb[0] - pa[0], pb[1] - pa[1]];
        let d2 = [qb[0] - qa[0], qb[1] - qa[1]];
        let (l1, l2) = (d1[0].hypot(d1[1]), d2[0].hypot(d2[1]));
        s.mismatch = s.mismatch.max((l1 - l2).abs() / l1.max(l2).max(1e-300));
        let ang = (d1[0] * d2[1] - d1[1] * d2[0]).atan2(d1[0] * d2[0] + d1[1] * d2[1]);
        let q = (ang / (PI / 2.0)).round() * (PI / 2.0);
        s.quarter_turn_error = s.quarter_turn_error.max((ang - q).abs());
        if !s.angles.iter().any(|&x| {
            let d = (x - ang).abs();
            d < 1e-6 || (2.0 * PI - d).abs() < 1e-6
        }) && s.angles.len() < 64
        {
            s.angles.push(ang);
        }
    }
    s.angles.sort_by(f64::total_cmp);
    s
}
