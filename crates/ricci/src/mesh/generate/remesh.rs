//! Isotropic remeshing of a closed triangle mesh onto an implicit surface (Botsch & Kobbelt,
//! "A remeshing approach to multiresolution modeling", 2004), followed by an angle-improving
//! pass.
//!
//! One remeshing iteration with target edge length `L`:
//! 1. split every edge longer than `4/3 L` at its midpoint;
//! 2. collapse every edge shorter than `4/5 L` into its midpoint, unless that breaks the link
//!    condition (topology change), creates an edge longer than `4/3 L`, or folds a face (its
//!    normal leaves the 60° cone around the surface normal `∇f`);
//! 3. flip edges that bring the four valences closer to 6;
//! 4. tangential relaxation: move every vertex towards the mean of its neighbours, within the
//!    tangent plane;
//! 5. project every vertex back onto `f = 0` by Newton steps along `∇f`.
//!
//! Every operation is a local homeomorphism (split, flip of an edge whose diagonal is not an
//! edge yet, collapse under the link condition), so the topology of the input is preserved.
//!
//! The angle-improving pass alternates flips that raise the smaller minimum angle of two
//! adjacent faces with a per-vertex pattern search that moves a vertex within the surface to
//! maximise the smallest angle of its star.
//!
//! All loops run in index order and never iterate over hash maps: the output is deterministic.

use super::geom::*;
use crate::error::{Error, Result};

const NONE: u32 = u32::MAX;

/// A smooth implicit surface `f = 0`, `f < 0` inside, `∇f` pointing out.
pub trait Implicit {
    fn value(&self, p: [f64; 3]) -> f64;
    fn gradient(&self, p: [f64; 3]) -> [f64; 3];

    /// Newton projection along the gradient onto `f = 0` (stops at `|f| ≤ 1e-12` or after 30
    /// steps; each step is limited to `max_step` so a bad start cannot jump to another sheet).
    fn project(&self, mut p: [f64; 3], max_step: f64) -> [f64; 3] {
        for _ in 0..30 {
            let f = self.value(p);
            if f.abs() <= 1e-12 {
                break;
            }
            let g = self.gradient(p);
            let g2 = dot(g, g);
            if g2 < 1e-24 {
                break;
            }
            let mut step = scale(g, -f / g2);
            let s = norm(step);
            if s > max_step {
                step = scale(step, max_step / s);
            }
            p = add(p, step);
        }
        p
    }

    /// Unit outward normal at `p`.
    fn normal(&self, p: [f64; 3]) -> [f64; 3] {
        let g = self.gradient(p);
        let n = norm(g);
        if n > 0.0 {
            scale(g, 1.0 / n)
        } else {
            [0.0, 0.0, 1.0]
        }
    }
}

/// Mutable half-edge mesh of a closed oriented surface. Half-edge `3f + i` goes from
/// `faces[f][i]` to `faces[f][(i+1)%3]` (the convention of [`crate::mesh::Mesh`]).
pub(crate) struct TriMesh {
    pub pos: Vec<P3>,
    pub faces: Vec<[u32; 3]>,
    twin: Vec<u32>,
    /// One outgoing half-edge per vertex; `NONE` for removed vertices.
    vhe: Vec<u32>,
    valence: Vec<u32>,
    fdead: Vec<bool>,
}

#[inline]
fn next(h: u32) -> u32 {
    3 * (h / 3) + (h % 3 + 1) % 3
}
#[inline]
fn prev(h: u32) -> u32 {
    3 * (h / 3) + (h % 3 + 2) % 3
}

