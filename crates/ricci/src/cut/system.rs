//! Greedy construction of a canonical system of loops through the base vertex `x`, handle by
//! handle, as vertex-disjoint simple edge paths meeting only at `x` (paper 001 App. A,
//! 002 §6.2.2.1; the loops themselves are shortest-path loops as in Erickson–Whittlesey).
//! Used for surfaces with boundary and genus 0; closed surfaces of genus ≥ 1 are cut by the
//! cut-and-paste construction of [`super::schema`], which cannot run out of room.
//!
//! **Why the loops must be disjoint and how their ends are placed.** Cutting along `2g` simple
//! loops that meet only at `x` gives a disk iff the complement is connected; the word of the
//! disk boundary is then fixed by the cyclic order of the `4g` loop ends around `x` (a one-vertex
//! ribbon graph). Walking the disk boundary with the disk on the left, one arrives at `x` along
//! the end `E_{j+1}` and leaves along `E_j` (counter-clockwise numbering). Working this out, the
//! boundary reads `a₁b₁a₁⁻¹b₁⁻¹ … a_g b_g a_g⁻¹ b_g⁻¹` exactly when the ends of every handle are
//! **interleaved** (`a`, `b`, `a`, `b`) and **contiguous** (no other end between them). So:
//!
//! * the ends around `x` are "slots" (outgoing edges of `x`); the free slots between two
//!   consecutive ends form a *gap*; a new handle must put all its four ends into one gap, and,
//!   once two handles exist, only gaps between two different handles keep the earlier handles
//!   contiguous (the gaps inside a handle are lost);
//! * `a_i` is a short loop through `x` leaving and returning through one allowed gap whose
//!   Z₂ cohomology class is nonzero (non-separating: see [`super::homology`]). One Dijkstra
//!   tree is grown from each allowed gap (branches = slots, disjoint); an odd non-tree edge
//!   between two branches closes a simple loop; an odd edge inside one branch closes a lasso,
//!   whose return strand is rerouted by a second search to another slot of the gap, kept away
//!   from the outgoing strand so that room remains between them;
//! * `b_i` is the shortest path from a slot strictly between `a_i`'s ends to a slot outside them
//!   (same gap), avoiding `a_i` and all earlier loops: it crosses `a_i` once, at `x`;
//! * slots are a budget: every handle may waste at most its fair share of the spare slots, so
//!   that the later handles still find room (with the valence raised and the neighbourhood
//!   graded by [`crate::metric::refine`], there are enough of them);
//! * searches enter a neighbour of `x` only as a source or a target (loops must not run along
//!   the link of `x` and use up its slots), and edges next to earlier cuts cost three times
//!   their length, so that loops keep a free row of vertices between them;
//! * when no candidate works, the attempt fails with the complete handles found so far; the
//!   caller ([`super::canonical_cut`]) splits every edge touching them (a free row of vertices
//!   on both sides of every loop, the metric unchanged), raises the valence of `x` and
//!   resumes.
//!
//! With boundary, after the handles every boundary loop is joined to `x` by a shortest path
//! `c_k` through free vertices; these start from adjacent gaps so the word ends with
//! `c₁ d₁ c₁⁻¹ … c_b d_b c_b⁻¹` (`d_k` the boundary loop). A closed genus-0 surface is slit along
//! a path of two edges (word `c₁ c₁⁻¹`).
//!

mod handle;

use super::homology::Cohomology;
use crate::mesh::{Mesh, NONE};
use crate::numeric::dijkstra::Dijkstra as Search;
use std::collections::HashMap;

/// Candidate first loops tried per handle and budget round before refining along the loops
/// found so far (each try costs up to two Dijkstra searches).
const MAX_TRIES: usize = 12;

/// Extra relative cost of edges next to earlier cuts.
const NEAR_PENALTY: f64 = 2.0;
/// Extra relative cost next to the outgoing strand while rerouting the return strand of a
/// loop, so that the two strands leave room between them for the second loop.
const REPEL_PENALTY: f64 = 20.0;

