//! Least-squares conformal refinement of the written map on the input's own faces.
//!
//! The flow's map is exactly conformal on the flat intrinsic Delaunay triangulation `T`, but
//! the map written on the input faces is the linear interpolation of its vertex positions,
//! which is not conformal where the input's triangles are not Delaunay (and can fold where `T`
//! flipped input edges). This module moves the written UVs to the least-squares conformal map
//! (LSCM, Lévy–Petitjean–Ray–Maillot 2002 §3; the Cauchy–Riemann energy of Mullen–Tong–Alliez–
//! Desbrun 2008 §3.1) on the input faces of the opened surface, keeping what the flow decided:
//!
//! * **cones** stay where they are (their wedges are pinned; with fewer than two pinned points
//!   the wedges of two far-apart points are pinned too, removing the similarities);
//! * **seam transitions** stay the same rigid motions: the correction `δ` of the UVs is a
//!   section of the flat bundle of the seams' rotations — across a cut edge whose two sides'
//!   UV edge vectors differ by the rotation `R` (measured on the map), the corrections of the
//!   two copies of a vertex satisfy `δ₂ = R δ₁` — so a seam edge's two sides still differ by
//!   the same rotation and translation. A vertex whose copies are linked by rotations that
//!   compose to a non-trivial one (a cone) is pinned;
//! * the boundary of the opened surface (the surface's own boundary, and the homology cut of
//!   free seams) stays where the flow put it: its wedges are pinned, so the boundary keeps
//!   the lengths of the free boundary (`u = 0`), a circle stays a circle, and the two sides
//!   of a free homology seam keep equal lengths. Only the inside moves.
//!
//! The energy of a face `f` with local complex coordinates `z_j` and UVs `w_j` is
//! `A_f |∂w/∂z̄|² / s_f`, with `∂w/∂z̄ = Σ_j w_j (z_{j+2} − z_{j+1}) / Σ_j z̄_j (z_{j+2} − z_{j+1})`
//! and `s_f` the face's present scale (UV over 3D edge lengths squared), so that every face
//! counts by its relative (Beltrami) distortion whatever its size in the chart — the flow's
//! maps shrink parts of a surface by orders of magnitude. The minimiser is one sparse
//! Cholesky solve of the normal equations. [`improve`] keeps it only when no triangle folds
//! (or lies within rounding of folding) and, when the map it replaces did not fold, its qc
//! p95 is no larger; otherwise it tries half and a quarter of the step.

use super::ladder::unresolved_flags;
use crate::analysis::distortion::{face_distortions, stats, uv_stats};
use crate::error::{Error, Result};
use crate::mesh::Mesh;
use faer::sparse::{SparseColMat, Triplet};
use std::collections::HashMap;

type C = [f64; 2];

fn mul(a: C, b: C) -> C {
    [a[0] * b[0] - a[1] * b[1], a[0] * b[1] + a[1] * b[0]]
}
fn div(a: C, b: C) -> C {
    let d = b[0] * b[0] + b[1] * b[1];
    [
        (a[0] * b[0] + a[1] * b[1]) / d,
        (a[1] * b[0] - a[0] * b[1]) / d,
    ]
}
fn sub(a: C, b: C) -> C {
    [a[0] - b[0], a[1] - b[1]]
}
fn conj(a: C) -> C {
    [a[0], -a[1]]
}
fn unit(a: C) -> C {
    let n = a[0].hypot(a[1]);
    [a[0] / n, a[1] / n]
}

/// Wedges (vertices of the opened surface) with the rotation that carries each one's
/// correction to its class representative's: `δ_w = rot[w] · δ_root(w)`.
struct Bundle {
    parent: Vec<u32>,
    rot: Vec<C>,
    pinned: Vec<bool>,
}

impl Bundle {
    fn new(n: usize) -> Bundle {
        Bundle {
            parent: (0..n as u32).collect(),
            rot: vec![[1.0, 0.0]; n],
            pinned: vec![false; n],
        }
    }

