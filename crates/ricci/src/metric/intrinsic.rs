//! Intrinsic triangulations with log Penner coordinates: Ptolemy flips, the Penner Delaunay
//! criterion and metric-preserving splits down to a simplicial mesh (Springborn 2020,
//! "Ideal hyperbolic polyhedra and discrete uniformization" §§3–5; Gillespie–Springborn–Crane
//! 2021 "Discrete conformal equivalence of polyhedral surfaces" (CEPS) §§3–4; Gu–Luo–Sun–Wu 2018
//! (E²), Gu–Guo–Luo–Sun–Wu 2018 (H²); docs/DESIGN.md §3 "Our default").
//!
//! **Connectivity.** A Δ-complex: half-edge `h` lies in face `h / 3`, `next(h) = 3(h/3) +
//! (h%3 + 1)%3`; `origin[h]`, `twin[h]` (`NONE` on the boundary — there are no boundary
//! half-edges) and `edge[h]` are stored. Self-loops (`origin[h] == origin[next(h)]`) and several
//! edges between two vertices are allowed. Built from a [`Mesh`] with the same vertex, face and
//! edge ids. **Edge ids are stable under flips** (a flip changes an edge's endpoints, not its
//! id); half-edge ids are not (a flip rewrites the six half-edges of its two faces).
//!
//! **Metric.** Per edge a *log Penner coordinate* `λ_e` of the base metric: E² `λ = 2 log l`,
//! H² `λ = 2 log sinh(l/2)`. Vertex scaling by `u` is additive, `λ̃_ij = λ_ij + u_i + u_j`
//! (a self-loop at `i` gets `2u_i`). The Ptolemy flip of edge `e` in the quad `i, l, j, k`
//! (`e = ij`, new edge `kl`) is `e^{λ_f/2} e^{λ_e/2} = e^{(λ_il + λ_jk)/2} + e^{(λ_lj + λ_ki)/2}`;
//! it commutes with vertex scaling (both sides scale by `e^{(u_i+u_j+u_k+u_l)/2}`), so flips
//! act on the stored base coordinates and are valid for every `u`. The Penner Delaunay
//! criterion of `e` between triangles `(a, b, e)` and `(c, d, e)`, with `a = e^{λ̃_a/2}` etc.,
//! is `(a² + b² − e²)/(ab) + (c² + d² − e²)/(cd) ≥ 0`, i.e. `cos α + cos α' ≥ 0` for the
//! angles α, α' opposite `e` (E²) — no angles needed and valid for any positive coordinates.
//! In H² the same expression on `x = sinh(l/2)` is the hyperbolic Delaunay criterion (the test
//! `hyperbolic_penner_criterion_is_delaunay` checks it against the angle criterion
//! `α + α' ≤ β + γ + β' + γ'` of the empty circumcircle, and checks Ptolemy for `sinh(l/2)` on
//! points of a hyperbolic circle): `sinh(l/2)` is half the Minkowski chord `|p − q|` of points
//! on the hyperboloid, and points of a hyperbolic circle are concyclic in a spacelike plane.
//!
//! **Flip log.** Every flip appends its edge id to [`IntrinsicTriangulation::flip_log`], in
//! order: replaying the flips on the input triangulation (e.g. with normal coordinates)
//! reproduces the current connectivity.

use crate::error::{Error, Result};
use crate::mesh::{Mesh, NONE};
use crate::metric::Geometry;
use std::collections::{HashMap, VecDeque};

/// Threshold of the Penner Delaunay criterion: an edge is flipped only when
/// `cos α + cos α' < −DELAUNAY_EPS` (so cocircular quads do not cycle under rounding).
pub const DELAUNAY_EPS: f64 = 1e-12;

/// A Δ-complex triangulation with log Penner edge coordinates (see the module docs).
#[derive(Debug, Clone)]
pub struct IntrinsicTriangulation {
    pub n_vertices: usize,
    /// Origin vertex of every half-edge (`3F` of them).
    pub origin: Vec<u32>,
    /// Twin half-edge, `NONE` on the boundary.
    pub twin: Vec<u32>,
    /// Edge id of every half-edge.
    pub edge: Vec<u32>,
    /// One half-edge of every edge.
    pub edge_he: Vec<u32>,
    /// Log Penner coordinate `λ_e` of the base metric (`u = 0`), per edge id.
    pub lambda: Vec<f64>,
    /// Whether a vertex lies on the boundary (boundary edges never flip).
    pub boundary_vertex: Vec<bool>,
    /// Edge ids in the order they were flipped.
    pub flip_log: Vec<u32>,
}

/// The result of [`IntrinsicTriangulation::make_delaunay`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct DelaunayReport {
    /// Flips performed by this call.
    pub flips: usize,
    /// False when the flip budget ran out before every edge was Delaunay.
    pub delaunay: bool,
}

/// A simplicial mesh obtained from an intrinsic triangulation (see
/// [`IntrinsicTriangulation::to_simplicial`]).
#[derive(Debug, Clone)]
pub struct SimplicialMesh {
    pub mesh: Mesh,
    /// Edge lengths in the background geometry, by edge id of `mesh`.
    pub lengths: Vec<f64>,
    /// `vertex_origin[v] = v` for the input vertices (ids `< n_vertices` of the intrinsic
    /// triangulation), `NONE` for vertices inserted by splits (appended after them).
    pub vertex_origin: Vec<u32>,
    /// Number of edge splits that were needed.
    pub splits: usize,
}

/// Length of an edge from its (scaled) log Penner coordinate.
#[inline]
pub fn length_of_lambda(geometry: Geometry, lambda: f64) -> f64 {
    match geometry {
        Geometry::Euclidean => (0.5 * lambda).exp(),
        Geometry::Hyperbolic => 2.0 * (0.5 * lambda).exp().asinh(),
        Geometry::Spherical => 2.0 * (0.5 * lambda).exp().min(1.0).asin(),
    }
}

