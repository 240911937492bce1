//! Grading around a vertex ([`Refiner::grade_around`]): longest-edge bisections (LEPP)
//! of the faces near the vertex until every face within a radius is small against its
//! distance to the vertex (paper 000 Step 2, as the cut's base vertex needs it).

use super::*;

impl Refiner {
    /// Shortest-path distances (along edges, with the current lengths) from `x`, up to `cutoff`
    /// (farther vertices get `INFINITY`).
    pub(super) fn distances(&self, x: u32, cutoff: f64) -> Vec<f64> {
        let nv = self.n_vertices();
        // CSR adjacency from half-edges, both directions (interior edges appear twice).
        let mut deg = vec![0u32; nv + 1];
        for h in 0..self.len.len() as u32 {
            deg[self.origin(h) as usize] += 1;
            deg[self.origin(Self::next(h)) as usize] += 1;
        }
        let mut start = vec![0u32; nv + 1];
        for v in 0..nv {
            start[v + 1] = start[v] + deg[v];
        }
        let mut fill = start.clone();
        let mut adj = vec![(0u32, 0.0f64); start[nv] as usize];
        for h in 0..self.len.len() as u32 {
            let (a, b, l) = (
                self.origin(h),
                self.origin(Self::next(h)),
                self.len[h as usize],
            );
            adj[fill[a as usize] as usize] = (b, l);
            fill[a as usize] += 1;
            adj[fill[b as usize] as usize] = (a, l);
            fill[b as usize] += 1;
        }
        let mut search = Dijkstra::new(nv);
        search.offer(x, 0.0, NO_PRED);
        search.run(
            |v| {
                adj[start[v as usize] as usize..start[v as usize + 1] as usize]
                    .iter()
                    .copied()
            },
            |d, _| d > cutoff,
        );
        let mut dist = search.into_distances();
        for d in &mut dist {
            if *d > cutoff {
                *d = f64::INFINITY;
            }
        }
        dist
    }

    /// The half-edge along which face `f` is bisected by longest-edge refinement: its longest
    /// edge, except that faces at `x` are only ever split across their link edge (so the
    /// distance from `x` to its link never shrinks).
    pub(super) fn refinement_edge(&self, f: u32, x: u32) -> u32 {
        let t = self.faces[f as usize];
        if let Some(i) = t.iter().position(|&v| v == x) {
            return 3 * f + (i as u32 + 1) % 3;
        }
        let mut best = 3 * f;
        for k in 1..3 {
            if self.len[(3 * f + k) as usize] > self.len[best as usize] {
                best = 3 * f + k;
            }
        }
        best
    }

    /// The terminal edge of Rivara's longest-edge propagation path from face `f`: follow the
    /// longest edges until an edge is the longest of both its faces (or on the boundary).
    pub(super) fn lepp_edge(&self, f: u32, x: u32) -> u32 {
        let mut h = self.refinement_edge(f, x);
        for _ in 0..64 {
            let t = self.twin[h as usize];
            if t == NONE {
                break;
            }
            let r = self.refinement_edge(t / 3, x);
            if r == t || self.len[r as usize] <= self.len[h as usize] {
                break;
            }
            h = r;
        }
        h
    }

    /// **Longest-edge bisection** (Rivara's LEPP) started at face `f`: split the terminal
    /// edge of the longest-edge propagation path from `f` at its midpoint (metric-preserving,
    /// like [`Refiner::split`]); returns the new vertex. Repeated bisection of a face keeps
    /// the smallest angle of the refined faces above half the smallest input angle (Rivara),
    /// so refining a region never creates slivers there.
    pub fn bisect(&mut self, f: u32) -> Result<u32> {
        if f as usize >= self.faces.len() {
            return Err(Error::input(format!(
                "face {f} does not exist (the mesh has {} faces)",
                self.faces.len()
            )));
        }
        let h = self.lepp_edge(f, NONE);
        Ok(self.split(h, 0.5))
    }

    /// One LEPP step from face `f` (faces at `x` split across their link edge only), keeping
    /// the distances from `x` up to date.
    pub(super) fn lepp_step(&mut self, f: u32, x: u32, dist: &mut Vec<f64>) -> u32 {
        let h = self.lepp_edge(f, x);
        let m = self.split(h, 0.5);
        // Distance of the new vertex: the best over its neighbours.
        let (fan, closed) = self.fan(m);
        let mut dm = f64::INFINITY;
        for &h2 in &fan {
            let v = self.origin(Self::next(h2));
            dm = dm.min(dist[v as usize] + self.len[h2 as usize]);
        }
        if !closed {
            if let Some(&last) = fan.last() {
                let p = Self::prev(last);
                dm = dm.min(dist[self.origin(p) as usize] + self.len[p as usize]);
            }
        }
        dist.push(dm);
        m
    }

    /// Graded refinement around interior vertex `x` so that about `paths` vertex-disjoint paths
    /// can leave `x` side by side: every face (not incident to `x`) whose nearest vertex lies
    /// at distance `r < radius` from `x` is refined (by longest-edge bisection) until its
    /// longest edge is at most `Θ·r/paths`, with `Θ` the cone angle at `x`. `radius` bounds
    /// the refined region; `max_splits` bounds the work. Returns the number of splits.
    pub fn grade_around(
        &mut self,
        x: u32,
        paths: usize,
        radius: f64,
        max_splits: usize,
    ) -> Result<usize> {
        self.check_interior(x)?;
        let theta = self.cone_angle(x);
        if !(theta.is_finite() && theta > 0.0) || paths == 0 {
            return Ok(0);
        }
        let k = theta / paths as f64;
        let mut dist = self.distances(x, radius);
        let needs = |s: &Self, f: u32, dist: &[f64]| -> bool {
            let t = s.faces[f as usize];
            if t.contains(&x) {
                return false;
            }
            let r = t
                .iter()
                .map(|&v| dist[v as usize])
                .fold(f64::INFINITY, f64::min);
            if r.is_nan() || r >= radius {
                return false;
            }
            let lmax = s.len[3 * f as usize]
                .max(s.len[3 * f as usize + 1])
                .max(s.len[3 * f as usize + 2]);
            lmax > k * r
        };
        let mut work: Vec<u32> = (0..self.n_faces() as u32)
            .filter(|&f| needs(self, f, &dist))
            .collect();
        let mut n = 0;
        while let Some(f) = work.pop() {
            if n >= max_splits {
                break;
            }
            if !needs(self, f, &dist) {
                continue;
            }
            let nf_before = self.n_faces() as u32;
            let m = self.lepp_step(f, x, &mut dist);
            n += 1;
            work.push(f);
            for g in nf_before..self.n_faces() as u32 {
                work.push(g);
            }
            // The faces around the new vertex changed too.
            for c in self.fan(m).0 {
                work.push(c / 3);
            }
        }
        Ok(n)
    }
}
