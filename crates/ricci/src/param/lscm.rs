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
//! Cholesky solve of the normal equations, written as an `n × n` Hermitian system in the
//! complex corrections of the `n` moving wedge classes ([`Normal`]; its realification is the
//! real `2n × 2n` system of the rows' real and imaginary parts). Only a region around the
//! faces to improve moves, and a round visits only that region's faces. [`improve`] keeps
//! the result only when no triangle folds (or lies within rounding of folding) and, when the
//! map it replaces did not fold, its qc p95 is no larger.

use super::ladder::{is_unresolved, unresolved_tolerance};
use crate::analysis::distortion::{face_distortion, face_distortions, qc_p95};
use crate::error::{Error, Result};
use crate::mesh::Mesh;
use crate::numeric::sparse::Cholesky;
use faer::c64;
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
    /// Per corner, its wedge.
    wedge: Vec<u32>,
    /// Per wedge, its class's root and rotation (`δ_wedge = ρ δ_root`).
    class: Vec<(u32, C)>,
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
    /// Corner `h`'s class root and rotation (`δ_h = ρ δ_root`).
    fn root(&self, h: usize) -> (u32, C) {
        self.class[self.wedge[h] as usize]
    }

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
        let class: Vec<(u32, C)> = (0..nw as u32).map(|w| b.find(w)).collect();
        let roots = |h: usize| class[wedge[h] as usize];
        let mut is_cone = vec![false; mesh.n_vertices()];
        for &c in cones {
            is_cone[c as usize] = true;
        }
        for h in 0..nc {
            if is_cone[mesh.he_origin(h as u32) as usize] {
                b.pinned[roots(h).0 as usize] = true;
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
                    b.pinned[roots(c as usize).0 as usize] = true;
                }
            }
        }
        Ok(Wedges {
            bundle: b,
            wedge,
            class,
        })
    }

    /// Per wedge, whether its class is pinned when only the `movable` vertices move: the
    /// cones, the boundary, the vertices not `movable`, and at least two pinned in all.
    fn pinned(&self, mesh: &Mesh, uv: &[C], movable: &[bool]) -> Vec<bool> {
        let nc = mesh.n_corners();
        let roots = |h: usize| self.root(h);
        let mut pinned = self.bundle.pinned.clone();
        for h in 0..nc {
            if !movable[mesh.he_origin(h as u32) as usize] {
                pinned[roots(h).0 as usize] = true;
            }
        }
        // Fewer than two pinned points: pin the corner farthest from the first pinned one (or
        // from corner 0) until there are two.
        for _ in 0..2 {
            let mut on = (0..nc).filter(|&h| pinned[roots(h).0 as usize]);
            let first = on.next();
            if first.is_some_and(|f| on.any(|h| roots(h).0 != roots(f).0)) {
                break;
            }
            let from = first.map_or(uv[0], |h| uv[h]);
            let far = (0..nc)
                .filter(|&h| !pinned[roots(h).0 as usize])
                .max_by(|&x, &y| {
                    let dx = sub(uv[x], from);
                    let dy = sub(uv[y], from);
                    dx[0].hypot(dx[1]).total_cmp(&dy[0].hypot(dy[1]))
                });
            let Some(far) = far else { break };
            pinned[roots(far).0 as usize] = true;
        }
        pinned
    }
}

/// The vertices that move in a round of [`improve`].
struct Region {
    /// Per vertex of the mesh, whether it moves.
    on: Vec<bool>,
    /// The moving vertices.
    vertices: Vec<u32>,
}

/// The vertices of the faces `seeds` grown by `rings` rings (each ring adds the vertices that
/// share a face with one already in): a breadth-first walk from the seeds, so a round costs
/// its region, not the mesh.
fn grow(mesh: &Mesh, seeds: &[u32], rings: usize) -> Region {
    let mut on = vec![false; mesh.n_vertices()];
    let mut vertices = Vec::new();
    for &f in seeds {
        for v in mesh.face(f) {
            if !on[v as usize] {
                on[v as usize] = true;
                vertices.push(v);
            }
        }
    }
    let mut start = 0;
    for _ in 0..rings {
        let end = vertices.len();
        for i in start..end {
            for w in mesh.vertex_neighbors(vertices[i]) {
                if !on[w as usize] {
                    on[w as usize] = true;
                    vertices.push(w);
                }
            }
        }
        start = end;
    }
    Region { on, vertices }
}

