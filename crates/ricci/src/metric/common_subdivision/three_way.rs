//! The three-way overlay (CEPS §5) for a flip log that starts with isometric flips: the input
//! mesh `M`, the input metric's Delaunay triangulation `T_iso` (reached by the isometric
//! prefix of the log, Euclidean), and the final triangulation `T` (reached from `T_iso` by
//! Ptolemy flips).
//!
//! [`CommonSubdivision::from_triangulation`] maps every input face to the ideal triangle of
//! `T`'s hyperbolic structure spanned by its straightened edges. On an input edge that the
//! isometric flips removed that map can be extremely distorted: on the disks whose boundary
//! faces were split off-centre, flowed on their double (issue 15, docs/notes/wave2-s8-half8.md),
//! crossings land within 1e-14 … 1e-21 of a boundary vertex and pieces flip. Here the map is
//! the composition the theory prescribes: `M → T_iso` is the identity of the input metric
//! (input edges are straight in every triangle of `T_iso`), `T_iso → T` is the projective map
//! of the Ptolemy flips. Every crossing of an input edge `e0` with an edge `ε` of `T` is
//! computed inside the triangle `τ` of `T_iso` holding it:
//!
//! - `e0`'s chord in `τ` comes from developing `e0`'s strip of `T_iso`-triangles in the plane
//!   (Euclidean lengths) and intersecting the straight segment with the strip's edges;
//! - `ε`'s chord in `τ` joins the points where `ε` crosses `τ`'s sides (or starts at a corner),
//!   taken from the common subdivision of `T_iso` (as the input, exact: Ptolemy flips only)
//!   with `T`;
//! - both chords are straight in `τ`'s barycentric coordinates (`τ` is the Klein model of its
//!   circumdisk, parent module), so the crossing is a line–line intersection; its position on
//!   `e0` is Euclidean (linear along the chord), its projective coordinate `log(β_0/β_1)` on
//!   `ε` follows from the cross-ratio with `ε`'s two ideal ends — the intersections of its line
//!   with `τ`'s circumcircle `Σ β_i β_j l_ij² = 0` — calibrated at one chord end, and checked
//!   at the other (`ThreeWayReport::calibration_error`).
//!
//! The combinatorics (which edge of `T` each crossing is on, in which order) stays the normal
//! coordinates' of the full log. Where the geometric order found here does not agree with it (a
//! vertex within rounding of an input edge: on the disk with 300 off-centre splits an input
//! face has height 7.1e-9 × its side, below what its edge lengths resolve), the places are
//! made monotone in the combinatorial order ([`super::monotone`]), and the change reported.

use super::input::{DeltaInput, InputComplex};
use super::monotone::MonotoneRepair;
use super::normal::{face_counts, replay_on, TriangleArcs};
use super::polygons::face_polygons;
use super::trace::walk;
use super::{CommonSubdivision, Tri};
use crate::error::{Error, Result};
use crate::mesh::{Mesh, NONE};
use crate::metric::intrinsic::{length_of_lambda, IntrinsicTriangulation};
use crate::metric::Geometry;

/// How far (as a fraction of its edge of `T_iso`) a crossing may fall outside that edge by
/// rounding before the strip is refused.
const SLACK: f64 = 1e-6;

/// What the three-way overlay measured.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct ThreeWayReport {
    /// Isometric flips of the log (the prefix to `T_iso`).
    pub isometric_flips: usize,
    /// Crossings of input edges with edges of `T` placed through `T_iso`.
    pub crossings: usize,
    /// Largest |log(β_0/β_1)| mismatch at the far end of a chord of an edge of `T` in a
    /// triangle of `T_iso` (the cross-ratio calibrated at one end, evaluated at the other):
    /// rounding when the two overlays agree.
    pub calibration_error: f64,
    /// Input edges whose crossings through `T_iso` did not match the normal coordinates'
    /// edges of `T` (a vertex within rounding of the edge): the runs that agree from either
    /// end are placed, the crossings in between by the monotone repair (`repair`).
    pub kept_edges: usize,
    /// Input edges whose crossings were found in another order than the normal coordinates'
    /// (within rounding of a vertex): paired with them edge of `T` by edge of `T`, their
    /// parameters on the input edge kept in sorted order.
    pub reordered_edges: usize,
    /// Why the crossings were left at the ideal-triangle map's places, if they were (e.g. the
    /// input metric's Delaunay triangulation has two edges between the same vertices).
    pub fallback: Option<String>,
    /// Largest change of a crossing's parameter on its input edge against the ideal-triangle
    /// map of [`CommonSubdivision::from_triangulation`].
    pub moved: f64,
    /// The monotone repair of the places found (a vertex within rounding of an input edge).
    pub repair: MonotoneRepair,
    /// Pairs of vertices joined by two or more edges of the input metric's Delaunay
    /// triangulation `T_iso` (a Δ-complex; camelhead's double has such pairs).
    pub iso_multi_edges: usize,
}

