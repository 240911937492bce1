//! Canonical system of loops on a closed surface of genus `g ≥ 1` by **cut-and-paste on the
//! fundamental polygon** (the reduction of the classification of surfaces, paper 002 §6.2.2.1
//! and Fig. 49; the loops themselves are shortest-path loops as in Erickson–Whittlesey). Unlike
//! the greedy of [`super::system`], this construction does not fail from any base vertex.
//!
//! **Phase 1 (a disk).** `2g` simple loops through the base vertex `x`, pairwise disjoint
//! except at `x`, whose Z₂ homology classes are linearly independent: for a one-vertex graph
//! `G` on a closed surface `S`, the exact sequence `0 → H₂(S) → H₂(S, G) → H₁(G) → H₁(S)` gives
//! `#components(S ∖ G) = 1 + dim ker(H₁(G) → H₁(S))`, so independent classes leave a connected
//! complement, of Euler characteristic `2 − 2g − (1 − 2g) = 1`: a disk. Each loop is the
//! shortest fundamental cycle (tree path, non-tree edge, tree path back) of a Dijkstra tree grown
//! from all free neighbours of `x`, whose two tree paths lie in different branches (so the loop
//! is simple) and whose class, read with the tree–cotree cocycles of [`super::homology`], is
//! independent of the loops found so far. If only a lasso (both paths in one branch) is
//! independent, its return strand is rerouted to `x` around its outgoing strand.
//!
//! **Phase 2 (normalization).** The word of the disk boundary is fixed by the cyclic order of
//! the `4g` loop ends around `x` (a one-vertex ribbon graph: arriving at `x` along end
//! `E_{j+1}` the boundary turns through the sector `j` between `E_j` and `E_{j+1}` and leaves
//! along `E_j`). A cut-and-paste move draws a chord `c` of the disk between two corners (a loop
//! through `x` leaving and returning through two sectors, disjoint from the other loops),
//! cuts the disk along it and glues the two pieces back along a side pair `s` with one copy in
//! each piece: with the disk `α s β | γ s⁻¹ δ` (chord from the corner before `α` to the one
//! between `β` and `γ`) the new disk reads `β c⁻¹ α δ c γ`. On the surface the move replaces the
//! loop `s` by the loop `c`. Every linked pair `a … b … a⁻¹ … b⁻¹` (one always exists among the
//! letters not yet in a commutator block of a one-vertex orientable word) becomes a block
//! `c d c⁻¹ d⁻¹` in two moves; the moves are planned on the word with the other letters grouped
//! into unsplittable blocks (a search over at most `8²·2 · 9²·3` move pairs), a move that
//! completes a block for any linked pair is preferred, and the word is read again from the mesh
//! after every move (sectors are numbered from a fixed loop end, so splits at `x` do not shift
//! them). `g` handles take at most `2g` moves (unit test on random one-vertex words).
//!
//! **Why it does not fail: no pinches.** A chord between two corners exists topologically; in
//! the mesh it is a path through *free* vertices (not on a loop), which exists if the free
//! vertices of the disk are connected and the two sectors of `x` have free neighbours. Call a
//! *chord edge* an uncut edge joining two cut vertices (`x` included), and an *ear* a triangle
//! with two cut edges (a leaf of the dual graph of the cut surface). If every chord edge is
//! the chord of an ear, the free vertices are connected: remove the ears (leaves) from the
//! connected dual graph; every remaining triangle has a free vertex (a triangle with three cut
//! vertices and no two cut edges has a chord edge that is not an ear's), and two remaining
//! triangles sharing an edge share a free vertex. So after every new loop each chord edge at
//! one of its vertices that is not an ear's is split at its midpoint, in place
//! ([`Refiner::split`]: intrinsic and metric-preserving; the new vertex is free, so no new
//! chord edge appears), and the cocycles are carried over to the new edges; when a loop is
//! removed, the chord edges of the ears it made are split. Ears are left alone because the
//! split halves the angle at the ear's apex (often `x`); a sector of `x` that is a single ear
//! is opened (its chord split, the new vertex joined to the free vertex across it) only when a
//! loop or a chord must start there. Only `O(length)` local splits per loop, no mesh rebuild.
//! (Intrinsic flips after the splits would restore angles, but the atlas develops the refined
//! mesh from its split provenance and positions, which flips make inconsistent; none are made.)
//!
//! If the shortest-path search of phase 1 finds no loop with a new class (its start must lie in
//! a sector that is an ear), every such sector is opened and the search repeated once.