/// Face `f`'s term of the energy (module docs) as a function of the corner UVs `q`: the
/// weighted coefficients `c_j` of `∂w/∂z̄ = Σ_j c_j q_j` and its present value `Σ_j c_j q_j`;
/// `None` for a face of zero area in 3D or in the map (it adds nothing).
fn face_term(positions: &[[f64; 3]], t: [u32; 3], q: &[C], boost: f64) -> Option<([C; 3], C)> {
    use crate::numeric::vec3;
    let p = |i: usize| positions[t[i] as usize];
    let e1 = vec3::sub(p(1), p(0));
    let e2 = vec3::sub(p(2), p(0));
    let l1 = vec3::norm(e1);
    let x2 = vec3::dot(e1, e2) / l1;
    let y2 = vec3::norm(vec3::cross(e1, e2)) / l1;
    let area = 0.5 * l1 * y2;
    if !(area > 0.0 && area.is_finite()) {
        return None;
    }
    let z = [[0.0, 0.0], [l1, 0.0], [x2, y2]];
    let s = [sub(z[2], z[1]), sub(z[0], z[2]), sub(z[1], z[0])];
    let mut d = [0.0, 0.0];
    for j in 0..3 {
        let x = mul(conj(z[j]), s[j]);
        d = [d[0] + x[0], d[1] + x[1]];
    }
    let (mut l2uv, mut l23) = (0.0, 0.0);
    for j in 0..3 {
        let a = sub(q[(j + 1) % 3], q[j]);
        l2uv += a[0] * a[0] + a[1] * a[1];
        let a3 = vec3::sub(p((j + 1) % 3), p(j));
        l23 += vec3::dot(a3, a3);
    }
    let scale = l2uv / l23;
    if !(scale > 0.0 && scale.is_finite()) {
        return None;
    }
    let wgt = (boost * area / scale).sqrt();
    let mut c = [[0.0, 0.0]; 3];
    let mut value = [0.0, 0.0];
    for j in 0..3 {
        let cj = div(s[j], d);
        c[j] = [wgt * cj[0], wgt * cj[1]];
        let x = mul(c[j], q[j]);
        value = [value[0] + x[0], value[1] + x[1]];
    }
    Some((c, value))
}

/// The normal equations `H δ = b` of a round as an `n × n` Hermitian system in the complex
/// corrections `δ_k` of the moving wedge classes (columns): with face rows
/// `Σ_j α_j δ_{k_j} + r_f` (`α_j = c_j ρ_j`, `ρ_j` the corner's rotation to its class),
/// `H_ik = Σ_f ᾱ_i α_k` and `b_i = −Σ_f ᾱ_i r_f`. Its realification is the real `2n × 2n`
/// normal equations of the rows' real and imaginary parts (a complex entry `h` is the block
/// `[[Re h, −Im h], [Im h, Re h]]`, as `R(ᾱ)ᵀR(β) = R(ᾱβ)` for `R(α)` the real matrix of
/// multiplication by `α`): the same minimiser with half the unknowns.
struct Normal {
    n: usize,
    /// Lower triangle in compressed sparse columns, rows sorted in each column.
    col_ptr: Vec<usize>,
    row_idx: Vec<usize>,
    values: Vec<c64>,
    rhs: Vec<c64>,
}

/// A face's row: the columns of its corners (`u32::MAX` for a pinned one), their coefficients
/// `α_j` and the value `r_f`.
type Row = ([u32; 3], [C; 3], C);