    /// Root of `w` and `ρ` with `δ_w = ρ δ_root` (with path compression).
    fn find(&mut self, w: u32) -> (u32, C) {
        let mut path = Vec::new();
        let mut x = w;
        while self.parent[x as usize] != x {
            path.push(x);
            x = self.parent[x as usize];
        }
        // From the node nearest the root outwards: rot[y] becomes y's rotation to the root.
        let mut rho = [1.0, 0.0];
        for &y in path.iter().rev() {
            rho = mul(self.rot[y as usize], rho);
            self.rot[y as usize] = rho;
            self.parent[y as usize] = x;
        }
        (
            x,
            if path.is_empty() {
                [1.0, 0.0]
            } else {
                self.rot[w as usize]
            },
        )
    }

    /// Link `δ_y = R δ_x`; a link that closes a loop with another rotation pins the class.
    fn link(&mut self, x: u32, y: u32, r: C) {
        let (rx, px) = self.find(x);
        let (ry, py) = self.find(y);
        let want = mul(r, px);
        if rx == ry {
            let d = sub(py, want);
            if d[0].hypot(d[1]) > 1e-9 {
                self.pinned[rx as usize] = true;
            }
            return;
        }
        // δ_ry = δ_y / py = R px δ_rx / py.
        self.parent[ry as usize] = rx;
        self.rot[ry as usize] = div(want, py);
        let p = self.pinned[ry as usize];
        self.pinned[rx as usize] |= p;
    }
}

/// The wedges of `mesh` opened along `cut` (module docs) in classes linked by the seam
/// rotations of `uv`, with the classes of the cones and of the boundary pinned: what every
/// round of [`improve`] shares (only the pins of the vertices that do not move change).
struct Wedges {
    bundle: Bundle,
    /// Per corner, its wedge's root and rotation (`δ_corner = ρ δ_root`).
    roots: Vec<(u32, C)>,
}

/// Wedge ids `0, 1, …` in the order of the corners that first meet them (a wedge is a vertex
/// with a sector between cut or boundary edges, named by [`super::seams::wedge_keys`]). Most
/// vertices have one wedge: a vertex's first wedge is kept beside it, further ones (seam
/// vertices) in a map.
fn wedge_ids(mesh: &Mesh, cut: &[bool]) -> (Vec<u32>, usize) {
    let keys = super::seams::wedge_keys(mesh, cut);
    let mut first: Vec<(u32, u32)> = vec![(u32::MAX, u32::MAX); mesh.n_vertices()];
    let mut more: HashMap<(u32, u32), u32> = HashMap::new();
    let mut n = 0u32;
    let ids = (0..mesh.n_corners() as u32)
        .map(|h| {
            let (v, k) = (mesh.he_origin(h) as usize, keys[h as usize]);
            let f = &mut first[v];
            if f.1 == u32::MAX {
                *f = (k, n);
            } else if f.0 != k {
                return *more.entry((v as u32, k)).or_insert_with(|| {
                    n += 1;
                    n - 1
                });
            } else {
                return f.1;
            }
            n += 1;
            n - 1
        })
        .collect();
    (ids, n as usize)
}

