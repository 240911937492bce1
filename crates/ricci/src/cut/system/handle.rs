//! One handle of the greedy construction of [`super`]: the loop `a_i` (non-separating, its two
//! ends in one allowed gap at `x`) chosen among the candidates of the gaps' Dijkstra trees,
//! then the loop `b_i` from a slot strictly between `a_i`'s ends to one outside them, which
//! crosses `a_i` once, at `x` (paper 001 App. A, 002 §6.2.2.1). Every candidate is judged
//! against the slot budget, so that the later handles still find room.

use super::{is_simple_loop, Candidate, Gap, NoRoom, RawKind, RawPath, Search, State, MAX_TRIES};
use crate::mesh::NONE;
use std::collections::HashMap;

/// The first search of one gap with its branches and parities (`State::s1`, `branch`,
/// `parity`), parked while another gap's tree is in use. Within one handle nothing the trees
/// depend on changes (blocked vertices, cuts near, slots: only `add_handle`, which ends the
/// handle), so a parked tree is the tree that growing it again would give.
struct Tree {
    search: Search,
    branch: Vec<u32>,
    parity: Vec<u64>,
}

/// The trees of one handle's gaps, one current (in `State`), the others parked.
struct Trees {
    parked: Vec<Option<Tree>>,
    /// Gap of the current tree (`usize::MAX` before the first).
    current: usize,
}

/// Why a candidate for `a_i` was rejected (indices into `SearchStats::rejected`).
const NO_LOOP: usize = 0;
const NOT_SIMPLE_OR_SEPARATING: usize = 1;
const ENDS_ADJACENT: usize = 2;
const SIDE_FULL: usize = 3;
const OVER_BUDGET: usize = 4;
const NO_TARGET: usize = 5;
const NO_SECOND_LOOP: usize = 6;

/// What the candidates of one handle are judged against.
struct Budget<'g> {
    gaps: &'g [Gap],
    /// Position of every slot of an allowed gap within its gap.
    pos_of: Vec<usize>,
    /// Free slots before the handle.
    cap_before: usize,
    /// Slots the later handles and connectors need.
    need_after: usize,
    /// Handles already placed, as blocks of ends.
    nblocks: usize,
    /// Slots this handle may waste (fair share, then all the slack).
    waste_max: usize,
}

/// The slots of `gap` strictly between positions `p < q` (`inside`, the shorter arc when the
/// gap is cyclic) and the others (`outside`, ordered from just after one end to just before
/// the other), with the number of outside slots that come after `q`.
fn split_gap(gap: &Gap, p: usize, q: usize) -> (Vec<usize>, Vec<usize>, usize) {
    let between: Vec<usize> = gap.slots[p + 1..q].to_vec();
    let mut rest: Vec<usize> = gap.slots[q + 1..].to_vec();
    let after_q = rest.len();
    rest.extend_from_slice(&gap.slots[..p]);
    if gap.before == NONE && between.len() > rest.len() {
        let l = between.len();
        (rest, between, l)
    } else {
        (between, rest, after_q)
    }
}