/// The lower triangle's pattern (column pointers, rows sorted in each column) of the normal
/// equations of the face `rows` in `n` columns: each face's pairs of columns bucketed by
/// column, then each column's rows sorted and deduplicated.
fn lower_pattern(n: usize, rows: &[Row]) -> (Vec<usize>, Vec<usize>) {
    let pairs = || {
        rows.iter().flat_map(|(k, _, _)| {
            let k = *k;
            (0..9).filter_map(move |p| {
                let (i, j) = (k[p / 3], k[p % 3]);
                (i != u32::MAX && j != u32::MAX && j <= i).then_some((i, j))
            })
        })
    };
    let mut start = vec![0usize; n + 1];
    for (_, j) in pairs() {
        start[j as usize + 1] += 1;
    }
    for j in 0..n {
        start[j + 1] += start[j];
    }
    let mut fill = start.clone();
    let mut all = vec![0usize; start[n]];
    for (i, j) in pairs() {
        all[fill[j as usize]] = i as usize;
        fill[j as usize] += 1;
    }
    let mut col_ptr = vec![0usize; n + 1];
    let mut row_idx = Vec::with_capacity(all.len());
    for j in 0..n {
        let column = &mut all[start[j]..start[j + 1]];
        column.sort_unstable();
        let first = row_idx.len();
        for &i in column.iter() {
            if row_idx.len() == first || row_idx[row_idx.len() - 1] != i {
                row_idx.push(i);
            }
        }
        col_ptr[j + 1] = row_idx.len();
    }
    (col_ptr, row_idx)
}

impl Normal {
    fn assemble(n: usize, rows: &[Row]) -> Normal {
        let (col_ptr, row_idx) = lower_pattern(n, rows);
        let mut values = vec![c64::new(0.0, 0.0); row_idx.len()];
        let mut rhs = vec![c64::new(0.0, 0.0); n];
        for (k, a, r) in rows {
            let r = c64::new(r[0], r[1]);
            for (&i, ai) in k.iter().zip(a) {
                if i == u32::MAX {
                    continue;
                }
                let ai = c64::new(ai[0], ai[1]).conj();
                rhs[i as usize] -= ai * r;
                for (&j, aj) in k.iter().zip(a) {
                    if j == u32::MAX || j > i {
                        continue;
                    }
                    let (lo, hi) = (col_ptr[j as usize], col_ptr[j as usize + 1]);
                    let slot = lo + row_idx[lo..hi].partition_point(|&x| x < i as usize);
                    values[slot] += ai * c64::new(aj[0], aj[1]);
                }
            }
        }
        Normal {
            n,
            col_ptr,
            row_idx,
            values,
            rhs,
        }
    }

    /// The minimiser `δ` (sparse Cholesky LLᴴ).
    fn solve(self) -> Result<Vec<c64>> {
        use faer::sparse::{SparseColMat, SymbolicSparseColMat};
        let n = self.n;
        let pattern = SymbolicSparseColMat::new_checked(n, n, self.col_ptr, None, self.row_idx);
        let a = SparseColMat::<usize, c64>::new(pattern, self.values);
        let chol = Cholesky::factor(a.as_ref()).map_err(|_| {
            Error::numerical("LSCM: the normal equations are not positive definite")
        })?;
        let mut x = self.rhs;
        chol.solve_in_place(faer::MatMut::from_column_major_slice_mut(&mut x, n, 1));
        Ok(x)
    }
}

