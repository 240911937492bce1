//! Tracing the input edges through the intrinsic triangulation `T` along their normal
//! coordinates, with the λ-lengths along each strip that place the crossings (see the parent
//! module, "Geometry: λ-lengths along a strip").

use super::input::{Between, InputComplex, LAMBDA_TIE};
use super::normal::{arc_end, face_counts, ArcEnd, TriangleArcs};
use super::polygons::face_polygons;
use super::sides::{leaving_corner, match_at_vertex, Leaving};
use super::{CommonSubdivision, Crossing, SubdivisionReport, Tri};
use crate::error::{Error, Result};
use crate::mesh::NONE;
use std::collections::HashMap;

/// `log(e^a + e^b)` without overflow.
#[inline]
fn log_add_exp(a: f64, b: f64) -> f64 {
    let m = a.max(b);
    m + ((a - m).exp() + (b - m).exp()).ln()
}

/// A step of a traced input edge: it crosses half-edge `h` of `T` into `face(h)`, at position
/// `p` along `h` (from its origin).
type Step = (u32, u32);

/// Follow an input edge that crosses `h` at position `p` into `face(h)` until it ends at a
/// corner; returns the further steps and the corner (`3f + i`) where it ends.
pub(super) fn walk(
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

/// Input edges traced so far: the crossing ids of every edge of `T` and what was found there.
struct Tracer<'a, M: InputComplex> {
    mesh: &'a M,
    tri: &'a Tri,
    normal: &'a [i32],
    arcs: Vec<TriangleArcs>,
    /// First crossing id of every edge of `T` (and the total at the end).
    offset: Vec<u32>,
    crossings: Vec<Option<Crossing>>,
    /// Input edges found (as an edge of `T` or traced).
    input_seen: Vec<bool>,
    /// The input half-edge along `edge_he[e]` of every edge `e` of `T` that is an input edge.
    shared_input: Vec<u32>,
    /// At the vertices where two input edges join the same vertices: the input half-edges by
    /// where they leave the vertex in `T` ([`super::sides`]).
    sides: HashMap<u32, HashMap<Leaving, u32>>,
    order_violations: usize,
}

/// The common subdivision of `mesh` and `tri` (replayed, with normal coordinates `normal`).
pub(super) fn build<M: InputComplex>(
    mesh: &M,
    tri: Tri,
    normal: Vec<i32>,
    flips: usize,
) -> Result<CommonSubdivision> {
    let ne = tri.n_edges();
    let arcs = (0..tri.n_faces() as u32)
        .map(|f| {
            TriangleArcs::new(face_counts(&tri, &normal, f)).ok_or_else(|| {
                Error::numerical(format!(
                    "normal coordinates of face {f} of the intrinsic triangulation are \
                     inconsistent"
                ))
            })
        })
        .collect::<Result<Vec<_>>>()?;
    let mut offset = Vec::with_capacity(ne + 1);
    let mut total = 0u32;
    for &n in &normal {
        offset.push(total);
        total += n.max(0) as u32;
    }
    offset.push(total);
    let n_cross = total as usize;
    let mut tracer = Tracer {
        mesh,
        tri: &tri,
        normal: &normal,
        arcs,
        offset,
        crossings: vec![None; n_cross],
        input_seen: vec![false; mesh.n_edges()],
        shared_input: vec![NONE; ne],
        sides: HashMap::new(),
        order_violations: 0,
    };
    let shared_edges = tracer.mark_shared_edges()?;
    // Trace every input edge that crosses T, starting from its first unvisited crossing.
    for e in 0..ne as u32 {
        for pc in 0..normal[e as usize].max(0) as u32 {
            let id = (tracer.offset[e as usize] + pc) as usize;
            if tracer.crossings[id].is_none() {
                tracer.trace(e, pc)?;
            }
        }
    }
    if let Some(e0) = tracer.input_seen.iter().position(|&s| !s) {
        let [a, b] = mesh.edge_vertices(e0 as u32);
        return Err(Error::numerical(format!(
            "input edge {e0} ({a}, {b}) was not found in the intrinsic triangulation"
        )));
    }
    let Tracer {
        arcs,
        offset,
        crossings,
        shared_input,
        mut order_violations,
        ..
    } = tracer;
    let crossings: Vec<Crossing> = crossings.into_iter().flatten().collect();
    if crossings.len() != n_cross {
        return Err(Error::numerical("a crossing of the overlay was not traced"));
    }
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
        shared_input,
        n_input_vertices: mesh.n_vertices(),
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
    for (f, a) in arcs.iter().enumerate() {
        face_polygons(mesh, &mut sub, a, f as u32)?;
    }
    Ok(sub)
}