/// Log Penner coordinate of an edge length.
#[inline]
pub fn lambda_of_length(geometry: Geometry, l: f64) -> f64 {
    match geometry {
        Geometry::Euclidean => 2.0 * l.ln(),
        Geometry::Hyperbolic => 2.0 * (0.5 * l).sinh().ln(),
        Geometry::Spherical => 2.0 * (0.5 * l).sin().ln(),
    }
}

/// `log(e^a + e^b)` without overflow.
#[inline]
fn log_add_exp(a: f64, b: f64) -> f64 {
    let m = a.max(b);
    m + ((a - m).exp() + (b - m).exp()).ln()
}

/// `(a² + b² − e²)/(ab)` from log Penner coordinates (`a = e^{λa/2}`): twice the cosine of the
/// angle opposite `e` in the Euclidean triangle with sides a, b, e.
#[inline]
pub fn penner_cosine_term(la: f64, lb: f64, le: f64) -> f64 {
    let d = 0.5 * (la - lb);
    d.exp() + (-d).exp() - (le - 0.5 * (la + lb)).exp()
}

impl IntrinsicTriangulation {
    /// The triangulation of `mesh` with per-edge `lengths` (background geometry, by edge id).
    pub fn from_mesh(mesh: &Mesh, geometry: Geometry, lengths: &[f64]) -> Result<Self> {
        if lengths.len() != mesh.n_edges() {
            return Err(Error::input(format!(
                "{} edge lengths given for a mesh with {} edges",
                lengths.len(),
                mesh.n_edges()
            )));
        }
        let nh = mesh.n_corners();
        let mut origin = Vec::with_capacity(nh);
        let mut twin = Vec::with_capacity(nh);
        let mut edge = Vec::with_capacity(nh);
        for h in 0..nh as u32 {
            origin.push(mesh.he_origin(h));
            let t = mesh.he_twin(h);
            twin.push(if mesh.is_boundary_halfedge(t) {
                NONE
            } else {
                t
            });
            edge.push(mesh.he_edge(h));
        }
        let mut lambda = Vec::with_capacity(mesh.n_edges());
        for (e, &l) in lengths.iter().enumerate() {
            let x = lambda_of_length(geometry, l);
            if l.is_nan() || l <= 0.0 || !x.is_finite() {
                return Err(Error::input(format!(
                    "edge {e} has length {l}, which has no log Penner coordinate in {}",
                    geometry.name()
                )));
            }
            lambda.push(x);
        }
        let edge_he = (0..mesh.n_edges() as u32)
            .map(|e| mesh.edge_halfedge(e))
            .collect();
        Ok(IntrinsicTriangulation {
            n_vertices: mesh.n_vertices(),
            origin,
            twin,
            edge,
            edge_he,
            lambda,
            boundary_vertex: (0..mesh.n_vertices() as u32)
                .map(|v| mesh.is_boundary_vertex(v))
                .collect(),
            flip_log: Vec::new(),
        })
    }

    pub fn n_faces(&self) -> usize {
        self.origin.len() / 3
    }
    pub fn n_edges(&self) -> usize {
        self.edge_he.len()
    }
    pub fn n_halfedges(&self) -> usize {
        self.origin.len()
    }
    #[inline]
    pub fn next(h: u32) -> u32 {
        3 * (h / 3) + (h % 3 + 1) % 3
    }
    #[inline]
    pub fn prev(h: u32) -> u32 {
        3 * (h / 3) + (h % 3 + 2) % 3
    }
    /// Tip vertex of half-edge `h`.
    #[inline]
    pub fn tip(&self, h: u32) -> u32 {
        self.origin[Self::next(h) as usize]
    }
    /// The two end vertices of edge `e` (equal for a self-loop).
    pub fn edge_vertices(&self, e: u32) -> [u32; 2] {
        let h = self.edge_he[e as usize];
        [self.origin[h as usize], self.tip(h)]
    }
    pub fn is_boundary_edge(&self, e: u32) -> bool {
        self.twin[self.edge_he[e as usize] as usize] == NONE
    }
    /// Vertices of face `f` in order (corner `3f + i` at `face(f)[i]`).
    pub fn face(&self, f: u32) -> [u32; 3] {
        let b = 3 * f as usize;
        [self.origin[b], self.origin[b + 1], self.origin[b + 2]]
    }
    /// Scaled coordinate `λ̃_e = λ_e + u_i + u_j` (an empty `u` means `u = 0`).
    #[inline]
    pub fn scaled_lambda(&self, e: u32, u: &[f64]) -> f64 {
        let l = self.lambda[e as usize];
        if u.is_empty() {
            return l;
        }
        let [a, b] = self.edge_vertices(e);
        l + u[a as usize] + u[b as usize]
    }
    /// Scaled coordinate of the edge of half-edge `h`.
    #[inline]
    fn he_lambda(&self, h: u32, u: &[f64]) -> f64 {
        let l = self.lambda[self.edge[h as usize] as usize];
        if u.is_empty() {
            return l;
        }
        l + u[self.origin[h as usize] as usize] + u[self.tip(h) as usize]
    }
    /// Edge lengths of the metric scaled by `u`, by edge id, in `geometry`.
    pub fn lengths(&self, geometry: Geometry, u: &[f64]) -> Vec<f64> {
        (0..self.n_edges() as u32)
            .map(|e| length_of_lambda(geometry, self.scaled_lambda(e, u)))
            .collect()
    }

    /// The Penner Delaunay quantity of edge `e` at `u`: `cos α + cos α'` for the Euclidean
    /// triangles with sides `e^{λ̃/2}` (see the module docs); `+∞` for boundary edges.
    pub fn delaunay_value(&self, e: u32, u: &[f64]) -> f64 {
        let h = self.edge_he[e as usize];
        let t = self.twin[h as usize];
        if t == NONE {
            return f64::INFINITY;
        }
        let le = self.he_lambda(h, u);
        let (h1, h2) = (Self::next(h), Self::prev(h));
        let (t1, t2) = (Self::next(t), Self::prev(t));
        0.5 * (penner_cosine_term(self.he_lambda(h1, u), self.he_lambda(h2, u), le)
            + penner_cosine_term(self.he_lambda(t1, u), self.he_lambda(t2, u), le))
    }