mod word;

use super::homology::Cohomology;
use super::system::{RawKind, RawPath, SearchStats};
use crate::error::{Error, Result};
use crate::mesh::{Mesh, NONE};
use crate::metric::refine::Refiner;
use crate::numeric::dijkstra::Dijkstra;
use word::{blocks, plan};

/// Loops and their bookkeeping on a mutable refinement.
struct Loops {
    verts: Vec<u32>,
}

/// The construction state: the refinement being split, the cocycles per half-edge, the loops.
pub(crate) struct Schema {
    r: Refiner,
    x: u32,
    words: usize,
    /// `(ω_k(e))_k` per half-edge of the refiner.
    omega: Vec<u64>,
    /// Loop through every vertex (`NONE` when free; `x` is always cut).
    loop_of: Vec<u32>,
    /// Position of every cut vertex in its loop.
    pos: Vec<u32>,
    loops: Vec<Option<Loops>>,
    /// Echelon basis (pivot bit, vector) of the classes of the current loops (phase 1).
    basis: Vec<(usize, Vec<u64>)>,
    /// The Dijkstra searches (distances, predecessor half-edges).
    search: Dijkstra,
    branch: Vec<u32>,
    parity: Vec<u64>,
    /// Scratch list of outgoing half-edges.
    buf: Vec<u32>,
    pub stats: SearchStats,
    /// Cut-and-paste moves made in phase 2.
    pub moves: usize,
}

/// A side of the disk boundary: the loop, its direction, and the end of the loop it leaves
/// `x` along (the sector before it is the corner before the side).
#[derive(Debug, Clone, Copy)]
struct SideRef {
    lp: u32,
    fwd: bool,
    leave_end: usize,
}

/// Loop ends around `x` (loop, is its start) and free neighbours of `x` with their sectors.
type Rotation = (Vec<(u32, bool)>, Vec<(u32, usize)>);

impl Schema {
    /// Start from the refined mesh (its half-edge ids are the refiner's) with its cocycles.
    /// The cocycles of `coh` per interior half-edge of `mesh` (the half-edge ids of a
    /// [`Refiner`] started from it).
    pub(crate) fn halfedge_cocycles(mesh: &Mesh, coh: &Cohomology) -> Vec<u64> {
        let words = coh.words;
        let nh = mesh.n_corners();
        let mut omega = vec![0u64; nh * words];
        for h in 0..nh {
            omega[h * words..(h + 1) * words].copy_from_slice(coh.edge(mesh.he_edge(h as u32)));
        }
        omega
    }

    /// Start from a refiner with the cocycles per half-edge ([`Schema::halfedge_cocycles`]).
    pub(crate) fn new(r: Refiner, omega: Vec<u64>, words: usize, x: u32) -> Schema {
        Schema {
            r,
            x,
            words,
            omega,
            loop_of: Vec::new(),
            pos: Vec::new(),
            loops: Vec::new(),
            basis: Vec::new(),
            search: Dijkstra::new(0),
            branch: Vec::new(),
            parity: Vec::new(),
            buf: Vec::new(),
            stats: SearchStats {
                attempts: 1,
                ..SearchStats::default()
            },
            moves: 0,
        }
    }

    /// The refinement (to be finished into a mesh; vertex ids are kept).
    pub(crate) fn into_refiner(self) -> Refiner {
        self.r
    }

    fn ensure(&mut self) {
        let nv = self.r.n_vertices();
        if self.loop_of.len() < nv {
            self.loop_of.resize(nv, NONE);
            self.pos.resize(nv, 0);
            self.search.grow(nv);
            self.branch.resize(nv, NONE);
            self.parity.resize(nv * self.words, 0);
        }
    }

