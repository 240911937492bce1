//! Manifold triangular B-splines over a flat cone metric (paper 000 §5, paper 002 §5.3.1).
//!
//! The domain is the surface itself, with a flat metric whose curvature sits on a few cone
//! vertices (one for genus ≥ 2, none for a torus or an open surface) and a set of charts
//! ([`FlatCharts`]): the affine atlas of [`crate::atlas`] or the independent provider
//! [`LocalCharts`] of this module.
//!
//! **Domain.** Paper 000 §5 removes the one-ring of the extraordinary point: the triangles of
//! the spline are the faces not incident to a singular vertex (*active* faces); the link of
//! each singular vertex is a boundary of the spline domain (a *hole*).
//!
//! **Knots.** Every vertex `v` gets a cloud `t_{v,0} = v, t_{v,1..n}` in its *vertex frame*,
//! the development of its star from the edge lengths with `v` at the origin and its first
//! outgoing half-edge along `+x` ([`star_frame`]). A chart that contains `v`'s star (minus faces
//! at a cone) sees the cloud through the rigid motion fitted from the star's corners, so the
//! knots — and therefore every basis function — are the same geometric objects in every chart.
//! Placement follows [`crate::spline::dms::KnotClouds::place`] with the same criteria: inside
//! `spread ×` the smallest altitude at the vertex; at vertices on a boundary of the spline
//! domain (the mesh boundary or a hole's link) inside the wedge outside both boundary edges, so
//! the DMS boundary condition holds and the basis is a **partition of unity on every active
//! face, up to the hole's link** (asserted by the tests); candidates keep the best worst-triple
//! [`crate::spline::dms::general_position`], and clouds of triangles with thin `Δ_β` (thinner
//! than `min(0.05, ½ ×` the triangle's own relative area) or small `Ω_I` are shrunk — the
//! floor relative to the triangle, so that a cap triangle (rocker-arm.off) does not collapse
//! its vertices' clouds to 10⁻⁴ of the face.
//!
//! **Basis.** The DMS basis of an active triangle `I` is built by
//! [`TriangleBasis::new`] in `I`'s home chart ([`FlatCharts::home_chart`]) from the three
//! clouds mapped there. Its support (inside the convex hull of its knots) lies in the union of
//! the stars of `I`'s vertices, which the home chart contains.
//!
//! **Evaluation** at a point of face `g`: every active triangle `I` sharing a vertex with `g`
//! contributes, evaluated in `I`'s home chart at the point with the same barycentric
//! coordinates in `g` (the transition on `g`, as an affine map of `g`'s corners; see
//! *Conditioning*); partials are rotated back into the chart the point was given in. Values therefore do not
//! depend on the chart (to rounding), and partials transform by the rotation of the transition
//! ([`rotate_partials`]). Limits are taken from inside `g` (direction towards its centroid).
//!
//! **Conditioning.** A point is carried into each home chart by its barycentric coordinates
//! in its face, and handed to the basis as an offset from the basis's knot centroid built from
//! differences of the face's corners ([`ManifoldSpace::basis_at_bary`]): its rounding is then
//! `ε h` (h the face size) whatever the chart. Going through absolute chart coordinates costs
//! `ε |u|` instead, and an affine-atlas chart is up to ~5·10³ face sizes across near the cone
//! (eight.off), which made order-2 partials differ between charts by 1.5e-6 (relative).
//! That is not enough for partials: at edge midpoints and near vertices the thin basis
//! functions (knot sets from one or two clouds) have order-2 partials up to 10³ × and order-3
//! partials up to 10⁸ × those of `F` (relative to the face), and their sum cancels. Three
//! roundings each moved `∂²F` by 1e-9 … 2e-7 of itself (as much as moving the point by one
//! ulp in one chart): the simplex recurrence's, each basis's own rounding of the point's offset
//! (the point then differs from basis to basis by `ε h`, and the third partials make that
//! noise), and that of `Σ c N` with `|c|` the distance from the origin. With the default
//! [`Precision::Extended`] the offset and the recurrence are double-double
//! ([`crate::spline::simplex::SimplexFamily::eval_offset_extended`]) and the sum is formed as
//! `c_0 + Σ (c − c_0) N`; partials then agree between charts to ≤ 6e-12 of the largest partial
//! of their order and jump across edges by ≤ 1e-10 (3holes, genus3, fertility, eight, a
//! generated genus-2 surface; see the tests). Values alone are computed in double.
//!
//! **Fairing.** The constraints of paper 000 eq. 14 compare blossoms of neighbouring
//! triangles; their weights are computed in the vertex frame of a shared vertex (every cloud
//! brought there through the faces of the pair), not in the home charts. Built from the home
//! charts, they carried the charts' rounding and inconsistency (over the affine atlas 1.8e-11
//! of a star), and the redundant constraints of neighbouring edges then disagreed by more than
//! the fairing's 1e-10: on eight.off the solve stalled at a residual of 1.3e-4 after 21 s; it
//! now converges in 2 steps (0.6 s) to the same control points as over `LocalCharts`.
//!
//! Control points are stored for every face (`face * (n+1)(n+2)/2 + position of β`); those of
//! faces at a cone are used by no basis function. [`ManifoldSpace`] implements
//! [`SplineSpace`], so [`crate::spline::fit::fair`] (paper 000 eq. 14) and
//! [`crate::spline::fit::fit`] work on it unchanged (the fairing constraints of an edge compare
//! blossoms after mapping the arguments between the two triangles' home charts). The flat
//! metric of a single cone distorts areas by orders of magnitude, so the thin-plate energy of
//! the fit is taken per face in the face's own scale (quadrature weight `(h_f / h̄)²`, `h_f` the
//! face's mean edge length): without it the energy of tiny faces dominates and the normal
//! equations become numerically singular.

use std::collections::HashMap;
use std::f64::consts::PI;

use num_complex::Complex64 as C;
use rayon::prelude::*;

use crate::atlas::{fit_rigid, ChartId, FlatCharts};
use crate::error::{Error, Result};
use crate::layout::RigidMotion;
use crate::mesh::Mesh;
use crate::numeric::dd::Dd;

use super::dms::combine;
use super::dms::{
    blossom_weights_of, general_position_involving, hash64, multi_indices, needs_shrink,
    per_triangle, unit, KnotOptions, Precision, TriangleBasis, Workspace, MAX_DEGREE,
};
use super::simplex::{det3, n_partials, partial_index, Point};
use super::space::SplineSpace;

#[inline]
pub(crate) fn cz(p: Point) -> C {
    C::new(p[0], p[1])
}
#[inline]
pub(crate) fn pt(z: C) -> Point {
    [z.re, z.im]
}
#[inline]
pub(crate) fn apply(m: &RigidMotion, p: Point) -> Point {
    pt(m.rot * cz(p) + m.t)
}
#[inline]
fn rotate(rot: C, p: Point) -> Point {
    pt(rot * cz(p))
}