    /// Whether edge `e` satisfies the Penner Delaunay criterion at `u` (boundary edges do).
    pub fn is_delaunay(&self, e: u32, u: &[f64]) -> bool {
        self.delaunay_value(e, u) >= -DELAUNAY_EPS
    }

    /// Whether edge `e` can be flipped: interior and its two sides in different faces.
    pub fn is_flippable(&self, e: u32) -> bool {
        let h = self.edge_he[e as usize];
        let t = self.twin[h as usize];
        t != NONE && t / 3 != h / 3
    }

    /// Ptolemy flip of edge `e` (see the module docs); returns false (and changes nothing) for
    /// boundary edges and edges with the same face on both sides. Appends `e` to `flip_log`.
    pub fn flip(&mut self, e: u32) -> bool {
        if !self.is_flippable(e) {
            return false;
        }
        let h = self.edge_he[e as usize];
        let t = self.twin[h as usize];
        let (f0, f1) = (h / 3, t / 3);
        let (h1, h2) = (Self::next(h), Self::prev(h));
        let (t1, t2) = (Self::next(t), Self::prev(t));
        let lam = |x: u32| self.lambda[self.edge[x as usize] as usize];
        // Quad i, l, j, k: opposite sides (il = t1, jk = h1) and (lj = t2, ki = h2).
        let new_lambda = 2.0 * log_add_exp(0.5 * (lam(t1) + lam(h1)), 0.5 * (lam(t2) + lam(h2)))
            - self.lambda[e as usize];
        let k = self.origin[h2 as usize];
        let l = self.origin[t2 as usize];
        // New faces: f0 = (k→l, l→j, j→k) = (new, t2, h1); f1 = (l→k, k→i, i→l) = (new, h2, t1).
        let (a0, b0) = (3 * f0, 3 * f1);
        let moved = [(t2, a0 + 1), (h1, a0 + 2), (h2, b0 + 1), (t1, b0 + 2)];
        let old: [(u32, u32, u32); 4] = moved.map(|(s, _)| {
            (
                self.origin[s as usize],
                self.edge[s as usize],
                self.twin[s as usize],
            )
        });
        let map = |x: u32| -> Option<u32> { moved.iter().find(|m| m.0 == x).map(|m| m.1) };
        for (m, &(_, dst)) in moved.iter().enumerate() {
            let (o, ed, tw) = old[m];
            self.origin[dst as usize] = o;
            self.edge[dst as usize] = ed;
            self.edge_he[ed as usize] = dst;
            if tw == NONE {
                self.twin[dst as usize] = NONE;
            } else if let Some(nt) = map(tw) {
                self.twin[dst as usize] = nt;
            } else {
                self.twin[dst as usize] = tw;
                self.twin[tw as usize] = dst;
            }
        }
        self.origin[a0 as usize] = k;
        self.origin[b0 as usize] = l;
        self.edge[a0 as usize] = e;
        self.edge[b0 as usize] = e;
        self.twin[a0 as usize] = b0;
        self.twin[b0 as usize] = a0;
        self.edge_he[e as usize] = a0;
        self.lambda[e as usize] = new_lambda;
        self.flip_log.push(e);
        true
    }

    /// Flip edges until every edge satisfies the Penner Delaunay criterion at `u` (queue-based;
    /// at most `budget` flips).
    ///
    /// The first pass visits every edge in order; its tests are made up front in parallel
    /// on the triangulation as it is, and made again only for the edges whose two triangles
    /// a flip has changed since (the flipped edge and its quad's sides): the same flips as
    /// one sequential pass.
    pub fn make_delaunay(&mut self, u: &[f64], budget: usize) -> DelaunayReport {
        use rayon::prelude::*;
        let ne = self.n_edges();
        let initially_fine: Vec<bool> = (0..ne as u32)
            .into_par_iter()
            .with_min_len(4096)
            .map(|e| self.is_delaunay(e, u) || !self.is_flippable(e))
            .collect();
        let mut changed = vec![false; ne];
        let mut queued = vec![true; ne];
        let mut queue: VecDeque<u32> = (0..ne as u32).collect();
        let mut flips = 0;
        let mut popped = 0usize;
        while let Some(e) = queue.pop_front() {
            queued[e as usize] = false;
            popped += 1;
            let fine = if popped <= ne && !changed[e as usize] {
                initially_fine[e as usize]
            } else {
                self.is_delaunay(e, u) || !self.is_flippable(e)
            };
            if fine {
                continue;
            }
            if flips >= budget {
                return DelaunayReport {
                    flips,
                    delaunay: false,
                };
            }
            self.flip(e);
            flips += 1;
            changed[e as usize] = true;
            let h = self.edge_he[e as usize];
            let t = self.twin[h as usize];
            for x in [Self::next(h), Self::prev(h), Self::next(t), Self::prev(t)] {
                let f = self.edge[x as usize];
                changed[f as usize] = true;
                if !queued[f as usize] {
                    queued[f as usize] = true;
                    queue.push_back(f);
                }
            }
        }
        DelaunayReport {
            flips,
            delaunay: true,
        }
    }

    /// Isometric flip of edge `e` for the base metric (`u = 0`) in `geometry`: the new edge
    /// gets the true length of the other diagonal of the quad laid out in the background
    /// (cosine law with the sum of the two corner angles at one end of `e`). Only meaningful
    /// when the quad is convex (as it is for a non-Delaunay edge of valid triangles). Appends
    /// `e` to `flip_log`; false for unflippable edges.
    pub fn flip_isometric(&mut self, e: u32, geometry: Geometry) -> bool {
        if !self.is_flippable(e) {
            return false;
        }
        let h = self.edge_he[e as usize];
        let t = self.twin[h as usize];
        let len = |x: u32| length_of_lambda(geometry, self.lambda[self.edge[x as usize] as usize]);
        let (lij, ljk, lki) = (len(h), len(Self::next(h)), len(Self::prev(h)));
        let (lil, llj) = (len(Self::next(t)), len(Self::prev(t)));
        let theta = geometry.angle(ljk, lij, lki) + geometry.angle(llj, lij, lil);
        let lkl = geometry.side(lki, lil, theta);
        self.flip(e);
        self.lambda[e as usize] = lambda_of_length(geometry, lkl);
        true
    }