    #[inline]
    fn om(&self, h: u32) -> &[u64] {
        &self.omega[h as usize * self.words..(h as usize + 1) * self.words]
    }

    /// Outgoing half-edges of `v` (closed surface: the fan closes).
    fn outgoing(&self, v: u32) -> Vec<u32> {
        let mut out = Vec::with_capacity(8);
        self.for_outgoing(v, |h| out.push(h));
        out
    }

    #[inline]
    fn for_outgoing(&self, v: u32, mut f: impl FnMut(u32)) {
        let h0 = self.r.vertex_corner(v);
        if h0 == NONE {
            return;
        }
        let mut h = h0;
        loop {
            f(h);
            h = self.r.he_twin(Refiner::he_prev(h));
            if h == h0 || h == NONE {
                break;
            }
        }
    }

    #[inline]
    fn free(&self, v: u32) -> bool {
        v != self.x && self.loop_of[v as usize] == NONE
    }

    /// Whether `v` (not `x`) is the first or last vertex after `x` of its (closed) loop.
    fn is_spoke(&self, v: u32) -> bool {
        let l = self.loop_of[v as usize];
        if l == NONE {
            return false;
        }
        let Some(lp) = &self.loops[l as usize] else {
            return false;
        };
        let p = self.pos[v as usize] as usize;
        p == 1 || (lp.verts.last() == Some(&self.x) && p + 2 == lp.verts.len())
    }

    fn is_cut_edge(&self, v: u32, w: u32) -> bool {
        if v == self.x {
            return self.is_spoke(w);
        }
        if w == self.x {
            return self.is_spoke(v);
        }
        let (lv, lw) = (self.loop_of[v as usize], self.loop_of[w as usize]);
        lv != NONE && lv == lw && self.pos[v as usize].abs_diff(self.pos[w as usize]) == 1
    }

    /// Split the edge `v → w` at its midpoint, carrying the cocycles over; the new vertex.
    fn split_edge(&mut self, v: u32, w: u32) -> Option<u32> {
        let h = self
            .outgoing(v)
            .into_iter()
            .find(|&h| self.r.he_tip(h) == w)?;
        let wd = self.words;
        let f = h / 3;
        let i = h % 3;
        let (h_bc, h_ca) = (3 * f + (i + 1) % 3, 3 * f + (i + 2) % 3);
        let ab = self.om(h).to_vec();
        let bc = self.om(h_bc).to_vec();
        let ca = self.om(h_ca).to_vec();
        let hg = self.r.he_twin(h);
        let (gf, ad, db) = if hg != NONE {
            let gf = hg / 3;
            let j = hg % 3;
            (
                gf,
                self.om(3 * gf + (j + 1) % 3).to_vec(),
                self.om(3 * gf + (j + 2) % 3).to_vec(),
            )
        } else {
            (NONE, vec![0; wd], vec![0; wd])
        };
        let nf = self.r.n_faces() as u32;
        let m = self.r.split(h, 0.5);
        self.omega.resize(self.r.n_halfedges() * wd, 0);
        let zero = vec![0u64; wd];
        let xor =
            |a: &[u64], b: &[u64]| -> Vec<u64> { a.iter().zip(b).map(|(p, q)| p ^ q).collect() };
        let mut set = |he: u32, val: &[u64]| {
            self.omega[he as usize * wd..(he as usize + 1) * wd].copy_from_slice(val);
        };
        // f = (a, m, c), f1 = (m, b, c) (see `Refiner::split`).
        set(3 * f, &ab);
        set(3 * f + 1, &bc);
        set(3 * f + 2, &ca);
        let f1 = nf;
        set(3 * f1, &zero);
        set(3 * f1 + 1, &bc);
        set(3 * f1 + 2, &bc);
        if gf != NONE {
            // gf = (b, m, d), g1 = (m, a, d).
            let md = xor(&ad, &ab);
            set(3 * gf, &zero);
            set(3 * gf + 1, &md);
            set(3 * gf + 2, &db);
            let g1 = nf + 1;
            set(3 * g1, &ab);
            set(3 * g1 + 1, &ad);
            set(3 * g1 + 2, &md);
        }
        self.ensure();
        Some(m)
    }

