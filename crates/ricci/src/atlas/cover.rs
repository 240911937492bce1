//! Step 5 of the atlas (paper 000 §4 Step 5, paper 002 §5.3.1): the cover of the surface by
//! charts. Every non-singular face gets a *home chart* that contains its whole neighbourhood
//! with one coordinate per vertex: the central chart where it suffices, *cut charts* developed
//! ([`super::develop`]) around the faces near the cut, and *local charts* for the faces graded
//! towards a cone whose home chart is too large for them ([`super::LOCAL_CHART_CONDITIONING`]).
//! Every chart is validated (lengths reproduced, no flipped face) when it is added.

use super::error::AtlasError;
use super::{develop, AffineAtlas, Chart, ChartId, ChartReport, FlatCharts};
use super::{LOCAL_CHART_CONDITIONING, LOCAL_CHART_RINGS};
use crate::error::Result;
use crate::mesh::NONE;
use crate::progress::Progress;
use std::collections::VecDeque;
use std::time::Instant;

impl AffineAtlas {
    /// Whether face `f` touches a singular vertex.
    pub(super) fn at_cone(&self, f: u32) -> bool {
        self.mesh.face(f).iter().any(|v| self.singular.contains(v))
    }

    /// The faces sharing a vertex with `f`, except faces at a cone (sorted).
    pub(super) fn neighbourhood(&self, f: u32) -> Vec<u32> {
        let mut out = Vec::with_capacity(24);
        for v in self.mesh.face(f) {
            for g in self.mesh.vertex_faces(v) {
                if !self.at_cone(g) {
                    out.push(g);
                }
            }
        }
        out.sort_unstable();
        out.dedup();
        out
    }

    /// Whether chart `c` contains the neighbourhood of `f` with one coordinate per vertex
    /// (within `tol`).
    pub(super) fn homes(&self, c: ChartId, f: u32, tol: f64) -> bool {
        let mut seen: Vec<(u32, [f64; 2])> = Vec::with_capacity(16);
        for g in self.neighbourhood(f) {
            let Some(co) = self.face_coords(c, g) else {
                return false;
            };
            let v = self.mesh.face(g);
            for i in 0..3 {
                match seen.iter().find(|s| s.0 == v[i]) {
                    Some(s) => {
                        if (s.1[0] - co[i][0]).hypot(s.1[1] - co[i][1]) > tol {
                            return false;
                        }
                    }
                    None => seen.push((v[i], co[i])),
                }
            }
        }
        true
    }

    pub(super) fn push_chart(
        &mut self,
        chart: Chart,
        kind: &'static str,
        rejected: usize,
    ) -> ChartId {
        let id = self.charts.len() as ChartId;
        for (k, &f) in chart.faces.iter().enumerate() {
            self.face_charts[f as usize].push((id, k as u32));
        }
        let mut flipped = 0;
        let mut lerr: f64 = 0.0;
        for (k, &f) in chart.faces.iter().enumerate() {
            if develop::signed_area2(&chart.coords[k]) <= 0.0 {
                flipped += 1;
            }
            lerr = lerr.max(develop::face_length_error(
                &self.mesh,
                &self.lengths,
                f,
                &chart.coords[k],
            ));
        }
        self.report.charts.push(ChartReport {
            id,
            kind,
            faces: chart.faces.len(),
            home_faces: 0,
            flipped_faces: flipped,
            max_length_error: lerr,
            rejected_faces: rejected,
        });
        self.charts.push(chart);
        id
    }

    /// Closure tolerance: 1e-7 of the mean edge length.
    pub(super) fn tolerance(&self) -> f64 {
        let n = self.lengths.len().max(1) as f64;
        1e-7 * self.lengths.iter().sum::<f64>() / n
    }

