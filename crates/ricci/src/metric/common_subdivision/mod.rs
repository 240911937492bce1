//! The common subdivision of the input triangulation `T0` and an intrinsic triangulation `T`
//! reached from it by Ptolemy flips, and the map from the input surface to a layout of `T`
//! (Gillespie–Springborn–Crane 2021, "Discrete conformal equivalence of polyhedral surfaces"
//! (CEPS) §5; Gillespie–Sharp–Crane 2021, "Integer coordinates for intrinsic geometry
//! processing" §§3–4 for normal coordinates; Penner, "Decorated Teichmüller theory", for
//! λ-lengths and the Ptolemy relation).
//!
//! **Why the two triangulations live on one surface.** Log Penner coordinates `λ_e` define a
//! *decorated cusped hyperbolic surface*: every triangle is an ideal hyperbolic triangle with a
//! horocycle at each vertex, and `Λ_e = e^{λ_e/2}` is the λ-length of edge `e` (the Euclidean
//! length in E², `sinh(l/2)` in H²). Vertex scaling `λ_ij + u_i + u_j` only resizes the
//! horocycles (the shears `log(Λ_a Λ_c / (Λ_b Λ_d))` are unchanged) and a Ptolemy flip
//! `Λ_kl Λ_ij = Λ_ik Λ_jl + Λ_il Λ_jk` is the flip of an ideal quadrilateral of that surface. So
//! `T0` and `T` are two ideal geodesic triangulations of one hyperbolic surface; every input
//! edge is a geodesic there and the common subdivision is their overlay.
//!
//! **Combinatorics: normal coordinates.** For every edge `e` of the current triangulation,
//! `n_e` is the number of times input edges cross `e`, or `−1` when `e` *is* an input edge.
//! Inside a triangle the input edges are disjoint geodesics, so they come in two kinds only:
//! arcs cutting off a corner (`C_m` of them at corner `m`) and arcs leaving a corner through
//! the opposite side (`E` of them, at one corner at most); with `x_j` crossings on the side
//! `j` (from corner `j` to corner `j+1`), `x_j = C_j + C_{j+1} + E_j`. A flip of `ij` in the
//! quadrilateral `i, l, j, k` replaces `ij` by `kl`; each piece of input edge in the
//! quadrilateral crosses `kl` iff its two ends are on different sides of `kl`: the corner arcs
//! at `k` and `l`, the arcs leaving `i` or `j`, the pieces running from the `i`-side of one
//! triangle to the `j`-side of the other, and `ij` itself when it was an input edge. A piece
//! running from `k` to `l` makes `kl` an input edge (`n_kl = −1`). (This is our derivation of
//! the flip formula of Gillespie–Sharp–Crane. No roundabouts are kept: an input edge is
//! identified by its two end vertices, and where the input is a Δ-complex with two edges
//! between the same vertices — the input metric's Delaunay triangulation in the three-way
//! overlay — by where it leaves its first vertex in the cyclic order of the input edges there,
//! recomputed from the normal coordinates at the vertices that need it, and checked against its
//! log Penner coordinate, which the strip's development recomputes; see [`input`], [`sides`].)
//!
//! **Geometry: λ-lengths along a strip.** Tracing an input edge `ab` through `T` gives the
//! strip of triangles it crosses. Developing the strip, the λ-length from the cusp `a` to every
//! vertex of the strip follows from the Ptolemy relation, triangle by triangle and with
//! positive terms only (no cancellation; computed as log-sum-exp), and likewise from `b`
//! backwards. Where `ab` crosses the edge `cd`, the crossing point is, in projective
//! coordinates with respect to the decorated light-like vectors `p_c, p_d` (or `p_a, p_b`),
//!
//! ```text
//! β_c / β_d = Λ_ad Λ_bd / (Λ_ac Λ_bc),      β_a / β_b = Λ_bc Λ_bd / (Λ_ac Λ_ad)
//! ```
//!
//! (for a cyclic Euclidean quadrilateral these are the intersecting-chords ratios
//! `PD/CP = DA·DB/(CA·CB)`). They are computed with the decoration of the input (the replayed
//! base coordinates), so `β_a/β_b` is the barycentric position on the input edge; a vertex
//! scaling `u` turns `β_c` into `β_c e^{−u_c}`.
//!
//! **Projective interpolation.** A Euclidean triangle is the Klein model of its circumdisk:
//! the point with barycentric coordinates `b` is the hyperbolic point `[Σ b_i p_i]` when
//! `−2⟨p_i, p_j⟩ = l_ij²` (the circumcircle `Σ b_i b_j l_ij² = 0` is the light cone). A
//! hyperbolic triangle with vertices `q_i` on the hyperboloid maps the same way with
//! `x = Σ b_i q_i` (a linear map sends `q_i` to light-like `p_i` with `−⟨p_i,p_j⟩ = cosh l_ij −
//! 1 = 2 sinh²(l_ij/2)`). So a point of `T`'s layout is `Σ β_i P_i / Σ β_i` (E²) or the
//! normalised `Σ β_i q_i` (H², Poincaré disk), and a point of an input face (in both
//! geometries) has barycentric coordinates `β`. The maps agree along shared edges, so the UV map
//! is continuous, and each common-subdivision polygon (the intersection of two ideal triangles)
//! is convex in both charts: a fan triangulation has no flipped triangle.