    /// Whether the uncut edge `v → w` (half-edge `h`) has an *ear* on one side: a triangle
    /// whose two other edges are cut. An ear is a leaf of the dual graph of the cut surface,
    /// so its chord edge does not disconnect the free vertices and is left alone (splitting it
    /// would halve the angle at the ear's apex, possibly `x`, for nothing); a sector of `x`
    /// that is a single ear is split when a chord has to start there ([`Schema::chord`]).
    fn is_ear_chord(&self, h: u32) -> bool {
        let t = self.r.he_twin(h);
        [h, t].into_iter().filter(|&g| g != NONE).any(|g| {
            let (v, w) = (self.r.he_origin(g), self.r.he_tip(g));
            let c = self.r.he_origin(Refiner::he_prev(g));
            self.is_cut_edge(w, c) && self.is_cut_edge(c, v)
        })
    }

    /// Split (at the midpoint) every chord edge at the given
    /// vertices: uncut, both ends cut (`x` included), and not the chord of an ear.
    fn depinch_at(&mut self, verts: &[u32]) {
        let x = self.x;
        let mut pairs = Vec::new();
        for &v in verts {
            if v == x || self.loop_of[v as usize] == NONE {
                continue;
            }
            self.for_outgoing(v, |h| {
                let w = self.r.he_tip(h);
                let cut = w == x || self.loop_of[w as usize] != NONE;
                if cut && !self.is_cut_edge(v, w) && !self.is_ear_chord(h) {
                    pairs.push((v.min(w), v.max(w)));
                }
            });
        }
        pairs.sort_unstable();
        pairs.dedup();
        for (a, b) in pairs {
            self.split_edge(a, b);
        }
    }

    /// Split the chord edges at the vertices of loop `l` (see the module docs).
    fn depinch(&mut self, l: usize) {
        let verts = match &self.loops[l] {
            Some(lp) => lp.verts.clone(),
            None => return,
        };
        self.depinch_at(&verts);
    }

    /// Remove loop `l`; the ears it made disappear, so their chord edges may now pinch: they
    /// are split.
    fn remove(&mut self, l: usize) {
        let verts = match &self.loops[l] {
            Some(lp) => lp.verts.clone(),
            None => return,
        };
        self.unmark(l);
        let mut around = Vec::new();
        for &v in &verts {
            if v != self.x {
                self.for_outgoing(v, |h| around.push(self.r.he_tip(h)));
            }
        }
        around.sort_unstable();
        around.dedup();
        self.depinch_at(&around);
    }

    fn mark(&mut self, verts: Vec<u32>) -> usize {
        let id = self.loops.len();
        for (k, &v) in verts.iter().enumerate() {
            if v != self.x {
                self.loop_of[v as usize] = id as u32;
                self.pos[v as usize] = k as u32;
            }
        }
        self.loops.push(Some(Loops { verts }));
        id
    }

    fn unmark(&mut self, l: usize) {
        if let Some(lp) = self.loops[l].take() {
            for &v in &lp.verts {
                if v != self.x && self.loop_of[v as usize] == l as u32 {
                    self.loop_of[v as usize] = NONE;
                }
            }
        }
    }

    fn path_class(&self, verts: &[u32]) -> Option<Vec<u64>> {
        let mut c = vec![0u64; self.words];
        for w in verts.windows(2) {
            let h = self
                .outgoing(w[0])
                .into_iter()
                .find(|&h| self.r.he_tip(h) == w[1])?;
            for (a, b) in c.iter_mut().zip(self.om(h)) {
                *a ^= b;
            }
        }
        Some(c)
    }

    fn reduce(&self, mut c: Vec<u64>) -> Vec<u64> {
        for (pb, b) in &self.basis {
            if c[pb / 64] >> (pb % 64) & 1 == 1 {
                for (p, q) in c.iter_mut().zip(b) {
                    *p ^= q;
                }
            }
        }
        c
    }