impl Wedges {
    /// The classes of the wedges of `mesh` opened along `cut`, linked by the seam rotations
    /// of `uv`; the classes of `cones` and of the boundary pinned.
    fn new(mesh: &Mesh, cut: &[bool], cones: &[u32], uv: &[C]) -> Result<Wedges> {
        let nc = mesh.n_corners();
        let (wedge, nw) = wedge_ids(mesh, cut);
        let mut b = Bundle::new(nw);
        // Longest seam edges first: their rotation is measured best and defines the classes.
        let mut seam: Vec<(f64, u32)> = (0..mesh.n_edges() as u32)
            .filter(|&e| cut[e as usize] && !mesh.is_boundary_edge(e))
            .map(|e| {
                let h = mesh.edge_halfedge(e);
                let d = sub(uv[mesh.he_next(h) as usize], uv[h as usize]);
                (d[0].hypot(d[1]), e)
            })
            .collect();
        seam.sort_by(|x, y| y.0.total_cmp(&x.0));
        for &(_, e) in &seam {
            let h = mesh.edge_halfedge(e);
            let g = mesh.he_twin(h);
            let (hn, gn) = (mesh.he_next(h), mesh.he_next(g));
            // h: a → b on side 1; g: b → a on side 2.
            let d1 = sub(uv[hn as usize], uv[h as usize]);
            let d2 = sub(uv[g as usize], uv[gn as usize]);
            if !(d1[0].hypot(d1[1]) > 0.0 && d2[0].hypot(d2[1]) > 0.0) {
                return Err(Error::numerical("a seam edge has zero length in the map"));
            }
            let r = unit(div(d2, d1));
            b.link(wedge[h as usize], wedge[gn as usize], r);
            b.link(wedge[hn as usize], wedge[g as usize], r);
        }
        let roots: Vec<(u32, C)> = (0..nc as u32).map(|h| b.find(wedge[h as usize])).collect();
        let mut is_cone = vec![false; mesh.n_vertices()];
        for &c in cones {
            is_cone[c as usize] = true;
        }
        for h in 0..nc {
            if is_cone[mesh.he_origin(h as u32) as usize] {
                b.pinned[roots[h].0 as usize] = true;
            }
        }
        // The boundary of the opened surface keeps its place (module docs).
        for e in 0..mesh.n_edges() as u32 {
            if mesh.is_boundary_edge(e) {
                let mut h = mesh.edge_halfedge(e);
                if mesh.is_boundary_halfedge(h) {
                    h = mesh.he_twin(h);
                }
                for c in [h, mesh.he_next(h)] {
                    b.pinned[roots[c as usize].0 as usize] = true;
                }
            }
        }
        Ok(Wedges { bundle: b, roots })
    }

    /// Per wedge, whether its class is pinned when only the `movable` vertices move: the
    /// cones, the boundary, the vertices not `movable`, and at least two pinned in all.
    fn pinned(&self, mesh: &Mesh, uv: &[C], movable: &[bool]) -> Vec<bool> {
        let nc = mesh.n_corners();
        let roots = &self.roots;
        let mut pinned = self.bundle.pinned.clone();
        for h in 0..nc {
            if !movable[mesh.he_origin(h as u32) as usize] {
                pinned[roots[h].0 as usize] = true;
            }
        }
        // Fewer than two pinned points: pin the corner farthest from the first pinned one (or
        // from corner 0) until there are two.
        for _ in 0..2 {
            let mut on = (0..nc).filter(|&h| pinned[roots[h].0 as usize]);
            let first = on.next();
            if first.is_some_and(|f| on.any(|h| roots[h].0 != roots[f].0)) {
                break;
            }
            let from = first.map_or(uv[0], |h| uv[h]);
            let far = (0..nc)
                .filter(|&h| !pinned[roots[h].0 as usize])
                .max_by(|&x, &y| {
                    let dx = sub(uv[x], from);
                    let dy = sub(uv[y], from);
                    dx[0].hypot(dx[1]).total_cmp(&dy[0].hypot(dy[1]))
                });
            let Some(far) = far else { break };
            pinned[roots[far].0 as usize] = true;
        }
        pinned
    }
}