// `!(x < y)` is meant: it is also true for NaN.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

mod develop;
mod input;
mod monotone;
mod normal;
mod polygons;
mod rounding;
mod sides;
mod three_way;
mod trace;

use crate::error::{Error, Result};
use crate::mesh::Mesh;
use crate::metric::intrinsic::IntrinsicTriangulation;
use crate::metric::Geometry;
use crate::numeric::dd::{Cdd, Dd};

use normal::{replay, replay_on};
use trace::build;

pub use develop::{layout_euclidean, layout_hyperbolic};
pub use monotone::MonotoneRepair;
pub use normal::{flipped_normal_coordinate, TriangleArcs};
pub use rounding::repair_rounded_pieces;
pub use three_way::ThreeWayReport;

type Tri = IntrinsicTriangulation;

/// One crossing of an input edge with an edge of `T`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Crossing {
    /// The input edge (id of the input [`Mesh`]).
    pub input_edge: u32,
    /// Rank along the input edge from `mesh.edge_vertices(input_edge)[0]` (1 = first crossing).
    pub input_rank: u32,
    /// Barycentric parameter on the input edge from `edge_vertices[0]` (0) to `[1]` (1).
    pub input_t: f64,
    /// The edge of `T`.
    pub t_edge: u32,
    /// Index along the edge of `T` from `tri.edge_vertices(t_edge)[0]` (0-based).
    pub t_index: u32,
    /// `log(β_0 / β_1)` on the edge of `T` (its `edge_vertices` order), in the decoration of
    /// the input (vertex scaling `u` adds `u_1 − u_0`).
    pub t_log_ratio: f64,
}

/// What the replay and the overlay measured.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct SubdivisionReport {
    /// Flips replayed.
    pub flips: usize,
    /// Crossings of input edges with edges of `T`.
    pub crossings: usize,
    /// Edges of `T` that coincide with input edges.
    pub shared_edges: usize,
    /// Crossings whose geometric parameter is out of combinatorial order along their edge of
    /// `T` or their input edge (0 unless the metric is near degenerate).
    pub order_violations: usize,
    /// Polygons (intersections of an input face with a face of `T`).
    pub polygons: usize,
}

/// The common subdivision of the input triangulation and `T` (see the module docs).
///
/// Vertices `0..V` are the input vertices; vertex `V + c` is crossing `c`. Triangles come from
/// fan-triangulating the convex polygons `f0 ∩ t`; each knows its input face, its face of `T`,
/// the barycentric coordinates of its corners on the input face and their projective weights
/// on the face of `T` (input decoration).
#[derive(Debug, Clone)]
pub struct CommonSubdivision {
    /// `T`, replayed from the input with the flip log (base coordinates, `u = 0`).
    pub triangulation: IntrinsicTriangulation,
    /// Normal coordinates of `T`'s edges (crossings, `−1` for an input edge).
    pub normal: Vec<i32>,
    /// First crossing id of every edge of `T` (crossings of edge `e` are
    /// `crossing_offset[e] .. crossing_offset[e+1]`, in order along the edge).
    pub crossing_offset: Vec<u32>,
    pub crossings: Vec<Crossing>,
    /// The input half-edge along `triangulation.edge_he[e]` of every edge `e` of `T` that is an
    /// input edge (normal coordinate −1), `NONE` for the others.
    pub(crate) shared_input: Vec<u32>,
    /// Number of input vertices.
    pub n_input_vertices: usize,
    /// Triangles of the common subdivision (counter-clockwise).
    pub triangles: Vec<[u32; 3]>,
    /// Input face of every triangle.
    pub input_face: Vec<u32>,
    /// Face of `T` of every triangle.
    pub t_face: Vec<u32>,
    /// Per triangle corner (`3t + i`): barycentric coordinates on the input face (in the order
    /// of `mesh.face(input_face)`).
    pub input_barycentric: Vec<[f64; 3]>,
    /// Per triangle corner: projective weights on the face of `T` (in the order of
    /// `tri.face(t_face)`), decoration of the input; see [`CommonSubdivision::uv`].
    pub t_weights: Vec<[f64; 3]>,
    pub report: SubdivisionReport,
}