/// Side lengths of face `f`: `l[i]` is the edge opposite corner `i`.
pub fn face_side_lengths(mesh: &Mesh, lengths: &[f64], f: u32) -> [f64; 3] {
    let h = mesh.face_halfedges(f);
    [
        lengths[mesh.he_edge(h[1]) as usize],
        lengths[mesh.he_edge(h[2]) as usize],
        lengths[mesh.he_edge(h[0]) as usize],
    ]
}

/// The corners of a triangle with side lengths `l` (opposite corners 0, 1, 2): corner 0 at the
/// origin, corner 1 on the positive x axis, corner 2 above.
pub fn develop_face(l: [f64; 3]) -> [Point; 3] {
    let x = (l[1] * l[1] + l[2] * l[2] - l[0] * l[0]) / (2.0 * l[2]);
    let y = (l[1] * l[1] - x * x).max(0.0).sqrt();
    [[0.0, 0.0], [l[2], 0.0], [x, y]]
}

fn corner_angle(l: [f64; 3], i: usize) -> f64 {
    let (a, b, c) = (l[i], l[(i + 1) % 3], l[(i + 2) % 3]);
    ((b * b + c * c - a * a) / (2.0 * b * c))
        .clamp(-1.0, 1.0)
        .acos()
}

fn check_metric(mesh: &Mesh, lengths: &[f64]) -> Result<()> {
    if lengths.len() != mesh.n_edges() {
        return Err(Error::input(format!(
            "manifold spline: {} edge lengths for {} edges",
            lengths.len(),
            mesh.n_edges()
        )));
    }
    for f in 0..mesh.n_faces() as u32 {
        let l = face_side_lengths(mesh, lengths, f);
        let ok = l.iter().all(|x| x.is_finite() && *x > 0.0)
            && l[0] < l[1] + l[2]
            && l[1] < l[0] + l[2]
            && l[2] < l[0] + l[1];
        if !ok {
            return Err(Error::input(format!(
                "manifold spline: face {f} violates the triangle inequality in the flat metric (lengths {:.3e}, {:.3e}, {:.3e})",
                l[0], l[1], l[2]
            )));
        }
    }
    Ok(())
}

/// The development of the star of `v` from the edge lengths: `v` at the origin, the first
/// outgoing half-edge of [`Mesh::outgoing`] along `+x`, faces counter-clockwise. Each entry is a
/// face with its corner coordinates (in [`Mesh::face`] order) and the angle at which its first
/// edge at `v` leaves `v`; `total_angle` is the angle sum at `v`.
#[derive(Debug, Clone)]
pub struct StarFrame {
    pub faces: Vec<(u32, [Point; 3])>,
    pub start_angles: Vec<f64>,
    pub corner_angles: Vec<f64>,
    pub total_angle: f64,
}

impl StarFrame {
    fn coords_of(&self, f: u32) -> Option<&[Point; 3]> {
        self.faces.iter().find(|(g, _)| *g == f).map(|(_, c)| c)
    }
}

/// See [`StarFrame`].
pub fn star_frame(mesh: &Mesh, lengths: &[f64], v: u32) -> StarFrame {
    let mut faces = Vec::new();
    let mut start_angles = Vec::new();
    let mut corner_angles = Vec::new();
    let mut ang = 0.0f64;
    for h in mesh.outgoing(v) {
        if mesh.is_boundary_halfedge(h) {
            continue;
        }
        let f = h / 3;
        let i = h as usize % 3;
        let l = face_side_lengths(mesh, lengths, f);
        let th = corner_angle(l, i);
        let mut c = [[0.0; 2]; 3];
        let (la, lb) = (l[(i + 2) % 3], l[(i + 1) % 3]);
        c[(i + 1) % 3] = [la * ang.cos(), la * ang.sin()];
        c[(i + 2) % 3] = [lb * (ang + th).cos(), lb * (ang + th).sin()];
        faces.push((f, c));
        start_angles.push(ang);
        corner_angles.push(th);
        ang += th;
    }
    StarFrame {
        faces,
        start_angles,
        corner_angles,
        total_angle: ang,
    }
}

/// Partials of `F(u) = G(rot·u + t)` from the partials of `G` (same layout as
/// [`crate::spline::simplex::partial_index`], up to `order`): `∂_x = c ∂_1 + s ∂_2`,
/// `∂_y = −s ∂_1 + c ∂_2` with `rot = c + i s`, expanded per order.
pub fn rotation_matrix(order: usize, rot: C) -> Vec<f64> {
    let np = n_partials(order);
    let mut t = vec![0.0; np * np];
    let (c, s) = (rot.re, rot.im);
    for k in 0..=order {
        for a in 0..=k {
            let b = k - a;
            // poly[p] = coefficient of ∂_1^p ∂_2^(deg − p)
            let mut poly = vec![1.0];
            for (times, (cx, cy)) in [(a, (c, s)), (b, (-s, c))] {
                for _ in 0..times {
                    let mut next = vec![0.0; poly.len() + 1];
                    for (p, &w) in poly.iter().enumerate() {
                        next[p + 1] += cx * w;
                        next[p] += cy * w;
                    }
                    poly = next;
                }
            }
            let row = partial_index(a, b);
            for (p, &w) in poly.iter().enumerate() {
                t[row * np + partial_index(p, k - p)] += w;
            }
        }
    }
    t
}

/// Apply [`rotation_matrix`] to `n` functions' partials in place (`vals[i * np ..]`).
pub fn rotate_partials(order: usize, rot: C, vals: &mut [f64]) {
    if order == 0 || (rot.re == 1.0 && rot.im == 0.0) {
        return;
    }
    let np = n_partials(order);
    let t = rotation_matrix(order, rot);
    let mut tmp = vec![0.0; np];
    for chunk in vals.chunks_exact_mut(np) {
        for i in 0..np {
            let mut s = 0.0;
            for j in 0..np {
                s += t[i * np + j] * chunk[j];
            }
            tmp[i] = s;
        }
        chunk.copy_from_slice(&tmp);
    }
}

// ---------------------------------------------------------------------------------------------
// An independent chart provider

/// A chart provider built directly from a flat cone metric, independent of the affine atlas:
/// one chart per face `f`, the breadth-first development (from the edge lengths) of `f` and
/// every face sharing a vertex with `f` that is not incident to a singular vertex. A flat metric
/// is developable on that simply connected set, so it satisfies the [`FlatCharts`] contract;
/// with a `seed`, every chart is additionally moved by a pseudo-random rigid motion (a second,
/// differently placed provider for chart-independence tests).
#[derive(Debug, Clone)]
pub struct LocalCharts {
    mesh: Mesh,
    lengths: Vec<f64>,
    positions: Vec<[f64; 3]>,
    singular: Vec<u32>,
    charts: Vec<Vec<(u32, [Point; 3])>>,
    of_face: Vec<Vec<ChartId>>,
    home: Vec<Option<ChartId>>,
}

