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
use crate::spline::error::SplineError;

use super::dms::combine;
use super::dms::{
    blossom_weights_of, general_position_involving, hash64, multi_indices, needs_shrink,
    per_triangle, unit, KnotOptions, Precision, TriangleBasis, Workspace, MAX_DEGREE,
};
use super::simplex::{det3, n_partials, partial_index, Point};
use super::space::SplineSpace;

mod build;
mod charts;

pub(crate) use charts::{apply, check_metric, cz, pt, rotate, rotate_partials2_cached};
pub use charts::{
    develop_face, face_side_lengths, rotate_partials, rotation_matrix, star_frame, LocalCharts,
    StarFrame,
};

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

impl<'a, A: FlatCharts + Sync + ?Sized> ManifoldSpace<'a, A> {
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
            return Err(SplineError::FaceInHole { face: g }.into());
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
        slot: usize,
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
        if order == 2 {
            if ws.rot2.len() <= slot {
                ws.rot2.resize(slot + 1, None);
            }
            rotate_partials2_cached(back, &mut ws.rot2[slot], &mut ws.local[..nb * np]);
        } else {
            rotate_partials(order, back, &mut ws.local[..nb * np]);
        }
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
            self.push_basis(i, &x, bary, rotate(m.rot, dir), m.rot, order, k - a, ws);
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
            self.push_basis(i, &x, bary, rotate(m.rot, dir), m.rot, order, k - a, ws);
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