/// The least-squares conformal refinement (module docs) of the corner UVs `uv[3f + i]` of
/// `mesh` (3D `positions`) with the wedge classes `wedges` of its cut, only the vertices of
/// `region` moving, face `f`'s energy multiplied by `boost[f]`. Returns the corners that
/// move with their new UVs (the others keep theirs); the caller checks them for folds. Only
/// the region's faces are visited.
fn refine(
    positions: &[[f64; 3]],
    mesh: &Mesh,
    wedges: &Wedges,
    uv: &[C],
    region: &Region,
    boost: &[f64],
) -> Result<Vec<(u32, C)>> {
    let roots = |h: usize| wedges.root(h);
    // A class lies at one vertex (the seam links join copies of a vertex), so a moving
    // vertex's classes are pinned only by the cones and the boundary — unless fewer than two
    // vertices (with faces) stay, where [`Wedges::pinned`] adds pins.
    let staying = (0..mesh.n_vertices() as u32)
        .filter(|&v| !region.on[v as usize] && !mesh.is_isolated(v))
        .take(2)
        .count();
    let all_pins = (staying < 2).then(|| wedges.pinned(mesh, uv, &region.on));
    let pinned = all_pins.as_ref().unwrap_or(&wedges.bundle.pinned);
    let mut col = vec![u32::MAX; pinned.len()];
    let mut class: Vec<u32> = Vec::new();
    let corners: Vec<u32> = region
        .vertices
        .iter()
        .flat_map(|&v| mesh.vertex_corners(v))
        .collect();
    let corners = || corners.iter().copied();
    for h in corners() {
        let r = roots(h as usize).0 as usize;
        if col[r] == u32::MAX && !pinned[r] {
            col[r] = 0;
            class.push(r as u32);
        }
    }
    if class.is_empty() {
        return Ok(Vec::new());
    }
    class.sort_unstable();
    for (k, &r) in class.iter().enumerate() {
        col[r as usize] = k as u32;
    }
    let mut faces: Vec<u32> = corners()
        .filter(|&h| col[roots(h as usize).0 as usize] != u32::MAX)
        .map(|h| h / 3)
        .collect();
    faces.sort_unstable();
    faces.dedup();
    let rows: Vec<Row> = faces
        .iter()
        .filter_map(|&f| {
            let f = f as usize;
            let (c, value) = face_term(
                positions,
                mesh.face(f as u32),
                &uv[3 * f..3 * f + 3],
                boost[f],
            )?;
            let mut k = [u32::MAX; 3];
            let mut a = [[0.0, 0.0]; 3];
            for j in 0..3 {
                let (r, rho) = roots(3 * f + j);
                k[j] = col[r as usize];
                a[j] = mul(c[j], rho);
            }
            Some((k, a, value))
        })
        .collect();
    let delta = Normal::assemble(class.len(), &rows).solve()?;
    Ok(corners()
        .filter_map(|h| {
            let (r, rho) = roots(h as usize);
            let k = col[r as usize];
            (k != u32::MAX).then(|| {
                let d = mul(rho, [delta[k as usize].re, delta[k as usize].im]);
                (h, [uv[h as usize][0] + d[0], uv[h as usize][1] + d[1]])
            })
        })
        .collect())
}

/// A candidate map: `uv` with the corners of a round moved, and its faces that are
/// unresolved ([`super::ladder::unresolved_flags`]) found by re-testing only the faces that
/// moved (the others keep their verdict while the tolerance, set by the map's extent, stays).
struct Trial {
    uv: Vec<C>,
    tol: f64,
    /// The unresolved faces of the map the trial started from, in order.
    unresolved: Vec<u32>,
    /// The starting map's extent (smallest and largest coordinates, largest `|coordinate|`)
    /// and corners where each of these five is attained.
    extent: ([f64; 2], [f64; 2], f64),
    witnesses: [u32; 5],
}