    /// Make the base metric's triangulation Delaunay with isometric flips
    /// ([`IntrinsicTriangulation::flip_isometric`]): the intrinsic Delaunay triangulation of
    /// the input metric, on which the discrete conformal class is defined (Gu–Luo–Sun–Wu
    /// 2018 Def. 1.1; CEPS §4.1). Ptolemy flips from a non-Delaunay triangulation would
    /// change the conformal class. Requires valid triangles.
    pub fn make_delaunay_isometric(&mut self, geometry: Geometry, budget: usize) -> DelaunayReport {
        let ne = self.n_edges();
        let mut queued = vec![true; ne];
        let mut queue: VecDeque<u32> = (0..ne as u32).collect();
        let mut flips = 0;
        while let Some(e) = queue.pop_front() {
            queued[e as usize] = false;
            if self.is_delaunay(e, &[]) || !self.is_flippable(e) {
                continue;
            }
            if flips >= budget {
                return DelaunayReport {
                    flips,
                    delaunay: false,
                };
            }
            self.flip_isometric(e, geometry);
            flips += 1;
            let h = self.edge_he[e as usize];
            let t = self.twin[h as usize];
            for x in [Self::next(h), Self::prev(h), Self::next(t), Self::prev(t)] {
                let f = self.edge[x as usize];
                if !queued[f as usize] {
                    queued[f as usize] = true;
                    queue.push_back(f);
                }
            }
        }
        DelaunayReport {
            flips,
            delaunay: true,
        }
    }

    /// Whether every edge is Delaunay at `u`.
    pub fn all_delaunay(&self, u: &[f64]) -> bool {
        (0..self.n_edges() as u32).all(|e| self.is_delaunay(e, u) || !self.is_flippable(e))
    }

    /// Consistency check of the half-edge arrays (for tests and debugging): twins are mutual
    /// and join opposite directions of the same edge, `edge_he` points to its edge.
    pub fn check(&self) -> Result<()> {
        for h in 0..self.n_halfedges() as u32 {
            let t = self.twin[h as usize];
            if t != NONE
                && (self.twin[t as usize] != h
                    || self.edge[t as usize] != self.edge[h as usize]
                    || self.origin[t as usize] != self.tip(h)
                    || self.tip(t) != self.origin[h as usize])
            {
                return Err(Error::numerical(format!(
                    "intrinsic triangulation: half-edge {h} and its twin {t} disagree"
                )));
            }
        }
        for (e, &h) in self.edge_he.iter().enumerate() {
            if self.edge[h as usize] != e as u32 {
                return Err(Error::numerical(format!(
                    "intrinsic triangulation: edge {e} points to half-edge {h} of another edge"
                )));
            }
        }
        Ok(())
    }

    /// Split edge `e` at its midpoint (metric-preserving: the new vertex has curvature 0 and
    /// the new edges get their lengths from the median formula of `geometry`); the coordinates
    /// are read at `u = 0`. Returns the new vertex.
    fn split_edge(&mut self, e: u32, geometry: Geometry) -> u32 {
        let len =
            |t: &Self, h: u32| length_of_lambda(geometry, t.lambda[t.edge[h as usize] as usize]);
        let h = self.edge_he[e as usize];
        let t = self.twin[h as usize];
        let le = length_of_lambda(geometry, self.lambda[e as usize]);
        let half = 0.5 * le;
        // Median from the apex opposite `h`: sides b = |apex, origin(h)|, c = |apex, tip(h)|.
        let median = |b: f64, c: f64| -> f64 {
            match geometry {
                Geometry::Euclidean => (0.5 * (b * b + c * c) - 0.25 * le * le).max(0.0).sqrt(),
                Geometry::Hyperbolic => ((b.cosh() + c.cosh()) / (2.0 * half.cosh()))
                    .max(1.0)
                    .acosh(),
                Geometry::Spherical => ((b.cos() + c.cos()) / (2.0 * half.cos()))
                    .clamp(-1.0, 1.0)
                    .acos(),
            }
        };
        let m = self.n_vertices as u32;
        self.n_vertices += 1;
        self.boundary_vertex.push(t == NONE);
        let i = self.origin[h as usize];
        let (h1, h2) = (Self::next(h), Self::prev(h));
        let k = self.origin[h2 as usize];
        let mk = median(len(self, h2), len(self, h1));
        // New edges: e_mj (m–j), e_mk (m–k), and for an interior edge e_ml (m–l).
        let e_mj = self.n_edges() as u32;
        let e_mk = e_mj + 1;
        let lam_half = lambda_of_length(geometry, half);
        self.lambda[e as usize] = lam_half; // e becomes i–m
        self.lambda.push(lam_half);
        self.lambda.push(lambda_of_length(geometry, mk));
        self.edge_he.push(NONE);
        self.edge_he.push(NONE);
        let f0 = h / 3;
        let f2 = self.n_faces() as u32;
        let outer =
            |s: &Self, x: u32| (s.origin[x as usize], s.edge[x as usize], s.twin[x as usize]);
        let o_h1 = outer(self, h1);
        let j = o_h1.0;
        // New slots: f0 = (i→m, m→k, k→i=h2); f2 = (m→j, j→k=h1, k→m);
        // f1 = (j→m, m→l, l→j=t2); f3 = (m→i, i→l=t1, l→m).
        // (slot, origin, edge) of the new half-edges; the moved outer ones: (old, new, data).
        let mut fresh: Vec<(u32, u32, u32)> = vec![
            (3 * f0, i, e),
            (3 * f0 + 1, m, e_mk),
            (3 * f2, m, e_mj),
            (3 * f2 + 2, k, e_mk),
        ];
        let mut moved = vec![(h2, 3 * f0 + 2, outer(self, h2)), (h1, 3 * f2 + 1, o_h1)];
        let mut pairs = vec![(3 * f0 + 1, 3 * f2 + 2)];
        let mut n_new_faces = 1;
        if t != NONE {
            let (t1, t2) = (Self::next(t), Self::prev(t));
            let (f1, f3) = (t / 3, f2 + 1);
            let l = self.origin[t2 as usize];
            let ml = median(len(self, t2), len(self, t1));
            let e_ml = self.n_edges() as u32;
            self.lambda.push(lambda_of_length(geometry, ml));
            self.edge_he.push(NONE);
            fresh.extend([
                (3 * f1, j, e_mj),
                (3 * f1 + 1, m, e_ml),
                (3 * f3, m, e),
                (3 * f3 + 2, l, e_ml),
            ]);
            moved.push((t2, 3 * f1 + 2, outer(self, t2)));
            moved.push((t1, 3 * f3 + 1, outer(self, t1)));
            pairs.extend([(3 * f0, 3 * f3), (3 * f2, 3 * f1), (3 * f1 + 1, 3 * f3 + 2)]);
            n_new_faces = 2;
        }
        for _ in 0..3 * n_new_faces {
            self.origin.push(NONE);
            self.twin.push(NONE);
            self.edge.push(NONE);
        }
        for &(s, o, ed) in &fresh {
            self.origin[s as usize] = o;
            self.edge[s as usize] = ed;
            self.twin[s as usize] = NONE;
            self.edge_he[ed as usize] = s;
        }
        for &(_, dst, (o, ed, _)) in &moved {
            self.origin[dst as usize] = o;
            self.edge[dst as usize] = ed;
            self.edge_he[ed as usize] = dst;
        }
        for &(_, dst, (_, _, tw)) in &moved {
            if tw == NONE {
                self.twin[dst as usize] = NONE;
            } else if let Some(&(_, nt, _)) = moved.iter().find(|x| x.0 == tw) {
                self.twin[dst as usize] = nt;
            } else {
                self.twin[dst as usize] = tw;
                self.twin[tw as usize] = dst;
            }
        }
        for (a, b) in pairs {
            self.twin[a as usize] = b;
            self.twin[b as usize] = a;
        }
        m
    }