impl TriMesh {
    /// Build from a closed, consistently oriented, manifold triangle list.
    pub fn new(pos: Vec<P3>, faces: Vec<[u32; 3]>) -> Result<TriMesh> {
        let nh = 3 * faces.len();
        let mut keyed: Vec<(u64, u32)> = (0..nh as u32)
            .map(|h| {
                let t = faces[h as usize / 3];
                let (a, b) = (t[h as usize % 3], t[(h as usize % 3 + 1) % 3]);
                ((a.min(b) as u64) << 32 | a.max(b) as u64, h)
            })
            .collect();
        keyed.sort_unstable();
        let mut twin = vec![NONE; nh];
        if keyed.len() % 2 == 1 {
            return Err(Error::numerical(
                "remeshing: the surface mesh is not closed (odd number of half-edges)",
            ));
        }
        for pair in keyed.chunks(2) {
            let (k0, h0) = pair[0];
            let (k1, h1) = pair[1];
            if k0 != k1 {
                return Err(Error::numerical(format!(
                    "remeshing: the surface mesh is not closed (edge {}–{} has one face)",
                    k0 >> 32,
                    k0 as u32
                )));
            }
            twin[h0 as usize] = h1;
            twin[h1 as usize] = h0;
        }
        for w in keyed.windows(3) {
            if w[0].0 == w[2].0 {
                return Err(Error::numerical(format!(
                    "remeshing: edge {}–{} has more than two faces",
                    w[0].0 >> 32,
                    w[0].0 as u32
                )));
            }
        }
        let mut vhe = vec![NONE; pos.len()];
        let mut valence = vec![0u32; pos.len()];
        for h in 0..nh as u32 {
            let v = faces[h as usize / 3][h as usize % 3] as usize;
            if vhe[v] == NONE {
                vhe[v] = h;
            }
            valence[v] += 1;
        }
        let m = TriMesh {
            pos,
            fdead: vec![false; faces.len()],
            faces,
            twin,
            vhe,
            valence,
        };
        // Every vertex must have exactly one fan.
        let mut ring = Vec::new();
        for v in 0..m.pos.len() as u32 {
            if m.vhe[v as usize] == NONE {
                continue;
            }
            m.ring(v, &mut ring);
            if ring.len() != m.valence[v as usize] as usize {
                return Err(Error::numerical(format!(
                    "remeshing: vertex {v} is not manifold"
                )));
            }
        }
        Ok(m)
    }

    #[inline]
    fn org(&self, h: u32) -> u32 {
        self.faces[h as usize / 3][h as usize % 3]
    }
    #[inline]
    fn dst(&self, h: u32) -> u32 {
        self.org(next(h))
    }
    #[inline]
    fn p(&self, v: u32) -> P3 {
        self.pos[v as usize]
    }

    /// Outgoing half-edges of `v`, counter-clockwise.
    fn ring(&self, v: u32, out: &mut Vec<u32>) {
        out.clear();
        let start = self.vhe[v as usize];
        if start == NONE {
            return;
        }
        let mut h = start;
        loop {
            out.push(h);
            h = self.twin[prev(h) as usize];
            if h == start || out.len() > 10_000 {
                break;
            }
        }
    }

    fn find_he(&self, a: u32, b: u32) -> Option<u32> {
        let start = self.vhe[a as usize];
        if start == NONE {
            return None;
        }
        let mut h = start;
        for _ in 0..10_000 {
            if self.dst(h) == b {
                return Some(h);
            }
            h = self.twin[prev(h) as usize];
            if h == start {
                break;
            }
        }
        None
    }

    fn link(&mut self, h: u32, g: u32) {
        self.twin[h as usize] = g;
        self.twin[g as usize] = h;
    }