/// What a constructed path is.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum RawKind {
    /// First (`0`, found as the non-separating loop) or second (`1`) loop of handle `h`.
    Handle { handle: usize, which: u8 },
    /// Path from `x` to boundary loop `k` (index into `Mesh::boundary_loops`).
    Connector { boundary: usize },
    /// The two-edge slit of a closed genus-0 surface.
    Slit,
}

#[derive(Debug, Clone)]
pub(crate) struct RawPath {
    pub kind: RawKind,
    /// Vertices; closed loops start and end at `x`.
    pub vertices: Vec<u32>,
}

/// Counters describing the search.
#[derive(Debug, Clone, Default, serde::Serialize)]
pub struct SearchStats {
    /// Construction attempts (the first, then one per refinement along the loops).
    pub attempts: usize,
    /// Candidate first loops examined (all handles).
    pub candidates_tried: usize,
    /// Second-loop searches that found no path (the next candidate was tried).
    pub failed_second_loops: usize,
    /// Handles for which the fair slot budget had to be relaxed.
    pub relaxed_budgets: usize,
    /// Number of Dijkstra searches.
    pub searches: usize,
    /// Candidate first loops rejected, by reason: no simple return path, not simple or
    /// separating, ends adjacent at the base vertex, no free edge on one side, over the slot
    /// budget, no admissible end for the second loop, no second loop.
    pub rejected: [usize; 7],
    /// Cut-and-paste moves on the polygon (cut-and-paste construction).
    pub moves: usize,
}

/// Why a construction attempt failed (the caller refines more and retries).
#[derive(Debug, Clone)]
pub(crate) struct NoRoom(pub String);

/// A failed attempt: why, and what was found before (complete handles and connectors).
pub(crate) struct Failure {
    pub reason: NoRoom,
    pub paths: Vec<RawPath>,
    pub stats: SearchStats,
}

pub(crate) struct Input<'a> {
    pub mesh: &'a Mesh,
    pub lengths: &'a [f64],
    pub coh: &'a Cohomology,
    pub x: u32,
    pub genus: usize,
    pub boundary_loops: Vec<Vec<u32>>,
}

#[derive(Debug, Clone)]
struct Gap {
    /// Slot indices, counter-clockwise.
    slots: Vec<usize>,
    /// Path ids of the ends before and after the gap (`NONE` when there are no ends).
    before: u32,
    after: u32,
}

struct State<'a> {
    inp: &'a Input<'a>,
    /// Outgoing half-edges of `x`, counter-clockwise.
    slots: Vec<u32>,
    /// Path occupying each slot, or `NONE`.
    slot_path: Vec<u32>,
    /// Slot index of every neighbour of `x` (`NONE` for other vertices).
    slot_of: Vec<u32>,
    blocked: Vec<bool>,
    /// Free vertices next to a cut vertex (other than `x`): edges there cost more, so that
    /// later loops keep a free row of vertices between them and earlier ones.
    near: Vec<bool>,
    /// Temporary repulsion (see `REPEL_PENALTY`).
    repel: Vec<bool>,
    paths: Vec<RawPath>,
    stats: SearchStats,
    s1: Search,
    s2: Search,
    branch: Vec<u32>,
    parity: Vec<u64>,
    /// Outgoing half-edges of every vertex with their tips and lengths (CSR).
    adj_start: Vec<u32>,
    adj: Vec<(u32, u32, f64)>,
}

#[derive(Debug, Clone)]
struct Candidate {
    len: f64,
    /// Half-edge `u → w` closing the loop (for `x_edge`, the slot half-edge `x → w`).
    he: u32,
    x_edge: bool,
    ends: (usize, usize),
    /// Gap whose tree produced it.
    gap: usize,
}