/// A chord of an edge `eps` of `T` inside a triangle of `T_iso`: from `a` to `b` (barycentric
/// coordinates on the triangle, `a` earlier along `eps`), with `log(β_0/β_1)` on `eps` at both
/// ends (`+∞` / `−∞` at a corner).
#[derive(Clone, Copy)]
struct Chord {
    eps: u32,
    a: [f64; 3],
    b: [f64; 3],
    rho_a: f64,
    rho_b: f64,
}

impl CommonSubdivision {
    /// [`CommonSubdivision::from_triangulation_on`] when the first `isometric` flips of
    /// `t.flip_log` are isometric (Euclidean) flips of `start`'s metric (`start.lambda`: the
    /// input's Euclidean lengths as log Penner coordinates): the crossings are placed through
    /// the input metric's Delaunay triangulation (module docs). E² only.
    pub fn from_triangulation_three_way(
        mesh: &Mesh,
        start: IntrinsicTriangulation,
        t: &IntrinsicTriangulation,
        u: &[f64],
        isometric: usize,
    ) -> Result<(CommonSubdivision, ThreeWayReport)> {
        let full = Self::from_triangulation_on(mesh, start.clone(), t, u)?;
        let mut report = ThreeWayReport {
            isometric_flips: isometric,
            ..ThreeWayReport::default()
        };
        if isometric == 0 {
            return Ok((full, report));
        }
        let mut placed = full.clone();
        match place_through_iso(mesh, start, t, u, isometric, &mut placed, &mut report) {
            Ok(()) => Ok((placed, report)),
            Err(e) => {
                report.fallback = Some(e.to_string());
                Ok((full, report))
            }
        }
    }
}

/// The body of [`CommonSubdivision::from_triangulation_three_way`]: re-place the crossings of
/// `full` (the overlay by the ideal-triangle map) through `T_iso`.
fn place_through_iso(
    mesh: &Mesh,
    start: IntrinsicTriangulation,
    t: &IntrinsicTriangulation,
    u: &[f64],
    isometric: usize,
    full: &mut CommonSubdivision,
    report: &mut ThreeWayReport,
) -> Result<()> {
    {
        let log = &t.flip_log;
        if isometric > log.len() {
            return Err(Error::input(format!(
                "{isometric} isometric flips, but the flip log has {} entries",
                log.len()
            )));
        }
        // T_iso with its Euclidean lengths, and the input's normal coordinates there.
        let mut iso = start.clone();
        for &e in &log[..isometric] {
            if !iso.flip_isometric(e, Geometry::Euclidean) {
                return Err(Error::input(format!(
                    "isometric flip of edge {e} impossible"
                )));
            }
        }
        iso.flip_log.clear();
        let (comb, normal_iso) = replay_on(start, &log[..isometric])?;
        if comb.origin != iso.origin || comb.twin != iso.twin {
            return Err(Error::numerical(
                "the isometric flips do not replay to the same triangulation",
            ));
        }
        // T_iso as the input of the Ptolemy part (a Δ-complex: two of its edges may join the
        // same vertices, told apart by their λ): its overlay with T.
        let mesh_iso = DeltaInput::new(&iso).map_err(|e| {
            Error::numerical(format!(
                "the input metric's Delaunay triangulation is not a triangulation the three-way \
                 overlay takes ({e})"
            ))
        })?;
        report.iso_multi_edges = mesh_iso.multi_edges();
        let mut t_rest = t.clone();
        t_rest.flip_log = log[isometric..].to_vec();
        let s2 =
            CommonSubdivision::from_triangulation_on_input(&mesh_iso, iso.clone(), &t_rest, u)?;
        let chords = chords_in_iso_faces(&mesh_iso, &iso, &s2, report)?;
        place_crossings(mesh, &iso, &normal_iso, &s2, &chords, full, report)?;
        super::monotone::repair(mesh, full, &mut report.repair);
        rebuild_polygons(mesh, full)
    }
}