    /// A simplicial [`Mesh`] with the same metric (scaled by `u`): self-loops and multi-edges
    /// are split at their midpoints (metric-preserving, new vertices flat) until none remain.
    /// Input vertices keep their ids, new ones are appended; face `f` of the result is a piece
    /// of face `f` of `self` for `f < n_faces()`. Errors if 64 rounds of splits do not suffice.
    pub fn to_simplicial(&self, geometry: Geometry, u: &[f64]) -> Result<SimplicialMesh> {
        let mut t = self.clone();
        if !u.is_empty() {
            for e in 0..t.n_edges() as u32 {
                t.lambda[e as usize] = self.scaled_lambda(e, u);
            }
        }
        let n_input = self.n_vertices;
        let mut splits = 0;
        for _round in 0..64 {
            let mut seen: HashMap<(u32, u32), u32> = HashMap::with_capacity(t.n_edges());
            let mut bad = Vec::new();
            for e in 0..t.n_edges() as u32 {
                let [a, b] = t.edge_vertices(e);
                if a == b {
                    bad.push(e);
                    continue;
                }
                let key = (a.min(b), a.max(b));
                if seen.insert(key, e).is_some() {
                    bad.push(e);
                }
            }
            // Faces whose three vertices repeat another face's (possible without multi-edges
            // only on tiny complexes) are caught by Mesh::from_triangles below.
            if bad.is_empty() {
                let faces: Vec<[u32; 3]> = (0..t.n_faces() as u32).map(|f| t.face(f)).collect();
                let mesh = Mesh::from_triangles(t.n_vertices, faces)?;
                let mut lengths = vec![0.0; mesh.n_edges()];
                for h in 0..t.n_halfedges() as u32 {
                    lengths[mesh.he_edge(h) as usize] =
                        length_of_lambda(geometry, t.lambda[t.edge[h as usize] as usize]);
                }
                let vertex_origin = (0..t.n_vertices as u32)
                    .map(|v| if (v as usize) < n_input { v } else { NONE })
                    .collect();
                return Ok(SimplicialMesh {
                    mesh,
                    lengths,
                    vertex_origin,
                    splits,
                });
            }
            for e in bad {
                t.split_edge(e, geometry);
                splits += 1;
            }
        }
        Err(Error::numerical(format!(
            "the intrinsic triangulation did not become simplicial after {splits} edge splits"
        )))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::metric::kernel::triangle_angles;
    use crate::metric::{Euclidean, Hyperbolic};

    /// A tiny deterministic generator (xorshift) for reproducible random tests.
    pub(crate) struct Rng(u64);
    impl Rng {
        pub(crate) fn new(seed: u64) -> Rng {
            Rng(seed.wrapping_mul(0x9E37_79B9_7F4A_7C15) | 1)
        }
        pub(crate) fn next(&mut self) -> f64 {
            self.0 ^= self.0 << 13;
            self.0 ^= self.0 >> 7;
            self.0 ^= self.0 << 17;
            (self.0 >> 11) as f64 / (1u64 << 53) as f64
        }
    }

    fn disk_with_random_points(seed: u64) -> (Mesh, Vec<[f64; 2]>) {
        // Fan-like triangulation of a convex polygon with random interior points inserted by
        // splitting the containing triangle (a valid but far from Delaunay triangulation).
        let mut rng = Rng::new(seed);
        let n_boundary = 12;
        let mut pts: Vec<[f64; 2]> = (0..n_boundary)
            .map(|k| {
                let a = 2.0 * std::f64::consts::PI * k as f64 / n_boundary as f64;
                [a.cos(), a.sin()]
            })
            .collect();
        let mut faces: Vec<[u32; 3]> = (1..n_boundary as u32 - 1).map(|k| [0, k, k + 1]).collect();
        let orient = |a: [f64; 2], b: [f64; 2], c: [f64; 2]| {
            (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0])
        };
        for _ in 0..60 {
            let r = 0.9 * rng.next().sqrt();
            let a = 2.0 * std::f64::consts::PI * rng.next();
            let p = [r * a.cos(), r * a.sin()];
            let Some(fi) = faces.iter().position(|t| {
                let [a, b, c] = t.map(|v| pts[v as usize]);
                orient(a, b, p) > 1e-3 && orient(b, c, p) > 1e-3 && orient(c, a, p) > 1e-3
            }) else {
                continue;
            };
            let v = pts.len() as u32;
            pts.push(p);
            let [a, b, c] = faces[fi];
            faces[fi] = [a, b, v];
            faces.push([b, c, v]);
            faces.push([c, a, v]);
        }
        (Mesh::from_triangles(pts.len(), faces).unwrap(), pts)
    }