impl Trial {
    fn new(uv: &[C]) -> Trial {
        let tol = unresolved_tolerance(uv);
        let unresolved = (0..uv.len() as u32 / 3)
            .filter(|&f| is_unresolved(&uv[3 * f as usize..3 * f as usize + 3], tol))
            .collect();
        let (mut lo, mut hi, mut big) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2], 0.0f64);
        let mut witnesses = [0u32; 5];
        for (h, p) in uv.iter().enumerate() {
            for k in 0..2 {
                if p[k] < lo[k] {
                    (lo[k], witnesses[k]) = (p[k], h as u32);
                }
                if p[k] > hi[k] {
                    (hi[k], witnesses[2 + k]) = (p[k], h as u32);
                }
                if p[k].abs() > big {
                    (big, witnesses[4]) = (p[k].abs(), h as u32);
                }
            }
        }
        Trial {
            uv: uv.to_vec(),
            tol,
            unresolved,
            extent: (lo, hi, big),
            witnesses,
        }
    }

    /// The tolerance of the map now that `moved` moved from `old`: when every moved corner
    /// lay strictly inside the starting extent, the corners attaining it stayed, and the
    /// extent is theirs with the moved corners' new places; else a scan of the whole map.
    fn tolerance(&self, moved: &[(u32, C)], old: &[C]) -> f64 {
        let (lo, hi, big) = self.extent;
        let inside = moved.iter().all(|&(h, _)| {
            let p = old[h as usize];
            (0..2).all(|k| lo[k] < p[k] && p[k] < hi[k] && p[k].abs() < big)
        });
        if !inside {
            return unresolved_tolerance(&self.uv);
        }
        let points: Vec<C> = self
            .witnesses
            .iter()
            .map(|&h| self.uv[h as usize])
            .chain(moved.iter().map(|&(_, w)| w))
            .collect();
        unresolved_tolerance(&points)
    }

    /// Moves the corners `moved` of `uv` (the starting map) and returns the unresolved faces
    /// of the map then, in order.
    fn unresolved_after(&mut self, moved: &[(u32, C)], uv: &[C]) -> Vec<u32> {
        for &(h, w) in moved {
            self.uv[h as usize] = w;
        }
        let tol = self.tolerance(moved, uv);
        let test = |f: &u32| is_unresolved(&self.uv[3 * *f as usize..3 * *f as usize + 3], tol);
        if tol != self.tol {
            return (0..self.uv.len() as u32 / 3).filter(test).collect();
        }
        let mut touched: Vec<u32> = moved.iter().map(|&(h, _)| h / 3).collect();
        touched.sort_unstable();
        touched.dedup();
        let mut left: Vec<u32> = self
            .unresolved
            .iter()
            .filter(|f| touched.binary_search(f).is_err())
            .copied()
            .chain(touched.iter().copied().filter(test))
            .collect();
        left.sort_unstable();
        left
    }

    /// Puts the corners `moved` back where they were in `uv`.
    fn undo(&mut self, moved: &[(u32, C)], uv: &[C]) {
        for &(h, _) in moved {
            self.uv[h as usize] = uv[h as usize];
        }
    }
}

/// The faces whose map folds (`FaceDistortion::flipped`: Jacobian determinant `≤ 0`).
/// `face_distortion` evaluates the determinant only where the UV triangle's doubled area
/// `a₂ = u₁v₂ − u₂v₁` is not far above the rounding error of that evaluation, which is a few
/// `ε (|u₁|(|v₂| + |t v₁|) + (|u₂| + |t u₁|)|v₁|)` with `t = e₁·e₂/|e₁|²` the 3D triangle's
/// shear (the `t` terms cancel in exact arithmetic); elsewhere it is certainly positive.
fn flipped_faces(positions: &[[f64; 3]], faces: &[[u32; 3]], uv: &[C]) -> Vec<u32> {
    use crate::numeric::vec3;
    (0..faces.len())
        .filter(|&f| {
            let (t, q) = (faces[f], &uv[3 * f..3 * f + 3]);
            let p = |i: usize| positions[t[i] as usize];
            let (u1, v1) = (q[1][0] - q[0][0], q[1][1] - q[0][1]);
            let (u2, v2) = (q[2][0] - q[0][0], q[2][1] - q[0][1]);
            let (e1, e2) = (vec3::sub(p(1), p(0)), vec3::sub(p(2), p(0)));
            let shear = (vec3::dot(e1, e2) / vec3::dot(e1, e1)).abs();
            let scale =
                u1.abs() * (v2.abs() + shear * v1.abs()) + (u2.abs() + shear * u1.abs()) * v1.abs();
            let certainly_positive = u1 * v2 - u2 * v1 > 1e-10 * scale;
            !certainly_positive && face_distortion([p(0), p(1), p(2)], [q[0], q[1], q[2]]).flipped()
        })
        .map(|f| f as u32)
        .collect()
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
    let mut boost = vec![1.0; faces.len()];
    if folds == 0 {
        return improve_quasiconformality(positions, mesh, &wedges, uv, &boost);
    }
    let mut seeds = flipped_faces(positions, faces, uv);
    let mut bad = vec![false; faces.len()];
    for &f in &seeds {
        bad[f as usize] = true;
    }
    let mut trial = Trial::new(uv);
    let mut fewest = usize::MAX;
    let mut stalled = 0;
    for round in 1..=ROUNDS {
        let region = grow(mesh, &seeds, RINGS * round);
        let moved = refine(positions, mesh, &wedges, uv, &region, &boost).ok()?;
        let left = trial.unresolved_after(&moved, uv);
        if left.is_empty() {
            return Some(trial.uv);
        }
        trial.undo(&moved, uv);
        if left.len() < fewest {
            (fewest, stalled) = (left.len(), 0);
        } else {
            stalled += 1;
            if stalled == STALLED_ROUNDS {
                return None;
            }
        }
        for &f in &left {
            if !bad[f as usize] {
                bad[f as usize] = true;
                seeds.push(f);
            }
            boost[f as usize] *= BOOST;
        }
    }
    None
}