    /// Give every non-singular face a home chart: the central chart where it suffices, cut
    /// charts developed around the rest.
    pub(super) fn cover(&mut self, progress: &mut dyn Progress) -> Result<()> {
        let nf = self.mesh.n_faces();
        let tol = self.tolerance();
        let mut remaining: Vec<bool> = vec![false; nf];
        for f in 0..nf as u32 {
            if self.at_cone(f) {
                continue;
            }
            if self.homes(0, f, tol) {
                self.home[f as usize] = 0;
            } else {
                remaining[f as usize] = true;
            }
        }
        let total = remaining.iter().filter(|&&b| b).count().max(1);
        let mut guard = 0;
        while let Some(seed) = (0..nf as u32).find(|&f| remaining[f as usize]) {
            guard += 1;
            if guard > nf {
                break;
            }
            let left = remaining.iter().filter(|&&b| b).count();
            progress.report(
                "charts",
                Some(1.0 - left as f64 / total as f64),
                &format!(
                    "{} charts, {left} faces near the cut left",
                    self.charts.len()
                ),
            );
            // The connected cluster of remaining faces around the seed (across shared vertices).
            let mut in_cluster = vec![false; nf];
            let mut cluster = vec![seed];
            in_cluster[seed as usize] = true;
            let mut q = VecDeque::from([seed]);
            while let Some(f) = q.pop_front() {
                for v in self.mesh.face(f) {
                    for g in self.mesh.vertex_faces(v) {
                        if remaining[g as usize] && !in_cluster[g as usize] {
                            in_cluster[g as usize] = true;
                            cluster.push(g);
                            q.push_back(g);
                        }
                    }
                }
            }
            let mut homed = self.try_chart(&cluster, seed, &remaining, tol);
            if !homed.contains(&seed) {
                homed = self.try_chart(&[seed], seed, &remaining, tol);
            }
            if homed.is_empty() {
                return Err(AtlasError::ChartNotFlat { face: seed }.into());
            }
            for f in homed {
                remaining[f as usize] = false;
            }
        }
        self.add_local_charts(progress);
        Ok(())
    }

    /// Conditioning of face `f`'s neighbourhood in chart `c`: the largest
    /// `max(|x|, |y|) / (shortest metric side)` over the faces of [`Self::neighbourhood`]`(f)`
    /// there (`∞` when one is missing). Coordinates round to `ε |x|`, so `ε ×` this bounds
    /// the rounding of every face the spline basis of `f` is evaluated on, relative to that
    /// face.
    pub fn conditioning(&self, c: ChartId, f: u32) -> f64 {
        let mut worst: f64 = 0.0;
        for g in self.neighbourhood(f) {
            let Some(co) = self.face_coords(c, g) else {
                return f64::INFINITY;
            };
            let hs = self.mesh.face_halfedges(g);
            let short = hs
                .iter()
                .map(|&h| self.lengths[self.mesh.he_edge(h) as usize])
                .fold(f64::INFINITY, f64::min);
            let big = co
                .iter()
                .map(|p| p[0].abs().max(p[1].abs()))
                .fold(0.0, f64::max);
            worst = worst.max(big / short);
        }
        worst
    }