impl CommonSubdivision {
    /// Replay `flip_log` — Ptolemy flips only — on the input triangulation of `mesh` (edge
    /// lengths `lengths` in `geometry`) with normal coordinates, then build the common
    /// subdivision in the hyperbolic structure of the input. For a log that starts with
    /// isometric flips use [`CommonSubdivision::from_triangulation`].
    pub fn new(
        mesh: &Mesh,
        geometry: Geometry,
        lengths: &[f64],
        flip_log: &[u32],
    ) -> Result<CommonSubdivision> {
        let (tri, normal) = replay(mesh, geometry, lengths, flip_log)?;
        build(mesh, tri, normal, flip_log.len())
    }

    /// The common subdivision of `mesh` and the triangulation `t` a solver ended on, whose
    /// `lambda` holds the final metric's log Penner coordinates and whose `flip_log` leads
    /// from the input to it; `u` is the vertex scaling of the final metric (empty = 0).
    ///
    /// The combinatorics is replayed from the flip log (an isometric flip and a Ptolemy flip
    /// change the connectivity in the same way); the geometry comes from `t`'s hyperbolic
    /// structure with the decoration `λ_e − u_i − u_j`. When the log starts with isometric
    /// flips (to the input metric's Delaunay triangulation, as `flow::conformal` does), the
    /// input faces are mapped to the ideal triangles of that structure spanned by their
    /// (straightened) edges — a continuous, piecewise projective homeomorphism that agrees
    /// with the input metric on every input edge kept by the isometric flips.
    pub fn from_triangulation(
        mesh: &Mesh,
        geometry: Geometry,
        lengths: &[f64],
        t: &IntrinsicTriangulation,
        u: &[f64],
    ) -> Result<CommonSubdivision> {
        let (tri, normal) = replay(mesh, geometry, lengths, &t.flip_log)?;
        Self::from_replayed(mesh, tri, normal, t, u)
    }

    /// [`CommonSubdivision::from_triangulation`] with the input triangulation given: `start`
    /// is `mesh`'s triangulation (its half-edges and edge ids, e.g. from
    /// [`IntrinsicTriangulation::from_mesh`]) with the half-edge `edge_he` of every edge that
    /// the flips of `t.flip_log` were made from (a flip's result depends on that choice).
    pub fn from_triangulation_on(
        mesh: &Mesh,
        start: IntrinsicTriangulation,
        t: &IntrinsicTriangulation,
        u: &[f64],
    ) -> Result<CommonSubdivision> {
        Self::from_triangulation_on_input(mesh, start, t, u)
    }

    /// [`CommonSubdivision::from_triangulation_on`] for any input triangulation (a Δ-complex:
    /// [`input::DeltaInput`]).
    fn from_triangulation_on_input<M: input::InputComplex>(
        mesh: &M,
        start: IntrinsicTriangulation,
        t: &IntrinsicTriangulation,
        u: &[f64],
    ) -> Result<CommonSubdivision> {
        if start.origin.len() != mesh.n_corners() || start.n_edges() != mesh.n_edges() {
            return Err(Error::input(
                "the start triangulation is not a triangulation of the input mesh",
            ));
        }
        let (tri, normal) = replay_on(start, &t.flip_log)?;
        Self::from_replayed(mesh, tri, normal, t, u)
    }

