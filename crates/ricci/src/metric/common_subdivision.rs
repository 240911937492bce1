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
//! the flip formula of Gillespie–Sharp–Crane; no roundabouts are needed because the input has
//! no multi-edges, so an input edge is identified by its two end vertices.)
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

use crate::error::{Error, Result};
use crate::mesh::{Mesh, NONE};
use crate::metric::intrinsic::IntrinsicTriangulation;
use crate::metric::Geometry;

type Tri = IntrinsicTriangulation;

/// `log(e^a + e^b)` without overflow.
#[inline]
fn log_add_exp(a: f64, b: f64) -> f64 {
    let m = a.max(b);
    m + ((a - m).exp() + (b - m).exp()).ln()
}

/// The input edges inside one triangle, from the crossing counts `x_j ≥ 0` of its three
/// sides (side `j` runs from corner `j` to corner `j+1`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct TriangleArcs {
    /// Arcs cutting off corner `m` (joining sides `m` and `m+2`), nearest the corner first.
    pub corner: [u32; 3],
    /// Arcs through side `j` that leave the opposite corner `j+2` (nonzero for one side at most).
    pub through: [u32; 3],
}

impl TriangleArcs {
    /// Decompose the crossing counts; `None` if they are not the counts of disjoint arcs
    /// (a parity or sign violation).
    pub fn new(x: [i64; 3]) -> Option<TriangleArcs> {
        let x = x.map(|v| v.max(0));
        let mut through = [0i64; 3];
        for j in 0..3 {
            through[j] = (x[j] - x[(j + 1) % 3] - x[(j + 2) % 3]).max(0);
        }
        let mut corner = [0u32; 3];
        for m in 0..3 {
            let twice = x[m] + x[(m + 2) % 3] - x[(m + 1) % 3] - through[m] - through[(m + 2) % 3]
                + through[(m + 1) % 3];
            if twice < 0 || twice % 2 != 0 {
                return None;
            }
            corner[m] = (twice / 2) as u32;
        }
        Some(TriangleArcs {
            corner,
            through: through.map(|t| t as u32),
        })
    }
}

/// Where the arc crossing side `j` at position `p` (counted from corner `j`) goes inside the
/// triangle.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum ArcEnd {
    /// Crosses side `.0` at position `.1` (counted from that side's first corner).
    Side(usize, u32),
    /// Ends at corner `.0`.
    Corner(usize),
}

#[inline]
fn arc_end(arcs: &TriangleArcs, x: [u32; 3], j: usize, p: u32) -> ArcEnd {
    let c = arcs.corner[j];
    if p < c {
        let k = (j + 2) % 3;
        ArcEnd::Side(k, x[k] - 1 - p)
    } else if p < c + arcs.through[j] {
        ArcEnd::Corner((j + 2) % 3)
    } else {
        ArcEnd::Side((j + 1) % 3, x[j] - 1 - p)
    }
}

/// Crossing counts of the three sides of face `f`, as signed normal coordinates.
#[inline]
fn face_counts(tri: &Tri, normal: &[i32], f: u32) -> [i64; 3] {
    let b = 3 * f as usize;
    [0, 1, 2].map(|j| normal[tri.edge[b + j] as usize] as i64)
}