impl LocalCharts {
    /// Build the charts. `singular` lists the cone vertices (their incident faces get charts but
    /// no home chart).
    pub fn new(
        mesh: Mesh,
        lengths: Vec<f64>,
        positions: Vec<[f64; 3]>,
        singular: Vec<u32>,
        seed: Option<u64>,
    ) -> Result<LocalCharts> {
        check_metric(&mesh, &lengths)?;
        if positions.len() != mesh.n_vertices() {
            return Err(Error::input(format!(
                "local charts: {} positions for {} vertices",
                positions.len(),
                mesh.n_vertices()
            )));
        }
        let mut is_sing = vec![false; mesh.n_vertices()];
        for &s in &singular {
            if s as usize >= mesh.n_vertices() {
                return Err(Error::input(format!(
                    "local charts: singular vertex {s} does not exist"
                )));
            }
            is_sing[s as usize] = true;
        }
        let at_cone = |f: u32| mesh.face(f).iter().any(|&v| is_sing[v as usize]);
        let nf = mesh.n_faces() as u32;
        let charts: Vec<Vec<(u32, [Point; 3])>> = (0..nf)
            .into_par_iter()
            .map(|f| -> Result<Vec<(u32, [Point; 3])>> {
                let mut set: Vec<u32> = vec![f];
                for v in mesh.face(f) {
                    for g in mesh.vertex_faces(v) {
                        if !at_cone(g) {
                            set.push(g);
                        }
                    }
                }
                set.sort_unstable();
                set.dedup();
                let mut coords: HashMap<u32, [Point; 3]> = HashMap::with_capacity(set.len());
                let mut seedc = develop_face(face_side_lengths(&mesh, &lengths, f));
                if let Some(s) = seed {
                    let key = hash64(s ^ hash64(f as u64));
                    let m = RigidMotion::new(
                        2.0 * PI * unit(key),
                        C::new(10.0 * unit(key + 1) - 5.0, 10.0 * unit(key + 2) - 5.0),
                    );
                    seedc = seedc.map(|p| apply(&m, p));
                }
                coords.insert(f, seedc);
                let mut queue = std::collections::VecDeque::from([f]);
                while let Some(g) = queue.pop_front() {
                    let cg = coords[&g];
                    for h in mesh.face_halfedges(g) {
                        let t = mesh.he_twin(h);
                        if mesh.is_boundary_halfedge(t) {
                            continue;
                        }
                        let g2 = t / 3;
                        if coords.contains_key(&g2) || set.binary_search(&g2).is_err() {
                            continue;
                        }
                        let i = h as usize % 3;
                        let j = t as usize % 3;
                        let c2 = develop_face(face_side_lengths(&mesh, &lengths, g2));
                        let (m, _) =
                            fit_rigid(&[c2[j], c2[(j + 1) % 3]], &[cg[(i + 1) % 3], cg[i]]);
                        coords.insert(g2, c2.map(|p| apply(&m, p)));
                        queue.push_back(g2);
                    }
                }
                if coords.len() != set.len() {
                    return Err(Error::topology(format!(
                        "local charts: the faces around face {f} are not connected through edges"
                    )));
                }
                let mut v: Vec<(u32, [Point; 3])> = coords.into_iter().collect();
                v.sort_unstable_by_key(|x| x.0);
                Ok(v)
            })
            .collect::<Result<_>>()?;
        let mut of_face = vec![Vec::new(); nf as usize];
        for (c, ch) in charts.iter().enumerate() {
            for (g, _) in ch {
                of_face[*g as usize].push(c as ChartId);
            }
        }
        let home = (0..nf).map(|f| (!at_cone(f)).then_some(f)).collect();
        Ok(LocalCharts {
            mesh,
            lengths,
            positions,
            singular,
            charts,
            of_face,
            home,
        })
    }
}

impl FlatCharts for LocalCharts {
    fn mesh(&self) -> &Mesh {
        &self.mesh
    }
    fn lengths(&self) -> &[f64] {
        &self.lengths
    }
    fn positions(&self) -> &[[f64; 3]] {
        &self.positions
    }
    fn singular_vertices(&self) -> &[u32] {
        &self.singular
    }
    fn n_charts(&self) -> usize {
        self.charts.len()
    }
    fn face_coords(&self, c: ChartId, f: u32) -> Option<[[f64; 2]; 3]> {
        let ch = self.charts.get(c as usize)?;
        ch.binary_search_by_key(&f, |x| x.0).ok().map(|i| ch[i].1)
    }
    fn charts_of_face(&self, f: u32) -> Vec<ChartId> {
        self.of_face.get(f as usize).cloned().unwrap_or_default()
    }
    fn home_chart(&self, f: u32) -> Option<ChartId> {
        self.home.get(f as usize).copied().flatten()
    }
}

// ---------------------------------------------------------------------------------------------
// The spline space

/// Quality of the manifold spline space.
#[derive(Debug, Clone, Copy, serde::Serialize)]
pub struct ManifoldReport {
    pub degree: usize,
    /// Faces carrying a basis (not incident to a singular vertex).
    pub active_faces: usize,
    /// Control points of the active faces.
    pub control_points: usize,
    /// Smallest relative signed area of a `Δ_β^I` over all triangles.
    pub min_orientation: f64,
    /// Smallest `|Ω_I| / |I|`.
    pub min_omega_ratio: f64,
    /// Smallest general-position measure of a triangle's knots.
    pub min_general_position: f64,
    /// Largest residual of fitting a vertex frame into a home chart, relative to the star's
    /// size (≈ 1e-15 for a consistent chart).
    pub max_chart_residual: f64,
    /// Largest number of triangles evaluated at one point.
    pub max_candidates: usize,
}

/// The manifold DMS spline space over a chart provider (module docs).
pub struct ManifoldSpace<'a, A: FlatCharts + Sync + ?Sized> {
    charts: &'a A,
    degree: usize,
    active: Vec<bool>,
    /// Vertex frames (`None` for singular vertices).
    frames: Vec<Option<StarFrame>>,
    /// Knots in vertex frames, `[v * (n+1) + k]`.
    knots: Vec<Point>,
    home: Vec<ChartId>,
    bases: Vec<Option<TriangleBasis>>,
    /// Canonical chart of each face (its home chart, else the first chart containing it) and
    /// the face's corners there.
    canon: Vec<ChartId>,
    canon_coords: Vec<[Point; 3]>,
    /// Candidates of each face: `(I, motion canon(g) → home(I))`.
    cand_start: Vec<u32>,
    cand: Vec<(u32, RigidMotion, [Point; 3])>,
    report: ManifoldReport,
}