impl<'a> State<'a> {
    /// One handle: the loops `a_i` (non-separating) and `b_i` (crossing it once at `x`).
    pub(super) fn handle(&mut self, i: usize) -> Result<(), NoRoom> {
        let h_rem = self.inp.genus - i;
        let nbnd = self.inp.boundary_loops.len();
        let cap_before = self.capacity();
        if cap_before < 4 * h_rem + nbnd {
            return Err(NoRoom(format!(
                "only {cap_before} free edges at the base vertex for {h_rem} more handle(s)"
            )));
        }
        let slack = cap_before - 4 * h_rem - nbnd;
        let gaps = self.gaps();
        let none = vec![false; self.slots.len()];
        let allowed: Vec<usize> = (0..gaps.len())
            .filter(|&k| {
                self.handle_allowed(&gaps[k]) && self.usable_count(&gaps[k].slots, &none) >= 4
            })
            .collect();
        let mut pos_of = vec![0usize; self.slots.len()];
        for &k in &allowed {
            for (p, &s) in gaps[k].slots.iter().enumerate() {
                pos_of[s] = p;
            }
        }
        // Candidates from one tree per allowed gap.
        let mut best: HashMap<(usize, usize, usize, Vec<u64>), Candidate> = HashMap::new();
        let mut trees = Trees {
            parked: (0..gaps.len()).map(|_| None).collect(),
            current: usize::MAX,
        };
        for &k in &allowed {
            self.use_tree(&mut trees, k, &gaps[k].slots);
            self.collect_candidates(k, &gaps[k].slots, &mut best);
        }
        let mut cands: Vec<Candidate> = best.into_values().collect();
        cands.sort_by(|a, b| a.len.total_cmp(&b.len).then(a.ends.cmp(&b.ends)));
        if cands.is_empty() {
            return Err(NoRoom(format!(
                "no non-separating loop through the base vertex fits in its free edges (handle {})",
                i + 1
            )));
        }
        let mut budget = Budget {
            gaps: &gaps,
            pos_of,
            cap_before,
            need_after: 4 * (h_rem - 1) + nbnd,
            nblocks: self.n_handle_blocks(),
            waste_max: 0,
        };
        let mut why = [0usize; 7];
        // The loop `a` of every candidate tried: nothing it depends on changes between the
        // budget rounds, so the second round reuses it (same loops, fewer searches).
        let mut loops: Vec<Option<Option<Vec<u32>>>> = vec![None; cands.len().min(MAX_TRIES)];
        let fair = slack / h_rem;
        for (round, waste_max) in [fair, slack].into_iter().enumerate() {
            if round == 1 {
                if fair == slack {
                    break;
                }
                self.stats.relaxed_budgets += 1;
            }
            budget.waste_max = waste_max;
            for (j, c) in cands.iter().take(MAX_TRIES).enumerate() {
                if loops[j].is_none() {
                    self.use_tree(&mut trees, c.gap, &gaps[c.gap].slots);
                    loops[j] = Some(self.candidate_loop(c, &gaps[c.gap].slots));
                }
                self.stats.candidates_tried += 1;
                let a = loops[j].clone().flatten();
                match self.try_candidate(c, a, &budget) {
                    Ok((a, b)) => {
                        self.count_rejections(&why);
                        self.add_handle(i, a, b);
                        return Ok(());
                    }
                    Err(reason) => {
                        why[reason] += 1;
                        if reason == NO_SECOND_LOOP {
                            self.stats.failed_second_loops += 1;
                        }
                    }
                }
            }
        }
        self.count_rejections(&why);
        Err(NoRoom(format!(
            "handle {} of {}: no pair of crossing loops fits in the free edges at the base vertex",
            i + 1,
            self.inp.genus
        )))
    }

    /// Make the tree of gap `k` (sources `slots`) current: the parked one if it was grown in
    /// this handle, else a new one; the current tree is parked.
    fn use_tree(&mut self, trees: &mut Trees, k: usize, slots: &[usize]) {
        if trees.current == k {
            return;
        }
        let cached = trees.parked[k].take();
        let grow = cached.is_none();
        if trees.current != usize::MAX || !grow {
            let mut t = cached.unwrap_or_else(|| {
                let nv = self.mesh().n_vertices();
                Tree {
                    search: Search::new(nv),
                    branch: vec![NONE; nv],
                    parity: vec![0; nv * self.inp.coh.words],
                }
            });
            std::mem::swap(&mut self.s1, &mut t.search);
            std::mem::swap(&mut self.branch, &mut t.branch);
            std::mem::swap(&mut self.parity, &mut t.parity);
            if trees.current != usize::MAX {
                trees.parked[trees.current] = Some(t);
            }
        }
        if grow {
            self.grow_tree(slots);
        }
        trees.current = k;
    }

    fn count_rejections(&mut self, why: &[usize; 7]) {
        for (k, n) in why.iter().enumerate() {
            self.stats.rejected[k] += n;
        }
    }

    /// Cut the loops `a` and `b` of handle `i`.
    fn add_handle(&mut self, i: usize, a: Vec<u32>, b: Vec<u32>) {
        let id = self.paths.len() as u32;
        self.mark_path(id, &a);
        self.paths.push(RawPath {
            kind: RawKind::Handle {
                handle: i,
                which: 0,
            },
            vertices: a,
        });
        self.mark_path(id + 1, &b);
        self.paths.push(RawPath {
            kind: RawKind::Handle {
                handle: i,
                which: 1,
            },
            vertices: b,
        });
    }