/// The chords of the edges of `T` in every triangle of `T_iso` (from `s2`, the overlay of
/// `T_iso` as the input with `T`).
fn chords_in_iso_faces(
    mesh_iso: &DeltaInput,
    iso: &Tri,
    s2: &CommonSubdivision,
    report: &mut ThreeWayReport,
) -> Result<Vec<Vec<Chord>>> {
    let mut chords: Vec<Vec<Chord>> = vec![Vec::new(); iso.n_faces()];
    let tri = &s2.triangulation;
    let faces_of = |e: u32| -> [u32; 2] {
        let h = mesh_iso.edge_halfedge(e);
        [mesh_iso.he_face(h), mesh_iso.he_face(mesh_iso.he_twin(h))]
    };
    let bary_corner = |f: u32, v: u32| -> Option<[f64; 3]> {
        let i = mesh_iso.face(f).iter().position(|&w| w == v)?;
        let mut b = [0.0; 3];
        b[i] = 1.0;
        Some(b)
    };
    for eps in 0..tri.n_edges() as u32 {
        let n = s2.normal[eps as usize];
        if n < 0 {
            continue; // an edge of T_iso: handled where e0 crosses it
        }
        let [v0, v1] = tri.edge_vertices(eps);
        let cs = &s2.crossings[s2.crossing_offset[eps as usize] as usize
            ..s2.crossing_offset[eps as usize + 1] as usize];
        if cs.is_empty() {
            return Err(Error::numerical(format!(
                "edge {eps} of the final triangulation crosses no edge of the input metric's \
                 Delaunay triangulation and is none of them"
            )));
        }
        // Points along eps: v0, the crossings, v1 (with their input edge of T_iso, or NONE).
        let mut pts: Vec<(u32, u32, f64, f64)> = Vec::with_capacity(cs.len() + 2);
        pts.push((v0, NONE, 0.0, f64::INFINITY));
        for c in cs {
            pts.push((NONE, c.input_edge, c.input_t, c.t_log_ratio));
        }
        pts.push((v1, NONE, 0.0, f64::NEG_INFINITY));
        for k in 0..pts.len() - 1 {
            let (p, q) = (pts[k], pts[k + 1]);
            let cand: Vec<u32> = if p.1 != NONE && q.1 != NONE {
                let (fp, fq) = (faces_of(p.1), faces_of(q.1));
                fp.iter().copied().filter(|f| fq.contains(f)).collect()
            } else {
                let (edge, corner) = if p.1 == NONE { (q.1, p.0) } else { (p.1, q.0) };
                faces_of(edge)
                    .iter()
                    .copied()
                    .filter(|&f| {
                        let [a, b] = mesh_iso.edge_vertices(edge);
                        mesh_iso
                            .face(f)
                            .iter()
                            .any(|&w| w == corner && w != a && w != b)
                    })
                    .collect()
            };
            let [f] = cand[..] else {
                return Err(Error::numerical(format!(
                    "edge {eps} of the final triangulation: the triangle of the input metric's \
                     Delaunay triangulation between two of its crossings is not unique ({} \
                     candidates)",
                    cand.len()
                )));
            };
            let point = |x: (u32, u32, f64, f64)| -> Option<[f64; 3]> {
                if x.1 == NONE {
                    return bary_corner(f, x.0);
                }
                let [a, b] = mesh_iso.edge_vertices(x.1);
                let mut w = bary_corner(f, a)?;
                let wb = bary_corner(f, b)?;
                for i in 0..3 {
                    w[i] = w[i] * (1.0 - x.2) + wb[i] * x.2;
                }
                Some(w)
            };
            let (Some(a), Some(b)) = (point(p), point(q)) else {
                return Err(Error::numerical(format!(
                    "edge {eps} of the final triangulation: a chord end is not on its triangle"
                )));
            };
            chords[f as usize].push(Chord {
                eps,
                a,
                b,
                rho_a: p.3,
                rho_b: q.3,
            });
        }
    }
    // Check the cross-ratio calibration at the far end of every chord with two finite ends.
    for (f, list) in chords.iter().enumerate() {
        let l = side_lengths(iso, f as u32);
        for c in list {
            if c.rho_a.is_finite() && c.rho_b.is_finite() {
                let r = chord_rho(c, &l, 1.0)?;
                report.calibration_error = report.calibration_error.max((r - c.rho_b).abs());
            }
        }
    }
    Ok(chords)
}