    fn from_replayed<M: input::InputComplex>(
        mesh: &M,
        mut tri: IntrinsicTriangulation,
        normal: Vec<i32>,
        t: &IntrinsicTriangulation,
        u: &[f64],
    ) -> Result<CommonSubdivision> {
        if tri.origin != t.origin || tri.twin != t.twin || tri.edge != t.edge {
            return Err(Error::input(
                "replaying the flip log on the input does not reproduce the given triangulation",
            ));
        }
        if !u.is_empty() && u.len() != t.n_vertices {
            return Err(Error::input(format!(
                "{} scale factors for {} vertices",
                u.len(),
                t.n_vertices
            )));
        }
        for e in 0..t.n_edges() as u32 {
            let [a, b] = t.edge_vertices(e);
            let s = if u.is_empty() {
                0.0
            } else {
                u[a as usize] + u[b as usize]
            };
            let x = t.lambda[e as usize] - s;
            if !x.is_finite() {
                return Err(Error::input(format!(
                    "edge {e} of the triangulation has no finite log Penner coordinate"
                )));
            }
            tri.lambda[e as usize] = x;
        }
        build(mesh, tri, normal, t.flip_log.len())
    }

    /// Number of vertices (input vertices and crossings).
    pub fn n_vertices(&self) -> usize {
        self.n_input_vertices + self.crossings.len()
    }

    /// Positions of all vertices on the input surface (`positions` = the input's).
    pub fn positions(&self, mesh: &Mesh, positions: &[[f64; 3]]) -> Result<Vec<[f64; 3]>> {
        if positions.len() != self.n_input_vertices || mesh.n_vertices() != self.n_input_vertices {
            return Err(Error::input(format!(
                "{} positions for a common subdivision of a mesh with {} vertices",
                positions.len(),
                self.n_input_vertices
            )));
        }
        let mut out = positions.to_vec();
        for c in &self.crossings {
            let [a, b] = mesh.edge_vertices(c.input_edge);
            let (pa, pb) = (positions[a as usize], positions[b as usize]);
            let t = c.input_t;
            out.push([0, 1, 2].map(|k| (1.0 - t) * pa[k] + t * pb[k]));
        }
        Ok(out)
    }

    /// Parameter of crossing `c` along its edge of `T` (0 at `edge_vertices[0]`, 1 at `[1]`)
    /// in the projective interpolation of the metric with vertex scaling `u` (empty = 0).
    pub fn t_parameter(&self, c: u32, u: &[f64]) -> f64 {
        let cr = &self.crossings[c as usize];
        let [a, b] = self.triangulation.edge_vertices(cr.t_edge);
        let du = if u.is_empty() {
            0.0
        } else {
            u[b as usize] - u[a as usize]
        };
        // β_a/β_b = e^{ρ + u_b − u_a}; the parameter is β_b/(β_a + β_b).
        1.0 / (1.0 + (cr.t_log_ratio + du).exp())
    }

    /// Per-vertex vertex-scaling factors `u` of a final metric whose log Penner coordinates
    /// are `final_lambda` (by edge id of `T`), against the replayed base coordinates; the
    /// second value is the largest residual `|λ_final − λ_base − u_i − u_j|` (0 for a metric
    /// in the same discrete conformal class).
    pub fn scale_factors(&self, final_lambda: &[f64]) -> Result<(Vec<f64>, f64)> {
        let tri = &self.triangulation;
        if final_lambda.len() != tri.n_edges() {
            return Err(Error::input(format!(
                "{} final coordinates for {} edges",
                final_lambda.len(),
                tri.n_edges()
            )));
        }
        let d = |h: u32| {
            let e = tri.edge[h as usize] as usize;
            final_lambda[e] - tri.lambda[e]
        };
        let mut u = vec![f64::NAN; tri.n_vertices];
        for f in 0..tri.n_faces() as u32 {
            for j in 0..3u32 {
                let h = 3 * f + j; // corner j: u = (d(h) + d(prev h) − d(next h)) / 2
                let v = tri.origin[h as usize] as usize;
                if u[v].is_nan() {
                    u[v] = 0.5 * (d(h) + d(Tri::prev(h)) - d(Tri::next(h)));
                }
            }
        }
        let mut residual = 0.0f64;
        for e in 0..tri.n_edges() as u32 {
            let [a, b] = tri.edge_vertices(e);
            let r =
                final_lambda[e as usize] - tri.lambda[e as usize] - u[a as usize] - u[b as usize];
            residual = residual.max(r.abs());
        }
        for x in &mut u {
            if x.is_nan() {
                *x = 0.0;
            }
        }
        Ok((u, residual))
    }