/// The least-squares conformal refinement (module docs) of the corner UVs `uv[3f + i]` of
/// `mesh` (3D `positions`) with the wedge classes `wedges` of its cut, the wedges of vertices
/// not `movable` pinned, face `f`'s energy multiplied by `boost[f]`. Returns the new corner
/// UVs; the caller checks them for folds.
fn refine(
    positions: &[[f64; 3]],
    mesh: &Mesh,
    wedges: &Wedges,
    uv: &[C],
    movable: &[bool],
    boost: &[f64],
) -> Result<Vec<C>> {
    let nc = mesh.n_corners();
    let pinned = wedges.pinned(mesh, uv, movable);
    let (parent, roots) = (&wedges.bundle.parent, &wedges.roots);
    let nw = parent.len();
    let mut col = vec![u32::MAX; nw];
    let mut n = 0usize;
    for (w, c) in col.iter_mut().enumerate() {
        if parent[w] == w as u32 && !pinned[w] {
            *c = n as u32;
            n += 1;
        }
    }
    if n == 0 {
        return Ok(uv.to_vec());
    }
    let m = 2 * n;
    let mut trip: Vec<Triplet<usize, usize, f64>> = Vec::with_capacity(mesh.n_faces() * 42);
    let mut rhs = vec![0.0; m];
    for (f, t) in mesh.faces().iter().enumerate() {
        if (0..3).all(|j| col[roots[3 * f + j].0 as usize] == u32::MAX) {
            continue;
        }
        let p = |i: usize| positions[t[i] as usize];
        let e1 = crate::numeric::vec3::sub(p(1), p(0));
        let e2 = crate::numeric::vec3::sub(p(2), p(0));
        let l1 = crate::numeric::vec3::norm(e1);
        let x2 = crate::numeric::vec3::dot(e1, e2) / l1;
        let y2 = crate::numeric::vec3::norm(crate::numeric::vec3::cross(e1, e2)) / l1;
        let area = 0.5 * l1 * y2;
        if !(area > 0.0 && area.is_finite()) {
            continue;
        }
        let z = [[0.0, 0.0], [l1, 0.0], [x2, y2]];
        let s = [sub(z[2], z[1]), sub(z[0], z[2]), sub(z[1], z[0])];
        let mut d = [0.0, 0.0];
        for j in 0..3 {
            let x = mul(conj(z[j]), s[j]);
            d = [d[0] + x[0], d[1] + x[1]];
        }
        let q = |j: usize| uv[3 * f + j];
        let (mut l2uv, mut l23) = (0.0, 0.0);
        for j in 0..3 {
            let a = sub(q((j + 1) % 3), q(j));
            l2uv += a[0] * a[0] + a[1] * a[1];
            let a3 = crate::numeric::vec3::sub(p((j + 1) % 3), p(j));
            l23 += crate::numeric::vec3::dot(a3, a3);
        }
        let scale = l2uv / l23;
        if !(scale > 0.0 && scale.is_finite()) {
            continue;
        }
        let wgt = (boost[f] * area / scale).sqrt();
        let mut res = [0.0, 0.0];
        let mut cols: [(usize, C); 3] = [(usize::MAX, [0.0, 0.0]); 3];
        for j in 0..3 {
            let c = div(s[j], d);
            let c = [wgt * c[0], wgt * c[1]];
            let x = mul(c, q(j));
            res = [res[0] + x[0], res[1] + x[1]];
            let (r, rho) = roots[3 * f + j];
            let k = col[r as usize];
            if k != u32::MAX {
                cols[j] = (k as usize, mul(c, rho));
            }
        }
        // Real rows: Re and Im of Σ α_k δ_k + res, δ_k = (x_k, y_k) at columns 2k, 2k + 1.
        let mut rows: [[(usize, f64); 6]; 2] = [[(usize::MAX, 0.0); 6]; 2];
        for (j, &(k, a)) in cols.iter().enumerate() {
            if k == usize::MAX {
                continue;
            }
            rows[0][2 * j] = (2 * k, a[0]);
            rows[0][2 * j + 1] = (2 * k + 1, -a[1]);
            rows[1][2 * j] = (2 * k, a[1]);
            rows[1][2 * j + 1] = (2 * k + 1, a[0]);
        }
        for (row, r) in rows.iter().zip(res) {
            for &(i, a) in row {
                if i == usize::MAX {
                    continue;
                }
                rhs[i] -= a * r;
                for &(j, c) in row {
                    if j != usize::MAX && j <= i {
                        trip.push(Triplet::new(i, j, a * c));
                    }
                }
            }
        }
    }
    let a = SparseColMat::<usize, f64>::try_new_from_triplets(m, m, &trip)
        .map_err(|_| Error::numerical("LSCM: the normal equations could not be assembled"))?;
    drop(trip);
    let chol = crate::numeric::sparse::Cholesky::factor(a.as_ref())
        .map_err(|_| Error::numerical("LSCM: the normal equations are not positive definite"))?;
    chol.solve_in_place(faer::MatMut::from_column_major_slice_mut(&mut rhs, m, 1));
    Ok((0..nc)
        .map(|h| {
            let (r, rho) = roots[h];
            let k = col[r as usize];
            if k == u32::MAX {
                return uv[h];
            }
            let dk = mul(rho, [rhs[2 * k as usize], rhs[2 * k as usize + 1]]);
            [uv[h][0] + dk[0], uv[h][1] + dk[1]]
        })
        .collect())
}