/// Build the raw system, keeping the complete handles and connectors of `prior` (same vertex
/// ids). On failure, returns the reason and the paths found so far (the caller refines along
/// them and resumes).
pub(crate) fn build(
    inp: &Input,
    prior: &[RawPath],
) -> Result<(Vec<RawPath>, SearchStats), Box<Failure>> {
    let m = inp.mesh;
    let nv = m.n_vertices();
    let slots: Vec<u32> = m.outgoing(inp.x).collect();
    let mut slot_of = vec![NONE; nv];
    for (i, &h) in slots.iter().enumerate() {
        slot_of[m.he_tip(h) as usize] = i as u32;
    }
    let mut blocked = vec![false; nv];
    blocked[inp.x as usize] = true;
    for l in &inp.boundary_loops {
        for &v in l {
            blocked[v as usize] = true;
        }
    }
    let mut st = State {
        inp,
        slot_path: vec![NONE; slots.len()],
        slots,
        slot_of,
        near: vec![false; nv],
        repel: vec![false; nv],
        blocked,
        paths: Vec::new(),
        stats: SearchStats {
            attempts: 1,
            ..SearchStats::default()
        },
        s1: Search::new(nv),
        s2: Search::new(nv),
        branch: vec![NONE; nv],
        parity: vec![0; nv * inp.coh.words],
        adj_start: Vec::new(),
        adj: Vec::new(),
    };
    {
        let mut start = Vec::with_capacity(nv + 1);
        let mut adj = Vec::with_capacity(m.n_halfedges());
        start.push(0u32);
        for v in 0..nv as u32 {
            for h in m.outgoing(v) {
                adj.push((h, m.he_tip(h), inp.lengths[m.he_edge(h) as usize]));
            }
            start.push(adj.len() as u32);
        }
        st.adj_start = start;
        st.adj = adj;
    }
    for l in &inp.boundary_loops {
        for &v in l {
            st.mark_near(v);
        }
    }
    let nb = inp.boundary_loops.len();
    let mut connected = vec![false; nb];
    let mut handles_done = 0;
    for p in prior {
        let id = st.paths.len() as u32;
        st.mark_path(id, &p.vertices);
        st.paths.push(p.clone());
        match p.kind {
            RawKind::Handle { which: 1, .. } => handles_done += 1,
            RawKind::Connector { boundary } => connected[boundary] = true,
            _ => {}
        }
    }
    let fail = |e: NoRoom, st: &State| {
        Box::new(Failure {
            reason: e,
            paths: st.paths.clone(),
            stats: st.stats.clone(),
        })
    };
    if inp.genus == 0 && nb == 0 && st.paths.is_empty() {
        st.slit().map_err(|e| fail(e, &st))?;
    }
    for i in handles_done..inp.genus {
        st.handle(i).map_err(|e| fail(e, &st))?;
    }
    if inp.genus > 0 || nb >= 2 {
        while connected.iter().any(|&c| !c) {
            st.connector(&mut connected).map_err(|e| fail(e, &st))?;
        }
    }
    Ok((st.paths, st.stats))
}

impl SearchStats {
    /// Add the counters of another attempt.
    pub(crate) fn add(&mut self, o: &SearchStats) {
        self.attempts += o.attempts;
        self.candidates_tried += o.candidates_tried;
        self.failed_second_loops += o.failed_second_loops;
        self.relaxed_budgets += o.relaxed_budgets;
        self.searches += o.searches;
        for k in 0..self.rejected.len() {
            self.rejected[k] += o.rejected[k];
        }
        self.moves += o.moves;
    }
}

