//! The Hessian's sparsity pattern for [`super::conformal`]'s Newton iterations: the
//! lower-triangular pattern over the free vertices that only grows as Ptolemy flips create new
//! vertex pairs (entries of vanished pairs are kept as zeros), with the slot of every edge's
//! entry and the symbolic factorization (faer supernodal Cholesky; AMD, or the last ordering
//! reused while the factor's fill stays within [`REUSED_ORDERING_FILL`]).

use super::conformal::ConformalState;
use crate::error::Result;
use crate::mesh::NONE;
use crate::metric::intrinsic::IntrinsicTriangulation;
use crate::numeric::sparse::{LowerCsc, SymmetricSolver};

/// The lower-triangular Hessian pattern over the free vertices that only grows, with its
/// symbolic factorization.
pub(super) struct GrowingPattern {
    pub(super) free_index: Vec<u32>,
    pub(super) free_vertex: Vec<u32>,
    pub(super) col_ptr: Vec<u32>,
    pub(super) row_idx: Vec<u32>,
    /// Slot of every edge of the triangulation: its two ends' entry (the diagonal for a
    /// loop), `NONE` when an end is held. Kept by [`GrowingPattern::cover`].
    pub(super) edge_slot: Vec<u32>,
    pub(super) solver: Option<SymmetricSolver>,
    /// Symbolic factorizations computed.
    pub(super) symbolic_count: usize,
    /// Nonzeros of the factor of the last analysis with a new AMD ordering.
    pub(super) amd_factor_nnz: usize,
    /// Length of the triangulation's `flip_log` at the last [`GrowingPattern::cover`].
    pub(super) covered_flips: usize,
}

/// Most growth of the factor's nonzeros, relative to the last AMD analysis, accepted with a
/// reused ordering ([`GrowingPattern::cover`]).
const REUSED_ORDERING_FILL: f64 = 1.1;