/// Squared Euclidean side lengths of triangle `f` of `T_iso`: `[l01², l12², l20²]`.
fn side_lengths(iso: &Tri, f: u32) -> [f64; 3] {
    [0, 1, 2].map(|j| {
        let l = length_of_lambda(
            Geometry::Euclidean,
            iso.lambda[iso.edge[3 * f as usize + j] as usize],
        );
        l * l
    })
}

/// The symmetric bilinear form of `Σ β_i β_j l_ij²` (zero on the circumcircle).
fn bil(x: [f64; 3], y: [f64; 3], l: &[f64; 3]) -> f64 {
    0.5 * ((x[0] * y[1] + x[1] * y[0]) * l[0]
        + (x[1] * y[2] + x[2] * y[1]) * l[1]
        + (x[2] * y[0] + x[0] * y[2]) * l[2])
}

/// `log(β_0/β_1)` on the chord's edge of `T` at the point `a + x (b − a)` (module docs).
fn chord_rho(c: &Chord, l: &[f64; 3], x: f64) -> Result<f64> {
    let d = [c.b[0] - c.a[0], c.b[1] - c.a[1], c.b[2] - c.a[2]];
    let (qa, qb, qc) = (bil(d, d, l), 2.0 * bil(c.a, d, l), bil(c.a, c.a, l));
    let disc = qb * qb - 4.0 * qa * qc;
    if !(qa < 0.0) || !(disc >= 0.0) {
        return Err(Error::numerical(format!(
            "a chord of edge {} of the final triangulation does not meet the circumcircle of its \
             triangle twice",
            c.eps
        )));
    }
    let q = -0.5 * (qb + qb.signum() * disc.sqrt());
    let (r1, r2) = if q == 0.0 {
        (0.0, 0.0)
    } else {
        (q / qa, qc / q)
    };
    let (xc, xd) = (r1.min(r2), r1.max(r2));
    let log_k = if c.rho_a.is_finite() {
        c.rho_a - xd.ln() + (-xc).ln()
    } else if c.rho_b.is_finite() {
        c.rho_b - (xd - 1.0).ln() + (1.0 - xc).ln()
    } else {
        return Err(Error::numerical(format!(
            "a chord of edge {} of the final triangulation joins two corners",
            c.eps
        )));
    };
    Ok(log_k + (xd - x).ln() - (x - xc).ln())
}

/// Intersection of the segments `p0 → p1` and `a → b` (barycentric coordinates on one
/// triangle): the parameters `(μ, ν)` along each.
fn intersect(p0: [f64; 3], p1: [f64; 3], a: [f64; 3], b: [f64; 3]) -> Option<(f64, f64)> {
    // In the affine coordinates (β_1, β_2).
    let (d1, d2) = ([p1[1] - p0[1], p1[2] - p0[2]], [b[1] - a[1], b[2] - a[2]]);
    let r = [a[1] - p0[1], a[2] - p0[2]];
    let det = d1[0] * (-d2[1]) - d1[1] * (-d2[0]);
    if det == 0.0 || !det.is_finite() {
        return None;
    }
    let mu = (r[0] * (-d2[1]) - r[1] * (-d2[0])) / det;
    let nu = (d1[0] * r[1] - d1[1] * r[0]) / det;
    Some((mu, nu))
}

/// The third corner of a triangle with `|c − a| = la`, `|c − b| = lb`, left of `a → b`.
fn third(a: [f64; 2], b: [f64; 2], la: f64, lb: f64) -> [f64; 2] {
    let (dx, dy) = (b[0] - a[0], b[1] - a[1]);
    let lab = dx.hypot(dy);
    let (ex, ey) = (dx / lab, dy / lab);
    let x = (la * la - lb * lb + lab * lab) / (2.0 * lab);
    let y = (la * la - x * x).max(0.0).sqrt();
    [a[0] + x * ex - y * ey, a[1] + x * ey + y * ex]
}

/// Barycentric coordinates on the face of half-edge `h` of the point at parameter `s` from
/// `origin(h)` along it.
fn on_side(h: u32, s: f64) -> (u32, [f64; 3]) {
    let j = (h % 3) as usize;
    let mut b = [0.0; 3];
    b[j] = 1.0 - s;
    b[(j + 1) % 3] = s;
    (h / 3, b)
}