    /// UV of every triangle corner (`3t + i`) from a layout of `T` given per corner of `T`
    /// (`corner_uv[3f + i]` = position of corner `i` of face `f`: the plane for E², the
    /// Poincaré disk for H²) and the vertex scaling `u` of the laid-out metric (empty = 0).
    pub fn uv(
        &self,
        geometry: Geometry,
        u: &[f64],
        corner_uv: &[[f64; 2]],
    ) -> Result<Vec<[f64; 2]>> {
        let tri = &self.triangulation;
        if corner_uv.len() != 3 * tri.n_faces() {
            return Err(Error::input(format!(
                "layout has {} corners, the triangulation {}",
                corner_uv.len(),
                3 * tri.n_faces()
            )));
        }
        if !u.is_empty() && u.len() != tri.n_vertices {
            return Err(Error::input(format!(
                "{} scale factors for {} vertices",
                u.len(),
                tri.n_vertices
            )));
        }
        self.per_piece_corner(|t, f, c| {
            let p = [0, 1, 2].map(|i| corner_uv[3 * f + i]);
            interpolate(geometry, &p, &self.beta(t, c, u))
        })
    }

    /// Projective weights `β_i = w_i e^{−u_i}` of corner `c` of triangle `t` on its face of
    /// `T`, normalised in log space (largest 1).
    fn beta(&self, t: usize, c: usize, u: &[f64]) -> [f64; 3] {
        let verts = self.triangulation.face(self.t_face[t]);
        let w = self.t_weights[3 * t + c];
        let mut logs = [f64::NEG_INFINITY; 3];
        for i in 0..3 {
            if w[i] > 0.0 {
                let ui = if u.is_empty() {
                    0.0
                } else {
                    u[verts[i] as usize]
                };
                logs[i] = w[i].ln() - ui;
            }
        }
        let m = logs.iter().cloned().fold(f64::NEG_INFINITY, f64::max);
        logs.map(|l| if l.is_finite() { (l - m).exp() } else { 0.0 })
    }

    /// [`CommonSubdivision::uv`] for a hyperbolic layout of `T` given to double-double
    /// precision (`corner_hi[3f + i] + corner_lo[3f + i]`, Poincaré disk): the pieces are
    /// interpolated in the frame centred at a corner as in `uv`, but the Möbius maps into and
    /// out of that frame are evaluated in double-double, so every written point is the
    /// correctly rounded image of the interpolated one (far out in the disk the
    /// double-precision corners alone resolve only ~1e-16·e^r, and thin faces of `T` there
    /// came out flipped: seahorse2_100K).
    pub fn uv_hyperbolic_dd(
        &self,
        u: &[f64],
        corner_hi: &[[f64; 2]],
        corner_lo: &[[f64; 2]],
    ) -> Result<Vec<[f64; 2]>> {
        let tri = &self.triangulation;
        if corner_hi.len() != 3 * tri.n_faces() || corner_lo.len() != corner_hi.len() {
            return Err(Error::input(format!(
                "layout has {} corners ({} low parts), the triangulation {}",
                corner_hi.len(),
                corner_lo.len(),
                3 * tri.n_faces()
            )));
        }
        if !u.is_empty() && u.len() != tri.n_vertices {
            return Err(Error::input(format!(
                "{} scale factors for {} vertices",
                u.len(),
                tri.n_vertices
            )));
        }
        self.per_piece_corner(|t, f, c| {
            let p = [0, 1, 2].map(|i| {
                let (h, l) = (corner_hi[3 * f + i], corner_lo[3 * f + i]);
                Cdd {
                    re: Dd::new(h[0]) + Dd::new(l[0]),
                    im: Dd::new(h[1]) + Dd::new(l[1]),
                }
            });
            self.piece_uv_hyperbolic_dd(t, c, u, &p)
        })
    }