impl GrowingPattern {
    pub(super) fn new(held: &[bool]) -> GrowingPattern {
        let mut free_index = vec![NONE; held.len()];
        let mut free_vertex = Vec::new();
        for (v, &h) in held.iter().enumerate() {
            if !h {
                free_index[v] = free_vertex.len() as u32;
                free_vertex.push(v as u32);
            }
        }
        let n = free_vertex.len();
        GrowingPattern {
            free_index,
            free_vertex,
            col_ptr: (0..=n as u32).collect(),
            row_idx: (0..n as u32).collect(),
            edge_slot: Vec::new(),
            solver: None,
            symbolic_count: 0,
            amd_factor_nnz: 0,
            covered_flips: 0,
        }
    }
    pub(super) fn n(&self) -> usize {
        self.free_vertex.len()
    }
    pub(super) fn slot(&self, c: u32, r: u32) -> Option<usize> {
        let (s, t) = (
            self.col_ptr[c as usize] as usize,
            self.col_ptr[c as usize + 1] as usize,
        );
        self.row_idx[s..t].binary_search(&r).ok().map(|k| s + k)
    }
    /// The pattern's entry of the two ends of edge `e` (`NONE`: an end is held, or the pair
    /// is not in the pattern).
    pub(super) fn edge_entry(&self, tri: &IntrinsicTriangulation, e: u32) -> u32 {
        let [a, b] = tri.edge_vertices(e);
        let (ia, ib) = (self.free_index[a as usize], self.free_index[b as usize]);
        if ia == NONE || ib == NONE {
            return NONE;
        }
        self.slot(ia.min(ib), ia.max(ib)).map_or(NONE, |s| s as u32)
    }
    /// Make sure every vertex pair joined by an edge of `tri` is in the pattern, with the
    /// edges' slots; true when the pattern is new or grew and needs a new symbolic
    /// factorization ([`GrowingPattern::analysis`]).
    ///
    /// Only an edge flipped since the last call can join a new pair (the others kept their
    /// ends, whose pairs were covered then): those are `tri.flip_log` after the length it had.
    pub(super) fn cover(&mut self, tri: &IntrinsicTriangulation) -> bool {
        let full = self.solver.is_none() || self.edge_slot.len() != tri.n_edges();
        let flipped: Vec<u32> = match tri.flip_log.get(self.covered_flips..) {
            Some(tail) if !full => tail.to_vec(),
            _ => (0..tri.n_edges() as u32).collect(),
        };
        self.covered_flips = tri.flip_log.len();
        let mut missing: Vec<(u32, u32)> = Vec::new();
        for &e in &flipped {
            let [a, b] = tri.edge_vertices(e);
            let (ia, ib) = (self.free_index[a as usize], self.free_index[b as usize]);
            if a == b || ia == NONE || ib == NONE {
                continue;
            }
            let (c, r) = (ia.min(ib), ia.max(ib));
            if self.slot(c, r).is_none() {
                missing.push((c, r));
            }
        }
        let grew = !missing.is_empty();
        if grew {
            let moved = self.grow(missing);
            if !full {
                for s in self.edge_slot.iter_mut().filter(|s| **s != NONE) {
                    *s = moved[*s as usize];
                }
            }
        }
        if full {
            self.edge_slot = (0..tri.n_edges() as u32)
                .map(|e| self.edge_entry(tri, e))
                .collect();
        } else {
            for e in flipped {
                self.edge_slot[e as usize] = self.edge_entry(tri, e);
            }
        }
        grew || self.solver.is_none()
    }
    /// Merge the pairs `missing` (column, row; not in the pattern) into the pattern, columns
    /// kept sorted; returns the new slot of every old entry.
    pub(super) fn grow(&mut self, mut missing: Vec<(u32, u32)>) -> Vec<u32> {
        missing.sort_unstable();
        missing.dedup();
        let n = self.n();
        let mut col_ptr = Vec::with_capacity(n + 1);
        let mut row_idx = Vec::with_capacity(self.row_idx.len() + missing.len());
        let mut moved = Vec::with_capacity(self.row_idx.len());
        col_ptr.push(0u32);
        let mut new = missing.into_iter().peekable();
        for c in 0..n as u32 {
            let (s, t) = (
                self.col_ptr[c as usize] as usize,
                self.col_ptr[c as usize + 1] as usize,
            );
            for &r in &self.row_idx[s..t] {
                while let Some((_, x)) = new.next_if(|&(nc, nr)| nc == c && nr < r) {
                    row_idx.push(x);
                }
                moved.push(row_idx.len() as u32);
                row_idx.push(r);
            }
            while let Some((_, x)) = new.next_if(|&(nc, _)| nc == c) {
                row_idx.push(x);
            }
            col_ptr.push(row_idx.len() as u32);
        }
        self.col_ptr = col_ptr;
        self.row_idx = row_idx;
        moved
    }
    /// The symbolic factorization of the current pattern, and the factor size when it comes
    /// with a new AMD ordering.
    pub(super) fn analysis(&self) -> Result<(SymmetricSolver, Option<usize>)> {
        let pattern = LowerCsc {
            n: self.n(),
            col_ptr: &self.col_ptr,
            row_idx: &self.row_idx,
        };
        // A grown pattern keeps the fill-reducing ordering of the last AMD analysis while
        // the factor stays within `REUSED_ORDERING_FILL` of that analysis' factor: flips add
        // pairs of vertices two apart, which the old ordering usually absorbs with little
        // extra fill, and the AMD ordering is most of the cost of a symbolic analysis. Many
        // flips far from where the ordering expected them (the punctured sphere's flat
        // picture) make the fill grow instead; then AMD runs again.
        let ordering = self.solver.as_ref().and_then(|s| s.ordering());
        let reused = match ordering {
            Some((forward, inverse)) => {
                let s = SymmetricSolver::with_ordering(pattern, &forward, &inverse)?;
                let limit = REUSED_ORDERING_FILL * self.amd_factor_nnz as f64;
                (s.factor_nnz as f64 <= limit).then_some(s)
            }
            None => None,
        };
        Ok(match reused {
            Some(s) => (s, None),
            None => {
                let s = SymmetricSolver::new(pattern)?;
                let nnz = s.factor_nnz;
                (s, Some(nnz))
            }
        })
    }
    /// Lower-triangle values of `H = ∂K/∂u` (free vertices) from the state's Jacobians.
    pub(super) fn assemble(
        &self,
        tri: &IntrinsicTriangulation,
        st: &ConformalState,
        values: &mut Vec<f64>,
    ) {
        values.clear();
        values.resize(self.row_idx.len(), 0.0);
        for f in 0..tri.n_faces() {
            let vs = tri.face(f as u32);
            // Half-edge 3f + k joins corners k and k + 1.
            let es = [tri.edge[3 * f], tri.edge[3 * f + 1], tri.edge[3 * f + 2]];
            for m in 0..3 {
                let r = self.free_index[vs[m] as usize];
                if r == NONE {
                    continue;
                }
                for n in 0..3 {
                    let c = self.free_index[vs[n] as usize];
                    if c == NONE || c > r {
                        continue;
                    }
                    let s = if m == n {
                        // The diagonal comes first in its column (rows ≥ the column).
                        self.col_ptr[r as usize]
                    } else {
                        self.edge_slot[es[if n == (m + 1) % 3 { m } else { n }] as usize]
                    };
                    if s != NONE {
                        values[s as usize] -= st.jac[9 * f + 3 * m + n];
                    }
                }
            }
        }
    }
}