/// Normal coordinate of the edge `kl` that replaces `ij = edge_he[e]` under a flip, from the
/// coordinates of the quadrilateral (see the module docs). `Err` names the edge when the
/// coordinates are inconsistent.
pub fn flipped_normal_coordinate(tri: &Tri, normal: &[i32], e: u32) -> Result<i32> {
    let h = tri.edge_he[e as usize];
    let t = tri.twin[h as usize];
    if t == NONE {
        return Err(Error::input(format!(
            "edge {e} is a boundary edge and cannot flip"
        )));
    }
    let bad = || {
        Error::numerical(format!(
            "normal coordinates around edge {e} are not those of disjoint input edges"
        ))
    };
    let arcs_a = TriangleArcs::new(face_counts(tri, normal, h / 3)).ok_or_else(bad)?;
    let arcs_b = TriangleArcs::new(face_counts(tri, normal, t / 3)).ok_or_else(bad)?;
    let (jh, jt) = ((h % 3) as usize, (t % 3) as usize);
    // Triangle A = (i, j, k) with h = i→j; triangle B = (j, i, l) with t = j→i.
    let ci_a = arcs_a.corner[jh] as i64;
    let ck_a = arcs_a.corner[(jh + 2) % 3] as i64;
    let through_h = arcs_a.through[jh] as i64; // leave k through ij
    let leave_i_a = arcs_a.through[(jh + 1) % 3] as i64; // i → jk
    let leave_j_a = arcs_a.through[(jh + 2) % 3] as i64; // j → ki
    let ci_b = arcs_b.corner[(jt + 1) % 3] as i64;
    let cl_b = arcs_b.corner[(jt + 2) % 3] as i64;
    let through_t = arcs_b.through[jt] as i64; // leave l through ij
    let leave_j_b = arcs_b.through[(jt + 1) % 3] as i64; // j → il
    let leave_i_b = arcs_b.through[(jt + 2) % 3] as i64; // i → lj
                                                         // Along ij from i: side A has [0, ci_a) i-side, [ci_a, ci_a + through_h) from k, rest j-side;
                                                         // side B has [0, ci_b) i-side, [ci_b, ci_b + through_t) from l, rest j-side.
    let lo = ci_a.max(ci_b);
    let hi = (ci_a + through_h).min(ci_b + through_t);
    let crossing = (ci_a - ci_b - through_t).max(0) + (ci_b - ci_a - through_h).max(0);
    let others = ck_a + leave_i_a + leave_j_a + cl_b + leave_i_b + leave_j_b + crossing;
    if hi > lo {
        // An input edge runs from k to l through ij: it becomes the new edge.
        if hi - lo != 1 || others != 0 || normal[e as usize] < 0 {
            return Err(bad());
        }
        return Ok(-1);
    }
    let n = others + i64::from(normal[e as usize] == -1);
    i32::try_from(n).map_err(|_| Error::numerical(format!("edge {e}: {n} crossings overflow")))
}

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
        let (mut tri, normal) = replay(mesh, geometry, lengths, &t.flip_log)?;
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
        let mut out = Vec::with_capacity(3 * self.triangles.len());
        for (t, &f) in self.t_face.iter().enumerate() {
            let verts = tri.face(f);
            let p = [0, 1, 2].map(|i| corner_uv[3 * f as usize + i]);
            for c in 0..3 {
                let w = self.t_weights[3 * t + c];
                // β_i = w_i e^{−u_i}, normalised in log space.
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
                let beta = logs.map(|l| if l.is_finite() { (l - m).exp() } else { 0.0 });
                out.push(interpolate(geometry, &p, &beta)?);
            }
        }
        Ok(out)
    }

    /// Number of triangles whose UV triangle has non-positive signed area (Klein model for H²).
    pub fn flipped_triangles(&self, geometry: Geometry, uv: &[[f64; 2]]) -> usize {
        (0..self.triangles.len())
            .filter(|&t| {
                let q = [0, 1, 2].map(|i| {
                    let z = uv.get(3 * t + i).copied().unwrap_or([f64::NAN; 2]);
                    if geometry == Geometry::Hyperbolic {
                        let s = 2.0 / (1.0 + z[0] * z[0] + z[1] * z[1]);
                        [s * z[0], s * z[1]]
                    } else {
                        z
                    }
                });
                let a = (q[1][0] - q[0][0]) * (q[2][1] - q[0][1])
                    - (q[1][1] - q[0][1]) * (q[2][0] - q[0][0]);
                a.is_nan() || a <= 0.0
            })
            .count()
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

/// Projective interpolation in one face of `T`: E² `Σ β_i P_i / Σ β_i`; H² the normalised
/// `Σ β_i q_i` of the hyperboloid points `q_i` of Poincaré-disk points `P_i`.
fn interpolate(geometry: Geometry, p: &[[f64; 2]; 3], beta: &[f64; 3]) -> Result<[f64; 2]> {
    let s: f64 = beta.iter().sum();
    match geometry {
        Geometry::Euclidean => Ok([
            (beta[0] * p[0][0] + beta[1] * p[1][0] + beta[2] * p[2][0]) / s,
            (beta[0] * p[0][1] + beta[1] * p[1][1] + beta[2] * p[2][1]) / s,
        ]),
        Geometry::Hyperbolic => {
            let mut x = [0.0f64; 3];
            for i in 0..3 {
                let r2 = p[i][0] * p[i][0] + p[i][1] * p[i][1];
                if !(r2 < 1.0) {
                    return Err(Error::input(format!(
                        "layout point ({}, {}) is not inside the Poincaré disk",
                        p[i][0], p[i][1]
                    )));
                }
                let d = 1.0 - r2;
                x[0] += beta[i] * (1.0 + r2) / d;
                x[1] += beta[i] * 2.0 * p[i][0] / d;
                x[2] += beta[i] * 2.0 * p[i][1] / d;
            }
            let k = [x[1] / x[0], x[2] / x[0]];
            let r = (1.0 - k[0] * k[0] - k[1] * k[1]).max(0.0).sqrt();
            Ok([k[0] / (1.0 + r), k[1] / (1.0 + r)])
        }
        Geometry::Spherical => Err(Error::input(
            "projective interpolation is implemented for E² and H² layouts (the sphere goes \
             through a puncture)",
        )),
    }
}

/// A step of a traced input edge: it crosses half-edge `h` of `T` into `face(h)`, at position
/// `p` along `h` (from its origin).
type Step = (u32, u32);

/// Follow an input edge that crosses `h` at position `p` into `face(h)` until it ends at a
/// corner; returns the further steps and the corner (`3f + i`) where it ends.
fn walk(
    tri: &Tri,
    normal: &[i32],
    arcs: &[TriangleArcs],
    mut h: u32,
    mut p: u32,
    budget: usize,
) -> Result<(Vec<Step>, u32)> {
    let mut steps = Vec::new();
    for _ in 0..=budget {
        let f = h / 3;
        let j = (h % 3) as usize;
        let x = face_counts(tri, normal, f).map(|v| v.max(0) as u32);
        match arc_end(&arcs[f as usize], x, j, p) {
            ArcEnd::Corner(m) => return Ok((steps, 3 * f + m as u32)),
            ArcEnd::Side(k, q) => {
                let out = 3 * f + k as u32;
                let tw = tri.twin[out as usize];
                if tw == NONE {
                    return Err(Error::numerical(format!(
                        "an input edge leaves face {f} through a boundary edge"
                    )));
                }
                let n = normal[tri.edge[out as usize] as usize] as u32;
                h = tw;
                p = n - 1 - q;
                steps.push((h, p));
            }
        }
    }
    Err(Error::numerical(
        "tracing an input edge through the intrinsic triangulation did not end (inconsistent \
         normal coordinates)",
    ))
}

/// Half λ of the edge of half-edge `h` (the log λ-length).
#[inline]
fn half_lambda(tri: &Tri, h: u32) -> f64 {
    0.5 * tri.lambda[tri.edge[h as usize] as usize]
}

/// Replay `flip_log` on the input triangulation with normal coordinates.
fn replay(
    mesh: &Mesh,
    geometry: Geometry,
    lengths: &[f64],
    flip_log: &[u32],
) -> Result<(Tri, Vec<i32>)> {
    let mut tri = IntrinsicTriangulation::from_mesh(mesh, geometry, lengths)?;
    let mut normal = vec![-1i32; tri.n_edges()];
    for (step, &e) in flip_log.iter().enumerate() {
        if e as usize >= tri.n_edges() {
            return Err(Error::input(format!(
                "flip log entry {step} names edge {e}, but the mesh has {} edges",
                tri.n_edges()
            )));
        }
        if !tri.is_flippable(e) {
            return Err(Error::input(format!(
                "flip log entry {step}: edge {e} cannot be flipped (boundary, or one face on \
                 both sides)"
            )));
        }
        let n = flipped_normal_coordinate(&tri, &normal, e)?;
        tri.flip(e);
        normal[e as usize] = n;
    }
    tri.flip_log.clear();
    Ok((tri, normal))
}

fn build(mesh: &Mesh, tri: Tri, normal: Vec<i32>, flips: usize) -> Result<CommonSubdivision> {
    let nv = mesh.n_vertices();
    let ne = tri.n_edges();
    let nf = tri.n_faces();
    let mut arcs = Vec::with_capacity(nf);
    for f in 0..nf as u32 {
        arcs.push(
            TriangleArcs::new(face_counts(&tri, &normal, f)).ok_or_else(|| {
                Error::numerical(format!(
                "normal coordinates of face {f} of the intrinsic triangulation are inconsistent"
            ))
            })?,
        );
    }
    let mut offset = Vec::with_capacity(ne + 1);
    let mut total = 0u32;
    for e in 0..ne {
        offset.push(total);
        total += normal[e].max(0) as u32;
    }
    offset.push(total);
    let n_cross = total as usize;
    let mut crossings: Vec<Option<Crossing>> = vec![None; n_cross];
    let mut order_violations = 0usize;
    let mut input_seen = vec![false; mesh.n_edges()];
    let mut shared_edges = 0usize;
    for e in 0..ne as u32 {
        if normal[e as usize] == -1 {
            shared_edges += 1;
            let [a, b] = tri.edge_vertices(e);
            let h0 = mesh.halfedge_between(a, b).ok_or_else(|| {
                Error::numerical(format!(
                    "edge {e} of the intrinsic triangulation is marked as an input edge, but \
                     vertices {a} and {b} are not adjacent in the input"
                ))
            })?;
            input_seen[mesh.he_edge(h0) as usize] = true;
        }
    }
    // Trace every input edge that crosses T, starting from its first unvisited crossing.
    for e in 0..ne as u32 {
        let n = normal[e as usize];
        for pc in 0..n.max(0) as u32 {
            let id = (offset[e as usize] + pc) as usize;
            if crossings[id].is_some() {
                continue;
            }
            let g = tri.edge_he[e as usize];
            let tg = tri.twin[g as usize];
            let (fwd, end) = walk(&tri, &normal, &arcs, g, pc, n_cross)?;
            let (bwd, start) = walk(&tri, &normal, &arcs, tg, n as u32 - 1 - pc, n_cross)?;
            let mut path: Vec<Step> = bwd
                .iter()
                .rev()
                .map(|&(h, p)| {
                    let n = normal[tri.edge[h as usize] as usize] as u32;
                    (tri.twin[h as usize], n - 1 - p)
                })
                .collect();
            path.push((g, pc));
            path.extend_from_slice(&fwd);
            let a = tri.origin[start as usize];
            let b = tri.origin[end as usize];
            let h0 = mesh.halfedge_between(a, b).ok_or_else(|| {
                Error::numerical(format!(
                    "an input edge traced through the intrinsic triangulation joins vertices {a} \
                     and {b}, which are not adjacent in the input"
                ))
            })?;
            let e0 = mesh.he_edge(h0);
            if input_seen[e0 as usize] {
                return Err(Error::numerical(format!(
                    "input edge {e0} ({a}, {b}) was found twice in the intrinsic triangulation"
                )));
            }
            input_seen[e0 as usize] = true;
            let forward = mesh.edge_vertices(e0)[0] == a;
            // λ-lengths from a (forward) and from b (backward) to the ends of each crossed edge.
            let m = path.len();
            let mut la = vec![[0.0f64; 2]; m]; // [to origin(h_k), to tip(h_k)]
            let mut lb = vec![[0.0f64; 2]; m];
            {
                let x = tri.twin[path[0].0 as usize];
                la[0] = [
                    half_lambda(&tri, Tri::next(x)),
                    half_lambda(&tri, Tri::prev(x)),
                ];
                for k in 0..m - 1 {
                    let h = path[k].0;
                    let w = log_add_exp(
                        la[k][0] + half_lambda(&tri, Tri::next(h)),
                        la[k][1] + half_lambda(&tri, Tri::prev(h)),
                    ) - half_lambda(&tri, h);
                    let hn = path[k + 1].0;
                    la[k + 1] = if tri.twin[Tri::next(h) as usize] == hn {
                        [w, la[k][1]] // h_{k+1} = w → tip(h_k)
                    } else {
                        [la[k][0], w] // h_{k+1} = origin(h_k) → w
                    };
                }
                let hm = path[m - 1].0;
                lb[m - 1] = [
                    half_lambda(&tri, Tri::prev(hm)),
                    half_lambda(&tri, Tri::next(hm)),
                ];
                for k in (0..m - 1).rev() {
                    let hn = path[k + 1].0;
                    let g = tri.twin[hn as usize]; // in face(h_k), from tip(hn) to origin(hn)
                    let w = log_add_exp(
                        lb[k + 1][0] + half_lambda(&tri, Tri::prev(g)),
                        lb[k + 1][1] + half_lambda(&tri, Tri::next(g)),
                    ) - half_lambda(&tri, g);
                    let h = path[k].0;
                    lb[k] = if tri.twin[Tri::next(h) as usize] == hn {
                        [w, lb[k + 1][1]]
                    } else {
                        [lb[k + 1][0], w]
                    };
                }
            }
            let mut last_t = f64::NEG_INFINITY;
            for k in 0..m {
                let (h, p) = path[k];
                let et = tri.edge[h as usize];
                let canonical = tri.edge_he[et as usize] == h;
                let pcan = if canonical {
                    p
                } else {
                    normal[et as usize] as u32 - 1 - p
                };
                // β_o/β_τ = Λ_aτ Λ_bτ / (Λ_ao Λ_bo); β_a/β_b = Λ_bo Λ_bτ / (Λ_ao Λ_aτ).
                let rho_t = la[k][1] + lb[k][1] - la[k][0] - lb[k][0];
                let rho_in = lb[k][0] + lb[k][1] - la[k][0] - la[k][1];
                let (rank, rho_in) = if forward {
                    (k as u32 + 1, rho_in)
                } else {
                    ((m - k) as u32, -rho_in)
                };
                let input_t = 1.0 / (1.0 + rho_in.exp());
                // Order along the traced direction, in log space (no saturation near ends).
                let t_dir = if forward { -rho_in } else { rho_in };
                if !(t_dir > last_t) {
                    order_violations += 1;
                }
                last_t = t_dir;
                let id = (offset[et as usize] + pcan) as usize;
                if crossings[id].is_some() {
                    return Err(Error::numerical(format!(
                        "crossing {pcan} of edge {et} was traced twice"
                    )));
                }
                crossings[id] = Some(Crossing {
                    input_edge: e0,
                    input_rank: rank,
                    input_t,
                    t_edge: et,
                    t_index: pcan,
                    t_log_ratio: if canonical { rho_t } else { -rho_t },
                });
            }
        }
    }
    if let Some(e0) = input_seen.iter().position(|&s| !s) {
        let [a, b] = mesh.edge_vertices(e0 as u32);
        return Err(Error::numerical(format!(
            "input edge {e0} ({a}, {b}) was not found in the intrinsic triangulation"
        )));
    }
    let crossings: Vec<Crossing> = crossings
        .into_iter()
        .map(|c| c.expect("all traced"))
        .collect();
    for e in 0..ne {
        let cs = &crossings[offset[e] as usize..offset[e + 1] as usize];
        for w in cs.windows(2) {
            if !(w[1].t_log_ratio < w[0].t_log_ratio) {
                order_violations += 1;
            }
        }
    }
    let mut sub = CommonSubdivision {
        triangulation: tri,
        normal,
        crossing_offset: offset,
        crossings,
        n_input_vertices: nv,
        triangles: Vec::new(),
        input_face: Vec::new(),
        t_face: Vec::new(),
        input_barycentric: Vec::new(),
        t_weights: Vec::new(),
        report: SubdivisionReport {
            flips,
            crossings: n_cross,
            shared_edges,
            order_violations,
            polygons: 0,
        },
    };
    for f in 0..nf as u32 {
        face_polygons(mesh, &mut sub, &arcs[f as usize], f)?;
    }
    Ok(sub)
}

/// A point on the boundary of a face of `T`: its subdivision vertex and its weights on the
/// face's corners (input decoration).
#[derive(Clone, Copy)]
struct BoundaryPoint {
    vertex: u32,
    weights: [f64; 3],
    /// Crossing id, or `NONE` for a corner.
    crossing: u32,
}

/// Cut face `f` of `T` along its arcs into convex polygons, fan-triangulate them.
fn face_polygons(
    mesh: &Mesh,
    sub: &mut CommonSubdivision,
    arcs: &TriangleArcs,
    f: u32,
) -> Result<()> {
    let tri = &sub.triangulation;
    let normal = &sub.normal;
    let nv = sub.n_input_vertices as u32;
    let counts = face_counts(tri, normal, f);
    let x = counts.map(|v| v.max(0) as u32);
    let base = [0, 1 + x[0], 2 + x[0] + x[1]];
    let np = (3 + x[0] + x[1] + x[2]) as usize;
    let mut pts = Vec::with_capacity(np);
    for j in 0..3usize {
        let mut w = [0.0; 3];
        w[j] = 1.0;
        pts.push(BoundaryPoint {
            vertex: tri.origin[3 * f as usize + j],
            weights: w,
            crossing: NONE,
        });
        let h = 3 * f + j as u32;
        let e = tri.edge[h as usize];
        let canonical = tri.edge_he[e as usize] == h;
        for p in 0..x[j] {
            let pc = if canonical { p } else { x[j] - 1 - p };
            let id = sub.crossing_offset[e as usize] + pc;
            let c = &sub.crossings[id as usize];
            // ρ = log(β_origin(h) / β_tip(h)).
            let rho = if canonical {
                c.t_log_ratio
            } else {
                -c.t_log_ratio
            };
            let mut w = [0.0; 3];
            w[j] = 1.0 / (1.0 + (-rho).exp());
            w[(j + 1) % 3] = 1.0 / (1.0 + rho.exp());
            pts.push(BoundaryPoint {
                vertex: nv + id,
                weights: w,
                crossing: id,
            });
        }
    }
    // Neighbours of every boundary point: its two boundary neighbours and its chords.
    let mut nbr: Vec<Vec<usize>> = (0..np)
        .map(|i| vec![(i + 1) % np, (i + np - 1) % np])
        .collect();
    for j in 0..3usize {
        for p in 0..x[j] {
            let me = (base[j] + 1 + p) as usize;
            let other = match arc_end(arcs, x, j, p) {
                ArcEnd::Corner(m) => base[m] as usize,
                ArcEnd::Side(k, q) => (base[k] + 1 + q) as usize,
            };
            if !nbr[me].contains(&other) {
                nbr[me].push(other);
                nbr[other].push(me);
            }
        }
    }
    for (i, list) in nbr.iter_mut().enumerate() {
        list.sort_by_key(|&n| (n + np - i) % np);
        list.dedup();
    }
    let mut seen = vec![false; np]; // boundary segment i → i+1 used
    for s in 0..np {
        if seen[s] {
            continue;
        }
        let mut poly = vec![s];
        let (mut prev, mut cur) = (s, (s + 1) % np);
        seen[s] = true;
        let mut closed = false;
        for _ in 0..=np {
            if cur == s {
                closed = true;
                break;
            }
            poly.push(cur);
            let back = (prev + np - cur) % np;
            let next = *nbr[cur]
                .iter()
                .rev()
                .find(|&&n| (n + np - cur) % np < back)
                .ok_or_else(|| {
                    Error::numerical(format!(
                        "face {f} of T: a polygon of the overlay does not close"
                    ))
                })?;
            if next == (cur + 1) % np {
                seen[cur] = true;
            }
            prev = cur;
            cur = next;
        }
        if !closed || poly.len() < 3 {
            return Err(Error::numerical(format!(
                "face {f} of T: a polygon of the overlay does not close"
            )));
        }
        // The input face: left of every side that lies on an input edge.
        let mut f0 = NONE;
        for i in 0..poly.len() {
            let (a, b) = (poly[i], poly[(i + 1) % poly.len()]);
            let face = side_input_face(mesh, sub, &pts, f, base, np, a, b)?;
            if let Some(face) = face {
                if f0 == NONE {
                    f0 = face;
                } else if f0 != face {
                    return Err(Error::numerical(format!(
                        "face {f} of T: a polygon of the overlay lies in input faces {f0} and {face}"
                    )));
                }
            }
        }
        if f0 == NONE {
            return Err(Error::numerical(format!(
                "face {f} of T: a polygon of the overlay has no side on an input edge"
            )));
        }
        let fv = mesh.face(f0);
        let mut bary = Vec::with_capacity(poly.len());
        for &i in &poly {
            bary.push(input_barycentric(mesh, sub, &fv, &pts[i]).ok_or_else(|| {
                Error::numerical(format!(
                    "face {f} of T: a vertex of the overlay is not on input face {f0}"
                ))
            })?);
        }
        sub.report.polygons += 1;
        for k in 1..poly.len() - 1 {
            let corners = [0, k, k + 1];
            sub.triangles.push(corners.map(|c| pts[poly[c]].vertex));
            sub.input_face.push(f0);
            sub.t_face.push(f);
            for c in corners {
                sub.input_barycentric.push(bary[c]);
                sub.t_weights.push(pts[poly[c]].weights);
            }
        }
    }
    Ok(())
}

/// The input face left of the polygon side from boundary point `a` to `b` of face `f` of `T`,
/// when that side lies on an input edge.
#[allow(clippy::too_many_arguments)]
fn side_input_face(
    mesh: &Mesh,
    sub: &CommonSubdivision,
    pts: &[BoundaryPoint],
    f: u32,
    base: [u32; 3],
    np: usize,
    a: usize,
    b: usize,
) -> Result<Option<u32>> {
    let tri = &sub.triangulation;
    let (pa, pb) = (&pts[a], &pts[b]);
    let left_of = |h0: u32| -> Result<Option<u32>> {
        let face = mesh.he_face(h0);
        if face == NONE {
            return Err(Error::numerical(format!(
                "face {f} of T: an overlay polygon lies outside the input surface"
            )));
        }
        Ok(Some(face))
    };
    if b == (a + 1) % np {
        // A boundary segment: on an input edge only if it is a whole side of T that is one.
        if pa.crossing != NONE || pb.crossing != NONE {
            return Ok(None);
        }
        let j = match base.iter().position(|&x| x as usize == a) {
            Some(j) => j,
            None => return Ok(None),
        };
        let h = 3 * f + j as u32;
        if sub.normal[tri.edge[h as usize] as usize] != -1 {
            return Ok(None);
        }
        let h0 = mesh.halfedge_between(pa.vertex, pb.vertex).ok_or_else(|| {
            Error::numerical(format!(
                "face {f} of T: side {j} is marked as an input edge, but its ends are not \
                 adjacent in the input"
            ))
        })?;
        return left_of(h0);
    }
    // A chord: a piece of one input edge.
    let c = if pa.crossing != NONE {
        pa.crossing
    } else {
        pb.crossing
    };
    if c == NONE {
        return Err(Error::numerical(format!(
            "face {f} of T: an overlay chord joins two corners"
        )));
    }
    let e0 = sub.crossings[c as usize].input_edge;
    let [v0, _] = mesh.edge_vertices(e0);
    let rank = |p: &BoundaryPoint| -> Result<u64> {
        if p.crossing != NONE {
            let cr = &sub.crossings[p.crossing as usize];
            if cr.input_edge != e0 {
                return Err(Error::numerical(format!(
                    "face {f} of T: an overlay chord joins two different input edges"
                )));
            }
            Ok(cr.input_rank as u64)
        } else if p.vertex == v0 {
            Ok(0)
        } else {
            Ok(u64::MAX)
        }
    };
    let (ra, rb) = (rank(pa)?, rank(pb)?);
    let h0 = mesh.edge_halfedge(e0);
    if ra < rb {
        left_of(h0)
    } else {
        left_of(mesh.he_twin(h0))
    }
}

/// Barycentric coordinates of a boundary point on input face `fv`.
fn input_barycentric(
    mesh: &Mesh,
    sub: &CommonSubdivision,
    fv: &[u32; 3],
    p: &BoundaryPoint,
) -> Option<[f64; 3]> {
    let mut b = [0.0; 3];
    if p.crossing == NONE {
        let i = fv.iter().position(|&v| v == p.vertex)?;
        b[i] = 1.0;
        return Some(b);
    }
    let c = &sub.crossings[p.crossing as usize];
    let [v0, v1] = mesh.edge_vertices(c.input_edge);
    let i0 = fv.iter().position(|&v| v == v0)?;
    let i1 = fv.iter().position(|&v| v == v1)?;
    b[i0] = 1.0 - c.input_t;
    b[i1] = c.input_t;
    Some(b)
}

/// Breadth-first layout of `T` in the plane from its lengths at vertex scaling `u` (E²), one
/// position per corner (`3f + i`). Faces are placed across the edges of a spanning tree of the
/// dual graph, so the layout is continuous across those edges (across all edges for a flat
/// disk). `Err` if a triangle inequality fails.
pub fn layout_euclidean(tri: &Tri, u: &[f64]) -> Result<Vec<[f64; 2]>> {
    let nf = tri.n_faces();
    let len = |h: u32| (0.5 * tri.scaled_lambda(tri.edge[h as usize], u)).exp();
    let mut uv = vec![[f64::NAN; 2]; 3 * nf];
    let mut placed = vec![false; nf];
    let mut queue = std::collections::VecDeque::new();
    for root in 0..nf as u32 {
        if placed[root as usize] {
            continue;
        }
        let h = 3 * root;
        uv[h as usize] = [0.0, 0.0];
        uv[Tri::next(h) as usize] = [len(h), 0.0];
        place_third(&mut uv, h, len(Tri::next(h)), len(Tri::prev(h)))?;
        placed[root as usize] = true;
        queue.push_back(root);
        while let Some(f) = queue.pop_front() {
            for j in 0..3u32 {
                let h = 3 * f + j;
                let t = tri.twin[h as usize];
                if t == NONE || placed[(t / 3) as usize] {
                    continue;
                }
                // t runs tip(h) → origin(h).
                uv[t as usize] = uv[Tri::next(h) as usize];
                uv[Tri::next(t) as usize] = uv[h as usize];
                place_third(&mut uv, t, len(Tri::next(t)), len(Tri::prev(t)))?;
                placed[(t / 3) as usize] = true;
                queue.push_back(t / 3);
            }
        }
    }
    Ok(uv)
}

/// Place the corner opposite `h` to the left of origin(h) → tip(h): `a` = |tip − third|,
/// `b` = |third − origin|.
fn place_third(uv: &mut [[f64; 2]], h: u32, a: f64, b: f64) -> Result<()> {
    let p = uv[h as usize];
    let q = uv[Tri::next(h) as usize];
    let (dx, dy) = (q[0] - p[0], q[1] - p[1]);
    let c = dx.hypot(dy);
    let along = (b * b + c * c - a * a) / (2.0 * c);
    let h2 = b * b - along * along;
    if !(h2 > 0.0) {
        return Err(Error::numerical(format!(
            "face {} violates the triangle inequality (sides {a}, {b}, {c})",
            h / 3
        )));
    }
    let hgt = h2.sqrt();
    let (ux, uy) = (dx / c, dy / c);
    uv[Tri::prev(h) as usize] = [p[0] + along * ux - hgt * uy, p[1] + along * uy + hgt * ux];
    Ok(())
}

type Cx = (f64, f64);
#[inline]
fn cmul(a: Cx, b: Cx) -> Cx {
    (a.0 * b.0 - a.1 * b.1, a.0 * b.1 + a.1 * b.0)
}
#[inline]
fn cdiv(a: Cx, b: Cx) -> Cx {
    let d = b.0 * b.0 + b.1 * b.1;
    ((a.0 * b.0 + a.1 * b.1) / d, (a.1 * b.0 - a.0 * b.1) / d)
}

/// Breadth-first layout of `T` in the Poincaré disk from its hyperbolic lengths at vertex
/// scaling `u` (H², `sinh(l/2) = e^{λ̃/2}`), one position per corner, like
/// [`layout_euclidean`]. Each new corner is placed in the frame where the shared edge starts
/// at the origin (a Möbius map of the disk), by the hyperbolic law of cosines.
pub fn layout_hyperbolic(tri: &Tri, u: &[f64]) -> Result<Vec<[f64; 2]>> {
    let nf = tri.n_faces();
    let len = |h: u32| {
        2.0 * (0.5 * tri.scaled_lambda(tri.edge[h as usize], u))
            .exp()
            .asinh()
    };
    let mut uv = vec![[f64::NAN; 2]; 3 * nf];
    let mut placed = vec![false; nf];
    let mut queue = std::collections::VecDeque::new();
    for root in 0..nf as u32 {
        if placed[root as usize] {
            continue;
        }
        let h = 3 * root;
        uv[h as usize] = [0.0, 0.0];
        uv[Tri::next(h) as usize] = [(0.5 * len(h)).tanh(), 0.0];
        place_third_hyperbolic(&mut uv, h, len(h), len(Tri::next(h)), len(Tri::prev(h)))?;
        placed[root as usize] = true;
        queue.push_back(root);
        while let Some(f) = queue.pop_front() {
            for j in 0..3u32 {
                let h = 3 * f + j;
                let t = tri.twin[h as usize];
                if t == NONE || placed[(t / 3) as usize] {
                    continue;
                }
                uv[t as usize] = uv[Tri::next(h) as usize];
                uv[Tri::next(t) as usize] = uv[h as usize];
                place_third_hyperbolic(&mut uv, t, len(t), len(Tri::next(t)), len(Tri::prev(t)))?;
                placed[(t / 3) as usize] = true;
                queue.push_back(t / 3);
            }
        }
    }
    Ok(uv)
}

/// Place the corner opposite `h` (side lengths: `c` of `h`, `a` = tip → third, `b` = third →
/// origin) to the left of origin(h) → tip(h) in the Poincaré disk.
fn place_third_hyperbolic(uv: &mut [[f64; 2]], h: u32, c: f64, a: f64, b: f64) -> Result<()> {
    let p = uv[h as usize];
    let q = uv[Tri::next(h) as usize];
    let pc: Cx = (p[0], p[1]);
    let pbar: Cx = (p[0], -p[1]);
    // T(z) = (z − p)/(1 − p̄ z) takes p to 0.
    let tq = cdiv(
        (q[0] - pc.0, q[1] - pc.1),
        (
            1.0 - cmul(pbar, (q[0], q[1])).0,
            -cmul(pbar, (q[0], q[1])).1,
        ),
    );
    let theta = tq.1.atan2(tq.0);
    let cos_alpha = (b.cosh() * c.cosh() - a.cosh()) / (b.sinh() * c.sinh());
    if !(cos_alpha.abs() < 1.0) {
        return Err(Error::numerical(format!(
            "face {} violates the hyperbolic triangle inequality (sides {a}, {b}, {c})",
            h / 3
        )));
    }
    let alpha = cos_alpha.acos();
    let r = (0.5 * b).tanh();
    let w: Cx = (r * (theta + alpha).cos(), r * (theta + alpha).sin());
    // T⁻¹(w) = (w + p)/(1 + p̄ w).
    let num = (w.0 + pc.0, w.1 + pc.1);
    let pw = cmul(pbar, w);
    let z = cdiv(num, (1.0 + pw.0, pw.1));
    uv[Tri::prev(h) as usize] = [z.0, z.1];
    Ok(())
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