    fn independent(&self, c: &[u64]) -> bool {
        if c.len() > 8 {
            return self.reduce(c.to_vec()).iter().any(|&w| w != 0);
        }
        let mut t = [0u64; 8];
        t[..c.len()].copy_from_slice(c);
        for (pb, b) in &self.basis {
            if t[pb / 64] >> (pb % 64) & 1 == 1 {
                for (p, q) in t.iter_mut().zip(b) {
                    *p ^= q;
                }
            }
        }
        t.iter().any(|&w| w != 0)
    }

    fn add_to_basis(&mut self, c: &[u64]) {
        let r = self.reduce(c.to_vec());
        if let Some(k) = r.iter().position(|&w| w != 0) {
            let pb = 64 * k + r[k].trailing_zeros() as usize;
            self.basis.push((pb, r));
        }
    }

    // --- Dijkstra (`crate::numeric::dijkstra`) ---

    fn start_search(&mut self) {
        self.ensure();
        self.search.reset();
        self.stats.searches += 1;
    }
    #[inline]
    fn settled(&self, v: u32) -> bool {
        self.search.is_settled(v)
    }
    #[inline]
    fn offer(&mut self, v: u32, d: f64, h: u32) {
        self.search.offer(v, d, h);
    }
    fn pop(&mut self) -> Option<(f64, u32)> {
        self.search.pop()
    }
    /// `[x, …, v]` along the predecessors of the current search (sources have `pred` from `x`,
    /// or `NONE` for a source at distance 0).
    fn trace(&self, v: u32) -> Vec<u32> {
        let mut out = vec![v];
        let mut cur = v;
        loop {
            let h = self.search.pred(cur);
            if h == NONE {
                break;
            }
            cur = self.r.he_origin(h);
            out.push(cur);
            if cur == self.x {
                break;
            }
        }
        out.reverse();
        out
    }

    // --- Phase 1 ---

    /// A simple loop through `x`, disjoint from the current loops, with a class independent of
    /// theirs (see the module docs).
    fn independent_loop(&mut self) -> Result<()> {
        let x = self.x;
        let wd = self.words;
        self.start_search();
        for h in self.outgoing(x) {
            let n = self.r.he_tip(h);
            if self.free(n) {
                self.offer(n, self.r.length(h), h);
            }
        }
        // Best simple candidate: (length, v, w) with w == x for a non-tree spoke.
        let mut best: Option<(f64, u32, u32)> = None;
        let mut lassos: Vec<(f64, u32, u32)> = Vec::new();
        let mut cls = vec![0u64; wd];
        while let Some((d, v)) = self.pop() {
            if let Some((bl, _, _)) = best {
                if 2.0 * d >= bl {
                    break;
                }
            }
            let hp = self.search.pred(v);
            let u = self.r.he_origin(hp);
            let vi = v as usize;
            if u == x {
                self.branch[vi] = v;
                let o = self.om(hp).to_vec();
                self.parity[vi * wd..(vi + 1) * wd].copy_from_slice(&o);
            } else {
                self.branch[vi] = self.branch[u as usize];
                for k in 0..wd {
                    self.parity[vi * wd + k] =
                        self.parity[u as usize * wd + k] ^ self.omega[hp as usize * wd + k];
                }
            }
            let mut buf = std::mem::take(&mut self.buf);
            buf.clear();
            self.for_outgoing(v, |h| buf.push(h));
            for &h in &buf {
                let w = self.r.he_tip(h);
                let l = self.r.length(h);
                if w == x {
                    if self.r.he_twin(h) == hp {
                        continue;
                    }
                    for (k, c) in cls.iter_mut().enumerate() {
                        *c = self.parity[vi * wd + k] ^ self.omega[h as usize * wd + k];
                    }
                    self.stats.candidates_tried += 1;
                    if self.independent(&cls) && best.is_none_or(|b| d + l < b.0) {
                        best = Some((d + l, v, x));
                    }
                    continue;
                }
                if !self.free(w) {
                    continue;
                }
                if self.settled(w) {
                    if self.r.he_twin(h) == hp {
                        continue;
                    }
                    let wi = w as usize;
                    for (k, c) in cls.iter_mut().enumerate() {
                        *c = self.parity[vi * wd + k]
                            ^ self.parity[wi * wd + k]
                            ^ self.omega[h as usize * wd + k];
                    }
                    let len = d + self.search.dist(w) + l;
                    if best.is_some_and(|b| len >= b.0) {
                        continue;
                    }
                    self.stats.candidates_tried += 1;
                    if !self.independent(&cls) {
                        continue;
                    }
                    if self.branch[vi] != self.branch[wi] {
                        best = Some((len, v, w));
                    } else {
                        lassos.push((len, v, w));
                    }
                } else {
                    self.offer(w, d + l, h);
                }
            }
            self.buf = buf;
        }
        if let Some((_, v, w)) = best {
            let mut verts = self.trace(v);
            if w == x {
                verts.push(x);
            } else {
                let mut back = self.trace(w);
                back.reverse();
                verts.extend(back);
            }
            return self.accept(verts);
        }
        lassos.sort_by(|a, b| a.0.total_cmp(&b.0));
        lassos.truncate(8);
        // Keep the traces: rerouting runs new searches.
        let traced: Vec<(Vec<u32>, Vec<u32>)> = lassos
            .iter()
            .map(|&(_, u, w)| (self.trace(u), self.trace(w)))
            .collect();
        for (tu, tw) in traced {
            if self.try_lasso(tu, tw)? {
                return Ok(());
            }
        }
        Err(Error::numerical(format!(
            "no simple loop through vertex {x} with a new homology class was found after {} loops",
            self.basis.len()
        )))
    }