    /// `uv(t, f, c)` for every corner `c` of every triangle `t` (on face `f` of `T`), in
    /// corner order (`3t + c`), computed in parallel (rayon; each value depends only on its
    /// own inputs); the first error in that order, if any.
    fn per_piece_corner(
        &self,
        uv: impl Fn(usize, usize, usize) -> Result<[f64; 2]> + Sync,
    ) -> Result<Vec<[f64; 2]>> {
        use rayon::prelude::*;
        let all: Vec<Result<[f64; 2]>> = (0..3 * self.t_face.len())
            .into_par_iter()
            .map(|k| uv(k / 3, self.t_face[k / 3] as usize, k % 3))
            .collect();
        all.into_iter().collect()
    }

    /// UV of corner `c` of triangle `t` when the corners of its face of `T` are at `p`
    /// (Poincaré disk, double-double; see [`CommonSubdivision::uv_hyperbolic_dd`]).
    pub fn piece_uv_hyperbolic_dd(
        &self,
        t: usize,
        c: usize,
        u: &[f64],
        p: &[Cdd; 3],
    ) -> Result<[f64; 2]> {
        interpolate_hyperbolic_dd(p, &self.beta(t, c, u))
    }

    /// Number of triangles whose UV triangle is not positively oriented: signed area in E²;
    /// in H² the orientation of the geodesic triangle, evaluated with its first corner moved
    /// to the centre of the Poincaré disk ([`disk_orientation`]).
    pub fn flipped_triangles(&self, geometry: Geometry, uv: &[[f64; 2]]) -> usize {
        (0..self.triangles.len())
            .filter(|&t| !piece_positive(geometry, uv, t))
            .count()
    }

    /// Orientation of triangle `t` inside its face of `T` in exact terms: the determinant of
    /// the barycentric coordinates (normalised projective weights, vertex scaling `u`) of its
    /// three corners on that face. Positive when the piece has the face's orientation — then
    /// its UV triangle is positively oriented whenever the face's is, up to rounding.
    pub fn barycentric_orientation(&self, t: usize, u: &[f64]) -> f64 {
        let b = [0, 1, 2].map(|c| {
            let w = self.beta(t, c, u);
            let s = w[0] + w[1] + w[2];
            w.map(|x| x / s)
        });
        b[0][0] * (b[1][1] * b[2][2] - b[1][2] * b[2][1])
            - b[0][1] * (b[1][0] * b[2][2] - b[1][2] * b[2][0])
            + b[0][2] * (b[1][0] * b[2][1] - b[1][1] * b[2][0])
    }

    /// Per-vertex UVs when the per-corner UVs agree within `tol` at every vertex (a layout
    /// without seams); `None` otherwise. The second value is the largest disagreement.
    pub fn vertex_uv(&self, uv: &[[f64; 2]], tol: f64) -> (Option<Vec<[f64; 2]>>, f64) {
        let mut out = vec![[f64::NAN; 2]; self.n_vertices()];
        let mut worst = 0.0f64;
        for (t, tr) in self.triangles.iter().enumerate() {
            for i in 0..3 {
                let v = tr[i] as usize;
                let z = uv.get(3 * t + i).copied().unwrap_or([f64::NAN; 2]);
                if z[0].is_nan() || z[1].is_nan() {
                    worst = f64::INFINITY;
                } else if out[v][0].is_nan() {
                    out[v] = z;
                } else {
                    worst = worst.max((out[v][0] - z[0]).hypot(out[v][1] - z[1]));
                }
            }
        }
        (if worst <= tol { Some(out) } else { None }, worst)
    }
}

/// Whether the UV triangle `t` (corners `3t..3t+3` of `uv`) is positively oriented: signed
/// area in E², [`disk_orientation`] in H² (`false` for NaN).
pub fn piece_positive(geometry: Geometry, uv: &[[f64; 2]], t: usize) -> bool {
    let q = [0, 1, 2].map(|i| uv.get(3 * t + i).copied().unwrap_or([f64::NAN; 2]));
    let a = if geometry == Geometry::Hyperbolic {
        disk_orientation(q[0], q[1], q[2])
    } else {
        (q[1][0] - q[0][0]) * (q[2][1] - q[0][1]) - (q[1][1] - q[0][1]) * (q[2][0] - q[0][0])
    };
    a > 0.0
}

