//! Dijkstra's shortest paths on a graph with non-negative edge lengths, given by a neighbour
//! closure (half-edges of a mesh, a CSR adjacency, …).
//!
//! The order in which vertices are settled is fixed: smaller distance first, and among equal
//! distances the smaller vertex id ([`MinItem`]); a vertex's predecessor is the first one that
//! offered its final distance (offers must strictly improve). The cut loops, slits and
//! gradings built on these searches depend on exactly these choices, so every search of the
//! library goes through this one heap order.
//!
//! [`Dijkstra`] keeps its buffers between searches and resets only the vertices a search
//! touched, so that many small searches on a large mesh cost what they visit.

use std::cmp::Ordering;
use std::collections::BinaryHeap;

/// "No predecessor": the vertex is a source, or was not reached.
pub const NO_PRED: u32 = u32::MAX;

/// Min-heap item `(distance, vertex)` for [`BinaryHeap`]: the smallest distance is popped
/// first, ties go to the smaller vertex id (distances compared by `total_cmp`).
#[derive(Clone, Copy, Debug)]
pub struct MinItem(pub f64, pub u32);
impl PartialEq for MinItem {
    fn eq(&self, o: &Self) -> bool {
        self.cmp(o) == Ordering::Equal
    }
}
impl Eq for MinItem {}
impl PartialOrd for MinItem {
    fn partial_cmp(&self, o: &Self) -> Option<Ordering> {
        Some(self.cmp(o))
    }
}
impl Ord for MinItem {
    fn cmp(&self, o: &Self) -> Ordering {
        o.0.total_cmp(&self.0).then_with(|| o.1.cmp(&self.1))
    }
}

/// Buffers of a Dijkstra search over the vertices `0..n` (distances, predecessors, settled
/// flags, heap), reset in time proportional to what the last search touched.
#[derive(Debug, Clone)]
pub struct Dijkstra {
    dist: Vec<f64>,
    pred: Vec<u32>,
    settled: Vec<bool>,
    touched: Vec<u32>,
    heap: BinaryHeap<MinItem>,
}

impl Dijkstra {
    /// Empty search over `n` vertices (every distance infinite).
    pub fn new(n: usize) -> Dijkstra {
        Dijkstra {
            dist: vec![f64::INFINITY; n],
            pred: vec![NO_PRED; n],
            settled: vec![false; n],
            touched: Vec::new(),
            heap: BinaryHeap::new(),
        }
    }

    /// Extend to `n` vertices (new ones unreached); never shrinks.
    pub fn grow(&mut self, n: usize) {
        if n > self.dist.len() {
            self.dist.resize(n, f64::INFINITY);
            self.pred.resize(n, NO_PRED);
            self.settled.resize(n, false);
        }
    }

    /// Forget the last search.
    pub fn reset(&mut self) {
        for &v in &self.touched {
            self.dist[v as usize] = f64::INFINITY;
            self.pred[v as usize] = NO_PRED;
            self.settled[v as usize] = false;
        }
        self.touched.clear();
        self.heap.clear();
    }

    /// Tentative (final once settled) distance of `v`; infinite if not reached.
    #[inline]
    pub fn dist(&self, v: u32) -> f64 {
        self.dist[v as usize]
    }

    /// The tag given with the offer that set `v`'s distance ([`NO_PRED`] if none).
    #[inline]
    pub fn pred(&self, v: u32) -> u32 {
        self.pred[v as usize]
    }

    /// Whether `v` has been popped by [`Dijkstra::pop`].
    #[inline]
    pub fn is_settled(&self, v: u32) -> bool {
        self.settled[v as usize]
    }

    /// Offer distance `d` to `v`, reached via `via` (a predecessor vertex, a half-edge, …):
    /// taken if it is strictly smaller than the current one.
    #[inline]
    pub fn offer(&mut self, v: u32, d: f64, via: u32) {
        if d < self.dist[v as usize] {
            if self.dist[v as usize] == f64::INFINITY {
                self.touched.push(v);
            }
            self.dist[v as usize] = d;
            self.pred[v as usize] = via;
            self.heap.push(MinItem(d, v));
        }
    }

    /// Settle and return the next vertex with its distance, or `None` when the heap is empty.
    pub fn pop(&mut self) -> Option<(f64, u32)> {
        while let Some(MinItem(d, v)) = self.heap.pop() {
            if self.settled[v as usize] || d > self.dist[v as usize] {
                continue;
            }
            self.settled[v as usize] = true;
            return Some((d, v));
        }
        None
    }