    fn accept(&mut self, verts: Vec<u32>) -> Result<()> {
        let class = self.path_class(&verts).ok_or_else(|| {
            Error::numerical("internal error: a loop of the cut uses a missing edge")
        })?;
        self.add_to_basis(&class);
        let id = self.mark(verts);
        self.depinch(id);
        Ok(())
    }

    /// Lasso `x … z … u → w … z`: keep the strand to `u` (the longer tree path), reroute the
    /// return from `w` to any free neighbour of `x` around it.
    fn try_lasso(&mut self, tu: Vec<u32>, tw: Vec<u32>) -> Result<bool> {
        let x = self.x;
        let (a, w) = if tu.contains(tw.last().unwrap_or(&NONE)) {
            let u = *tu.last().unwrap_or(&NONE);
            (tw, u)
        } else {
            let w = *tw.last().unwrap_or(&NONE);
            (tu, w)
        };
        if a.contains(&w) || !self.free(w) {
            return Ok(false);
        }
        if a.iter().skip(1).any(|&v| !self.free(v)) {
            return Ok(false);
        }
        let tmp = self.mark(a.clone());
        self.depinch(tmp);
        let mut xn = Vec::new();
        for h in self.outgoing(x) {
            xn.push(self.r.he_tip(h));
        }
        self.start_search();
        let mut is_target = std::collections::HashSet::new();
        for &n in &xn {
            if self.free(n) {
                is_target.insert(n);
            }
        }
        self.offer(w, 0.0, NONE);
        let mut end = None;
        while let Some((_, v)) = self.pop() {
            if is_target.contains(&v) {
                end = Some(v);
                break;
            }
            let mut buf = std::mem::take(&mut self.buf);
            buf.clear();
            self.for_outgoing(v, |h| buf.push(h));
            for &h in &buf {
                let z = self.r.he_tip(h);
                if self.free(z) && !self.settled(z) {
                    let l = self.r.length(h);
                    self.offer(z, self.search.dist(v) + l, h);
                }
            }
            self.buf = buf;
        }
        self.unmark(tmp);
        self.loops.pop();
        let Some(t) = end else {
            return Ok(false);
        };
        // Path w → t from the predecessors.
        let mut back = vec![t];
        let mut cur = t;
        while cur != w {
            cur = self.r.he_origin(self.search.pred(cur));
            back.push(cur);
        }
        back.reverse();
        let mut verts = a;
        verts.extend(back);
        verts.push(x);
        let Some(class) = self.path_class(&verts) else {
            return Ok(false);
        };
        if !self.independent(&class) {
            return Ok(false);
        }
        self.accept(verts)?;
        Ok(true)
    }