    /// The loops `a` (candidate `c`'s loop, `None` when it has none) and `b` of a handle, or
    /// why the candidate is rejected.
    fn try_candidate(
        &mut self,
        c: &Candidate,
        a: Option<Vec<u32>>,
        budget: &Budget,
    ) -> Result<(Vec<u32>, Vec<u32>), usize> {
        let gap = &budget.gaps[c.gap];
        let a = a.ok_or(NO_LOOP)?;
        if !is_simple_loop(&a) || !self.loop_parity_nonzero(&a) {
            return Err(NOT_SIMPLE_OR_SEPARATING);
        }
        let (e0, e1) = (
            self.slot_of[a[1] as usize] as usize,
            self.slot_of[a[a.len() - 2] as usize] as usize,
        );
        let (p0, p1) = (budget.pos_of[e0], budget.pos_of[e1]);
        let (p, q) = (p0.min(p1), p0.max(p1));
        if q < p + 2 {
            return Err(ENDS_ADJACENT);
        }
        let (inside, outside, after_q) = split_gap(gap, p, q);
        let ok = self.usable_beside(&a);
        let usable = |sl: &[usize]| sl.iter().filter(|&&s| ok[s]).count();
        if usable(&inside) == 0 || usable(&outside) == 0 {
            return Err(SIDE_FULL);
        }
        let cap_other: usize = if budget.nblocks >= 2 {
            (0..budget.gaps.len())
                .filter(|&k| k != c.gap && self.handle_allowed(&budget.gaps[k]))
                .map(|k| usable(&budget.gaps[k].slots))
                .sum()
        } else {
            0
        };
        let within = |cap: usize| {
            cap >= budget.need_after
                && budget.cap_before.saturating_sub(4 + cap) <= budget.waste_max
        };
        if !within(cap_other + usable(&outside) - 1) {
            return Err(OVER_BUDGET);
        }
        // Targets for b: outside slots that keep the capacity within budget.
        let mut target_ok = vec![false; self.slots.len()];
        let mut prefix = vec![0usize; outside.len() + 1];
        for (k, &s) in outside.iter().enumerate() {
            prefix[k + 1] = prefix[k] + ok[s] as usize;
        }
        for (k, &s) in outside.iter().enumerate() {
            if !ok[s] {
                continue;
            }
            let left = prefix[k];
            let right = prefix[outside.len()] - prefix[k + 1];
            let cap = if gap.before == NONE {
                left.max(right)
            } else if k < after_q {
                cap_other + right
            } else {
                cap_other + left
            };
            target_ok[s] = within(cap);
        }
        if !target_ok.iter().any(|&t| t) {
            return Err(NO_TARGET);
        }
        let b = self
            .second_loop(&a, &inside, &target_ok)
            .ok_or(NO_SECOND_LOOP)?;
        Ok((a, b))
    }

    /// Slots still usable once the loop `a` is cut (`a` may pass next to `x`).
    fn usable_beside(&mut self, a: &[u32]) -> Vec<bool> {
        for &v in &a[1..a.len() - 1] {
            self.repel[v as usize] = true;
        }
        let ok = (0..self.slots.len())
            .map(|s| self.usable(s) && !self.repel[self.slot_nbr(s) as usize])
            .collect();
        for &v in &a[1..a.len() - 1] {
            self.repel[v as usize] = false;
        }
        ok
    }

    /// Shortest path from a usable slot in `inside` to a slot with `target_ok`, avoiding
    /// blocked vertices and the vertices of `a`; returned closed at `x`.
    fn second_loop(&mut self, a: &[u32], inside: &[usize], target_ok: &[bool]) -> Option<Vec<u32>> {
        let m = self.mesh();
        let x = self.inp.x;
        for &v in &a[1..a.len() - 1] {
            self.blocked[v as usize] = true;
        }
        self.s2.reset();
        self.stats.searches += 1;
        for &s in inside {
            if self.usable(s) {
                let v = self.slot_nbr(s);
                let l = self.slot_len(s);
                self.s2.offer(v, l, self.slots[s]);
            }
        }
        let mut best = f64::INFINITY;
        let mut best_v = NONE;
        while let Some((d, v)) = self.s2.pop() {
            if d >= best {
                break;
            }
            let sv = self.slot_of[v as usize];
            if sv != NONE && target_ok[sv as usize] && m.he_origin(self.s2.pred(v)) != x {
                let total = d + self.slot_len(sv as usize);
                if total < best {
                    best = total;
                    best_v = v;
                }
            }
            for k in self.adj_start[v as usize]..self.adj_start[v as usize + 1] {
                let (g, w, l) = self.adj[k as usize];
                let sw = self.slot_of[w as usize];
                if self.blocked[w as usize]
                    || self.s2.is_settled(w)
                    || (sw != NONE && !target_ok[sw as usize])
                {
                    continue;
                }
                self.s2.offer(w, d + self.cost2(v, w, l), g);
            }
        }
        for &v in &a[1..a.len() - 1] {
            self.blocked[v as usize] = false;
        }
        if best_v == NONE {
            return None;
        }
        let mut b = Self::trace(&self.s2, m, x, best_v);
        b.push(x);
        Some(b)
    }
}