    fn live_faces(&self) -> impl Iterator<Item = u32> + '_ {
        (0..self.faces.len() as u32).filter(|&f| !self.fdead[f as usize])
    }

    /// Split the edge of half-edge `h` at point `p`; returns the new vertex.
    fn split(&mut self, h: u32, p: P3) -> u32 {
        let t = self.twin[h as usize];
        let (f0, f1) = (h / 3, t / 3);
        let (a, b, c) = (self.org(h), self.dst(h), self.org(prev(h)));
        let d = self.org(prev(t));
        let t_bc = self.twin[next(h) as usize];
        let t_ca = self.twin[prev(h) as usize];
        let t_ad = self.twin[next(t) as usize];
        let t_db = self.twin[prev(t) as usize];
        let m = self.pos.len() as u32;
        self.pos.push(p);
        self.vhe.push(NONE);
        self.valence.push(4);
        let f2 = self.faces.len() as u32;
        let f3 = f2 + 1;
        self.faces.push([m, b, c]);
        self.faces.push([m, a, d]);
        self.fdead.push(false);
        self.fdead.push(false);
        self.twin.extend([NONE; 6]);
        self.faces[f0 as usize] = [a, m, c];
        self.faces[f1 as usize] = [b, m, d];
        self.link(3 * f0, 3 * f3);
        self.link(3 * f0 + 1, 3 * f2 + 2);
        self.link(3 * f0 + 2, t_ca);
        self.link(3 * f2, 3 * f1);
        self.link(3 * f2 + 1, t_bc);
        self.link(3 * f1 + 1, 3 * f3 + 2);
        self.link(3 * f1 + 2, t_db);
        self.link(3 * f3 + 1, t_ad);
        self.vhe[a as usize] = 3 * f0;
        self.vhe[b as usize] = 3 * f2 + 1;
        self.vhe[c as usize] = 3 * f0 + 2;
        self.vhe[d as usize] = 3 * f1 + 2;
        self.vhe[m as usize] = 3 * f0 + 1;
        self.valence[c as usize] += 1;
        self.valence[d as usize] += 1;
        m
    }

    /// The quad `(a, b, c, d)` around the edge of `h = a→b` (c in h's face, d in the twin's).
    fn quad(&self, h: u32) -> [u32; 4] {
        let t = self.twin[h as usize];
        [
            self.org(h),
            self.dst(h),
            self.org(prev(h)),
            self.org(prev(t)),
        ]
    }

    /// Flip the edge of `h` (the caller checked that the other diagonal is not an edge).
    fn flip(&mut self, h: u32) {
        let t = self.twin[h as usize];
        let (f0, f1) = (h / 3, t / 3);
        let [a, b, c, d] = self.quad(h);
        let t_bc = self.twin[next(h) as usize];
        let t_ca = self.twin[prev(h) as usize];
        let t_ad = self.twin[next(t) as usize];
        let t_db = self.twin[prev(t) as usize];
        self.faces[f0 as usize] = [c, a, d];
        self.faces[f1 as usize] = [d, b, c];
        self.link(3 * f0, t_ca);
        self.link(3 * f0 + 1, t_ad);
        self.link(3 * f0 + 2, 3 * f1 + 2);
        self.link(3 * f1, t_db);
        self.link(3 * f1 + 1, t_bc);
        self.vhe[a as usize] = 3 * f0 + 1;
        self.vhe[b as usize] = 3 * f1 + 1;
        self.vhe[c as usize] = 3 * f0;
        self.vhe[d as usize] = 3 * f1;
        self.valence[a as usize] -= 1;
        self.valence[b as usize] -= 1;
        self.valence[c as usize] += 1;
        self.valence[d as usize] += 1;
    }

    /// Whether collapsing the edge of `h` keeps the surface a manifold of the same topology
    /// (link condition: the only common neighbours of its ends are the two opposite vertices).
    fn link_condition(&self, h: u32, ring: &mut Vec<u32>) -> bool {
        let [a, b, c, d] = self.quad(h);
        if self.valence[c as usize] <= 3 || self.valence[d as usize] <= 3 {
            return false;
        }
        if self.valence[a as usize] + self.valence[b as usize] <= 6 {
            return false;
        }
        self.ring(b, ring);
        let nb: Vec<u32> = ring.iter().map(|&g| self.dst(g)).collect();
        self.ring(a, ring);
        let mut common = 0;
        for &g in ring.iter() {
            let x = self.dst(g);
            if nb.contains(&x) {
                if x != c && x != d {
                    return false;
                }
                common += 1;
            }
        }
        common == 2
    }

    /// Collapse the edge of `h = a→b`, moving `a` to `p` and removing `b`.
    fn collapse(&mut self, h: u32, p: P3, ring: &mut Vec<u32>) {
        let t = self.twin[h as usize];
        let [a, b, c, d] = self.quad(h);
        let t1 = self.twin[next(h) as usize]; // c→b
        let t2 = self.twin[prev(h) as usize]; // a→c
        let t3 = self.twin[next(t) as usize]; // d→a
        let t4 = self.twin[prev(t) as usize]; // b→d
        self.ring(b, ring);
        for &g in ring.iter() {
            self.faces[g as usize / 3][g as usize % 3] = a;
        }
        self.link(t1, t2);
        self.link(t3, t4);
        for f in [h / 3, t / 3] {
            self.fdead[f as usize] = true;
            for i in 0..3 {
                self.twin[3 * f as usize + i] = NONE;
            }
        }
        self.vhe[a as usize] = t2;
        self.vhe[c as usize] = t1;
        self.vhe[d as usize] = t3;
        self.vhe[b as usize] = NONE;
        self.valence[a as usize] += self.valence[b as usize] - 4;
        self.valence[c as usize] -= 1;
        self.valence[d as usize] -= 1;
        self.valence[b as usize] = 0;
        self.pos[a as usize] = p;
    }

    /// Remove dead faces and vertices; returns positions and faces.
    pub fn into_parts(self) -> (Vec<P3>, Vec<[u32; 3]>) {
        let mut id = vec![NONE; self.pos.len()];
        let mut pos = Vec::new();
        for (v, (&h, &p)) in self.vhe.iter().zip(&self.pos).enumerate() {
            if h != NONE {
                id[v] = pos.len() as u32;
                pos.push(p);
            }
        }
        let faces = self
            .live_faces()
            .map(|f| self.faces[f as usize].map(|v| id[v as usize]))
            .collect();
        (pos, faces)
    }

    pub fn n_faces(&self) -> usize {
        self.fdead.iter().filter(|d| !**d).count()
    }

    /// Edges as `(length², half-edge)` with `h < twin(h)`, live faces only.
    fn edges(&self) -> Vec<(f64, u32)> {
        let mut out = Vec::with_capacity(self.faces.len() * 3 / 2);
        for f in self.live_faces() {
            for h in 3 * f..3 * f + 3 {
                if h < self.twin[h as usize] {
                    let l = dist(self.p(self.org(h)), self.p(self.dst(h)));
                    out.push((l, h));
                }
            }
        }
        out
    }

    /// Whether some face around `v` folds over (normal outside the cone of half-angle
    /// acos(`cos_limit`) around `up`) when `v` is at `p`.
    fn star_folds(&self, p: P3, up: P3, cos_limit: f64, ring: &[u32]) -> bool {
        ring.iter().any(|&g| {
            let n = tri_normal(p, self.p(self.dst(g)), self.p(self.org(prev(g))));
            let nn = norm(n) * norm(up);
            nn == 0.0 || dot(n, up) <= cos_limit * nn
        })
    }

    /// Smallest angle among the faces around `v` when `v` is at `p` (`-1` if one folds over,
    /// i.e. its normal leaves the cone of half-angle acos(`cos_limit`) around `up`).
    fn star_quality(&self, p: P3, up: P3, cos_limit: f64, ring: &[u32]) -> f64 {
        let mut q = f64::INFINITY;
        for &g in ring {
            let (x, y) = (self.p(self.dst(g)), self.p(self.org(prev(g))));
            q = q.min(oriented_min_angle(p, x, y, up, cos_limit));
            if q < 0.0 {
                return q;
            }
        }
        q
    }
}