    // --- the ribbon graph at x ---

    /// Loop ends around `x` counter-clockwise (loop, is its start), and the sector of every
    /// free neighbour of `x` (sector `j` lies between ends `j` and `j + 1`).
    fn rotation(&self) -> Rotation {
        let x = self.x;
        let mut ends = Vec::new();
        let mut free_nbrs = Vec::new();
        for h in self.outgoing(x) {
            let n = self.r.he_tip(h);
            if self.free(n) {
                free_nbrs.push((n, ends.len()));
                continue;
            }
            if self.is_spoke(n) {
                let l = self.loop_of[n as usize];
                let start = self.pos[n as usize] == 1;
                ends.push((l, start));
            }
        }
        let ne = ends.len();
        // Number from a fixed end (the start of the loop with the smallest id), so that the
        // numbering does not depend on where the fan of `x` starts (splits move it).
        let r = (0..ne)
            .filter(|&k| ends[k].1)
            .min_by_key(|&k| ends[k].0)
            .unwrap_or(0);
        let ends: Vec<(u32, bool)> = ends[r..].iter().chain(&ends[..r]).copied().collect();
        // Neighbours before the first end lie in the last sector.
        let free_nbrs = free_nbrs
            .into_iter()
            .map(|(n, k)| (n, (k + 2 * ne - 1 - r) % ne.max(1)))
            .collect();
        (ends, free_nbrs)
    }

    /// The boundary word of the cut (one face of the ribbon graph per returned vector).
    fn faces(ends: &[(u32, bool)]) -> Vec<Vec<SideRef>> {
        let n = ends.len();
        let mut partner = vec![0usize; n];
        for i in 0..n {
            for j in 0..n {
                if i != j && ends[i].0 == ends[j].0 {
                    partner[i] = j;
                }
            }
        }
        let mut seen = vec![false; n];
        let mut out = Vec::new();
        for s in 0..n {
            if seen[s] {
                continue;
            }
            let mut face = Vec::new();
            let mut j = s;
            while !seen[j] {
                seen[j] = true;
                face.push(SideRef {
                    lp: ends[j].0,
                    fwd: ends[j].1,
                    leave_end: j,
                });
                j = (partner[j] + n - 1) % n;
            }
            out.push(face);
        }
        out
    }

    /// Sector `j` of `x` without a free neighbour is one ear `(x, n_j, n_{j+1})`: split its
    /// chord edge; the new vertex is joined to the free vertex across it.
    fn open_sector(&mut self, j: usize) {
        let x = self.x;
        let (ends, _) = self.rotation();
        let ne = ends.len();
        let mut tips = Vec::new();
        for h in self.outgoing(x) {
            let n = self.r.he_tip(h);
            if !self.free(n) && self.is_spoke(n) {
                tips.push(n);
            }
        }
        if tips.len() != ne || ne == 0 {
            return;
        }
        // The same numbering as `rotation`.
        let first = tips
            .iter()
            .position(|&n| {
                let l = self.loop_of[n as usize];
                (l, self.pos[n as usize] == 1) == ends[0]
            })
            .unwrap_or(0);
        tips.rotate_left(first);
        let (a, b) = (tips[j], tips[(j + 1) % ne]);
        self.split_edge(a, b);
    }