/// Vertices of `faces` marked in `seed`, grown by `rings` rings of faces.
fn grow(mesh: &Mesh, seed: &[bool], rings: usize) -> Vec<bool> {
    let mut on = vec![false; mesh.n_vertices()];
    for (t, _) in mesh.faces().iter().zip(seed).filter(|x| *x.1) {
        for &v in t {
            on[v as usize] = true;
        }
    }
    for _ in 0..rings {
        let touch: Vec<bool> = mesh
            .faces()
            .iter()
            .map(|t| t.iter().any(|&v| on[v as usize]))
            .collect();
        for (t, _) in mesh.faces().iter().zip(&touch).filter(|x| *x.1) {
            for &v in t {
                on[v as usize] = true;
            }
        }
    }
    on
}

/// Rings around the faces to improve whose vertices move ([`improve`]).
const RINGS: usize = 3;
/// Rounds of [`improve`] on a map with folded faces: each multiplies the energy of the faces
/// still folded (or within rounding of folding) by [`BOOST`] and widens the region by
/// [`RINGS`].
const ROUNDS: usize = 6;
const BOOST: f64 = 100.0;
/// Rounds in a row without fewer unresolved faces (folded or within rounding of folding) than
/// the best round so far after which [`improve`] gives up on a folded map. Measured counts per
/// round: seahorse2_100K (8 cones, free) 1, 3, 1, 0 — unfolded in round 4 after two rounds
/// without progress; horse (8 cones) 1, 1, 1, 2, 1, 2 — never; so three, not two.
const STALLED_ROUNDS: usize = 3;

/// The refined corner UVs when they are better, else `None` (keep `uv`). Only the vertices
/// within [`RINGS`] rings of the faces to improve move: the folded faces when `uv` has some
/// (`folds > 0`; then rounds with the energy of the faces still folded boosted, given up after
/// [`STALLED_ROUNDS`] rounds without fewer of them, and the result is kept when no triangle
/// folds or lies within rounding of folding), else the faces of qc above the map's 95th
/// percentile (kept when no triangle folds and qc p95 does not grow). The rest of the map
/// stays as the flow made it.
pub(super) fn improve(
    positions: &[[f64; 3]],
    mesh: &Mesh,
    cut: &[bool],
    cones: &[u32],
    uv: &[C],
    folds: usize,
) -> Option<Vec<C>> {
    let faces = mesh.faces();
    let wedges = Wedges::new(mesh, cut, cones, uv).ok()?;
    let d = face_distortions(positions, faces, uv);
    let mut boost = vec![1.0; faces.len()];
    if folds > 0 {
        let mut bad: Vec<bool> = d.iter().map(|x| x.flipped()).collect();
        let mut fewest = usize::MAX;
        let mut stalled = 0;
        for round in 1..=ROUNDS {
            let movable = grow(mesh, &bad, RINGS * round);
            let cand = refine(positions, mesh, &wedges, uv, &movable, &boost).ok()?;
            let left = unresolved_flags(faces, &cand);
            let unresolved = left.iter().filter(|&&x| x).count();
            if unresolved == 0 {
                return Some(cand);
            }
            if unresolved < fewest {
                (fewest, stalled) = (unresolved, 0);
            } else {
                stalled += 1;
                if stalled == STALLED_ROUNDS {
                    return None;
                }
            }
            for (f, _) in left.iter().enumerate().filter(|x| *x.1) {
                bad[f] = true;
                boost[f] *= BOOST;
            }
        }
        return None;
    }
    let before = stats(&d).qc_p95;
    let top: Vec<bool> = d.iter().map(|x| x.qc() > before).collect();
    let movable = grow(mesh, &top, RINGS);
    let cand = refine(positions, mesh, &wedges, uv, &movable, &boost).ok()?;
    let after = uv_stats(positions, faces, &cand).qc_p95;
    let left = unresolved_flags(faces, &cand)
        .iter()
        .filter(|&&x| x)
        .count();
    (left == 0 && after <= before).then_some(cand)
}