/// Knot placement in vertex frames (module docs).
struct Placement<'m> {
    mesh: &'m Mesh,
    n: usize,
    active: &'m [bool],
    /// Per corner `3f + i`: vertex frame of corner `i` → canonical development of `f`.
    corner_motion: &'m [RigidMotion],
}

impl Placement<'_> {
    /// Knot array of active face `f` (three clouds mapped into its canonical frame).
    fn face_knots(&self, knots: &[Point], f: u32, out: &mut Vec<Point>) {
        let n = self.n;
        out.clear();
        for (i, &w) in self.mesh.face(f).iter().enumerate() {
            let m = &self.corner_motion[3 * f as usize + i];
            for k in 0..=n {
                out.push(apply(m, knots[w as usize * (n + 1) + k]));
            }
        }
    }
    /// Worst knot triple involving `v`'s moving knots over `v`'s active faces.
    fn local_quality(&self, v: u32, knots: &[Point], floor: f64, arr: &mut Vec<Point>) -> f64 {
        let n = self.n;
        let mut q = f64::INFINITY;
        for h in self.mesh.vertex_corners(v) {
            let f = h / 3;
            if !self.active[f as usize] {
                continue;
            }
            let i = h as usize % 3;
            arr.clear();
            let m = &self.corner_motion[h as usize];
            for k in 1..=n {
                arr.push(apply(m, knots[v as usize * (n + 1) + k]));
            }
            for (mm, &w) in self.mesh.face(f).iter().enumerate() {
                let mw = &self.corner_motion[3 * f as usize + mm];
                if mm == i {
                    arr.push(apply(mw, knots[w as usize * (n + 1)]));
                } else {
                    for k in 0..=n {
                        arr.push(apply(mw, knots[w as usize * (n + 1) + k]));
                    }
                }
            }
            q = q.min(general_position_involving(arr, n, floor));
            if q <= floor {
                return q;
            }
        }
        q
    }
}