/// Settings of [`remesh`].
pub(crate) struct RemeshParams {
    pub target_edge: f64,
    pub iterations: usize,
    /// Rounds of the angle-improving pass.
    pub quality_rounds: usize,
}

/// Remesh `m` (closed) onto the implicit surface `field`.
pub(crate) fn remesh<F: Implicit>(
    m: &mut TriMesh,
    field: &F,
    params: &RemeshParams,
    progress: &mut dyn crate::progress::Progress,
) {
    let l = params.target_edge;
    let (lo, hi) = (0.8 * l, 4.0 / 3.0 * l);
    let max_step = 0.5 * l;
    let total = (params.iterations + params.quality_rounds) as f64;
    for v in 0..m.pos.len() {
        if m.vhe[v] != NONE {
            m.pos[v] = field.project(m.pos[v], max_step);
        }
    }
    for it in 0..params.iterations {
        progress.report(
            "remesh",
            Some(it as f64 / total),
            &format!("iteration {}: {} faces", it + 1, m.n_faces()),
        );
        split_long_edges(m, field, hi, max_step);
        collapse_short_edges(m, field, lo, hi, max_step);
        equalize_valences(m, field);
        tangential_relaxation(m, field, max_step);
    }
    for round in 0..params.quality_rounds {
        progress.report(
            "remesh",
            Some((params.iterations + round) as f64 / total),
            &format!("angle improvement round {}", round + 1),
        );
        improving_flips(m, field);
        optimize_vertices(m, field, l, max_step);
    }
}

/// Cosine of the largest accepted angle between a face normal and the surface normal.
const COS_FOLD: f64 = 0.5;

fn face_ok<F: Implicit>(field: &F, a: P3, b: P3, c: P3) -> bool {
    let cen = scale(add(add(a, b), c), 1.0 / 3.0);
    let n = tri_normal(a, b, c);
    let g = field.gradient(cen);
    let nn = norm(n) * norm(g);
    nn > 0.0 && dot(n, g) > COS_FOLD * nn
}