impl<M: InputComplex> Tracer<'_, M> {
    /// Mark the input edges that are edges of `T` (normal coordinate −1); their number.
    fn mark_shared_edges(&mut self) -> Result<usize> {
        let mut shared = 0;
        for e in 0..self.tri.n_edges() as u32 {
            if self.normal[e as usize] == -1 {
                shared += 1;
                let [a, b] = self.tri.edge_vertices(e);
                let lambda = self.tri.lambda[e as usize];
                let along = Leaving::Along(self.tri.edge_he[e as usize]);
                let h0 = self
                    .input_halfedge(a, b, lambda, |_| Ok(along))?
                    .ok_or_else(|| {
                        Error::numerical(format!(
                            "edge {e} of the intrinsic triangulation is marked as an input edge, \
                         but vertices {a} and {b} are not adjacent in the input"
                        ))
                    })?;
                self.input_seen[self.mesh.he_edge(h0) as usize] = true;
                self.shared_input[e as usize] = h0;
            }
        }
        Ok(shared)
    }

    /// The input half-edge from `a` to `b` whose log Penner coordinate is `lambda` up to
    /// rounding; where several join `a` and `b`, the one leaving `a` at `leaving()` in `T`
    /// ([`super::sides`]), checked against `lambda`. `None` when `a` and `b` are not adjacent.
    fn input_halfedge(
        &mut self,
        a: u32,
        b: u32,
        lambda: f64,
        leaving: impl FnOnce(&[TriangleArcs]) -> Result<Leaving>,
    ) -> Result<Option<u32>> {
        let mesh = self.mesh;
        let hs = match mesh.halfedges_between(a, b) {
            Between::None => return Ok(None),
            Between::One(h) => return Ok(Some(h)),
            Between::Many(hs) => hs,
        };
        let at = leaving(&self.arcs)?;
        if !self.sides.contains_key(&a) {
            let out = (0..self.tri.n_halfedges() as u32)
                .find(|&h| self.tri.origin[h as usize] == a)
                .ok_or_else(|| Error::numerical(format!("vertex {a} of T has no edge")))?;
            let m = match_at_vertex(mesh, self.tri, self.normal, &self.arcs, a, out)?;
            self.sides.insert(a, m);
        }
        let h = *self.sides[&a].get(&at).ok_or_else(|| {
            Error::numerical(format!(
                "an input edge leaving vertex {a} was not found around it in T"
            ))
        })?;
        if !hs.contains(&h) {
            return Err(Error::numerical(format!(
                "the input edge leaving vertex {a} there does not end at vertex {b}"
            )));
        }
        let dist = |x: u32| (mesh.edge_lambda(mesh.he_edge(x)) - lambda).abs();
        let nearest = hs.iter().map(|&x| dist(x)).fold(f64::INFINITY, f64::min);
        if !(dist(h) <= nearest + LAMBDA_TIE) {
            return Err(Error::numerical(format!(
                "the input edge from vertex {a} to {b} found by side has log Penner coordinate                  {}, another one {lambda}'s nearer",
                mesh.edge_lambda(mesh.he_edge(h))
            )));
        }
        Ok(Some(h))
    }

    /// The whole strip of the input edge through crossing `pc` of edge `e` of `T`: its steps
    /// from end to end, and the corners (`3f + i`) where it starts and ends.
    fn strip(&self, e: u32, pc: u32) -> Result<(Vec<Step>, u32, u32)> {
        let (tri, normal) = (self.tri, self.normal);
        let n = normal[e as usize] as u32;
        let budget = self.crossings.len();
        let g = tri.edge_he[e as usize];
        let tg = tri.twin[g as usize];
        let (fwd, end) = walk(tri, normal, &self.arcs, g, pc, budget)?;
        let (bwd, start) = walk(tri, normal, &self.arcs, tg, n - 1 - pc, budget)?;
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
        Ok((path, start, end))
    }

    /// Trace the input edge through crossing `pc` of edge `e` of `T` and record its crossings.
    fn trace(&mut self, e: u32, pc: u32) -> Result<()> {
        let (path, start, end) = self.strip(e, pc)?;
        let (mesh, tri, normal) = (self.mesh, self.tri, self.normal);
        let a = tri.origin[start as usize];
        let b = tri.origin[end as usize];
        let (la, lb) = strip_lambdas(tri, &path);
        let lambda_ab = strip_end_lambda(tri, &path, &la);
        let h0 = self
            .input_halfedge(a, b, lambda_ab, |arcs| {
                leaving_corner(tri, normal, arcs, start, path[0])
            })?
            .ok_or_else(|| {
                Error::numerical(format!(
                    "an input edge traced through the intrinsic triangulation joins vertices {a} \
                 and {b}, which are not adjacent in the input"
                ))
            })?;
        let e0 = mesh.he_edge(h0);
        if self.input_seen[e0 as usize] {
            return Err(Error::numerical(format!(
                "input edge {e0} ({a}, {b}) was found twice in the intrinsic triangulation"
            )));
        }
        self.input_seen[e0 as usize] = true;
        let forward = mesh.edge_vertices(e0)[0] == a;
        let m = path.len();
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
            // Order along the traced direction, in log space (no saturation near ends).
            let t_dir = if forward { -rho_in } else { rho_in };
            if !(t_dir > last_t) {
                self.order_violations += 1;
            }
            last_t = t_dir;
            let id = (self.offset[et as usize] + pcan) as usize;
            if self.crossings[id].is_some() {
                return Err(Error::numerical(format!(
                    "crossing {pcan} of edge {et} was traced twice"
                )));
            }
            self.crossings[id] = Some(Crossing {
                input_edge: e0,
                input_rank: rank,
                input_t: 1.0 / (1.0 + rho_in.exp()),
                t_edge: et,
                t_index: pcan,
                t_log_ratio: if canonical { rho_t } else { -rho_t },
            });
        }
        Ok(())
    }
}