    /// Shortest chord of the disk from a free neighbour of `x` in sector `p` to one in sector
    /// `q`, as a loop `[x, …, x]`.
    fn chord(&mut self, p: usize, q: usize) -> Option<Vec<u32>> {
        let x = self.x;
        for sector in [p, q] {
            let (_, nbrs) = self.rotation();
            if nbrs.iter().all(|&(_, s)| s != sector) {
                self.open_sector(sector);
            }
        }
        let (_, nbrs) = self.rotation();
        let mut target_len = std::collections::HashMap::new();
        let spokes: Vec<(u32, f64)> = self
            .outgoing(x)
            .into_iter()
            .map(|h| (self.r.he_tip(h), self.r.length(h)))
            .collect();
        let len_of: std::collections::HashMap<u32, f64> = spokes.into_iter().collect();
        self.start_search();
        for &(n, s) in &nbrs {
            if s == p {
                let h = self
                    .outgoing(x)
                    .into_iter()
                    .find(|&h| self.r.he_tip(h) == n)?;
                self.offer(n, len_of[&n], h);
            }
            if s == q {
                target_len.insert(n, len_of[&n]);
            }
        }
        let mut best = f64::INFINITY;
        let mut best_v = NONE;
        while let Some((d, v)) = self.pop() {
            if d >= best {
                break;
            }
            if let Some(&l) = target_len.get(&v) {
                if d + l < best {
                    best = d + l;
                    best_v = v;
                }
            }
            let mut buf = std::mem::take(&mut self.buf);
            buf.clear();
            self.for_outgoing(v, |h| buf.push(h));
            for &h in &buf {
                let z = self.r.he_tip(h);
                if self.free(z) && !self.settled(z) {
                    let l = self.r.length(h);
                    self.offer(z, d + l, h);
                }
            }
            self.buf = buf;
        }
        if best_v == NONE {
            return None;
        }
        let mut verts = self.trace(best_v);
        verts.push(x);
        Some(verts)
    }

    /// Build the canonical system (phase 1, then phase 2); the loops as raw handle paths in
    /// the order of the blocks of the word.
    pub(crate) fn build(&mut self, genus: usize) -> Result<Vec<RawPath>> {
        self.ensure();
        for _ in 0..2 * genus {
            // The loop may have to start in a sector that is a single ear: then every such
            // sector is opened (each split halves an angle at `x`) and the search repeated.
            if self.independent_loop().is_err() {
                let (ends, _) = self.rotation();
                for j in 0..ends.len() {
                    let (_, nbrs) = self.rotation();
                    if nbrs.iter().all(|&(_, s)| s != j) {
                        self.open_sector(j);
                    }
                }
                self.independent_loop()?;
            }
        }
        let x = self.x;
        let max_moves = 4 * genus + 8;
        loop {
            let (ends, _) = self.rotation();
            let faces = Self::faces(&ends);
            if faces.len() != 1 || ends.len() != 4 * genus {
                return Err(Error::numerical(format!(
                    "internal error: the {} loops through vertex {x} cut the surface into {} pieces",
                    2 * genus,
                    faces.len()
                )));
            }
            let word = &faces[0];
            let letters: Vec<i64> = word
                .iter()
                .map(|s| {
                    if s.fwd {
                        s.lp as i64 + 1
                    } else {
                        -(s.lp as i64 + 1)
                    }
                })
                .collect();
            let blocks = blocks(&letters);
            if blocks.len() == genus {
                let mut out = Vec::new();
                for (k, &(d, e)) in blocks.iter().enumerate() {
                    for (which, l) in [(0u8, d), (1u8, e)] {
                        let lp = self.loops[(l.unsigned_abs() - 1) as usize]
                            .as_ref()
                            .ok_or_else(|| {
                                Error::numerical("internal error: a removed loop is in the word")
                            })?;
                        out.push(RawPath {
                            kind: RawKind::Handle { handle: k, which },
                            vertices: lp.verts.clone(),
                        });
                    }
                }
                return Ok(out);
            }
            if self.moves >= max_moves {
                return Err(Error::numerical(format!(
                    "the cut-and-paste normalization did not reach a canonical word in {max_moves} moves"
                )));
            }
            let moves = plan(&letters).unwrap_or_default();
            if moves.is_empty() {
                return Err(Error::numerical(
                    "internal error: no cut-and-paste move makes a new handle",
                ));
            }
            let (pc, qc, s) = moves[0];
            let (p, q) = (word[pc].leave_end, word[qc].leave_end);
            let c = self.chord(p, q).ok_or_else(|| {
                Error::numerical(format!(
                    "internal error: no chord of the cut disk joins sectors {p} and {q} at vertex {x}"
                ))
            })?;
            // Mark the chord first: the splits after removing `s` must keep it an edge path.
            let removed = (s.unsigned_abs() - 1) as usize;
            let id = self.mark(c);
            self.remove(removed);
            self.depinch(id);
            self.moves += 1;
        }
    }
}