    /// Step 5, conditioning: a single cone of angle `2π(2g − 1)` grades the faces around it
    /// down by orders of magnitude (1e-7 of the central chart on 3holes.off), and a face whose
    /// corners are stored in a chart `10⁷` of its size across has them to only `1e-9` of
    /// itself — the spline bases built there then jump by up to `1e-3` (relative) across
    /// edges. Every face whose home chart has [`Self::conditioning`] above
    /// [`LOCAL_CHART_CONDITIONING`] is rehomed in a *local chart*: the development
    /// ([`develop`]) of the neighbourhoods of the faces still to rehome within
    /// [`LOCAL_CHART_RINGS`] vertex-rings of a seed face, seeded there (so the coordinates are
    /// of the size of the cluster), with the closure tolerance 1e-7 of the seed's
    /// neighbourhood's mean edge, validated like every chart. A face of the cluster takes it as
    /// its home chart when the chart contains its neighbourhood with one coordinate per vertex
    /// and conditions it within the bound; a seed left over gets a chart of its own
    /// neighbourhood alone (kept when it is better conditioned than the old home).
    fn add_local_charts(&mut self, progress: &mut dyn Progress) {
        let t0 = Instant::now();
        let nf = self.mesh.n_faces();
        let mut todo: Vec<bool> = (0..nf as u32)
            .map(|f| {
                let h = self.home[f as usize];
                h != NONE && self.conditioning(h, f) > LOCAL_CHART_CONDITIONING
            })
            .collect();
        let list: Vec<u32> = (0..nf as u32).filter(|&f| todo[f as usize]).collect();
        let mut region = vec![false; nf];
        let mut stamp = vec![u32::MAX; nf];
        for (k, &f) in list.iter().enumerate() {
            if !todo[f as usize] {
                continue;
            }
            if k % 64 == 0 {
                progress.report(
                    "charts",
                    Some(k as f64 / list.len().max(1) as f64),
                    &format!("local charts near the cone: {k} of {} faces", list.len()),
                );
            }
            // Faces to rehome within LOCAL_CHART_RINGS vertex-rings of f.
            let mut cluster = vec![f];
            stamp[f as usize] = f;
            let mut front = vec![f];
            for _ in 0..LOCAL_CHART_RINGS {
                let mut next = Vec::new();
                for &g in &front {
                    for v in self.mesh.face(g) {
                        for e in self.mesh.vertex_faces(v) {
                            if todo[e as usize] && stamp[e as usize] != f {
                                stamp[e as usize] = f;
                                cluster.push(e);
                                next.push(e);
                            }
                        }
                    }
                }
                front = next;
            }
            self.try_local_chart(&cluster, f, &mut todo, &mut region, true);
            if todo[f as usize] {
                self.try_local_chart(&[f], f, &mut todo, &mut region, false);
                todo[f as usize] = false;
            }
        }
        self.report.local_charts = self
            .report
            .charts
            .iter()
            .filter(|c| c.kind == "local")
            .count();
        let (mut left, mut worst) = (0usize, 0.0f64);
        for &f in &list {
            let c = self.conditioning(self.home[f as usize], f);
            if c > LOCAL_CHART_CONDITIONING {
                left += 1;
                worst = worst.max(c);
            }
        }
        if left > 0 {
            self.report.notes.push(format!(
                "{left} faces keep a home chart more than {LOCAL_CHART_CONDITIONING:.0e} of \
                 their size across (worst {worst:.2e}): no local chart conditioned them \
                 better; their coordinates there are accurate to ~{:.0e} of the face",
                worst * f64::EPSILON
            ));
        }
        self.report.seconds_local_charts = t0.elapsed().as_secs_f64();
    }

    /// One local chart for `cluster` seeded at `seed` ([`Self::add_local_charts`]); `strict`:
    /// a face is rehomed only within [`LOCAL_CHART_CONDITIONING`], else whenever the chart
    /// conditions it better than its old home. The chart is dropped when it rehomes nothing.
    fn try_local_chart(
        &mut self,
        cluster: &[u32],
        seed: u32,
        todo: &mut [bool],
        region: &mut [bool],
        strict: bool,
    ) {
        let mut sum = 0.0;
        let mut count = 0usize;
        for g in self.neighbourhood(seed) {
            for h in self.mesh.face_halfedges(g) {
                sum += self.lengths[self.mesh.he_edge(h) as usize];
                count += 1;
            }
        }
        let tol = 1e-7 * sum / count.max(1) as f64;
        let mut marked = Vec::new();
        for &f in cluster {
            for g in self.neighbourhood(f) {
                if !region[g as usize] {
                    region[g as usize] = true;
                    marked.push(g);
                }
            }
        }
        let dev = develop::develop(&self.mesh, &self.lengths, region, seed, tol);
        for g in marked {
            region[g as usize] = false;
        }
        if dev.faces.is_empty() {
            return;
        }
        let id = self.push_chart(
            Chart {
                faces: dev.faces,
                coords: dev.coords,
            },
            "local",
            dev.rejected,
        );
        let mut any = false;
        for &f in cluster {
            if !todo[f as usize] || !self.homes(id, f, tol) {
                continue;
            }
            let c = self.conditioning(id, f);
            let better = if strict {
                c <= LOCAL_CHART_CONDITIONING
            } else {
                c < self.conditioning(self.home[f as usize], f)
            };
            if better {
                self.home[f as usize] = id;
                todo[f as usize] = false;
                any = true;
            }
        }
        if !any {
            self.pop_chart(id);
        }
    }