impl<'a, A: FlatCharts + Sync + ?Sized> ManifoldSpace<'a, A> {
    /// Place knots and build the basis of every active face in its home chart. Errors name the
    /// face or vertex at fault (a missing home chart, a chart inconsistent with a vertex star,
    /// knots that violate the DMS conditions).
    pub fn new(charts: &'a A, degree: usize, opts: &KnotOptions) -> Result<Self> {
        let mesh = charts.mesh();
        let lengths = charts.lengths();
        let n = degree;
        if !(2..=MAX_DEGREE).contains(&n) {
            return Err(Error::input(format!(
                "manifold spline degree {n} is not supported (2..={MAX_DEGREE})"
            )));
        }
        if !(opts.spread > 0.0 && opts.spread <= 0.45) {
            return Err(Error::input(format!(
                "knot spread {} is outside (0, 0.45]",
                opts.spread
            )));
        }
        check_metric(mesh, lengths)?;
        let nv = mesh.n_vertices();
        let nf = mesh.n_faces();
        let mut is_sing = vec![false; nv];
        for &s in charts.singular_vertices() {
            if s as usize >= nv {
                return Err(Error::input(format!(
                    "manifold spline: singular vertex {s} does not exist"
                )));
            }
            is_sing[s as usize] = true;
        }
        let active: Vec<bool> = mesh
            .faces()
            .iter()
            .map(|t| t.iter().all(|&v| !is_sing[v as usize]))
            .collect();
        if !active.iter().any(|&a| a) {
            return Err(Error::input(
                "manifold spline: every face is incident to a singular vertex",
            ));
        }
        let frames: Vec<Option<StarFrame>> = (0..nv as u32)
            .into_par_iter()
            .map(|v| {
                (!is_sing[v as usize] && !mesh.is_isolated(v)).then(|| star_frame(mesh, lengths, v))
            })
            .collect();
        let canon_dev: Vec<[Point; 3]> = (0..nf as u32)
            .map(|f| develop_face(face_side_lengths(mesh, lengths, f)))
            .collect();
        let mut corner_motion = vec![RigidMotion::new(0.0, C::new(0.0, 0.0)); 3 * nf];
        for f in 0..nf as u32 {
            if !active[f as usize] {
                continue;
            }
            for (i, &v) in mesh.face(f).iter().enumerate() {
                let fr = frames[v as usize].as_ref().ok_or_else(|| {
                    Error::input(format!("manifold spline: vertex {v} has no star"))
                })?;
                let c = fr.coords_of(f).ok_or_else(|| {
                    Error::input(format!(
                        "manifold spline: face {f} missing in the star of {v}"
                    ))
                })?;
                corner_motion[3 * f as usize + i] = fit_rigid(c, &canon_dev[f as usize]).0;
            }
        }
        // Radius and wedge per vertex (in the vertex frame).
        let mut radius = vec![0.0f64; nv];
        let mut wedge = vec![(0.0, PI); nv];
        let mut used = vec![false; nv];
        for v in 0..nv as u32 {
            let Some(fr) = frames[v as usize].as_ref() else {
                continue;
            };
            let mut r = f64::INFINITY;
            for (_, c) in &fr.faces {
                let area2 = det3(c[0], c[1], c[2]);
                // altitude at v = 2A / opposite side; v is the corner at the origin
                let i = c
                    .iter()
                    .position(|p| p[0] == 0.0 && p[1] == 0.0)
                    .unwrap_or(0);
                let (p, q) = (c[(i + 1) % 3], c[(i + 2) % 3]);
                let opp = (p[0] - q[0]).hypot(p[1] - q[1]);
                r = r.min(opts.spread * area2.abs() / opp);
            }
            radius[v as usize] = r;
            let k = fr.faces.len();
            let act: Vec<bool> = fr.faces.iter().map(|(f, _)| active[*f as usize]).collect();
            used[v as usize] = act.iter().any(|&a| a);
            let boundary = mesh.is_boundary_vertex(v);
            if act.iter().all(|&a| a) && !boundary {
                continue; // full circle
            }
            if !used[v as usize] {
                continue;
            }
            // Runs of active faces (cyclic for interior vertices).
            let starts: Vec<usize> = (0..k)
                .filter(|&j| {
                    act[j]
                        && if j == 0 {
                            boundary || !act[k - 1]
                        } else {
                            !act[j - 1]
                        }
                })
                .collect();
            if starts.len() != 1 {
                return Err(Error::input(format!(
                    "manifold spline: vertex {v} touches the boundary of the spline domain in {} separate places (e.g. next to two cones); not supported",
                    starts.len()
                )));
            }
            let j0 = starts[0];
            let mut span = 0.0;
            let mut j = j0;
            while act[j] {
                span += fr.corner_angles[j];
                j = (j + 1) % k;
                if j == j0 || (boundary && j == 0) {
                    break;
                }
            }
            let a0 = fr.start_angles[j0];
            let a1 = a0 + span;
            let half = 0.5 * span.min(2.0 * PI - span).max(0.0);
            if !(half > 1e-6) {
                return Err(Error::input(format!(
                    "manifold spline: the boundary of the spline domain folds back on itself at vertex {v}"
                )));
            }
            wedge[v as usize] = (0.5 * (a0 + a1) + PI, half);
        }
        let candidate = |v: usize, r: f64, attempt: u64, out: &mut [Point]| {
            let (center, half) = wedge[v];
            let key =
                hash64(opts.seed ^ hash64(v as u64) ^ attempt.wrapping_mul(0xA24B_AED4_963E_E407));
            out[0] = [0.0, 0.0];
            for k in 1..=n {
                let rr = r * (0.6 + 0.4 * unit(key.wrapping_add(2 * k as u64)));
                let t = unit(key.wrapping_add(2 * k as u64 + 1));
                let ang = if half >= PI {
                    2.0 * PI * t
                } else {
                    center + 0.75 * half * (2.0 * t - 1.0)
                };
                out[k] = [rr * ang.cos(), rr * ang.sin()];
            }
        };
        let mut knots = vec![[0.0; 2]; nv * (n + 1)];
        for v in 0..nv {
            if used[v] {
                candidate(v, radius[v], 0, &mut knots[v * (n + 1)..(v + 1) * (n + 1)]);
            }
        }
        let pl = Placement {
            mesh,
            n,
            active: &active,
            corner_motion: &corner_motion,
        };
        const CANDIDATES: u64 = 32;
        let mut trial = vec![[0.0; 2]; n + 1];
        let mut dirty = used.clone();
        let mut counter = 0u64;
        let mut arr = Vec::with_capacity(3 * (n + 1));
        for round in 0..12 {
            for sweep in 0..2 {
                for v in 0..nv {
                    if !dirty[v] {
                        continue;
                    }
                    let range = v * (n + 1)..(v + 1) * (n + 1);
                    let mut best_q = pl.local_quality(v as u32, &knots, 0.0, &mut arr);
                    if sweep > 0 && best_q > 0.05 {
                        continue;
                    }
                    let mut best = knots[range.clone()].to_vec();
                    for _ in 0..CANDIDATES {
                        counter += 1;
                        candidate(v, radius[v], counter, &mut trial);
                        knots[range.clone()].copy_from_slice(&trial);
                        let q = pl.local_quality(v as u32, &knots, best_q, &mut arr);
                        if q > best_q {
                            best_q = q;
                            best.copy_from_slice(&trial);
                        }
                    }
                    knots[range].copy_from_slice(&best);
                }
            }
            dirty.fill(false);
            let mut any = false;
            for f in 0..nf as u32 {
                if !active[f as usize] {
                    continue;
                }
                pl.face_knots(&knots, f, &mut arr);
                if needs_shrink(n, &arr) {
                    for &v in &mesh.face(f) {
                        dirty[v as usize] = true;
                    }
                    any = true;
                }
            }
            if !any || round == 11 {
                break;
            }
            for v in 0..nv {
                if dirty[v] {
                    radius[v] *= 0.7;
                    for k in 1..=n {
                        let t = &mut knots[v * (n + 1) + k];
                        *t = [0.7 * t[0], 0.7 * t[1]];
                    }
                }
            }
        }
        // Bases in home charts.
        let built: Vec<Option<(ChartId, TriangleBasis, f64)>> = (0..nf as u32)
            .into_par_iter()
            .map(|f| -> Result<Option<(ChartId, TriangleBasis, f64)>> {
                if !active[f as usize] {
                    return Ok(None);
                }
                let h = charts.home_chart(f).ok_or_else(|| {
                    Error::input(format!(
                        "manifold spline: the charts give no home chart for face {f}, which is not incident to a singular vertex"
                    ))
                })?;
                let mut clouds: Vec<Vec<Point>> = Vec::with_capacity(3);
                let mut worst = 0.0f64;
                let own = charts.face_coords(h, f).ok_or_else(|| {
                    Error::input(format!("manifold spline: face {f} is not in its home chart {h}"))
                })?;
                for (corner, v) in mesh.face(f).into_iter().enumerate() {
                    let fr = frames[v as usize].as_ref().ok_or_else(|| {
                        Error::input(format!("manifold spline: vertex {v} has no star"))
                    })?;
                    let mut a = Vec::new();
                    let mut b = Vec::new();
                    let mut size = 0.0f64;
                    for (g, c) in &fr.faces {
                        if !active[*g as usize] {
                            continue;
                        }
                        if let Some(x) = charts.face_coords(h, *g) {
                            a.extend_from_slice(c);
                            b.extend_from_slice(&x);
                            for p in c {
                                size = size.max(p[0].hypot(p[1]));
                            }
                        }
                    }
                    if a.is_empty() {
                        return Err(Error::input(format!(
                            "manifold spline: home chart {h} of face {f} contains none of the faces around vertex {v}"
                        )));
                    }
                    let (m, res) = fit_rigid(&a, &b);
                    worst = worst.max(res / size.max(1e-300));
                    if !(res <= 1e-6 * size) {
                        return Err(Error::input(format!(
                            "manifold spline: home chart {h} of face {f} is not a consistent development of the star of vertex {v} (residual {res:.2e} relative to {size:.2e})"
                        )));
                    }
                    // t_{v,0} = v exactly as the chart places it (the fitted motion is off by
                    // the chart's rounding), so that points at vertices and on edges, which are
                    // mapped through the same chart coordinates, land exactly on knot lines.
                    let mut cl: Vec<Point> = knots[v as usize * (n + 1)..(v as usize + 1) * (n + 1)]
                        .iter()
                        .map(|&p| apply(&m, p))
                        .collect();
                    cl[0] = own[corner];
                    clouds.push(cl);
                }
                let basis = TriangleBasis::new(n, [&clouds[0], &clouds[1], &clouds[2]])
                    .map_err(|e| Error::input(format!("manifold spline, face {f}: {e}")))?;
                Ok(Some((h, basis, worst)))
            })
            .collect::<Result<_>>()?;
        let mut home = vec![ChartId::MAX; nf];
        let mut bases = Vec::with_capacity(nf);
        let mut report = ManifoldReport {
            degree: n,
            active_faces: 0,
            control_points: 0,
            min_orientation: f64::INFINITY,
            min_omega_ratio: f64::INFINITY,
            min_general_position: f64::INFINITY,
            max_chart_residual: 0.0,
            max_candidates: 0,
        };
        for (f, b) in built.into_iter().enumerate() {
            match b {
                Some((h, basis, res)) => {
                    home[f] = h;
                    report.active_faces += 1;
                    report.min_orientation = report.min_orientation.min(basis.min_orientation());
                    report.min_omega_ratio = report.min_omega_ratio.min(basis.omega_ratio());
                    report.min_general_position =
                        report.min_general_position.min(basis.general_position());
                    report.max_chart_residual = report.max_chart_residual.max(res);
                    bases.push(Some(basis));
                }
                None => bases.push(None),
            }
        }
        report.control_points = report.active_faces * per_triangle(n);
        let mut canon = vec![0; nf];
        let mut canon_coords = vec![[[0.0; 2]; 3]; nf];
        for f in 0..nf as u32 {
            let c = if active[f as usize] {
                home[f as usize]
            } else {
                *charts.charts_of_face(f).first().ok_or_else(|| {
                    Error::input(format!("manifold spline: face {f} is in no chart"))
                })?
            };
            canon[f as usize] = c;
            canon_coords[f as usize] = charts.face_coords(c, f).ok_or_else(|| {
                Error::input(format!(
                    "manifold spline: chart {c} is listed for face {f} but has no coordinates for it"
                ))
            })?;
        }
        #[allow(clippy::type_complexity)]
        let cands: Vec<Vec<(u32, RigidMotion, [Point; 3])>> = (0..nf as u32)
            .into_par_iter()
            .map(|g| -> Result<Vec<(u32, RigidMotion, [Point; 3])>> {
                if !active[g as usize] {
                    return Ok(Vec::new());
                }
                let mut set: Vec<u32> = Vec::new();
                for v in mesh.face(g) {
                    for i in mesh.vertex_faces(v) {
                        if active[i as usize] {
                            set.push(i);
                        }
                    }
                }
                set.sort_unstable();
                set.dedup();
                set.into_iter()
                    .map(|i| {
                        let hc = home[i as usize];
                        let b = charts.face_coords(hc, g).ok_or_else(|| {
                            Error::input(format!(
                                "manifold spline: face {g} shares a vertex with face {i} but is not in its home chart {hc}"
                            ))
                        })?;
                        Ok((i, fit_rigid(&canon_coords[g as usize], &b).0, b))
                    })
                    .collect()
            })
            .collect::<Result<_>>()?;
        let mut cand_start = vec![0u32; nf + 1];
        let mut cand = Vec::new();
        for (g, c) in cands.into_iter().enumerate() {
            report.max_candidates = report.max_candidates.max(c.len());
            cand.extend(c);
            cand_start[g + 1] = cand.len() as u32;
        }
        Ok(ManifoldSpace {
            charts,
            degree: n,
            active,
            frames,
            knots,
            home,
            bases,
            canon,
            canon_coords,
            cand_start,
            cand,
            report,
        })
    }