/// Every input edge crossing `T_iso`: its Euclidean strip, its chords, their crossings with
/// the chords of `T`'s edges; written into `full`'s crossings (module docs).
#[allow(clippy::too_many_arguments)]
fn place_crossings(
    mesh: &Mesh,
    iso: &Tri,
    normal_iso: &[i32],
    s2: &CommonSubdivision,
    chords: &[Vec<Chord>],
    full: &mut CommonSubdivision,
    report: &mut ThreeWayReport,
) -> Result<()> {
    let arcs = (0..iso.n_faces() as u32)
        .map(|f| {
            TriangleArcs::new(face_counts(iso, normal_iso, f))
                .ok_or_else(|| Error::numerical("inconsistent normal coordinates on T_iso"))
        })
        .collect::<Result<Vec<_>>>()?;
    // full's crossings per input edge, by rank.
    let mut by_edge: Vec<Vec<u32>> = vec![Vec::new(); mesh.n_edges()];
    for (id, c) in full.crossings.iter().enumerate() {
        by_edge[c.input_edge as usize].push(id as u32);
    }
    for list in &mut by_edge {
        list.sort_by_key(|&id| full.crossings[id as usize].input_rank);
    }
    let mut done = vec![false; mesh.n_edges()];
    let budget: usize = normal_iso.iter().map(|&n| n.max(0) as usize).sum();
    for e in 0..iso.n_edges() as u32 {
        for pc in 0..normal_iso[e as usize].max(0) as u32 {
            // The strip of the input edge through crossing pc of e (as `Tracer::strip`).
            let n = normal_iso[e as usize] as u32;
            let g = iso.edge_he[e as usize];
            let tg = iso.twin[g as usize];
            let (fwd, end) = walk(iso, normal_iso, &arcs, g, pc, budget)?;
            let (bwd, start) = walk(iso, normal_iso, &arcs, tg, n - 1 - pc, budget)?;
            let (a, b) = (iso.origin[start as usize], iso.origin[end as usize]);
            let h0 = mesh.halfedge_between(a, b).ok_or_else(|| {
                Error::numerical(format!(
                    "an input edge traced through the input metric's Delaunay triangulation \
                     joins vertices {a} and {b}, which are not adjacent in the input"
                ))
            })?;
            let e0 = mesh.he_edge(h0);
            if done[e0 as usize] {
                continue;
            }
            done[e0 as usize] = true;
            let mut path: Vec<u32> = bwd
                .iter()
                .rev()
                .map(|&(h, _)| iso.twin[h as usize])
                .collect();
            path.push(g);
            path.extend(fwd.iter().map(|&(h, _)| h));
            let xs = develop_strip(iso, &path, start, end).map_err(|x| {
                Error::numerical(format!(
                    "input edge {e0} ({a}, {b}) leaves its strip of the input metric's Delaunay \
                     triangulation (parameters {:.17e}, {:.17e})",
                    x.0, x.1
                ))
            })?;
            let mut found = crossings_along(iso, s2, chords, &path, &xs, start, end)?;
            found.sort_by(|p, q| p.0.total_cmp(&q.0));
            let forward = mesh.edge_vertices(e0)[0] == a;
            if !forward {
                found.reverse();
            }
            let ids = &by_edge[e0 as usize];
            let matches = ids.len() == found.len()
                && ids
                    .iter()
                    .zip(&found)
                    .all(|(&id, f)| full.crossings[id as usize].t_edge == f.1);
            if !matches {
                if let Some(paired) = pair_by_edge(full, ids, &found) {
                    found = paired;
                    report.reordered_edges += 1;
                } else {
                    // The geometric path passes a vertex on the other side than the normal
                    // coordinates say (within rounding of it): the crossings that agree from
                    // either end are placed, the others left to the monotone repair.
                    report.kept_edges += 1;
                    align_ends(full, ids, &found, forward, report);
                    continue;
                }
            }
            for (&id, f) in ids.iter().zip(&found) {
                let c = &mut full.crossings[id as usize];
                let t = if forward { f.0 } else { 1.0 - f.0 };
                report.moved = report.moved.max((t - c.input_t).abs());
                c.input_t = t;
                c.t_log_ratio = f.2;
                report.crossings += 1;
            }
        }
    }
    Ok(())
}