    /// Remove the last chart (`id`) again.
    fn pop_chart(&mut self, id: ChartId) {
        if let Some(chart) = self.charts.pop() {
            for &f in &chart.faces {
                self.face_charts[f as usize].retain(|x| x.0 != id);
            }
            self.report.charts.pop();
        }
    }

    /// Develop the union of the neighbourhoods of `cluster` from `seed`; keep the chart if it
    /// homes some remaining face; returns the faces it homes.
    fn try_chart(&mut self, cluster: &[u32], seed: u32, remaining: &[bool], tol: f64) -> Vec<u32> {
        let nf = self.mesh.n_faces();
        let mut region = vec![false; nf];
        for &f in cluster {
            for g in self.neighbourhood(f) {
                region[g as usize] = true;
            }
        }
        let dev = develop::develop(&self.mesh, &self.lengths, &region, seed, tol);
        if dev.faces.is_empty() {
            return Vec::new();
        }
        let id = self.push_chart(
            Chart {
                faces: dev.faces.clone(),
                coords: dev.coords,
            },
            "cut",
            dev.rejected,
        );
        let homed: Vec<u32> = cluster
            .iter()
            .copied()
            .filter(|&f| remaining[f as usize] && self.homes(id, f, tol))
            .collect();
        if homed.is_empty() {
            self.pop_chart(id);
            return Vec::new();
        }
        for &f in &homed {
            self.home[f as usize] = id;
        }
        homed
    }

    pub(super) fn finish_report(&mut self) {
        let mut worst: f64 = 0.0;
        let mut worst_rel: f64 = 0.0;
        let mut worst_cond: f64 = 0.0;
        for f in 0..self.mesh.n_faces() as u32 {
            let short = self
                .mesh
                .face_halfedges(f)
                .iter()
                .map(|&h| self.lengths[self.mesh.he_edge(h) as usize])
                .fold(f64::INFINITY, f64::min);
            let cs = &self.face_charts[f as usize];
            for k in 1..cs.len() {
                if let Some((_, r)) = self.transition(cs[0].0, cs[k].0, f) {
                    worst = worst.max(r);
                    worst_rel = worst_rel.max(r / short);
                }
            }
            let h = self.home[f as usize];
            if h != NONE {
                worst_cond = worst_cond.max(self.conditioning(h, f));
            }
        }
        self.report.max_transition_error = worst;
        self.report.max_relative_transition_error = worst_rel;
        self.report.max_home_conditioning = worst_cond;
        for c in &mut self.report.charts {
            c.home_faces = 0;
        }
        let mut without = 0;
        for f in 0..self.mesh.n_faces() {
            let h = self.home[f];
            if h != NONE {
                self.report.charts[h as usize].home_faces += 1;
            } else if !self.at_cone(f as u32) {
                without += 1;
            }
        }
        self.report.faces_without_home = without;
        self.report.flipped_faces = self.report.charts.iter().map(|c| c.flipped_faces).sum();
        self.report.max_length_error = self
            .report
            .charts
            .iter()
            .map(|c| c.max_length_error)
            .fold(0.0, f64::max);
    }
}