/// [`improve`] of a map without folds: the vertices within [`RINGS`] rings of the faces of qc
/// above the map's 95th percentile move; kept when no triangle folds and qc p95 does not grow.
fn improve_quasiconformality(
    positions: &[[f64; 3]],
    mesh: &Mesh,
    wedges: &Wedges,
    uv: &[C],
    boost: &[f64],
) -> Option<Vec<C>> {
    let faces = mesh.faces();
    let mut d = face_distortions(positions, faces, uv);
    let before = qc_p95(&d);
    let top: Vec<u32> = (0..faces.len() as u32)
        .filter(|&f| d[f as usize].qc() > before)
        .collect();
    let region = grow(mesh, &top, RINGS);
    let moved = refine(positions, mesh, wedges, uv, &region, boost).ok()?;
    let mut trial = Trial::new(uv);
    if !trial.unresolved_after(&moved, uv).is_empty() {
        return None;
    }
    for &(h, _) in &moved {
        let f = h as usize / 3;
        let t = faces[f];
        let q = &trial.uv[3 * f..3 * f + 3];
        d[f] = face_distortion(
            [t[0], t[1], t[2]].map(|v| positions[v as usize]),
            [q[0], q[1], q[2]],
        );
    }
    (qc_p95(&d) <= before).then_some(trial.uv)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The complex Hermitian normal equations of [`Normal::assemble`] realified equal the real
    /// `2n × 2n` normal equations of the rows' real and imaginary parts, assembled here densely
    /// from the same face rows (unknowns `x_k = Re δ_k`, `y_k = Im δ_k`); and the sparse complex
    /// solve satisfies the real equations. A pair of pants, UVs a jittered projection,
    /// corner rotations arbitrary unit numbers, every fifth vertex pinned.
    #[test]
    fn hermitian_normal_equations_realify_to_the_real_ones() {
        let s = crate::mesh::generate::pair_of_pants(16).unwrap();
        let (mesh, pos) = (&s.mesh, &s.positions);
        let nv = mesh.n_vertices();
        let column = |v: u32| {
            if v.is_multiple_of(5) {
                u32::MAX
            } else {
                v - v / 5 - 1
            }
        };
        let n = (0..nv as u32).filter(|&v| column(v) != u32::MAX).count();
        let mut rows: Vec<Row> = Vec::new();
        for (f, t) in mesh.faces().iter().enumerate() {
            let q: Vec<C> = (0..3)
                .map(|j| {
                    let p = pos[t[j] as usize];
                    let jitter = ((3 * f + j) as f64 * 0.7).sin() * 0.01;
                    [p[0] + 0.3 * p[2] + jitter, p[1] - 0.2 * p[2]]
                })
                .collect();
            let boost = 1.0 + (f % 3) as f64 * 10.0;
            let Some((c, value)) = face_term(pos, *t, &q, boost) else {
                continue;
            };
            let mut k = [u32::MAX; 3];
            let mut a = [[0.0, 0.0]; 3];
            for j in 0..3 {
                let phi = (3 * f + j) as f64 * 0.37;
                k[j] = column(t[j]);
                a[j] = mul(c[j], [phi.cos(), phi.sin()]);
            }
            rows.push((k, a, value));
        }
        // The real normal equations N x = b, unknowns (x_0, y_0, x_1, y_1, …).
        let mut nrm = vec![vec![0.0; 2 * n]; 2 * n];
        let mut b = vec![0.0; 2 * n];
        for (k, a, r) in &rows {
            let mut re = vec![0.0; 2 * n];
            let mut im = vec![0.0; 2 * n];
            for j in 0..3 {
                if k[j] == u32::MAX {
                    continue;
                }
                let i = 2 * k[j] as usize;
                // α (x + i y) = (αr x − αi y) + i (αi x + αr y).
                re[i] += a[j][0];
                re[i + 1] -= a[j][1];
                im[i] += a[j][1];
                im[i + 1] += a[j][0];
            }
            for (row, rv) in [(&re, r[0]), (&im, r[1])] {
                let on: Vec<usize> = (0..2 * n).filter(|&p| row[p] != 0.0).collect();
                for &p in &on {
                    b[p] -= row[p] * rv;
                    for &q in &on {
                        nrm[p][q] += row[p] * row[q];
                    }
                }
            }
        }
        let h = Normal::assemble(n, &rows);
        let mut dense = vec![vec![c64::new(0.0, 0.0); n]; n];
        for (j, span) in h.col_ptr.windows(2).enumerate() {
            for s in span[0]..span[1] {
                let i = h.row_idx[s];
                assert!(i >= j, "an entry above the diagonal");
                dense[i][j] = h.values[s];
                dense[j][i] = h.values[s].conj();
            }
        }
        let big = nrm.iter().flatten().fold(0.0f64, |m, x| m.max(x.abs()));
        for i in 0..n {
            for j in 0..n {
                let z = dense[i][j];
                let block = [[z.re, -z.im], [z.im, z.re]];
                for (di, brow) in block.iter().enumerate() {
                    for (dj, &x) in brow.iter().enumerate() {
                        let want = nrm[2 * i + di][2 * j + dj];
                        assert!((x - want).abs() <= 1e-12 * big, "H[{i}][{j}]");
                    }
                }
            }
            let (br, bi) = (h.rhs[i].re, h.rhs[i].im);
            assert!(
                (br - b[2 * i]).abs() <= 1e-12 * big && (bi - b[2 * i + 1]).abs() <= 1e-12 * big
            );
        }
        let delta = h.solve().unwrap();
        let x: Vec<f64> = delta.iter().flat_map(|z| [z.re, z.im]).collect();
        let bmax = b.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        for p in 0..2 * n {
            let nx: f64 = (0..2 * n).map(|q| nrm[p][q] * x[q]).sum();
            assert!((nx - b[p]).abs() <= 1e-9 * bmax, "real equation {p}");
        }
    }

    /// [`grow`]'s breadth-first walk equals the definition: the seed faces' vertices, then
    /// `rings` times every vertex of a face touching one already in (all faces scanned).
    #[test]
    fn grown_region_equals_face_rings() {
        let s = crate::mesh::generate::genus(2, 12).unwrap();
        let mesh = &s.mesh;
        let seeds = [3u32, 40, 41];
        for rings in 0..4 {
            let mut on = vec![false; mesh.n_vertices()];
            for &f in &seeds {
                for v in mesh.face(f) {
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
            let region = grow(mesh, &seeds, rings);
            assert_eq!(region.on, on, "{rings} rings");
            let mut listed = region.vertices.clone();
            listed.sort_unstable();
            listed.dedup();
            assert_eq!(listed.len(), region.vertices.len());
            assert_eq!(listed.len(), on.iter().filter(|&&x| x).count());
        }
    }
}