    fn planar_lengths(mesh: &Mesh, pts: &[[f64; 2]]) -> Vec<f64> {
        (0..mesh.n_edges() as u32)
            .map(|e| {
                let [a, b] = mesh.edge_vertices(e);
                let (p, q) = (pts[a as usize], pts[b as usize]);
                ((p[0] - q[0]).powi(2) + (p[1] - q[1]).powi(2)).sqrt()
            })
            .collect()
    }

    #[test]
    fn flip_twice_restores_coordinates_and_ptolemy_holds() {
        let (mesh, pts) = disk_with_random_points(3);
        let l = planar_lengths(&mesh, &pts);
        let mut t = IntrinsicTriangulation::from_mesh(&mesh, Geometry::Euclidean, &l).unwrap();
        let before = t.lambda.clone();
        let mut flipped = 0;
        for e in 0..t.n_edges() as u32 {
            if !t.is_flippable(e) {
                continue;
            }
            // Ptolemy against the planar positions: the new diagonal's Euclidean length when
            // the quad is convex satisfies l_e l_f = l_a l_c + l_b l_d only if cocircular, so
            // check the algebraic relation itself.
            let h = t.edge_he[e as usize];
            let tw = t.twin[h as usize];
            let side = |x: u32| (0.5 * t.lambda[t.edge[x as usize] as usize]).exp();
            let rhs = side(IntrinsicTriangulation::next(tw))
                * side(IntrinsicTriangulation::next(h))
                + side(IntrinsicTriangulation::prev(tw)) * side(IntrinsicTriangulation::prev(h));
            let le = (0.5 * t.lambda[e as usize]).exp();
            assert!(t.flip(e));
            t.check().unwrap();
            let lf = (0.5 * t.lambda[e as usize]).exp();
            assert!((le * lf - rhs).abs() <= 1e-13 * rhs, "Ptolemy at edge {e}");
            assert!(t.flip(e));
            t.check().unwrap();
            flipped += 2;
        }
        assert_eq!(t.flip_log.len(), flipped);
        for e in 0..t.n_edges() {
            assert!((t.lambda[e] - before[e]).abs() <= 1e-14 * before[e].abs().max(1.0));
            let mut a = t.edge_vertices(e as u32);
            let mut b = mesh.edge_vertices(e as u32);
            a.sort();
            b.sort();
            assert_eq!(a, b, "edge {e} changed its end points");
        }
    }

    #[test]
    fn ptolemy_flip_of_a_cocircular_quad_is_isometric() {
        // Four points on the unit circle: the flipped diagonal is their true distance.
        let ang = [0.3f64, 1.9, 3.0, 4.4];
        let p: Vec<[f64; 2]> = ang.iter().map(|a| [a.cos(), a.sin()]).collect();
        let mesh = Mesh::from_triangles(4, vec![[0, 1, 2], [0, 2, 3]]).unwrap();
        let l = planar_lengths(&mesh, &p);
        let mut t = IntrinsicTriangulation::from_mesh(&mesh, Geometry::Euclidean, &l).unwrap();
        let e = (0..t.n_edges() as u32)
            .find(|&e| !t.is_boundary_edge(e))
            .unwrap();
        assert!(t.delaunay_value(e, &[]).abs() < 1e-14);
        t.flip(e);
        let [a, b] = t.edge_vertices(e);
        let want = ((p[a as usize][0] - p[b as usize][0]).powi(2)
            + (p[a as usize][1] - p[b as usize][1]).powi(2))
        .sqrt();
        assert!((length_of_lambda(Geometry::Euclidean, t.lambda[e as usize]) - want).abs() < 1e-14);
        assert_eq!(
            {
                let mut x = [a, b];
                x.sort();
                x
            },
            [1, 3]
        );
    }

    #[test]
    fn delaunay_by_flips_matches_the_geometric_criterion() {
        for seed in 1..6 {
            let (mesh, pts) = disk_with_random_points(seed);
            let l = planar_lengths(&mesh, &pts);
            let mut t = IntrinsicTriangulation::from_mesh(&mesh, Geometry::Euclidean, &l).unwrap();
            let rep = t.make_delaunay_isometric(Geometry::Euclidean, 100_000);
            assert!(rep.delaunay && rep.flips > 0);
            t.check().unwrap();
            // Every flipped edge joins two of the planar points: its length from the flips
            // equals the distance of its end points (flips of a planar triangulation are
            // isometric there because the quads are convex... only for Delaunay-driven flips
            // of a convex quad is the Ptolemy value not the distance, so compare angles via
            // positions instead).
            for e in 0..t.n_edges() as u32 {
                if t.is_boundary_edge(e) {
                    continue;
                }
                let h = t.edge_he[e as usize];
                let tw = t.twin[h as usize];
                let opp = |x: u32| pts[t.origin[IntrinsicTriangulation::prev(x) as usize] as usize];
                let [a, b] = t.edge_vertices(e).map(|v| pts[v as usize]);
                let angle = |c: [f64; 2]| {
                    let (u, v) = ([a[0] - c[0], a[1] - c[1]], [b[0] - c[0], b[1] - c[1]]);
                    (u[0] * v[1] - u[1] * v[0])
                        .abs()
                        .atan2(u[0] * v[0] + u[1] * v[1])
                };
                let s = angle(opp(h)) + angle(opp(tw));
                assert!(
                    s <= std::f64::consts::PI + 1e-12,
                    "seed {seed}: edge {e} has opposite angles summing to {s}"
                );
            }
        }
    }