/// `(z − a)/(1 − ā z)`: the Möbius map of the Poincaré disk that moves `a` to the centre.
#[inline]
fn to_centre(a: [f64; 2], z: [f64; 2]) -> [f64; 2] {
    let (nx, ny) = (z[0] - a[0], z[1] - a[1]);
    // 1 − ā z
    let (dx, dy) = (
        1.0 - (a[0] * z[0] + a[1] * z[1]),
        -(a[0] * z[1] - a[1] * z[0]),
    );
    let d = dx * dx + dy * dy;
    [(nx * dx + ny * dy) / d, (ny * dx - nx * dy) / d]
}

/// `(w + a)/(1 + ā w)`: the inverse of [`to_centre`].
#[inline]
fn from_centre(a: [f64; 2], w: [f64; 2]) -> [f64; 2] {
    let (nx, ny) = (w[0] + a[0], w[1] + a[1]);
    let (dx, dy) = (1.0 + (a[0] * w[0] + a[1] * w[1]), a[0] * w[1] - a[1] * w[0]);
    let d = dx * dx + dy * dy;
    [(nx * dx + ny * dy) / d, (ny * dx - nx * dy) / d]
}

/// Orientation of the geodesic triangle `a, b, c` of the Poincaré disk: positive when it is
/// counter-clockwise. It is Möbius invariant, so it is evaluated with `a` moved to the centre,
/// where the geodesics through `a` are straight; this keeps its relative accuracy far out in
/// the disk (the Klein model's coordinates lose it quadratically in `1 − |z|`).
pub fn disk_orientation(a: [f64; 2], b: [f64; 2], c: [f64; 2]) -> f64 {
    let (wb, wc) = (to_centre(a, b), to_centre(a, c));
    wb[0] * wc[1] - wb[1] * wc[0]
}

/// Projective interpolation in one face of `T`: E² `Σ β_i P_i / Σ β_i`; H² the normalised
/// `Σ β_i q_i` of the hyperboloid points `q_i` of Poincaré-disk points `P_i`, computed in the
/// frame where the corner of largest weight is the centre of the disk. (Far out in the disk,
/// `1 − |P|²` and the Klein model's `1 − |k|²` cancel: evaluated in place, a piece at hyperbolic
/// distance 14 from the centre lost about 5 of its 16 digits and thin pieces came out flipped.)
fn interpolate(geometry: Geometry, p: &[[f64; 2]; 3], beta: &[f64; 3]) -> Result<[f64; 2]> {
    let s: f64 = beta.iter().sum();
    match geometry {
        Geometry::Euclidean => {
            // As offsets from the corner of largest weight: exact at the corners, and the
            // offsets of a thin piece keep their relative accuracy (camel.off had 2 pieces
            // flipped by the rounding of Σ β_i P_i).
            let j = (0..3)
                .max_by(|&a, &b| beta[a].total_cmp(&beta[b]))
                .unwrap_or(0);
            let (mut x, mut y) = (0.0, 0.0);
            for i in (0..3).filter(|&i| i != j) {
                x += beta[i] * (p[i][0] - p[j][0]);
                y += beta[i] * (p[i][1] - p[j][1]);
            }
            Ok([p[j][0] + x / s, p[j][1] + y / s])
        }
        Geometry::Hyperbolic => {
            for z in p {
                if !(z[0] * z[0] + z[1] * z[1] < 1.0) {
                    return Err(Error::input(format!(
                        "layout point ({}, {}) is not inside the Poincaré disk",
                        z[0], z[1]
                    )));
                }
            }
            let j = (0..3)
                .max_by(|&a, &b| beta[a].total_cmp(&beta[b]))
                .unwrap_or(0);
            let centre = p[j];
            let mut x = [0.0f64; 3];
            for i in 0..3 {
                if beta[i] == 0.0 {
                    continue;
                }
                let w = if i == j {
                    [0.0, 0.0]
                } else {
                    to_centre(centre, p[i])
                };
                let r2 = w[0] * w[0] + w[1] * w[1];
                let d = 1.0 - r2;
                x[0] += beta[i] * (1.0 + r2) / d;
                x[1] += beta[i] * 2.0 * w[0] / d;
                x[2] += beta[i] * 2.0 * w[1] / d;
            }
            // Hyperboloid point → Poincaré disk directly: x' / (x_0 + |x|) with
            // |x| = sqrt(x_0² − |x'|²) (no cancellation near the centre).
            let q = (x[0] * x[0] - x[1] * x[1] - x[2] * x[2]).max(0.0).sqrt();
            let w = [x[1] / (x[0] + q), x[2] / (x[0] + q)];
            Ok(from_centre(centre, w))
        }
        Geometry::Spherical => Err(Error::input(
            "projective interpolation is implemented for E² and H² layouts (the sphere goes \
             through a puncture)",
        )),
    }
}