fn split_long_edges<F: Implicit>(m: &mut TriMesh, field: &F, hi: f64, max_step: f64) {
    // Repeat until no long edge is left (each pass at most halves the long ones).
    for _ in 0..8 {
        let mut long: Vec<(f64, u32, u32)> = m
            .edges()
            .into_iter()
            .filter(|e| e.0 > hi)
            .map(|(l, h)| (l, m.org(h), m.dst(h)))
            .collect();
        if long.is_empty() {
            return;
        }
        long.sort_by(|x, y| y.0.total_cmp(&x.0).then((x.1, x.2).cmp(&(y.1, y.2))));
        for (_, a, b) in long {
            let Some(h) = m.find_he(a, b) else { continue };
            let (pa, pb) = (m.p(a), m.p(b));
            if dist(pa, pb) <= hi {
                continue;
            }
            let p = field.project(lerp(pa, pb, 0.5), max_step);
            m.split(h, p);
        }
    }
}

fn collapse_short_edges<F: Implicit>(m: &mut TriMesh, field: &F, lo: f64, hi: f64, max_step: f64) {
    let mut ring = Vec::new();
    let mut ring_b = Vec::new();
    for _ in 0..4 {
        let mut short: Vec<(f64, u32, u32)> = m
            .edges()
            .into_iter()
            .filter(|e| e.0 < lo)
            .map(|(l, h)| (l, m.org(h), m.dst(h)))
            .collect();
        if short.is_empty() {
            return;
        }
        short.sort_by(|x, y| x.0.total_cmp(&y.0).then((x.1, x.2).cmp(&(y.1, y.2))));
        let mut done = 0;
        for (_, a, b) in short {
            if m.vhe[a as usize] == NONE || m.vhe[b as usize] == NONE {
                continue;
            }
            let Some(h) = m.find_he(a, b) else { continue };
            let (pa, pb) = (m.p(a), m.p(b));
            if dist(pa, pb) >= lo {
                continue;
            }
            if !m.link_condition(h, &mut ring) {
                continue;
            }
            let p = field.project(lerp(pa, pb, 0.5), max_step);
            // Check the faces that survive around a and b with the moved vertex.
            let (f0, f1) = (h / 3, m.twin[h as usize] / 3);
            let mut ok = true;
            m.ring(a, &mut ring);
            m.ring(b, &mut ring_b);
            for &g in ring.iter().chain(ring_b.iter()) {
                if g / 3 == f0 || g / 3 == f1 {
                    continue;
                }
                let (x, y) = (m.p(m.dst(g)), m.p(m.org(prev(g))));
                if dist(p, x) > hi || !face_ok(field, p, x, y) {
                    ok = false;
                    break;
                }
            }
            if ok {
                m.collapse(h, p, &mut ring);
                done += 1;
            }
        }
        if done == 0 {
            return;
        }
    }
}

fn equalize_valences<F: Implicit>(m: &mut TriMesh, field: &F) {
    let dev = |v: u32, m: &TriMesh| (m.valence[v as usize] as i64 - 6).abs();
    for h in 0..m.faces.len() as u32 * 3 {
        if m.fdead[h as usize / 3] || h > m.twin[h as usize] {
            continue;
        }
        let [a, b, c, d] = m.quad(h);
        if m.valence[a as usize] <= 4 || m.valence[b as usize] <= 4 {
            continue;
        }
        let before = dev(a, m) + dev(b, m) + dev(c, m) + dev(d, m);
        let after = (m.valence[a as usize] as i64 - 7).abs()
            + (m.valence[b as usize] as i64 - 7).abs()
            + (m.valence[c as usize] as i64 - 5).abs()
            + (m.valence[d as usize] as i64 - 5).abs();
        if after >= before || m.find_he(c, d).is_some() {
            continue;
        }
        let (pa, pb, pc, pd) = (m.p(a), m.p(b), m.p(c), m.p(d));
        if !face_ok(field, pc, pa, pd) || !face_ok(field, pd, pb, pc) {
            continue;
        }
        m.flip(h);
    }
}