/// The strip `path` of an input edge through `T_iso` (from corner `start` to corner `end`)
/// developed in the plane (Euclidean lengths): for every crossed half-edge, the parameter of
/// the crossing along the input edge and along the half-edge (from its origin). On failure,
/// the parameters that fell outside `(0, 1)`.
fn develop_strip(
    iso: &Tri,
    path: &[u32],
    start: u32,
    end: u32,
) -> std::result::Result<Vec<(f64, f64)>, (f64, f64)> {
    let len = |h: u32| {
        length_of_lambda(
            Geometry::Euclidean,
            iso.lambda[iso.edge[h as usize] as usize],
        )
    };
    let x = iso.twin[path[0] as usize];
    if Tri::prev(x) != start {
        return Err((f64::NAN, f64::NAN));
    }
    let (p, q) = ([0.0, 0.0], [len(x), 0.0]);
    let pa = third(p, q, len(Tri::prev(x)), len(Tri::next(x)));
    // Endpoints (origin, tip) of every crossed half-edge.
    let mut ends: Vec<([f64; 2], [f64; 2])> = vec![(q, p)];
    for k in 0..path.len() {
        let h = path[k];
        let (o, t) = ends[k];
        let w = third(o, t, len(Tri::prev(h)), len(Tri::next(h)));
        if k + 1 < path.len() {
            ends.push(if iso.twin[Tri::next(h) as usize] == path[k + 1] {
                (w, t)
            } else {
                (o, w)
            });
        } else {
            if Tri::prev(h) != end {
                return Err((f64::NAN, f64::NAN));
            }
            ends.push((w, w));
        }
    }
    let pb = ends[path.len()].0;
    let mut xs = Vec::with_capacity(path.len());
    for &(o, t) in &ends[..path.len()] {
        let d1 = [pb[0] - pa[0], pb[1] - pa[1]];
        let d2 = [t[0] - o[0], t[1] - o[1]];
        let r = [o[0] - pa[0], o[1] - pa[1]];
        let det = d1[0] * (-d2[1]) + d1[1] * d2[0];
        let xk = (r[0] * (-d2[1]) + r[1] * d2[0]) / det;
        let sk = (d1[0] * r[1] - d1[1] * r[0]) / det;
        // A vertex within rounding of the input edge (an input face of height 7e-9 × its side
        // on the disk with 300 splits: its apex is placed from its lengths to ~1e-8) may put a
        // crossing a little past the end of its edge of T_iso: clamped.
        if !(xk > 0.0 && xk < 1.0 && sk > -SLACK && sk < 1.0 + SLACK) {
            return Err((xk, sk));
        }
        xs.push((xk, sk.clamp(0.0, 1.0)));
    }
    Ok(xs)
}

/// The crossings of an input edge (strip `path` of `T_iso` from corner `start` to `end`,
/// crossing parameters `xs`) with the edges of `T`: `(x along the input edge, edge of T,
/// log(β_0/β_1) on it)`, unsorted.
fn crossings_along(
    iso: &Tri,
    s2: &CommonSubdivision,
    chords: &[Vec<Chord>],
    path: &[u32],
    xs: &[(f64, f64)],
    start: u32,
    end: u32,
) -> Result<Vec<(f64, u32, f64)>> {
    // The chords of e0 and the crossings with T's edges, in order along e0.
    let mut found: Vec<(f64, u32, f64)> = Vec::new();
    for k in 0..=path.len() {
        let (f, p0, x0) = if k == 0 {
            let mut w = [0.0; 3];
            w[(start % 3) as usize] = 1.0;
            (start / 3, w, 0.0)
        } else {
            let (f, w) = on_side(path[k - 1], xs[k - 1].1);
            (f, w, xs[k - 1].0)
        };
        let (p1, x1) = if k == path.len() {
            let mut w = [0.0; 3];
            w[(end % 3) as usize] = 1.0;
            (w, 1.0)
        } else {
            let h = iso.twin[path[k] as usize];
            if h / 3 != f {
                return Err(Error::numerical("a strip of T_iso is not connected"));
            }
            (on_side(h, 1.0 - xs[k].1).1, xs[k].0)
        };
        let l = side_lengths(iso, f);
        for c in &chords[f as usize] {
            let Some((mu, nu)) = intersect(p0, p1, c.a, c.b) else {
                continue;
            };
            if mu > 0.0 && mu < 1.0 && nu > 0.0 && nu < 1.0 {
                found.push((x0 + mu * (x1 - x0), c.eps, chord_rho(c, &l, nu)?));
            }
        }
        if k < path.len() {
            let et = iso.edge[path[k] as usize];
            if s2.normal[et as usize] == -1 {
                // e0 crosses an edge of T that is an edge of T_iso.
                let h = path[k];
                let s = xs[k].1;
                let rho = ((1.0 - s) / s).ln();
                let canonical = s2.triangulation.edge_vertices(et)[0] == iso.origin[h as usize];
                found.push((xs[k].0, et, if canonical { rho } else { -rho }));
            }
        }
    }
    Ok(found)
}