/// The hyperbolic branch of [`interpolate`] with double-double corners: `to_centre` and
/// `from_centre` in double-double, the hyperboloid sum near the centre in double precision,
/// one rounding at the end.
fn interpolate_hyperbolic_dd(p: &[Cdd; 3], beta: &[f64; 3]) -> Result<[f64; 2]> {
    for z in p {
        let d = Dd::ONE - z.norm_sqr();
        if d.hi.is_nan() || d.hi <= 0.0 {
            return Err(Error::input(format!(
                "layout point ({}, {}) is not inside the Poincaré disk",
                z.re.hi, z.im.hi
            )));
        }
    }
    let j = (0..3)
        .max_by(|&a, &b| beta[a].total_cmp(&beta[b]))
        .unwrap_or(0);
    let centre = p[j];
    let mut x = [0.0f64; 3];
    for i in 0..3 {
        if beta[i] == 0.0 {
            continue;
        }
        let w = if i == j {
            [0.0, 0.0]
        } else {
            // (z − a)/(1 − ā z)
            let q = (p[i] - centre) / (Cdd::ONE - centre.conj() * p[i]);
            [q.re.hi, q.im.hi]
        };
        let r2 = w[0] * w[0] + w[1] * w[1];
        let d = 1.0 - r2;
        x[0] += beta[i] * (1.0 + r2) / d;
        x[1] += beta[i] * 2.0 * w[0] / d;
        x[2] += beta[i] * 2.0 * w[1] / d;
    }
    let q = (x[0] * x[0] - x[1] * x[1] - x[2] * x[2]).max(0.0).sqrt();
    let w = Cdd {
        re: Dd::new(x[1] / (x[0] + q)),
        im: Dd::new(x[2] / (x[0] + q)),
    };
    // (w + a)/(1 + ā w)
    let z = (w + centre) / (Cdd::ONE + centre.conj() * w);
    Ok([z.re.hi, z.im.hi])
}

impl CommonSubdivision {
    /// The common subdivision as a surface for writing `uv.obj`: positions on the input
    /// surface, one UV per vertex; a vertex whose corners get different UVs (a seam of the
    /// layout, beyond `tol`) is duplicated once per distinct UV.
    pub fn uv_surface(
        &self,
        mesh: &Mesh,
        positions: &[[f64; 3]],
        uv: &[[f64; 2]],
        tol: f64,
    ) -> Result<crate::mesh::Surface> {
        if uv.len() != 3 * self.triangles.len() {
            return Err(Error::input(format!(
                "{} UVs for {} triangle corners",
                uv.len(),
                3 * self.triangles.len()
            )));
        }
        let pos = self.positions(mesh, positions)?;
        let mut copies: Vec<Vec<(u32, [f64; 2])>> = vec![Vec::new(); self.n_vertices()];
        let mut out_pos = Vec::with_capacity(pos.len());
        let mut out_uv = Vec::with_capacity(pos.len());
        let mut faces = Vec::with_capacity(self.triangles.len());
        for (t, tr) in self.triangles.iter().enumerate() {
            let mut f = [0u32; 3];
            for i in 0..3 {
                let v = tr[i] as usize;
                let z = uv[3 * t + i];
                let found = copies[v]
                    .iter()
                    .find(|(_, w)| (w[0] - z[0]).hypot(w[1] - z[1]) <= tol)
                    .map(|c| c.0);
                f[i] = match found {
                    Some(id) => id,
                    None => {
                        let id = out_pos.len() as u32;
                        out_pos.push(pos[v]);
                        out_uv.push(z);
                        copies[v].push((id, z));
                        id
                    }
                };
            }
            faces.push(f);
        }
        let mut s = crate::mesh::Surface::new(out_pos, faces)?;
        s.uvs = Some(out_uv);
        Ok(s)
    }
}