fn tangential_relaxation<F: Implicit>(m: &mut TriMesh, field: &F, max_step: f64) {
    let mut ring = Vec::new();
    let mut target = m.pos.clone();
    for v in 0..m.pos.len() as u32 {
        if m.vhe[v as usize] == NONE {
            continue;
        }
        m.ring(v, &mut ring);
        let mut c = [0.0; 3];
        for &g in &ring {
            c = add(c, m.p(m.dst(g)));
        }
        c = scale(c, 1.0 / ring.len() as f64);
        let p = m.p(v);
        let n = field.normal(p);
        let d = sub(c, p);
        let t = sub(d, scale(n, dot(n, d)));
        target[v as usize] = field.project(add(p, t), max_step);
    }
    // Accept a move only where it does not fold a face (checked against the old neighbours).
    for v in 0..m.pos.len() as u32 {
        if m.vhe[v as usize] == NONE {
            continue;
        }
        m.ring(v, &mut ring);
        let p = target[v as usize];
        let up = field.normal(p);
        if !m.star_folds(p, up, COS_FOLD, &ring) {
            m.pos[v as usize] = p;
        }
    }
}

/// Flip edges where that raises the smaller of the two faces' minimum angles, as long as the
/// new faces do not fold and the quad is nearly flat (the flip does not cut a ridge).
fn improving_flips<F: Implicit>(m: &mut TriMesh, field: &F) {
    for _ in 0..4 {
        let mut flips = 0;
        for h in 0..m.faces.len() as u32 * 3 {
            if m.fdead[h as usize / 3] || h > m.twin[h as usize] {
                continue;
            }
            let [a, b, c, d] = m.quad(h);
            if m.valence[a as usize] <= 4 || m.valence[b as usize] <= 4 {
                continue;
            }
            let (pa, pb, pc, pd) = (m.p(a), m.p(b), m.p(c), m.p(d));
            let before = min_angle(pa, pb, pc).min(min_angle(pb, pa, pd));
            let after = min_angle(pc, pa, pd).min(min_angle(pd, pb, pc));
            if after <= before + 1e-3 {
                continue;
            }
            // Flatness: the two new faces' normals within 25°, and none folds.
            let (n0, n1) = (tri_normal(pc, pa, pd), tri_normal(pd, pb, pc));
            if dot(n0, n1) < 0.9 * norm(n0) * norm(n1) {
                continue;
            }
            if !face_ok(field, pc, pa, pd) || !face_ok(field, pd, pb, pc) {
                continue;
            }
            if m.find_he(c, d).is_some() {
                continue;
            }
            m.flip(h);
            flips += 1;
        }
        if flips == 0 {
            break;
        }
    }
}