    pub fn charts(&self) -> &'a A {
        self.charts
    }
    pub fn degree(&self) -> usize {
        self.degree
    }
    pub fn report(&self) -> ManifoldReport {
        self.report
    }
    /// Is face `f` a triangle of the spline (not incident to a singular vertex)?
    pub fn is_active(&self, f: u32) -> bool {
        self.active.get(f as usize).copied().unwrap_or(false)
    }
    /// The basis of active face `f`, in its home chart.
    pub fn basis(&self, f: u32) -> Option<&TriangleBasis> {
        self.bases.get(f as usize).and_then(|b| b.as_ref())
    }
    /// Home chart of active face `f`.
    pub fn home_chart(&self, f: u32) -> Option<ChartId> {
        self.is_active(f).then(|| self.home[f as usize])
    }
    /// The chart in which [`Self::basis_at`] takes points of face `f` and returns partials.
    pub fn canonical_chart(&self, f: u32) -> ChartId {
        self.canon[f as usize]
    }
    /// Corners of face `f` in its canonical chart.
    pub fn canonical_coords(&self, f: u32) -> [Point; 3] {
        self.canon_coords[f as usize]
    }
    /// The point with barycentric coordinates `bary` of face `f`, in its canonical chart.
    pub fn face_point(&self, f: u32, bary: [f64; 3]) -> Point {
        let c = self.canon_coords[f as usize];
        [
            bary[0] * c[0][0] + bary[1] * c[1][0] + bary[2] * c[2][0],
            bary[0] * c[0][1] + bary[1] * c[1][1] + bary[2] * c[2][1],
        ]
    }
    /// The vertex frame of `v` (`None` for singular vertices).
    pub fn vertex_frame(&self, v: u32) -> Option<&StarFrame> {
        self.frames.get(v as usize).and_then(|f| f.as_ref())
    }
    /// The knot cloud `t_{v,0..n}` of `v` in its vertex frame.
    pub fn cloud(&self, v: u32) -> &[Point] {
        let m = self.degree + 1;
        &self.knots[v as usize * m..(v as usize + 1) * m]
    }
    /// Faces whose basis may be non-zero on face `g`.
    pub fn candidates(&self, g: u32) -> impl Iterator<Item = u32> + '_ {
        let (a, b) = (
            self.cand_start[g as usize] as usize,
            self.cand_start[g as usize + 1] as usize,
        );
        self.cand[a..b].iter().map(|x| x.0)
    }

    fn check_point(&self, g: u32, u: Point) -> Result<()> {
        if g as usize >= self.active.len() || !u[0].is_finite() || !u[1].is_finite() {
            return Err(Error::input(format!(
                "manifold spline evaluation at ({}, {}) in face {g}: the surface has {} faces and the point must be finite",
                u[0],
                u[1],
                self.active.len()
            )));
        }
        if !self.active[g as usize] {
            return Err(Error::input(format!(
                "manifold spline evaluation in face {g}: the face is incident to a singular vertex (the hole of the spline)"
            )));
        }
        Ok(())
    }

    /// Basis `i` at the point with barycentric coordinates `bary` of face `g`, whose corners in
    /// `i`'s home chart are `x`: the point is formed as an offset from the basis's knot centroid
    /// (`(x_0 − o) + b_1 (x_1 − x_0) + b_2 (x_2 − x_0)`, every term of the size of the face),
    /// so its rounding is `ε h`, not `ε |x|` — the home chart may be large against the face
    /// (module docs, *Conditioning*).
    #[allow(clippy::too_many_arguments)]
    fn push_basis(
        &self,
        i: u32,
        x: &[Point; 3],
        bary: [f64; 3],
        dir: Point,
        back: C,
        order: usize,
        ws: &mut Workspace,
    ) {
        let n = self.degree;
        let nb = per_triangle(n);
        let np = n_partials(order);
        let Some(basis) = self.bases[i as usize].as_ref() else {
            return;
        };
        let o = basis.origin();
        let off: Point = std::array::from_fn(|k| {
            (x[0][k] - o[k]) + bary[1] * (x[1][k] - x[0][k]) + bary[2] * (x[2][k] - x[0][k])
        });
        if !basis.may_contain([o[0] + off[0], o[1] + off[1]]) {
            return;
        }
        if ws.local.len() < nb * np {
            ws.local.resize(nb * np, 0.0);
        }
        match ws.precision {
            // Values alone are well conditioned (a convex combination): double suffices.
            Precision::Extended if order > 0 => {
                // The offset in double-double too: rounded in double, each basis would see
                // the point moved by its own `ε h`, and the thin bases' third partials
                // (10⁵ × those of `F` relative to the face) turn that into noise in `∂²F`.
                let (b1, b2) = (Dd::new(bary[1]), Dd::new(bary[2]));
                let offd: [Dd; 2] = std::array::from_fn(|k| {
                    let x0 = Dd::new(x[0][k]);
                    (x0 - Dd::new(o[k]))
                        + b1 * (Dd::new(x[1][k]) - x0)
                        + b2 * (Dd::new(x[2][k]) - x0)
                });
                basis.eval_offset_extended(offd, dir, order, &mut ws.simplex_dd, &mut ws.local)
            }
            _ => basis.eval_offset(off, dir, order, &mut ws.simplex, &mut ws.local),
        }
        rotate_partials(order, back, &mut ws.local[..nb * np]);
        for b in 0..nb {
            ws.indices.push((i as usize * nb + b) as u32);
        }
        ws.values.extend_from_slice(&ws.local[..nb * np]);
    }

    /// All basis functions that may be non-zero at `u` (coordinates in the canonical chart of
    /// face `g`), values and partials up to `order` in that chart, as limits from inside `g`;
    /// written to `ws.indices` / `ws.values` like [`crate::spline::dms::DmsSpace::basis_at`].
    pub fn basis_at_point(
        &self,
        g: u32,
        u: Point,
        order: usize,
        ws: &mut Workspace,
    ) -> Result<usize> {
        self.check_point(g, u)?;
        let bary = barycentric(&self.canon_coords[g as usize], u);
        self.basis_at_bary(g, bary, order, ws)
    }

    /// [`Self::basis_at_point`] at the point with barycentric coordinates `bary` of face `g`
    /// (exact at `g`'s corners and edges): the point is placed in each home chart from `g`'s
    /// own corners there, never through canonical-chart coordinates.
    pub fn basis_at_bary(
        &self,
        g: u32,
        bary: [f64; 3],
        order: usize,
        ws: &mut Workspace,
    ) -> Result<usize> {
        self.check_point(g, [bary[0], bary[1] + bary[2]])?;
        ws.indices.clear();
        ws.values.clear();
        let c = self.canon_coords[g as usize];
        let dir = inward_direction_bary(&c, bary);
        let (a, b) = (
            self.cand_start[g as usize] as usize,
            self.cand_start[g as usize + 1] as usize,
        );
        for k in a..b {
            let (i, m, x) = self.cand[k];
            self.push_basis(i, &x, bary, rotate(m.rot, dir), m.rot, order, ws);
        }
        Ok(ws.indices.len())
    }

    /// Like [`Self::basis_at_point`] for a point given in any chart `chart` containing `g`,
    /// with partials in that chart. The point is carried to the home charts by its barycentric
    /// coordinates in `g` (the affine map of `g`'s corners, which is the transition up to the
    /// charts' rounding); the rotations of the partials are computed directly from the charts
    /// (no cached motions), so comparing charts tests the whole chain.
    pub fn basis_in_chart(
        &self,
        chart: ChartId,
        g: u32,
        u: Point,
        order: usize,
        ws: &mut Workspace,
    ) -> Result<usize> {
        self.check_point(g, u)?;
        let c = self.charts.face_coords(chart, g).ok_or_else(|| {
            Error::input(format!("manifold spline: face {g} is not in chart {chart}"))
        })?;
        ws.indices.clear();
        ws.values.clear();
        let bary = barycentric(&c, u);
        let dir = inward_direction_bary(&c, bary);
        let (a, b) = (
            self.cand_start[g as usize] as usize,
            self.cand_start[g as usize + 1] as usize,
        );
        for k in a..b {
            let i = self.cand[k].0;
            let hi = self.home[i as usize];
            let (m, _) = self.charts.transition(chart, hi, g).ok_or_else(|| {
                Error::input(format!(
                    "manifold spline: no transition from chart {chart} to the home chart of face {i} on face {g}"
                ))
            })?;
            let x = self.charts.face_coords(hi, g).ok_or_else(|| {
                Error::input(format!(
                    "manifold spline: face {g} is not in the home chart {hi} of face {i}"
                ))
            })?;
            self.push_basis(i, &x, bary, rotate(m.rot, dir), m.rot, order, ws);
        }
        Ok(ws.indices.len())
    }

    /// `F = Σ c N` and partials up to `order` at barycentric `bary` of face `g`, in the
    /// canonical chart of `g` (`out[k * dim + d]`).
    #[allow(clippy::too_many_arguments)]
    pub fn evaluate(
        &self,
        control: &[f64],
        dim: usize,
        g: u32,
        bary: [f64; 3],
        order: usize,
        ws: &mut Workspace,
        out: &mut [f64],
    ) -> Result<()> {
        let np = n_partials(order);
        if control.len() != SplineSpace::n_control_points(self) * dim || out.len() < np * dim {
            return Err(Error::input(
                "manifold spline evaluation: control points or output of the wrong size",
            ));
        }
        if !bary.iter().all(|b| b.is_finite()) {
            return Err(Error::input(format!(
                "manifold spline evaluation in face {g}: barycentric coordinates {bary:?} are not finite"
            )));
        }
        let m = self.basis_at_bary(g, bary, order, ws)?;
        combine(control, dim, m, np, ws, out);
        Ok(())
    }

    /// `F` and partials at the point `u` of face `g` given in chart `chart`, partials in that
    /// chart (see [`Self::basis_in_chart`]).
    #[allow(clippy::too_many_arguments)]
    pub fn evaluate_in_chart(
        &self,
        control: &[f64],
        dim: usize,
        chart: ChartId,
        g: u32,
        u: Point,
        order: usize,
        ws: &mut Workspace,
        out: &mut [f64],
    ) -> Result<()> {
        let np = n_partials(order);
        if control.len() != SplineSpace::n_control_points(self) * dim || out.len() < np * dim {
            return Err(Error::input(
                "manifold spline evaluation: control points or output of the wrong size",
            ));
        }
        let m = self.basis_in_chart(chart, g, u, order, ws)?;
        combine(control, dim, m, np, ws, out);
        Ok(())
    }

    /// Paper 000 §5 step (i): control points from the degree-`n` subdivision of every domain
    /// triangle mapped linearly onto the embedding, `c_{I,β} = Σ_m β_m P_{v_m} / n` (3 numbers
    /// per control point; those of inactive faces too, though unused).
    pub fn subdivision_control_points(&self) -> Vec<f64> {
        let n = self.degree;
        let pos = self.charts.positions();
        let mesh = self.charts.mesh();
        let mut c = Vec::with_capacity(mesh.n_faces() * per_triangle(n) * 3);
        for t in mesh.faces() {
            for beta in multi_indices(n) {
                for d in 0..3 {
                    let s: f64 = (0..3).map(|m| beta[m] as f64 * pos[t[m] as usize][d]).sum();
                    c.push(s / n as f64);
                }
            }
        }
        c
    }

    /// Sum of all basis functions at a point (1 where the partition of unity holds).
    pub fn basis_sum(&self, g: u32, bary: [f64; 3], ws: &mut Workspace) -> Result<f64> {
        let m = self.basis_at_bary(g, bary, 0, ws)?;
        Ok(ws.values[..m].iter().sum())
    }
}