    /// The Ptolemy flips of [`IntrinsicTriangulation::make_delaunay`] (first pass tested up
    /// front in parallel) against one sequential queue written here: the same flips in the
    /// same order and the same coordinates, for scale factors that make flips cascade.
    #[test]
    fn make_delaunay_flips_as_one_sequential_queue() {
        let sequential = |t: &mut IntrinsicTriangulation, u: &[f64]| {
            let ne = t.n_edges();
            let mut queued = vec![true; ne];
            let mut queue: VecDeque<u32> = (0..ne as u32).collect();
            while let Some(e) = queue.pop_front() {
                queued[e as usize] = false;
                if t.delaunay_value(e, u) >= -DELAUNAY_EPS || !t.is_flippable(e) {
                    continue;
                }
                t.flip(e);
                let h = t.edge_he[e as usize];
                let tw = t.twin[h as usize];
                for x in [
                    IntrinsicTriangulation::next(h),
                    IntrinsicTriangulation::prev(h),
                    IntrinsicTriangulation::next(tw),
                    IntrinsicTriangulation::prev(tw),
                ] {
                    let f = t.edge[x as usize];
                    if !queued[f as usize] {
                        queued[f as usize] = true;
                        queue.push_back(f);
                    }
                }
            }
        };
        let mut cascades = 0;
        for seed in 1..8 {
            let (mesh, pts) = disk_with_random_points(seed);
            let l = planar_lengths(&mesh, &pts);
            let mut base =
                IntrinsicTriangulation::from_mesh(&mesh, Geometry::Euclidean, &l).unwrap();
            base.make_delaunay_isometric(Geometry::Euclidean, 100_000);
            base.flip_log.clear();
            let mut rng = Rng::new(100 + seed);
            for amplitude in [0.5, 2.0] {
                let u: Vec<f64> = (0..base.n_vertices)
                    .map(|_| amplitude * (2.0 * rng.next() - 1.0))
                    .collect();
                let (mut a, mut b) = (base.clone(), base.clone());
                let rep = a.make_delaunay(&u, 100_000);
                sequential(&mut b, &u);
                assert!(rep.delaunay && a.all_delaunay(&u));
                assert_eq!(rep.flips, b.flip_log.len(), "seed {seed}");
                assert_eq!(a.flip_log, b.flip_log, "seed {seed}: flip order");
                assert_eq!(a.lambda, b.lambda);
                assert_eq!((a.origin, a.twin, a.edge), (b.origin, b.twin, b.edge));
                // Flips beyond the first pass (an edge tested again after its quad changed).
                let distinct: std::collections::HashSet<_> = b.flip_log.iter().collect();
                if b.flip_log.len() > distinct.len() {
                    cascades += 1;
                }
            }
        }
        assert!(
            cascades > 0,
            "no edge flipped twice: the test needs stronger scale factors"
        );
    }

    #[test]
    fn isometric_flips_of_a_planar_triangulation_keep_true_distances() {
        // Every edge after the isometric Delaunay flips joins two of the planar points at their
        // true distance; a Ptolemy flip of a non-cocircular quad would not (Ptolemy's
        // inequality |AC||BD| < |AB||CD| + |BC||DA|).
        for seed in [7, 8] {
            let (mesh, pts) = disk_with_random_points(seed);
            let l = planar_lengths(&mesh, &pts);
            let mut t = IntrinsicTriangulation::from_mesh(&mesh, Geometry::Euclidean, &l).unwrap();
            let mut p = t.clone();
            let e0 = (0..t.n_edges() as u32)
                .find(|&e| t.is_flippable(e) && !t.is_delaunay(e, &[]))
                .unwrap();
            p.flip(e0);
            t.make_delaunay_isometric(Geometry::Euclidean, 100_000);
            for e in 0..t.n_edges() as u32 {
                let [a, b] = t.edge_vertices(e);
                let (p, q) = (pts[a as usize], pts[b as usize]);
                let d = ((p[0] - q[0]).powi(2) + (p[1] - q[1]).powi(2)).sqrt();
                let le = length_of_lambda(Geometry::Euclidean, t.lambda[e as usize]);
                assert!(
                    (le - d).abs() <= 1e-12 * d,
                    "edge {e}: {le} vs distance {d}"
                );
            }
            let [a, b] = p.edge_vertices(e0);
            let (x, y) = (pts[a as usize], pts[b as usize]);
            let d = ((x[0] - y[0]).powi(2) + (x[1] - y[1]).powi(2)).sqrt();
            assert!(
                d < length_of_lambda(Geometry::Euclidean, p.lambda[e0 as usize]) * (1.0 - 1e-9)
            );
        }
    }

    /// Random valid hyperbolic triangle side lengths.
    fn hyperbolic_triangle(rng: &mut Rng) -> [f64; 3] {
        loop {
            let l = [
                0.05 + 2.5 * rng.next(),
                0.05 + 2.5 * rng.next(),
                0.05 + 2.5 * rng.next(),
            ];
            if l[0] < l[1] + l[2] && l[1] < l[0] + l[2] && l[2] < l[0] + l[1] {
                return l;
            }
        }
    }