impl<'a> State<'a> {
    fn mesh(&self) -> &'a Mesh {
        self.inp.mesh
    }
    fn slot_len(&self, s: usize) -> f64 {
        self.inp.lengths[self.mesh().he_edge(self.slots[s]) as usize]
    }
    fn slot_nbr(&self, s: usize) -> u32 {
        self.mesh().he_tip(self.slots[s])
    }
    fn usable(&self, s: usize) -> bool {
        self.slot_path[s] == NONE && !self.blocked[self.slot_nbr(s) as usize]
    }
    fn path_block(&self, p: u32) -> Option<usize> {
        match self.paths[p as usize].kind {
            RawKind::Handle { handle, .. } => Some(handle),
            _ => None,
        }
    }
    fn is_connector(&self, p: u32) -> bool {
        matches!(self.paths[p as usize].kind, RawKind::Connector { .. })
    }

    /// Gaps between consecutive ends around `x`.
    fn gaps(&self) -> Vec<Gap> {
        let d = self.slots.len();
        let ends: Vec<usize> = (0..d).filter(|&s| self.slot_path[s] != NONE).collect();
        if ends.is_empty() {
            return vec![Gap {
                slots: (0..d).collect(),
                before: NONE,
                after: NONE,
            }];
        }
        let mut out = Vec::with_capacity(ends.len());
        for (k, &e) in ends.iter().enumerate() {
            let e2 = ends[(k + 1) % ends.len()];
            let mut slots = Vec::new();
            let mut s = (e + 1) % d;
            while s != e2 {
                slots.push(s);
                s = (s + 1) % d;
            }
            out.push(Gap {
                slots,
                before: self.slot_path[e],
                after: self.slot_path[e2],
            });
        }
        out
    }

    fn n_handle_blocks(&self) -> usize {
        self.paths
            .iter()
            .filter(|p| matches!(p.kind, RawKind::Handle { which: 0, .. }))
            .count()
    }

    /// Whether a new handle may use gap `g`.
    fn handle_allowed(&self, g: &Gap) -> bool {
        if g.before == NONE || self.n_handle_blocks() <= 1 {
            return true;
        }
        self.path_block(g.before) != self.path_block(g.after)
    }

    fn usable_count(&self, slots: &[usize], extra_blocked: &[bool]) -> usize {
        slots
            .iter()
            .filter(|&&s| self.usable(s) && !extra_blocked[s])
            .count()
    }

    /// Free capacity for later handles (see module docs): with a single handle only one of its
    /// gaps will ever be used, otherwise all gaps between different handles stay usable.
    fn capacity(&self) -> usize {
        let none = vec![false; self.slots.len()];
        let gaps = self.gaps();
        if self.n_handle_blocks() <= 1 {
            gaps.iter()
                .map(|g| self.usable_count(&g.slots, &none))
                .max()
                .unwrap_or(0)
        } else {
            gaps.iter()
                .filter(|g| self.handle_allowed(g))
                .map(|g| self.usable_count(&g.slots, &none))
                .sum()
        }
    }

    /// Dijkstra from all usable slots in `sources` (slot list); settles every reachable free
    /// vertex, recording branch (slot) and cohomology parity of the tree path from `x`.
    fn grow_tree(&mut self, sources: &[usize]) {
        let m = self.mesh();
        let words = self.inp.coh.words;
        self.s1.reset();
        self.stats.searches += 1;
        for &s in sources {
            if self.usable(s) {
                let v = self.slot_nbr(s);
                let l = self.slot_len(s);
                self.s1.offer(v, l, self.slots[s]);
            }
        }
        while let Some((d, v)) = self.s1.pop() {
            let h = self.s1.pred(v);
            let u = m.he_origin(h);
            let om = self.inp.coh.edge(m.he_edge(h));
            if u == self.inp.x {
                self.branch[v as usize] = self.slot_of[v as usize];
                self.parity[v as usize * words..(v as usize + 1) * words].copy_from_slice(om);
            } else {
                self.branch[v as usize] = self.branch[u as usize];
                for (w, &o) in om.iter().enumerate() {
                    self.parity[v as usize * words + w] = self.parity[u as usize * words + w] ^ o;
                }
            }
            for k in self.adj_start[v as usize]..self.adj_start[v as usize + 1] {
                let (g, w, l) = self.adj[k as usize];
                // Neighbours of x are only entered from x: loops must not run along the link.
                if self.blocked[w as usize]
                    || self.s1.is_settled(w)
                    || self.slot_of[w as usize] != NONE
                {
                    continue;
                }
                let l = self.cost2(v, w, l);
                self.s1.offer(w, d + l, g);
            }
        }
    }

    /// Vertices of the tree path `x → … → v` in the first search.
    fn trace(search: &Search, m: &Mesh, x: u32, v: u32) -> Vec<u32> {
        let mut out = vec![v];
        let mut cur = v;
        while cur != x {
            let h = search.pred(cur);
            cur = m.he_origin(h);
            out.push(cur);
        }
        out.reverse();
        out
    }

    fn mark_near(&mut self, v: u32) {
        let m = self.mesh();
        for h in m.outgoing(v) {
            self.near[m.he_tip(h) as usize] = true;
        }
    }

    /// Search cost of the edge `u → w` of length `l`: its length, more next to earlier cuts
    /// and, while rerouting, next to the outgoing strand.
    #[inline]
    fn cost2(&self, u: u32, w: u32, l: f64) -> f64 {
        let (o, t) = (u as usize, w as usize);
        let k = self.near[o] as u8 + self.near[t] as u8;
        let r = self.repel[o] as u8 + self.repel[t] as u8;
        l * (1.0 + NEAR_PENALTY * k as f64 * 0.5 + REPEL_PENALTY * r as f64 * 0.5)
    }

    fn mark_path(&mut self, id: u32, verts: &[u32]) {
        let x = self.inp.x;
        for &v in verts {
            if v != x {
                self.blocked[v as usize] = true;
                self.mark_near(v);
            }
        }
        // End slots: the first and (for loops) the last edge at x.
        let first = verts[1];
        self.slot_path[self.slot_of[first as usize] as usize] = id;
        if verts.len() > 2 && *verts.last().unwrap_or(&NONE) == x {
            let last = verts[verts.len() - 2];
            self.slot_path[self.slot_of[last as usize] as usize] = id;
        }
    }

    /// Collect the candidate first loops of the tree grown from gap `k`: edges `(u, w)` between
    /// two settled vertices whose fundamental cycle has odd parity, best per (branches, parity).
    fn collect_candidates(
        &self,
        k: usize,
        sources: &[usize],
        out: &mut HashMap<(usize, usize, usize, Vec<u64>), Candidate>,
    ) {
        let m = self.mesh();
        let words = self.inp.coh.words;
        let mut par = vec![0u64; words];
        let mut consider = |c: Candidate, par: &[u64]| {
            if par.iter().all(|&w| w == 0) {
                return;
            }
            let key = (k, c.ends.0, c.ends.1, par.to_vec());
            match out.get(&key) {
                Some(o) if o.len <= c.len => {}
                _ => {
                    out.insert(key, c);
                }
            }
        };
        for e in 0..m.n_edges() as u32 {
            let h = m.edge_halfedge(e);
            let (u, w) = (m.he_origin(h), m.he_tip(h));
            if !(self.s1.is_settled(u) && self.s1.is_settled(w)) {
                continue;
            }
            // Tree edges close nothing.
            if self.s1.pred(w) == h || self.s1.pred(u) == m.he_twin(h) {
                continue;
            }
            let (bu, bw) = (
                self.branch[u as usize] as usize,
                self.branch[w as usize] as usize,
            );
            let om = self.inp.coh.edge(e);
            for j in 0..words {
                par[j] = self.parity[u as usize * words + j]
                    ^ self.parity[w as usize * words + j]
                    ^ om[j];
            }
            let len = self.s1.dist(u) + self.s1.dist(w) + self.inp.lengths[e as usize];
            consider(
                Candidate {
                    len,
                    he: h,
                    x_edge: false,
                    ends: (bu.min(bw), bu.max(bw)),
                    gap: k,
                },
                &par,
            );
        }
        for &s in sources {
            let w = self.slot_nbr(s);
            if !self.usable(s) || !self.s1.is_settled(w) {
                continue;
            }
            let bw = self.branch[w as usize] as usize;
            if bw == s {
                continue;
            }
            let om = self.inp.coh.edge(m.he_edge(self.slots[s]));
            for j in 0..words {
                par[j] = self.parity[w as usize * words + j] ^ om[j];
            }
            let len = self.s1.dist(w) + self.slot_len(s);
            consider(
                Candidate {
                    len,
                    he: self.slots[s],
                    x_edge: true,
                    ends: (bw.min(s), bw.max(s)),
                    gap: k,
                },
                &par,
            );
        }
    }

    /// The loop of a candidate, simple at `x`: tree path to `u`, the edge, tree path back from
    /// `w` when `w` lies in another branch, otherwise the shortest path from `w` back to another
    /// slot of the gap avoiding the path to `u` (the lasso's stem is rerouted).
    fn candidate_loop(&mut self, c: &Candidate, gap_slots: &[usize]) -> Option<Vec<u32>> {
        let m = self.mesh();
        let x = self.inp.x;
        if c.x_edge {
            let w = m.he_tip(c.he);
            let mut v = Self::trace(&self.s1, m, x, w);
            v.push(x);
            return Some(v);
        }
        let (u, w) = (m.he_origin(c.he), m.he_tip(c.he));
        let mut a = Self::trace(&self.s1, m, x, u);
        if self.branch[u as usize] != self.branch[w as usize] {
            let mut back = Self::trace(&self.s1, m, x, w);
            back.reverse();
            a.extend(back);
            return Some(a);
        }
        // Reroute: Dijkstra from w to the other slots of the gap, avoiding a's vertices and
        // keeping away from them.
        let mut repelled = Vec::new();
        for &v in &a[1..] {
            self.blocked[v as usize] = true;
            for h in m.outgoing(v) {
                let z = m.he_tip(h);
                if !self.repel[z as usize] {
                    self.repel[z as usize] = true;
                    repelled.push(z);
                }
            }
        }
        let mut target = vec![false; self.slots.len()];
        for &s in gap_slots {
            if self.usable(s) {
                target[s] = true;
            }
        }
        self.s2.reset();
        self.stats.searches += 1;
        self.s2.offer(w, 0.0, NONE);
        let mut best = f64::INFINITY;
        let mut best_v = NONE;
        while let Some((d, v)) = self.s2.pop() {
            if d >= best {
                break;
            }
            let sv = self.slot_of[v as usize];
            if sv != NONE && target[sv as usize] {
                let t = d + self.slot_len(sv as usize);
                if t < best {
                    best = t;
                    best_v = v;
                }
            }
            for k in self.adj_start[v as usize]..self.adj_start[v as usize + 1] {
                let (g, z, l) = self.adj[k as usize];
                let sz = self.slot_of[z as usize];
                if self.blocked[z as usize]
                    || self.s2.is_settled(z)
                    || (sz != NONE && !target[sz as usize])
                {
                    continue;
                }
                self.s2.offer(z, d + self.cost2(v, z, l), g);
            }
        }
        for &v in &a[1..] {
            self.blocked[v as usize] = false;
        }
        for z in repelled {
            self.repel[z as usize] = false;
        }
        if best_v == NONE {
            return None;
        }
        // Path w → … → best_v, then x.
        let mut back = vec![best_v];
        let mut cur = best_v;
        while cur != w {
            cur = m.he_origin(self.s2.pred(cur));
            back.push(cur);
        }
        back.reverse();
        a.extend(back);
        a.push(x);
        Some(a)
    }

    fn loop_parity_nonzero(&self, a: &[u32]) -> bool {
        let m = self.mesh();
        let words = self.inp.coh.words;
        let mut p = vec![0u64; words];
        for w in a.windows(2) {
            let Some(h) = m.halfedge_between(w[0], w[1]) else {
                return false;
            };
            for (x, y) in p.iter_mut().zip(self.inp.coh.edge(m.he_edge(h))) {
                *x ^= y;
            }
        }
        p.iter().any(|&x| x != 0)
    }

    /// Path from `x` to the nearest boundary loop not yet connected.
    fn connector(&mut self, connected: &mut [bool]) -> Result<(), NoRoom> {
        let m = self.mesh();
        let x = self.inp.x;
        let nb = self.inp.boundary_loops.len();
        let mut loop_of: HashMap<u32, usize> = HashMap::new();
        for (k, l) in self.inp.boundary_loops.iter().enumerate() {
            if !connected[k] {
                for &v in l {
                    loop_of.insert(v, k);
                }
            }
        }
        let remaining = connected.iter().filter(|&&c| !c).count();
        let gaps = self.gaps();
        let any_connector = self
            .paths
            .iter()
            .enumerate()
            .any(|(p, _)| self.is_connector(p as u32));
        let mut sources = Vec::new();
        let free = |st: &Self, s: usize| {
            st.slot_path[s] == NONE
                && (!st.blocked[st.slot_nbr(s) as usize] || loop_of.contains_key(&st.slot_nbr(s)))
        };
        for g in &gaps {
            let ok = if any_connector {
                (g.before != NONE && self.is_connector(g.before))
                    || (g.after != NONE && self.is_connector(g.after))
            } else {
                self.handle_allowed(g)
            };
            let room = g.slots.iter().filter(|&&s| free(self, s)).count();
            if ok && room >= remaining {
                sources.extend(g.slots.iter().copied().filter(|&s| free(self, s)));
            }
        }
        // Direct edges from x to a boundary vertex.
        let mut best = f64::INFINITY;
        let mut best_end: Option<(u32, u32)> = None; // (vertex before target or x, target)
        for &s in &sources {
            let v = self.slot_nbr(s);
            if loop_of.contains_key(&v) && self.slot_len(s) < best {
                best = self.slot_len(s);
                best_end = Some((x, v));
            }
        }
        self.s1.reset();
        self.stats.searches += 1;
        for &s in &sources {
            if self.usable(s) {
                let v = self.slot_nbr(s);
                self.s1.offer(v, self.slot_len(s), self.slots[s]);
            }
        }
        while let Some((d, v)) = self.s1.pop() {
            if d >= best {
                break;
            }
            for k in self.adj_start[v as usize]..self.adj_start[v as usize + 1] {
                let (g, w, l) = self.adj[k as usize];
                let l = self.cost2(v, w, l);
                if loop_of.contains_key(&w) {
                    if d + l < best {
                        best = d + l;
                        best_end = Some((v, w));
                    }
                    continue;
                }
                if self.blocked[w as usize]
                    || self.s1.is_settled(w)
                    || self.slot_of[w as usize] != NONE
                {
                    continue;
                }
                self.s1.offer(w, d + l, g);
            }
        }
        let Some((v, t)) = best_end else {
            return Err(NoRoom(format!(
                "{remaining} of {nb} boundary loops cannot be reached from the base vertex through free vertices"
            )));
        };
        let mut path = if v == x {
            vec![x]
        } else {
            Self::trace(&self.s1, m, x, v)
        };
        path.push(t);
        let k = loop_of[&t];
        connected[k] = true;
        let id = self.paths.len() as u32;
        self.paths.push(RawPath {
            kind: RawKind::Connector { boundary: k },
            vertices: path.clone(),
        });
        self.mark_path(id, &path);
        Ok(())
    }

    /// Closed genus 0: slit along the two shortest edges `x → y → z`.
    fn slit(&mut self) -> Result<(), NoRoom> {
        let m = self.mesh();
        let x = self.inp.x;
        let s = (0..self.slots.len())
            .min_by(|&a, &b| self.slot_len(a).total_cmp(&self.slot_len(b)))
            .ok_or_else(|| NoRoom("the base vertex has no edges".into()))?;
        let y = self.slot_nbr(s);
        let z = m
            .outgoing(y)
            .filter(|&h| m.he_tip(h) != x)
            .min_by(|&a, &b| {
                self.inp.lengths[m.he_edge(a) as usize]
                    .total_cmp(&self.inp.lengths[m.he_edge(b) as usize])
            })
            .map(|h| m.he_tip(h))
            .ok_or_else(|| NoRoom("the base vertex's neighbour has no other edge".into()))?;
        let id = self.paths.len() as u32;
        self.paths.push(RawPath {
            kind: RawKind::Slit,
            vertices: vec![x, y, z],
        });
        self.mark_path(id, &[x, y, z]);
        Ok(())
    }
}

fn is_simple_loop(v: &[u32]) -> bool {
    let mut s: Vec<u32> = v[..v.len() - 1].to_vec();
    s.sort_unstable();
    s.windows(2).all(|w| w[0] != w[1])
}