impl<A: FlatCharts + Sync + ?Sized> SplineSpace for ManifoldSpace<'_, A> {
    fn degree(&self) -> usize {
        self.degree
    }
    fn n_triangles(&self) -> usize {
        self.active.len()
    }
    fn neighbour_pairs(&self) -> Vec<(u32, u32, usize)> {
        let mesh = self.charts.mesh();
        let mut out = Vec::new();
        for h in 0..mesh.n_corners() as u32 {
            let t = mesh.he_twin(h);
            if mesh.is_boundary_halfedge(t) {
                continue;
            }
            let (i, j) = (h / 3, t / 3);
            if self.active[i as usize] && self.active[j as usize] {
                out.push((i, j, (h as usize % 3 + 2) % 3));
            }
        }
        out
    }
    fn blossom_weights_between(&self, i: u32, beta: [usize; 3], j: u32, out: &mut [f64]) {
        // In the vertex frame of a vertex `v` shared by I and J (small coordinates, developed
        // from the edge lengths), not in the home charts: the weights then carry rounding of
        // the faces' size instead of `ε |chart coordinates|` and the charts' own inconsistency,
        // which over the affine atlas made the redundant constraints of neighbouring edges
        // disagree by more than the fairing's tolerance (module docs, *Fairing*).
        let n = self.degree;
        let mesh = self.charts.mesh();
        let (ti, tj) = (mesh.face(i), mesh.face(j));
        let Some(v) = ti.iter().copied().find(|x| tj.contains(x)) else {
            out.fill(0.0);
            return;
        };
        let Some(fv) = self.frames[v as usize].as_ref() else {
            out.fill(0.0);
            return;
        };
        // Cloud of vertex `x` in v's frame, through the faces of {I, J} at x.
        let cloud_in_v = |x: u32| -> Option<Vec<Point>> {
            let fx = self.frames[x as usize].as_ref()?;
            let mut a = Vec::with_capacity(6);
            let mut b = Vec::with_capacity(6);
            let mut corner = None;
            for (f, t) in [(i, ti), (j, tj)] {
                if let Some(m) = t.iter().position(|&y| y == x) {
                    let (cx, cv) = (fx.coords_of(f)?, fv.coords_of(f)?);
                    a.extend_from_slice(cx);
                    b.extend_from_slice(cv);
                    corner.get_or_insert(cv[m]);
                }
            }
            let m = fit_rigid(&a, &b).0;
            let mut cl: Vec<Point> = self.cloud(x).iter().map(|&p| apply(&m, p)).collect();
            cl[0] = corner?;
            Some(cl)
        };
        let mut kj = Vec::with_capacity(3 * (n + 1));
        for &x in &tj {
            match cloud_in_v(x) {
                Some(c) => kj.extend_from_slice(&c),
                None => {
                    out.fill(0.0);
                    return;
                }
            }
        }
        let mut args: Vec<Point> = Vec::with_capacity(n);
        for (mi, &bm) in beta.iter().enumerate() {
            if bm == 0 {
                continue;
            }
            let x = ti[mi];
            let cl = match tj.iter().position(|&y| y == x) {
                Some(mj) => kj[mj * (n + 1)..(mj + 1) * (n + 1)].to_vec(),
                None => match cloud_in_v(x) {
                    Some(c) => c,
                    None => {
                        out.fill(0.0);
                        return;
                    }
                },
            };
            args.extend_from_slice(&cl[..bm]);
        }
        blossom_weights_of(n, &kj, &args, out);
    }
    fn basis_at(&self, face: u32, param: Point, order: usize, ws: &mut Workspace) -> Result<usize> {
        self.basis_at_point(face, param, order, ws)
    }
    fn quadrature_with(&self, rule: &[([f64; 3], f64)]) -> Vec<(u32, Point, f64)> {
        let mut q = Vec::new();
        let (hbar, _) = self.domain_scale();
        let mesh = self.charts.mesh();
        let lengths = self.charts.lengths();
        for f in 0..self.active.len() as u32 {
            if !self.active[f as usize] {
                continue;
            }
            let [a, b, c] = self.canon_coords[f as usize];
            // Each face's energy in its own scale (see the module docs): weight (h_f / h̄)².
            let l = face_side_lengths(mesh, lengths, f);
            let hf = (l[0] + l[1] + l[2]) / 3.0;
            let area = 0.5 * det3(a, b, c) * (hf / hbar).powi(2);
            for &(bary, w) in rule {
                q.push((f, self.face_point(f, bary), area * w));
            }
        }
        q
    }
    fn domain_scale(&self) -> (f64, f64) {
        let l = self.charts.lengths();
        let mean = l.iter().sum::<f64>() / l.len().max(1) as f64;
        let area: f64 = (0..self.active.len())
            .filter(|&f| self.active[f])
            .map(|f| {
                let [a, b, c] = self.canon_coords[f];
                0.5 * det3(a, b, c)
            })
            .sum();
        (mean, area)
    }
}

/// Direction from the point with barycentric coordinates `bary` towards the centroid of the
/// triangle `c`, `Σ_m (1/3 − b_m) (c_m − c_0)` (from differences, so of the face's size
/// whatever the coordinates): the side from which values there are taken as limits from
/// inside the face (any direction at the centroid itself).
fn inward_direction_bary(c: &[Point; 3], bary: [f64; 3]) -> Point {
    let w1 = 1.0 / 3.0 - bary[1];
    let w2 = 1.0 / 3.0 - bary[2];
    let dir: Point = std::array::from_fn(|k| w1 * (c[1][k] - c[0][k]) + w2 * (c[2][k] - c[0][k]));
    if dir == [0.0, 0.0] {
        [1.0, 0.0]
    } else {
        dir
    }
}

/// Barycentric coordinates of `u` in the triangle `c` (exact at its corners).
fn barycentric(c: &[Point; 3], u: Point) -> [f64; 3] {
    let area = det3(c[0], c[1], c[2]);
    [
        det3(u, c[1], c[2]) / area,
        det3(c[0], u, c[2]) / area,
        det3(c[0], c[1], u) / area,
    ]
}