/// Pattern search per vertex (Gauss–Seidel order): try 8 tangent directions, keep the move that
/// raises the smallest angle of the star, halve the step when none does.
fn optimize_vertices<F: Implicit>(m: &mut TriMesh, field: &F, l: f64, max_step: f64) {
    let mut ring = Vec::new();
    let threshold = 40f64.to_radians();
    for v in 0..m.pos.len() as u32 {
        if m.vhe[v as usize] == NONE {
            continue;
        }
        m.ring(v, &mut ring);
        let mut p = m.p(v);
        let mut q = m.star_quality(p, field.normal(p), COS_FOLD, &ring);
        if q >= threshold {
            continue;
        }
        let mut step = 0.2 * l;
        for _ in 0..14 {
            let n = field.normal(p);
            let t1 = {
                let a = if n[0].abs() < 0.9 {
                    [1.0, 0.0, 0.0]
                } else {
                    [0.0, 1.0, 0.0]
                };
                let t = cross(n, a);
                scale(t, 1.0 / norm(t))
            };
            let t2 = cross(n, t1);
            let mut best = (q, p);
            for k in 0..8 {
                let th = k as f64 * std::f64::consts::FRAC_PI_4;
                let d = add(scale(t1, step * th.cos()), scale(t2, step * th.sin()));
                let cand = field.project(add(p, d), max_step);
                let qc = m.star_quality(cand, field.normal(cand), COS_FOLD, &ring);
                if qc > best.0 {
                    best = (qc, cand);
                }
            }
            if best.0 > q {
                q = best.0;
                p = best.1;
            } else {
                step *= 0.5;
            }
            if step < 1e-3 * l {
                break;
            }
        }
        m.pos[v as usize] = p;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::generate::icosphere;

    /// Twins are an involution between opposite half-edges, every live vertex has one closed
    /// fan whose size is its stored valence, and `vhe` leaves its vertex.
    fn check_invariants(m: &TriMesh) -> (usize, usize, usize) {
        let mut ring = Vec::new();
        let (mut v, mut e2, mut f) = (0, 0, 0);
        for face in m.live_faces() {
            f += 1;
            for h in 3 * face..3 * face + 3 {
                let t = m.twin[h as usize];
                assert!(!m.fdead[t as usize / 3], "twin of {h} in a dead face");
                assert_eq!(m.twin[t as usize], h);
                assert_eq!(m.org(t), m.dst(h));
                assert_eq!(m.dst(t), m.org(h));
                e2 += 1;
            }
        }
        for x in 0..m.pos.len() as u32 {
            if m.vhe[x as usize] == NONE {
                continue;
            }
            v += 1;
            assert_eq!(m.org(m.vhe[x as usize]), x);
            m.ring(x, &mut ring);
            assert_eq!(ring.len(), m.valence[x as usize] as usize, "vertex {x}");
            assert!(ring.iter().all(|&h| m.org(h) == x));
        }
        (v, e2 / 2, f)
    }

    fn sphere_mesh() -> TriMesh {
        let s = icosphere(2).unwrap();
        TriMesh::new(s.positions, s.mesh.faces().to_vec()).unwrap()
    }

    #[test]
    fn split_flip_collapse_keep_the_mesh_valid_and_chi() {
        let mut m = sphere_mesh();
        let (v0, e0, f0) = check_invariants(&m);
        assert_eq!(v0 as i64 - e0 as i64 + f0 as i64, 2);
        let mut ring = Vec::new();
        // Deterministic pseudo-random sequence of operations.
        let mut state = 12345u64;
        let mut rand = |n: usize| {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (state >> 33) as usize % n
        };
        let (mut splits, mut flips, mut collapses) = (0, 0, 0);
        for step in 0..600 {
            let live: Vec<u32> = m.live_faces().collect();
            let h = 3 * live[rand(live.len())] + rand(3) as u32;
            match step % 3 {
                0 => {
                    let p = lerp(m.p(m.org(h)), m.p(m.dst(h)), 0.5);
                    m.split(h, p);
                    splits += 1;
                }
                1 => {
                    let [a, b, c, d] = m.quad(h);
                    if m.valence[a as usize] > 3
                        && m.valence[b as usize] > 3
                        && m.find_he(c, d).is_none()
                    {
                        m.flip(h);
                        flips += 1;
                    }
                }
                _ => {
                    if m.link_condition(h, &mut ring) {
                        let p = lerp(m.p(m.org(h)), m.p(m.dst(h)), 0.5);
                        m.collapse(h, p, &mut ring);
                        collapses += 1;
                    }
                }
            }
            let (v, e, f) = check_invariants(&m);
            assert_eq!(
                v as i64 - e as i64 + f as i64,
                2,
                "χ changed at step {step}"
            );
            assert_eq!(f, m.n_faces());
        }
        assert!(splits > 100 && flips > 50 && collapses > 50);
        let (pos, faces) = m.into_parts();
        let s = crate::mesh::Surface::new(pos, faces).unwrap();
        assert_eq!(crate::mesh::topology(&s.mesh).components[0].genus, 0);
    }

    #[test]
    fn link_condition_refuses_a_collapse_that_pinches() {
        // Triangular bipyramid: equator 0, 1, 2, apexes 3 (top) and 4 (bottom). Collapsing an
        // equator edge would glue the two apex fans along the third equator vertex (three
        // common neighbours): refused. Collapsing an apex edge gives a tetrahedron: allowed.
        let pos = vec![
            [1.0, 0.0, 0.0],
            [-0.5, 0.8, 0.0],
            [-0.5, -0.8, 0.0],
            [0.0, 0.0, 1.0],
            [0.0, 0.0, -1.0],
        ];
        let faces = vec![
            [0, 1, 3],
            [1, 2, 3],
            [2, 0, 3],
            [1, 0, 4],
            [2, 1, 4],
            [0, 2, 4],
        ];
        let m = TriMesh::new(pos, faces).unwrap();
        let mut ring = Vec::new();
        for h in 0..18 {
            let equator = m.org(h) < 3 && m.dst(h) < 3;
            assert_eq!(m.link_condition(h, &mut ring), !equator, "half-edge {h}");
        }
        // An open mesh is refused by the constructor.
        assert!(TriMesh::new(vec![[0.0; 3]; 3], vec![[0, 1, 2]]).is_err());
    }
}