    #[test]
    fn hyperbolic_penner_criterion_is_delaunay() {
        // Quad (e; a, b) ∪ (e; c, d): compare sign of the Penner expression on x = sinh(l/2)
        // with the empty-circle angle criterion α + α' ≤ β + γ + β' + γ' (the signed base
        // angles (β + γ − α)/2 of the isosceles triangles over e from the circumcentres add
        // up to ≥ 0).
        let mut rng = Rng::new(11);
        let mut agree = 0;
        for _ in 0..20000 {
            let [le, la, lb] = hyperbolic_triangle(&mut rng);
            // Second triangle on e.
            let (lc, ld) = loop {
                let c = 0.05 + 2.5 * rng.next();
                let d = 0.05 + 2.5 * rng.next();
                if le < c + d && c < le + d && d < le + c {
                    break (c, d);
                }
            };
            let (th1, _, _) = triangle_angles::<Hyperbolic>([le, la, lb]);
            let (th2, _, _) = triangle_angles::<Hyperbolic>([le, lc, ld]);
            let angle_crit = (th1[1] + th1[2] - th1[0]) + (th2[1] + th2[2] - th2[0]);
            let lam = |l: f64| lambda_of_length(Geometry::Hyperbolic, l);
            let penner = penner_cosine_term(lam(la), lam(lb), lam(le))
                + penner_cosine_term(lam(lc), lam(ld), lam(le));
            if angle_crit.abs() < 1e-9 || penner.abs() < 1e-9 {
                continue;
            }
            assert_eq!(
                angle_crit > 0.0,
                penner > 0.0,
                "e={le} a={la} b={lb} c={lc} d={ld}: angle criterion {angle_crit}, Penner {penner}"
            );
            agree += 1;
        }
        assert!(agree > 15000);
        // Euclidean sanity: the same criterion is cos α + cos α' ≥ 0.
        let (th1, _, _) = triangle_angles::<Euclidean>([1.0, 0.8, 0.7]);
        let (th2, _, _) = triangle_angles::<Euclidean>([1.0, 0.6, 0.9]);
        let p = penner_cosine_term(2.0 * 0.8f64.ln(), 2.0 * 0.7f64.ln(), 0.0)
            + penner_cosine_term(2.0 * 0.6f64.ln(), 2.0 * 0.9f64.ln(), 0.0);
        assert!((p - 2.0 * (th1[0].cos() + th2[0].cos())).abs() < 1e-14);
    }

    #[test]
    fn hyperbolic_ptolemy_on_a_circle() {
        // Points on a hyperbolic circle of radius r around the hyperboloid's apex.
        let mut rng = Rng::new(5);
        for _ in 0..200 {
            let r = 0.1 + 3.0 * rng.next();
            let mut a: Vec<f64> = (0..4)
                .map(|_| 2.0 * std::f64::consts::PI * rng.next())
                .collect();
            a.sort_by(f64::total_cmp);
            let p: Vec<[f64; 3]> = a
                .iter()
                .map(|t| [r.sinh() * t.cos(), r.sinh() * t.sin(), r.cosh()])
                .collect();
            let d = |i: usize, j: usize| {
                let ip = p[i][2] * p[j][2] - p[i][0] * p[j][0] - p[i][1] * p[j][1];
                ip.max(1.0).acosh()
            };
            let x = |i: usize, j: usize| (0.5 * d(i, j)).sinh();
            let lhs = x(0, 2) * x(1, 3);
            let rhs = x(0, 1) * x(2, 3) + x(1, 2) * x(3, 0);
            assert!((lhs - rhs).abs() <= 1e-9 * rhs, "{lhs} vs {rhs}");
            // And the Penner quantity of diagonal 02 vanishes.
            let lam = |i: usize, j: usize| 2.0 * x(i, j).ln();
            let v = penner_cosine_term(lam(0, 1), lam(1, 2), lam(0, 2))
                + penner_cosine_term(lam(2, 3), lam(3, 0), lam(0, 2));
            assert!(v.abs() < 1e-7, "{v}");
        }
    }

    #[test]
    fn to_simplicial_splits_loops_and_keeps_the_metric() {
        // A flat torus from a 2×2 grid flipped into a Δ-complex with loops.
        let n = 3u32;
        let mut faces = Vec::new();
        let id = |i: u32, j: u32| (i % n) + n * (j % n);
        for j in 0..n {
            for i in 0..n {
                faces.push([id(i, j), id(i + 1, j), id(i + 1, j + 1)]);
                faces.push([id(i, j), id(i + 1, j + 1), id(i, j + 1)]);
            }
        }
        let mesh = Mesh::from_triangles((n * n) as usize, faces).unwrap();
        let l: Vec<f64> = (0..mesh.n_edges() as u32)
            .map(|e| {
                let [a, b] = mesh.edge_vertices(e);
                let (ai, aj, bi, bj) = (a % n, a / n, b % n, b / n);
                let di = (bi + n - ai) % n;
                let dj = (bj + n - aj) % n;
                if di != 0 && dj != 0 {
                    2f64.sqrt()
                } else {
                    1.0
                }
            })
            .collect();
        let mut t = IntrinsicTriangulation::from_mesh(&mesh, Geometry::Euclidean, &l).unwrap();
        // Scale one vertex up a lot so that Delaunay flips create loops / multi-edges.
        let mut u = vec![0.0; t.n_vertices];
        u[0] = 3.0;
        t.make_delaunay(&u, 10_000);
        t.check().unwrap();
        let s = t.to_simplicial(Geometry::Euclidean, &u).unwrap();
        // Curvature of the simplicial mesh: the input vertices as in the Δ-complex, 0 at the
        // new ones; Gauss–Bonnet 0.
        let k = crate::metric::curvature(&s.mesh, Geometry::Euclidean, &s.lengths);
        for (v, &kv) in k.iter().enumerate() {
            if v >= t.n_vertices {
                assert!(kv.abs() < 1e-12, "new vertex {v} has curvature {kv}");
            }
        }
        assert!(k.iter().sum::<f64>().abs() < 1e-10);
        assert_eq!(s.vertex_origin.len(), s.mesh.n_vertices());
    }
}
