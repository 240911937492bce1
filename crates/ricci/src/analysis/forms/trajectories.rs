//! Critical horizontal trajectories of a holomorphic 1-form (paper 002 §4.2.4, the "critical
//! trajectories through the zeros" of the conformal net; Strebel, *Quadratic differentials*,
//! ch. IV): the curves along which `ω` is real and positive, i.e. the gradient lines of
//! `Re φ` (`φ = ∫ω`), that leave a zero.
//!
//! A discrete harmonic form is constant on each face, so `Re ω` is a vector `X_f` in the
//! face's plane ([`super::zeros`]) and a horizontal trajectory is traced face by face as a
//! straight segment along `±X_f` (`Re φ` increasing: *outgoing*; decreasing: *incoming*),
//! in each face's own frame (so the cut and the periods play no role). Where the fields of two
//! faces both point at their common edge the trajectory runs along the edge.
//!
//! **Departures from a vertex.** Going once counter-clockwise around vertex `p`, let `ψ` be
//! the angle of `X` against the radial direction: inside a face it decreases with the radial
//! angle (by the corner angle `θ`), across an edge it jumps by the turn `δ ∈ (−π, π]` of `X`
//! — the same `θ` and `δ` from which [`super::zeros`] computes the Poincaré–Hopf index, so the
//! lifted `ψ` decreases in all by exactly `2π(1 − ind_p) = 2π(m + 1)` at a zero of order `m`
//! (by `2π` at a regular vertex). The field leaves `p` where `ψ ≡ 0` and arrives where
//! `ψ ≡ π`; for each of the `m + 1` levels `2πk` (and `π + 2πk`) in the range of the lifted
//! `ψ`, the trajectory starts where `ψ` passes that level for the last time (inside a face:
//! along `±X_f`; at a jump: along the edge). Hence exactly `2(m + 1)` critical trajectories
//! leave a zero of order `m` — `Σ 2(m_i + 1)` in all — even where the discrete field turns
//! back and forth near the zero (counting the sign changes of `Im φ` around the 1-ring does
//! not have this property: near a zero `|ω|` is small and the conjugate form's discretization
//! error moves the saddle of `Im φ` to a neighbouring vertex). A trajectory that runs into a
//! vertex continues by the same rule (one departure at a regular vertex) and stops at a zero,
//! after `length` (in `∫|ω| = |Δ Re φ|`), or after `max_faces` steps.

use super::cochain::on_halfedge;
use super::zeros::{angle_between, face_vector, wrap};
use super::HolomorphicForm;
use crate::mesh::{Mesh, NONE};
use crate::metric::IntrinsicMetric;
use std::f64::consts::PI;

/// A point on edge `from → to` of the mesh at `(1 − t)·from + t·to` (`t = 0`: the vertex).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EdgePoint {
    pub from: u32,
    pub to: u32,
    pub t: f64,
}

impl EdgePoint {
    /// The point on a surface with these vertex positions.
    pub fn position(&self, pos: &[[f64; 3]]) -> [f64; 3] {
        let (a, b) = (pos[self.from as usize], pos[self.to as usize]);
        std::array::from_fn(|k| a[k] + self.t * (b[k] - a[k]))
    }

    fn vertex(v: u32) -> EdgePoint {
        EdgePoint {
            from: v,
            to: v,
            t: 0.0,
        }
    }
}

/// One critical horizontal trajectory: it starts at the zero `zero` (the first point) and
/// runs with `Re φ` increasing (`outgoing`) or decreasing.
#[derive(Debug, Clone)]
pub struct Trajectory {
    pub zero: u32,
    pub outgoing: bool,
    pub points: Vec<EdgePoint>,
    /// `∫|ω|` along it (`|Δ Re φ|`).
    pub length: f64,
}

/// How a trajectory leaves a vertex: into the face of an outgoing half-edge (its corner at
/// the vertex), or along an outgoing half-edge.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Departure {
    Face(u32),
    Edge(u32),
}

/// Where the tracing is: at a vertex, or at parameter `s` on half-edge `h` whose face was just
/// crossed.
#[derive(Debug, Clone, Copy)]
enum At {
    Vertex(u32),
    Edge(u32, f64),
}

type Frame = ([f64; 2], [[f64; 2]; 3]);

/// The face-constant field of `Re ω` with the faces' frames.
struct Field<'a> {
    mesh: &'a Mesh,
    re: &'a [f64],
    frames: Vec<Option<Frame>>,
    /// Vertices where trajectories end (the zeros).
    stop: Vec<bool>,
}

fn cross(a: [f64; 2], b: [f64; 2]) -> f64 {
    a[0] * b[1] - a[1] * b[0]
}