/// The log Penner coordinate `λ_ab` of the traced input edge from the strip's first cusp `a`
/// to its last `b` (Ptolemy in the last triangle, as in [`strip_lambdas`]).
fn strip_end_lambda(tri: &Tri, path: &[Step], la: &[[f64; 2]]) -> f64 {
    let m = path.len();
    let h = path[m - 1].0;
    let w = log_add_exp(
        la[m - 1][0] + half_lambda(tri, Tri::next(h)),
        la[m - 1][1] + half_lambda(tri, Tri::prev(h)),
    ) - half_lambda(tri, h);
    2.0 * w
}

/// Log λ-lengths along a strip (Ptolemy, triangle by triangle, positive terms only): for every
/// step `h_k`, from the strip's first cusp `a` (first list) and from its last cusp `b`
/// (second list) to `[origin(h_k), tip(h_k)]`.
#[allow(clippy::type_complexity)]
fn strip_lambdas(tri: &Tri, path: &[Step]) -> (Vec<[f64; 2]>, Vec<[f64; 2]>) {
    let m = path.len();
    let mut la = vec![[0.0f64; 2]; m];
    let mut lb = vec![[0.0f64; 2]; m];
    let x = tri.twin[path[0].0 as usize];
    la[0] = [
        half_lambda(tri, Tri::next(x)),
        half_lambda(tri, Tri::prev(x)),
    ];
    for k in 0..m - 1 {
        let h = path[k].0;
        let w = log_add_exp(
            la[k][0] + half_lambda(tri, Tri::next(h)),
            la[k][1] + half_lambda(tri, Tri::prev(h)),
        ) - half_lambda(tri, h);
        let hn = path[k + 1].0;
        la[k + 1] = if tri.twin[Tri::next(h) as usize] == hn {
            [w, la[k][1]] // h_{k+1} = w → tip(h_k)
        } else {
            [la[k][0], w] // h_{k+1} = origin(h_k) → w
        };
    }
    let hm = path[m - 1].0;
    lb[m - 1] = [
        half_lambda(tri, Tri::prev(hm)),
        half_lambda(tri, Tri::next(hm)),
    ];
    for k in (0..m - 1).rev() {
        let hn = path[k + 1].0;
        let g = tri.twin[hn as usize]; // in face(h_k), from tip(hn) to origin(hn)
        let w = log_add_exp(
            lb[k + 1][0] + half_lambda(tri, Tri::prev(g)),
            lb[k + 1][1] + half_lambda(tri, Tri::next(g)),
        ) - half_lambda(tri, g);
        let h = path[k].0;
        lb[k] = if tri.twin[Tri::next(h) as usize] == hn {
            [w, lb[k + 1][1]]
        } else {
            [lb[k + 1][0], w]
        };
    }
    (la, lb)
}