    /// Settle vertices until the heap is empty or `stop(d, v)` holds for the vertex just
    /// settled (which is then returned, not expanded); `neighbours(v)` lists the `(w, length)`
    /// pairs leaving `v`, each offered `d + length` with predecessor `v`. Start with
    /// [`Dijkstra::offer`] on the sources.
    pub fn run<I>(
        &mut self,
        mut neighbours: impl FnMut(u32) -> I,
        mut stop: impl FnMut(f64, u32) -> bool,
    ) -> Option<u32>
    where
        I: IntoIterator<Item = (u32, f64)>,
    {
        while let Some((d, v)) = self.pop() {
            if stop(d, v) {
                return Some(v);
            }
            for (w, l) in neighbours(v) {
                self.offer(w, d + l, v);
            }
        }
        None
    }

    /// The distances (infinite where not reached).
    pub fn into_distances(self) -> Vec<f64> {
        self.dist
    }
}

/// Distances from `sources` (all at distance 0) to every vertex of `0..n`, infinite where
/// unreachable; `neighbours(v)` lists the `(w, length)` pairs leaving `v`.
pub fn distances<I>(n: usize, sources: &[u32], neighbours: impl FnMut(u32) -> I) -> Vec<f64>
where
    I: IntoIterator<Item = (u32, f64)>,
{
    let mut search = Dijkstra::new(n);
    for &s in sources {
        search.offer(s, 0.0, NO_PRED);
    }
    search.run(neighbours, |_, _| false);
    search.into_distances()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Bellman–Ford relaxation to a fixed point, the reference for the distances.
    fn bellman_ford(n: usize, edges: &[(u32, u32, f64)], source: u32) -> Vec<f64> {
        let mut d = vec![f64::INFINITY; n];
        d[source as usize] = 0.0;
        for _ in 0..n {
            for &(a, b, l) in edges {
                for (x, y) in [(a, b), (b, a)] {
                    if d[x as usize] + l < d[y as usize] {
                        d[y as usize] = d[x as usize] + l;
                    }
                }
            }
        }
        d
    }

    fn csr(n: usize, edges: &[(u32, u32, f64)]) -> Vec<Vec<(u32, f64)>> {
        let mut adj = vec![Vec::new(); n];
        for &(a, b, l) in edges {
            adj[a as usize].push((b, l));
            adj[b as usize].push((a, l));
        }
        adj
    }

    #[test]
    fn distances_match_bellman_ford_on_a_random_graph() {
        let n = 60;
        let mut s = 0x9e37_79b9_7f4a_7c15u64;
        let mut rand = || {
            s ^= s << 13;
            s ^= s >> 7;
            s ^= s << 17;
            s
        };
        let mut edges = Vec::new();
        for _ in 0..200 {
            let (a, b) = ((rand() % n) as u32, (rand() % n) as u32);
            edges.push((a, b, (rand() % 1000) as f64 / 100.0));
        }
        let adj = csr(n as usize, &edges);
        for src in [0u32, 7, 33] {
            let want = bellman_ford(n as usize, &edges, src);
            let got = distances(n as usize, &[src], |v| adj[v as usize].iter().copied());
            assert_eq!(got, want, "source {src}");
        }
    }

    #[test]
    fn ties_settle_the_smaller_vertex_first_and_keep_the_first_predecessor() {
        // A square 0–1–3, 0–2–3 with equal lengths: 1 and 2 tie at distance 1, 1 is settled
        // first and is the first to offer 3 its final distance 2.
        let adj = csr(4, &[(0, 2, 1.0), (0, 1, 1.0), (2, 3, 1.0), (1, 3, 1.0)]);
        let mut search = Dijkstra::new(4);
        search.offer(0, 0.0, NO_PRED);
        let mut order = Vec::new();
        search.run(
            |v| adj[v as usize].iter().copied(),
            |_, v| {
                order.push(v);
                false
            },
        );
        assert_eq!(order, vec![0, 1, 2, 3]);
        assert_eq!(search.pred(3), 1);
        assert_eq!(search.pred(0), NO_PRED);
        // Stop at the first settled vertex satisfying the predicate; reset forgets it all.
        search.reset();
        search.offer(3, 0.0, NO_PRED);
        let hit = search.run(|v| adj[v as usize].iter().copied(), |_, v| v == 0);
        assert_eq!(hit, Some(0));
        assert_eq!(search.dist(0), 2.0);
        assert_eq!(search.pred(0), 1);
        search.reset();
        assert!((0..4).all(|v| search.dist(v) == f64::INFINITY && !search.is_settled(v)));
    }
}