fn sub(a: [f64; 2], b: [f64; 2]) -> [f64; 2] {
    [a[0] - b[0], a[1] - b[1]]
}

/// Corners of a face in its frame (`c_0 = 0`, `c_{i+1} = c_i + d_i`).
fn corners(d: &[[f64; 2]; 3]) -> [[f64; 2]; 3] {
    [[0.0, 0.0], d[0], [d[0][0] + d[1][0], d[0][1] + d[1][1]]]
}

/// Where the ray `x + s v` (`s > 0`) crosses the segment `a b`: `(s, τ)` with the point at
/// `a + τ (b − a)`.
fn hit(x: [f64; 2], v: [f64; 2], a: [f64; 2], b: [f64; 2]) -> Option<(f64, f64)> {
    let e = sub(b, a);
    let den = cross(v, e);
    if den.abs() <= 1e-300 || den.is_nan() {
        return None;
    }
    let ax = sub(a, x);
    let s = cross(ax, e) / den;
    let tau = cross(ax, v) / den;
    (s > 0.0 && (-1e-9..=1.0 + 1e-9).contains(&tau)).then_some((s, tau.clamp(0.0, 1.0)))
}

impl Field<'_> {
    fn frame(&self, h: u32) -> Option<Frame> {
        let f = self.mesh.he_face(h);
        if f == NONE {
            return None;
        }
        self.frames[f as usize]
    }

    /// The departures from `p` (module docs): levels `offset + 2πk` of the lifted `ψ`
    /// (`offset` 0: along `+X`; π: along `−X`).
    fn departures(&self, p: u32, offset: f64) -> Vec<Departure> {
        let m = self.mesh;
        if m.is_isolated(p) || m.is_boundary_vertex(p) {
            return Vec::new();
        }
        let rel = |h: u32| {
            self.frame(h)
                .map(|(x, d)| angle_between(d[(h % 3) as usize], x))
        };
        let corner = |h: u32| {
            self.frame(h).map(|(_, d)| {
                let p = d[((h + 2) % 3) as usize];
                angle_between(d[(h % 3) as usize], [-p[0], -p[1]])
            })
        };
        let h0 = m.vertex_halfedge(p);
        let Some(a0) = rel(h0) else {
            return Vec::new();
        };
        // (departure, ψ at its start, ψ at its end) in counter-clockwise order.
        let mut segs: Vec<(Departure, f64, f64)> = Vec::new();
        let (mut h, mut a) = (h0, a0);
        for _ in 0..=m.valence(p) {
            let (Some(th), Some(rn)) = (corner(h), rel(m.he_twin(m.he_prev(h)))) else {
                return Vec::new();
            };
            let next = m.he_twin(m.he_prev(h));
            let b = a - th;
            let an = b + wrap(rn - b);
            segs.push((Departure::Face(h), a, b));
            segs.push((Departure::Edge(next), b, an));
            (h, a) = (next, an);
            if h == h0 {
                break;
            }
        }
        if h != h0 {
            return Vec::new();
        }
        let mut out = Vec::new();
        let mut level = offset + 2.0 * PI * ((a0 - offset) / (2.0 * PI)).floor();
        while level > a && out.len() <= segs.len() {
            // The last passage through `level` (after it ψ stays below).
            if let Some(s) = segs.iter().rev().find(|s| s.1.max(s.2) >= level) {
                if s.2 < level {
                    out.push(s.0);
                }
            }
            level -= 2.0 * PI;
        }
        out
    }

    /// Arrive at parameter `tau` of the local edge `k` (half-edge `3f + k`) of face `f`.
    fn arrive(&self, f: u32, k: u32, tau: f64, tr: &mut Trajectory) -> At {
        let e = 3 * f + k;
        let m = self.mesh;
        let v = if tau < 1e-9 {
            Some(m.he_origin(e))
        } else if tau > 1.0 - 1e-9 {
            Some(m.he_tip(e))
        } else {
            None
        };
        match v {
            Some(v) => {
                tr.points.push(EdgePoint::vertex(v));
                At::Vertex(v)
            }
            None => {
                tr.points.push(EdgePoint {
                    from: m.he_origin(e),
                    to: m.he_tip(e),
                    t: tau,
                });
                At::Edge(e, tau)
            }
        }
    }

    /// Run along half-edge `h` from its origin at parameter `s` to its tip (or back to its
    /// origin when `Re φ` increases that way), if that is the direction of the trajectory.
    fn slide(&self, h: u32, s: f64, dir: f64, tr: &mut Trajectory) -> Option<At> {
        let r = on_halfedge(self.mesh, self.re, h);
        if r == 0.0 || r.is_nan() {
            return None;
        }
        let (v, frac) = if dir * r > 0.0 {
            (self.mesh.he_tip(h), 1.0 - s)
        } else {
            (self.mesh.he_origin(h), s)
        };
        tr.length += r.abs() * frac;
        tr.points.push(EdgePoint::vertex(v));
        Some(At::Vertex(v))
    }

    /// Leave a vertex by a departure.
    fn leave(&self, dep: Departure, dir: f64, tr: &mut Trajectory) -> Option<At> {
        match dep {
            Departure::Edge(h) => {
                // Only if `Re φ` changes the right way along the edge (it does when the
                // fields of both faces point at it).
                if dir * on_halfedge(self.mesh, self.re, h) > 0.0 {
                    self.slide(h, 0.0, dir, tr)
                } else {
                    None
                }
            }
            Departure::Face(h) => {
                let (x, d) = self.frame(h)?;
                let c = corners(&d);
                let i = (h % 3) as usize;
                let v = [dir * x[0], dir * x[1]];
                let k = (i + 1) % 3;
                let (s, tau) = hit(c[i], v, c[k], c[(k + 1) % 3])?;
                tr.length += s * (x[0] * x[0] + x[1] * x[1]);
                Some(self.arrive(h / 3, k as u32, tau, tr))
            }
        }
    }

    /// Cross the face beyond half-edge `h` (point at parameter `s` on it).
    fn cross_face(&self, h: u32, s: f64, dir: f64, tr: &mut Trajectory) -> Option<At> {
        let t = self.mesh.he_twin(h);
        let (x, d) = self.frame(t)?;
        let c = corners(&d);
        let j = (t % 3) as usize;
        let (a, b) = (c[j], c[(j + 1) % 3]);
        let p = [
            a[0] + (1.0 - s) * (b[0] - a[0]),
            a[1] + (1.0 - s) * (b[1] - a[1]),
        ];
        let v = [dir * x[0], dir * x[1]];
        if cross(d[j], v) <= 0.0 {
            // Both faces' fields point at the edge: run along it.
            return self.slide(t, 1.0 - s, dir, tr);
        }
        let best = [(j + 1) % 3, (j + 2) % 3]
            .into_iter()
            .filter_map(|k| hit(p, v, c[k], c[(k + 1) % 3]).map(|(s, tau)| (s, k, tau)))
            .min_by(|a, b| a.0.total_cmp(&b.0))?;
        tr.length += best.0 * (x[0] * x[0] + x[1] * x[1]);
        Some(self.arrive(t / 3, best.1 as u32, best.2, tr))
    }

    fn trace(
        &self,
        zero: u32,
        outgoing: bool,
        first: Departure,
        length: f64,
        max_faces: usize,
    ) -> Trajectory {
        let dir = if outgoing { 1.0 } else { -1.0 };
        let mut tr = Trajectory {
            zero,
            outgoing,
            points: vec![EdgePoint::vertex(zero)],
            length: 0.0,
        };
        let mut at = self.leave(first, dir, &mut tr);
        for _ in 0..max_faces {
            if tr.length >= length {
                break;
            }
            at = match at {
                Some(At::Edge(h, s)) => self.cross_face(h, s, dir, &mut tr),
                Some(At::Vertex(v)) if !self.stop[v as usize] => {
                    let offset = if outgoing { 0.0 } else { PI };
                    match self.departures(v, offset).first() {
                        Some(&d) => self.leave(d, dir, &mut tr),
                        None => None,
                    }
                }
                _ => break,
            };
        }
        tr
    }
}