/// An input edge whose crossings found through `T_iso` (`found`, sorted from the edge's first
/// vertex when `forward`) do not pair with its crossings in `full` (`ids`, by rank) edge of `T`
/// by edge of `T`: the longest runs that agree from either end are written; the crossings in
/// between get NaN places, filled in by [`super::monotone::repair`].
fn align_ends(
    full: &mut CommonSubdivision,
    ids: &[u32],
    found: &[(f64, u32, f64)],
    forward: bool,
    report: &mut ThreeWayReport,
) {
    let (n, m) = (ids.len(), found.len());
    let edge = |k: usize| full.crossings[ids[k] as usize].t_edge;
    let mut p = 0;
    while p < n.min(m) && edge(p) == found[p].1 {
        p += 1;
    }
    let mut q = 0;
    while q < (n - p).min(m - p) && edge(n - 1 - q) == found[m - 1 - q].1 {
        q += 1;
    }
    for k in 0..n {
        let c = &mut full.crossings[ids[k] as usize];
        let f = if k < p {
            Some(found[k])
        } else if k >= n - q {
            Some(found[m - (n - k)])
        } else {
            None
        };
        match f {
            Some(f) => {
                let t = if forward { f.0 } else { 1.0 - f.0 };
                report.moved = report.moved.max((t - c.input_t).abs());
                c.input_t = t;
                c.t_log_ratio = f.2;
                report.crossings += 1;
            }
            None => {
                c.input_t = f64::NAN;
                c.t_log_ratio = f64::NAN;
            }
        }
    }
}

/// `found` (crossings along an input edge, sorted) re-ordered as `ids` (its crossings in
/// `full`, by rank): the k-th crossing with an edge `ε` of `T` paired with the k-th found on
/// `ε`, the parameters along the input edge kept in sorted order. `None` when the counts per
/// edge of `T` differ.
fn pair_by_edge(
    full: &CommonSubdivision,
    ids: &[u32],
    found: &[(f64, u32, f64)],
) -> Option<Vec<(f64, u32, f64)>> {
    if ids.len() != found.len() {
        return None;
    }
    let mut used = vec![false; found.len()];
    let mut out = Vec::with_capacity(ids.len());
    for (k, &id) in ids.iter().enumerate() {
        let eps = full.crossings[id as usize].t_edge;
        let j = (0..found.len()).find(|&j| !used[j] && found[j].1 == eps)?;
        used[j] = true;
        out.push((found[k].0, eps, found[j].2));
    }
    Some(out)
}

/// Recompute the pieces of `sub` from its (re-placed) crossings.
fn rebuild_polygons(mesh: &Mesh, sub: &mut CommonSubdivision) -> Result<()> {
    sub.triangles.clear();
    sub.input_face.clear();
    sub.t_face.clear();
    sub.input_barycentric.clear();
    sub.t_weights.clear();
    sub.report.polygons = 0;
    let nf = sub.triangulation.n_faces() as u32;
    for f in 0..nf {
        let arcs = TriangleArcs::new(face_counts(&sub.triangulation, &sub.normal, f))
            .ok_or_else(|| Error::numerical("inconsistent normal coordinates"))?;
        face_polygons(mesh, sub, &arcs, f)?;
    }
    // Geometric order along the edges of T.
    let mut violations = 0;
    for e in 0..sub.triangulation.n_edges() {
        let cs =
            &sub.crossings[sub.crossing_offset[e] as usize..sub.crossing_offset[e + 1] as usize];
        violations += cs
            .windows(2)
            .filter(|w| !(w[1].t_log_ratio < w[0].t_log_ratio))
            .count();
    }
    sub.report.order_violations = violations;
    Ok(())
}