/// The critical horizontal trajectories from each of the vertices `zeros` (zeros of `form`
/// on a mesh with Euclidean edge lengths `lengths`; module docs): `2(m + 1)` from a zero of
/// order `m`, each traced for at most `length` (in `∫|ω|`) and `max_faces` faces.
pub fn critical_trajectories(
    mesh: &Mesh,
    metric: &IntrinsicMetric,
    form: &HolomorphicForm,
    zeros: &[u32],
    length: f64,
    max_faces: usize,
) -> Vec<Trajectory> {
    let lengths = metric.lengths();
    let frames = (0..mesh.n_faces() as u32)
        .map(|f| face_vector(mesh, lengths, &form.re, f))
        .collect();
    let mut stop = vec![false; mesh.n_vertices()];
    for &p in zeros {
        if let Some(s) = stop.get_mut(p as usize) {
            *s = true;
        }
    }
    let field = Field {
        mesh,
        re: &form.re,
        frames,
        stop,
    };
    let mut out = Vec::new();
    for &p in zeros {
        if (p as usize) >= mesh.n_vertices() {
            continue;
        }
        for (outgoing, offset) in [(true, 0.0), (false, PI)] {
            for d in field.departures(p, offset) {
                out.push(field.trace(p, outgoing, d, length, max_faces));
            }
        }
    }
    out
}
