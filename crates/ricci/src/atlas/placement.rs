//! Automatic placement of the single cone by least area distortion (paper 000 §4 Step 1).
//!
//! The paper runs one full flow per vertex and keeps the vertex whose flat metric has the
//! least distortion `D(v) = Σ_f (log S_f − log s_f)² / n`. Here all vertices are ranked with
//! **one factorization** of the flow's Hessian at the initial metric (`H = ∂K/∂u`, a weighted
//! cotangent-like Laplacian, pinned at one vertex) and a few solves:
//!
//! * Linearized flow: the cone target `K̄ = κ e_v` (`κ = 2πχ`) is reached from the initial
//!   curvature `K⁰` by `δu ≈ G (κ e_v − K⁰)`, `G = H⁺` (pinned inverse).
//! * The log-area change of face `f` is `(P δu)_f` with `P = ∂ log A_f / ∂u` (chain rule
//!   through the scheme's `∂l/∂u` and `∂ log A/∂l_a = a (b² + c² − a²) / (8A²)`).
//! * With `w = log A⁰ − log S − P G K⁰` and the best global scale (the flow rescales the
//!   area), `D(v) ≈ Var(w) + 2κ Cov(w, P G e_v) + κ² Var(P G e_v)`. The middle term is
//!   `(2κ/n)(G Pᵀ Π w)_v` for all `v` at once (one solve, `Π` the centring of face
//!   values); the last term is `κ² ‖Π P G e_v‖² / n`, one solve per vertex (a sparse
//!   triangular solve pair with the same factor). Up to `exact_limit` vertices every vertex
//!   is evaluated; above, `D` (smooth in `v`, paper 000 Fig. 10) is evaluated on a
//!   farthest-point sample of `samples` vertices and then on every vertex within the
//!   sample's covering radius of the `refine_best` best samples (twice, halving the radius).
//!   (A Hutchinson estimate of `diag(G M G)` from random ±1 probes was tried first: its
//!   error is of the order of the off-diagonal mass of the smooth matrix `G M G`, far above
//!   the differences between vertices — it gave negative variances on a 10k-vertex mesh.)
//! * The best `confirm` candidates are confirmed by full flows (valence raised to
//!   `4 − 2κ/π` by splits, Newton to 1e-9) and the one with the least measured distortion
//!   is chosen. A candidate whose flows fail with every scheme is flowed again on a mesh
//!   graded around the cone ([`candidate_mesh`]: a cone of angle `2π(1 + m)` needs a
//!   conformal factor growing like `m log r`, which the input's first rings do not resolve
//!   for large genus — botijo, genus 5). The flows run on a budget (iterations per scheme,
//!   candidates, Newton work in all; [`PlacementOptions`]), so a mesh where no candidate
//!   converges is refused in bounded time with one sentence saying what was tried.

use super::error::AtlasError;
use super::AtlasOptions;
use crate::error::{Error, Result};
use crate::flow::TargetSpec;
use crate::mesh::{Mesh, Surface};
use crate::metric::refine::Refiner;
use crate::metric::IntrinsicMetric;
use crate::metric::Scheme;
use crate::metric::{
    euler_characteristic, ConformalStructure, Evaluator, Geometry, HessianPattern,
};
use crate::numeric::sparse::SymmetricSolver;
use crate::progress::Progress;
use serde::Serialize;
use std::f64::consts::PI;
use std::time::Instant;

/// Options of the automatic placement.
#[derive(Debug, Clone)]
pub struct PlacementOptions {
    /// Candidates confirmed by full flows (default 3).
    pub confirm: usize,
    /// Up to this many vertices the variance term is computed exactly (default 4000).
    pub exact_limit: usize,
    /// Above `exact_limit`: size of the farthest-point sample evaluated exactly (default 300).
    pub samples: usize,
    /// Above `exact_limit`: the neighbourhoods of this many best samples are evaluated
    /// exactly (default 4).
    pub refine_best: usize,
    /// Newton iterations per scheme in one candidate's flow (default 40).
    pub candidate_iterations: usize,
    /// Candidates tried at most, best estimates first (default 12).
    pub max_candidates: usize,
    /// Newton work of all candidate flows together, in vertex-iterations (iterations times
    /// the number of input vertices, so that the budget bounds time whatever the mesh size;
    /// at least `candidate_iterations` iterations). When it is spent no further flow is run
    /// (default 6·10⁶: 145 iterations on botijo's 41k vertices, about 16 s of CPU on a 2-core
    /// Xeon VM; 1335 on fertility's 4.5k).
    pub confirm_budget: usize,
    /// Confirm a candidate on the graded mesh when no scheme converges on the ungraded one
    /// ([`candidate_mesh`]; default true).
    pub grade: bool,
}

impl Default for PlacementOptions {
    fn default() -> Self {
        PlacementOptions {
            confirm: 3,
            exact_limit: 4000,
            samples: 300,
            refine_best: 4,
            candidate_iterations: 40,
            max_candidates: 12,
            confirm_budget: 6_000_000,
            grade: true,
        }
    }
}

/// What the automatic placement did.
#[derive(Debug, Clone, Serialize)]
pub struct Placement {
    pub chosen: u32,
    /// "exact" (every vertex ranked) or "sampled".
    pub method: String,
    pub candidates: usize,
    /// Linearized estimate of every confirmed candidate and its measured distortion.
    pub confirmed: Vec<ConfirmedCandidate>,
    /// Candidates whose flow did not converge within the budget, and why.
    pub rejected: Vec<RejectedCandidate>,
    /// Newton iterations of all candidate flows.
    pub flow_iterations: usize,
    pub estimate_seconds: f64,
    pub confirm_seconds: f64,
}

#[derive(Debug, Clone, Serialize)]
pub struct ConfirmedCandidate {
    pub vertex: u32,
    pub estimate: f64,
    pub measured: f64,
    /// Scheme of the converged flow.
    pub scheme: String,
    /// Whether the flow needed the neighbourhood of the cone graded ([`candidate_mesh`]).
    pub graded: bool,
    /// Newton iterations of all the flows this candidate took.
    pub iterations: usize,
    pub seconds: f64,
}

/// A candidate whose single-cone flow did not converge.
#[derive(Debug, Clone, Serialize)]
pub struct RejectedCandidate {
    pub vertex: u32,
    pub estimate: f64,
    /// Smallest max |K − K̄| any of its flows reached (`None` if every flow failed).
    pub best_error: Option<f64>,
    pub iterations: usize,
    pub seconds: f64,
    pub reason: String,
}

/// The linearized area distortion `D(v)` of every vertex (`INFINITY` for boundary vertices)
/// and the method used ("exact" or "sampled"; unevaluated vertices get `INFINITY` too).
pub fn estimate(
    mesh: &Mesh,
    metric: &IntrinsicMetric,
    scheme: Scheme,
    options: &PlacementOptions,
) -> Result<(Vec<f64>, &'static str)> {
    let lengths = metric.lengths();
    let nv = mesh.n_vertices();
    let nf = mesh.n_faces();
    let chi = euler_characteristic(mesh);
    let kappa = 2.0 * PI * chi as f64;
    let structure = ConformalStructure::new(mesh, lengths, Geometry::Euclidean, scheme, 1.0)?;
    let mut ev = Evaluator::new(mesh, structure);
    let u0 = ev.structure.u0.clone();
    let pin = (0..nv as u32)
        .filter(|&v| !mesh.is_isolated(v))
        .max_by_key(|&v| (!mesh.is_boundary_vertex(v), mesh.valence(v)))
        .ok_or_else(|| Error::topology("the mesh has no faces"))?;
    let mut fixed = vec![false; nv];
    fixed[pin as usize] = true;
    let pattern = HessianPattern::new(&ev.data, &fixed);
    let mut values = vec![0.0; pattern.nnz()];
    if !ev.evaluate_with_hessian(&u0, &pattern, &mut values) {
        return Err(Error::numerical(
            "the initial metric lies outside the domain of the scheme",
        ));
    }
    let mut solver = SymmetricSolver::new(&pattern)?;
    if !solver.factor_llt(&values) {
        return Err(Error::numerical(
            "the Hessian of the flow at the initial metric is not positive definite",
        ));
    }
    let n = pattern.n();
    let mut solve = |rhs_full: &[f64]| -> Vec<f64> {
        let mut x: Vec<f64> = pattern
            .free_vertex
            .iter()
            .map(|&v| rhs_full[v as usize])
            .collect();
        solver.solve(&mut x);
        let mut out = vec![0.0; nv];
        for (k, &v) in pattern.free_vertex.iter().enumerate() {
            out[v as usize] = x[k];
        }
        out
    };
    let _ = n;
    // P: per face, ∂ log A_f / ∂u at its three corners; d: log A_f − log A_f(input).
    let (p, d) = log_area_derivatives(
        mesh,
        lengths,
        &ev.ws.lengths,
        &ev.ws.dlengths,
        &ev.data.edges,
    );
    let apply_p = |x: &[f64]| -> Vec<f64> {
        (0..nf)
            .map(|f| {
                let fv = mesh.face(f as u32);
                (0..3).map(|j| p[f][j] * x[fv[j] as usize]).sum()
            })
            .collect()
    };
    let centre = |y: &mut Vec<f64>| {
        let m = y.iter().sum::<f64>() / nf.max(1) as f64;
        y.iter_mut().for_each(|x| *x -= m);
    };
    let apply_pt = |y: &[f64]| -> Vec<f64> {
        let mut out = vec![0.0; nv];
        for f in 0..nf {
            let fv = mesh.face(f as u32);
            for j in 0..3 {
                out[fv[j] as usize] += p[f][j] * y[f];
            }
        }
        out
    };
    let nfl = nf.max(1) as f64;
    let k0 = ev.ws.curvature.clone();
    let gk = solve(&k0);
    let mut w = d.clone();
    let pgk = apply_p(&gk);
    for f in 0..nf {
        w[f] -= pgk[f];
    }
    centre(&mut w);
    let var_w = w.iter().map(|x| x * x).sum::<f64>() / nfl;
    let cov = solve(&apply_pt(&w)); // G Pᵀ Π w
    let exact_var = |v: u32, solve: &mut dyn FnMut(&[f64]) -> Vec<f64>| -> f64 {
        let mut e = vec![0.0; nv];
        e[v as usize] = 1.0;
        let g = solve(&e);
        let mut y = apply_p(&g);
        centre(&mut y);
        y.iter().map(|x| x * x).sum::<f64>() / nfl
    };
    let interior: Vec<u32> = (0..nv as u32)
        .filter(|&v| !mesh.is_isolated(v) && !mesh.is_boundary_vertex(v))
        .collect();
    let mut out = vec![f64::INFINITY; nv];
    let total =
        |v: u32, var: f64| var_w + 2.0 * kappa * cov[v as usize] / nfl + kappa * kappa * var;
    if interior.len() <= options.exact_limit {
        for &v in &interior {
            out[v as usize] = total(v, exact_var(v, &mut solve));
        }
        return Ok((out, "exact"));
    }
    // Large meshes: D is smooth in v (paper 000 Fig. 10), so evaluate it exactly on a
    // farthest-point sample, then on every vertex near the best samples, twice.
    let (samples, radius) = farthest_points(mesh, &interior, options.samples.max(8));
    for &v in &samples {
        out[v as usize] = total(v, exact_var(v, &mut solve));
    }
    let mut r = radius.max(1);
    for _round in 0..2 {
        let mut best: Vec<u32> = interior
            .iter()
            .copied()
            .filter(|&v| out[v as usize].is_finite())
            .collect();
        best.sort_by(|&a, &b| out[a as usize].total_cmp(&out[b as usize]));
        best.truncate(options.refine_best.max(1));
        for v in best {
            for w in within_hops(mesh, v, r) {
                if !mesh.is_boundary_vertex(w) && !out[w as usize].is_finite() {
                    out[w as usize] = total(w, exact_var(w, &mut solve));
                }
            }
        }
        r = r.div_ceil(2);
    }
    Ok((out, "sampled"))
}

/// Per face `f`: `∂ log A_f / ∂u` at its three corners (`A_f` by Heron from the current
/// lengths `l`, whose derivatives along the edge's two end variables are `dl`), and
/// `log A_f − log A_f(input)`; faces of zero area get zeros.
#[allow(clippy::type_complexity)]
fn log_area_derivatives(
    mesh: &Mesh,
    lengths: &[f64],
    l: &[f64],
    dl: &[[f64; 2]],
    edges: &[[u32; 2]],
) -> (Vec<[f64; 3]>, Vec<f64>) {
    let nf = mesh.n_faces();
    let mut p = vec![[0.0f64; 3]; nf];
    let mut d = vec![0.0; nf];
    for f in 0..nf as u32 {
        let fv = mesh.face(f);
        let e = mesh.face_edges_opposite(f);
        let s = e.map(|e| l[e as usize]);
        let a0 = crate::numeric::heron(s);
        let a_in = crate::numeric::heron(e.map(|e| lengths[e as usize]));
        if !(a0 > 0.0 && a_in > 0.0) {
            continue;
        }
        d[f as usize] = a0.ln() - a_in.ln();
        for i in 0..3 {
            let (a, b, c) = (s[i], s[(i + 1) % 3], s[(i + 2) % 3]);
            let dlog = a * (b * b + c * c - a * a) / (8.0 * a0 * a0);
            let ed = e[i] as usize;
            let [x, y] = edges[ed];
            for (j, &w) in fv.iter().enumerate() {
                if w == x {
                    p[f as usize][j] += dlog * dl[ed][0];
                } else if w == y {
                    p[f as usize][j] += dlog * dl[ed][1];
                }
            }
        }
    }
    (p, d)
}

/// Farthest-point sample of `count` vertices among `candidates` by edge hops, and the
/// covering radius (largest hop distance of a candidate from the sample).
fn farthest_points(mesh: &Mesh, candidates: &[u32], count: usize) -> (Vec<u32>, usize) {
    let nv = mesh.n_vertices();
    let mut dist = vec![usize::MAX; nv];
    let mut out = Vec::new();
    let Some(&first) = candidates.first() else {
        return (out, 0);
    };
    let mut next = first;
    loop {
        out.push(next);
        dist[next as usize] = 0;
        let mut q = std::collections::VecDeque::from([next]);
        while let Some(v) = q.pop_front() {
            let d = dist[v as usize] + 1;
            for w in mesh.vertex_neighbors(v) {
                if d < dist[w as usize] {
                    dist[w as usize] = d;
                    q.push_back(w);
                }
            }
        }
        let far = candidates
            .iter()
            .copied()
            .max_by_key(|&v| (dist[v as usize], std::cmp::Reverse(v)))
            .unwrap_or(first);
        if out.len() >= count || dist[far as usize] == 0 {
            return (out, dist[far as usize]);
        }
        next = far;
    }
}

/// Vertices within `hops` edges of `v` (including `v`).
fn within_hops(mesh: &Mesh, v: u32, hops: usize) -> Vec<u32> {
    let mut seen = std::collections::HashMap::new();
    seen.insert(v, 0usize);
    let mut q = std::collections::VecDeque::from([v]);
    let mut out = vec![v];
    while let Some(x) = q.pop_front() {
        let d = seen[&x];
        if d >= hops {
            continue;
        }
        for w in mesh.vertex_neighbors(x) {
            if let std::collections::hash_map::Entry::Vacant(e) = seen.entry(w) {
                e.insert(d + 1);
                out.push(w);
                q.push_back(w);
            }
        }
    }
    out
}

/// The mesh a candidate cone `v` (curvature `kappa`) is confirmed on: valence of `v` raised
/// to `⌈4 − 2κ/π⌉` by splits; with `graded`, the neighbourhood of `v` then graded as the
/// canonical cut grades around its base ([`Refiner::grade_around`] with `max(⌈4 − 2κ/π⌉, 8g)`
/// vertices per circle out to `1.5·that·mean spoke / cone angle`); then the one-ring
/// neighbours of `v` raised to valence 6 ([`super::raise_ring_valence`]).
///
/// Why grading: near a cone of angle `2π(1 + m)` (`m = −κ/2π = 2g − 2`) the flat metric is
/// `|z|^{2m} |dz|²`, so its log conformal factor grows like `m log r` from the cone, and an
/// edge from radius `r` to `r + h` changes it by about `m h / r`. The input triangulation,
/// whose first rings sit at `r ≈ h`, asks a vertex-based conformal factor to jump by several
/// units across one edge: on botijo (genus 5, `m = 8`) the single-cone flows then leave
/// faces that violate the triangle inequality within 3 rings of the cone and stall (every
/// scheme). Grading gives the rings `r` edges of length `≈ Θ r / n`, so the jump per edge is
/// bounded by `m Θ / n` wherever the input mesh is too coarse.
pub fn candidate_mesh(
    mesh: &Mesh,
    metric: &IntrinsicMetric,
    v: u32,
    kappa: f64,
    graded: bool,
) -> Result<crate::metric::refine::Refined> {
    let lengths = metric.lengths();
    let need = (4.0 - 2.0 * kappa / PI - 1e-9).ceil().max(3.0) as usize;
    let mut r = Refiner::new(mesh, lengths, Geometry::Euclidean, None)?;
    r.raise_valence(v, need)?;
    if graded {
        let genus = ((2 - euler_characteristic(mesh)) / 2).max(0) as usize;
        let grade = need.max(8 * genus);
        let spokes: Vec<f64> = mesh
            .outgoing(v)
            .map(|h| lengths[mesh.he_edge(h) as usize])
            .collect();
        let mean_spoke = spokes.iter().sum::<f64>() / spokes.len().max(1) as f64;
        let theta = r.cone_angle(v);
        let radius = 1.5 * grade as f64 * mean_spoke / theta.max(1e-3);
        r.grade_around(v, grade, radius, 40 * grade * grade + 1000)?;
    }
    let (refined, _) =
        super::raise_ring_valence(r.finish()?, &[(v, kappa)], 6, &Default::default())?;
    Ok(refined)
}

/// A candidate's converged single-cone flow.
#[derive(Debug, Clone)]
pub struct CandidateFlow {
    pub distortion: f64,
    pub scheme: Scheme,
    pub graded: bool,
    pub iterations: usize,
}

/// Why a candidate's flows did not give a metric.
#[derive(Debug, Clone)]
pub struct CandidateFailure {
    pub best_error: Option<f64>,
    pub iterations: usize,
    pub reason: String,
}

/// The single-cone flat metric at `v` and its measured area distortion, on the meshes of
/// [`candidate_mesh`] in the order `grading` (ungraded, graded: `[false, true]`) until one
/// converges with a scheme of [`super::flat_flow_limited`]. Every flow runs at most
/// `max_iterations` Newton iterations per scheme and `budget` iterations in all (spent
/// iterations are subtracted). The distortion is over the input faces.
#[allow(clippy::too_many_arguments)]
pub fn confirm_candidate(
    mesh: &Mesh,
    metric: &IntrinsicMetric,
    v: u32,
    scheme: Scheme,
    tolerance: f64,
    max_iterations: usize,
    grading: &[bool],
    budget: &mut usize,
) -> std::result::Result<CandidateFlow, CandidateFailure> {
    let kappa = 2.0 * PI * euler_characteristic(mesh) as f64;
    let mut iterations = 0;
    let mut best: Option<f64> = None;
    let mut reasons = Vec::new();
    for &graded in grading {
        if *budget == 0 {
            reasons.push("the iteration budget of the candidate flows is spent".to_string());
            break;
        }
        let what = if graded { "graded mesh" } else { "mesh" };
        let refined = match candidate_mesh(mesh, metric, v, kappa, graded) {
            Ok(r) => r,
            Err(e) => {
                reasons.push(format!("{what}: {e}"));
                continue;
            }
        };
        let limit = max_iterations.min(*budget).max(1);
        let run = super::flat_flow_limited(
            &refined.mesh,
            &IntrinsicMetric::euclidean(refined.lengths.clone()),
            TargetSpec::Cones(vec![(v, kappa)]),
            scheme,
            tolerance,
            max_iterations,
            budget,
        );
        match run {
            Ok(f) => {
                iterations += f.iterations;
                if f.best_error.is_finite() {
                    best = Some(best.map_or(f.best_error, |b: f64| b.min(f.best_error)));
                }
                if f.result.converged {
                    return Ok(CandidateFlow {
                        distortion: super::area_distortion(
                            &refined.mesh,
                            &refined.lengths,
                            &f.result.lengths,
                            &refined.face_origin,
                            mesh.n_faces(),
                        ),
                        scheme: f.scheme,
                        graded,
                        iterations,
                    });
                }
                reasons.push(format!(
                    "{what}: max |K − K̄| ≥ {:.3e} with every scheme (≤ {limit} iterations each)",
                    f.best_error
                ));
            }
            Err(e) => reasons.push(format!("{what}: {e}")),
        }
    }
    Err(CandidateFailure {
        best_error: best,
        iterations,
        reason: reasons.join("; "),
    })
}

/// The measured area distortion of the single-cone flat metric at `v` ([`confirm_candidate`]
/// with 400 iterations per scheme, no overall budget, the ungraded mesh first), Newton to
/// `tolerance`.
pub fn measured_distortion(
    mesh: &Mesh,
    metric: &IntrinsicMetric,
    v: u32,
    scheme: Scheme,
    tolerance: f64,
) -> Result<f64> {
    let mut budget = usize::MAX;
    confirm_candidate(
        mesh,
        metric,
        v,
        scheme,
        tolerance,
        400,
        &[false, true],
        &mut budget,
    )
    .map(|c| c.distortion)
    .map_err(|e| {
        let (vertex, reason) = (v, e.reason);
        AtlasError::SingleConeNotConverged { vertex, reason }.into()
    })
}

/// Rank with [`estimate`], confirm the best candidates with full flows, choose.
///
/// Candidates are tried in the order of their estimate until `confirm` converged, at most
/// `max_candidates`, and only while the `confirm_budget` of Newton work lasts; each
/// candidate's flows run at most `candidate_iterations` per scheme ([`confirm_candidate`]),
/// on the ungraded mesh and then (with `grade`) on the graded one. Once a candidate has
/// converged only on the graded mesh — evidence that the input triangulation is too coarse
/// for the cone's conformal factor, a property of the mesh and the genus more than of the
/// vertex — later candidates start on the graded mesh (and fall back to the ungraded one).
/// When none converges the error names the vertices tried, the best residual reached and the
/// time spent.
pub fn place(
    surface: &Surface,
    metric: &IntrinsicMetric,
    options: &AtlasOptions,
    progress: &mut dyn Progress,
) -> Result<Placement> {
    let t0 = Instant::now();
    let mesh = &surface.mesh;
    let (est, method) = estimate(mesh, metric, options.scheme, &options.placement)?;
    let estimate_seconds = t0.elapsed().as_secs_f64();
    let mut order: Vec<u32> = (0..mesh.n_vertices() as u32)
        .filter(|&v| est[v as usize].is_finite())
        .collect();
    order.sort_by(|&a, &b| est[a as usize].total_cmp(&est[b as usize]).then(a.cmp(&b)));
    if order.is_empty() {
        return Err(Error::topology(
            "the mesh has no interior vertex for the cone",
        ));
    }
    let t1 = Instant::now();
    let po = &options.placement;
    let k = po.confirm.max(1).min(order.len());
    let max_candidates = po.max_candidates.max(1);
    let budget_iterations =
        (po.confirm_budget / mesh.n_vertices().max(1)).max(po.candidate_iterations.max(1));
    let mut budget = budget_iterations;
    let mut confirmed = Vec::new();
    let mut rejected: Vec<RejectedCandidate> = Vec::new();
    let mut flow_iterations = 0;
    let mut grading: Vec<bool> = if po.grade {
        vec![false, true]
    } else {
        vec![false]
    };
    for (i, &v) in order.iter().enumerate() {
        if confirmed.len() >= k || i >= max_candidates || budget == 0 {
            break;
        }
        progress.report(
            "placement",
            Some(confirmed.len() as f64 / k as f64),
            &format!(
                "candidate {} (vertex {v}): full flow; {} of {k} confirmed, {} rejected",
                i + 1,
                confirmed.len(),
                rejected.len()
            ),
        );
        let tc = Instant::now();
        match confirm_candidate(
            mesh,
            metric,
            v,
            options.scheme,
            1e-9,
            po.candidate_iterations.max(1),
            &grading,
            &mut budget,
        ) {
            Ok(c) => {
                flow_iterations += c.iterations;
                if c.graded && grading[0] != c.graded {
                    grading = vec![true, false];
                }
                confirmed.push(ConfirmedCandidate {
                    vertex: v,
                    estimate: est[v as usize],
                    measured: c.distortion,
                    scheme: c.scheme.name().to_string(),
                    graded: c.graded,
                    iterations: c.iterations,
                    seconds: tc.elapsed().as_secs_f64(),
                })
            }
            Err(e) => {
                flow_iterations += e.iterations;
                rejected.push(RejectedCandidate {
                    vertex: v,
                    estimate: est[v as usize],
                    best_error: e.best_error,
                    iterations: e.iterations,
                    seconds: tc.elapsed().as_secs_f64(),
                    reason: e.reason,
                });
            }
        }
        let last_msg = match (confirmed.last(), rejected.last()) {
            (Some(c), _) if c.vertex == v => format!(
                "candidate {} (vertex {v}) converged: distortion {:.4} ({} scheme{}, {} \
                 iterations, {:.1} s)",
                i + 1,
                c.measured,
                c.scheme,
                if c.graded { ", graded mesh" } else { "" },
                c.iterations,
                c.seconds
            ),
            (_, Some(r)) => format!(
                "candidate {} (vertex {v}) did not converge: best max |K − K̄| {} after {} \
                 iterations ({:.1} s)",
                i + 1,
                r.best_error
                    .map_or("none".to_string(), |e| format!("{e:.3e}")),
                r.iterations,
                r.seconds
            ),
            _ => String::new(),
        };
        // One line per candidate, under its own stage name (the CLI prints these lines).
        progress.report(
            "placement candidate",
            Some(confirmed.len() as f64 / k as f64),
            &last_msg,
        );
    }
    let Some(chosen) = confirmed
        .iter()
        .min_by(|a, b| a.measured.total_cmp(&b.measured))
        .map(|c| c.vertex)
    else {
        return Err(no_candidate_error(
            &rejected,
            order.len(),
            options,
            budget_iterations,
            t0.elapsed().as_secs_f64(),
        ));
    };
    Ok(Placement {
        chosen,
        method: method.to_string(),
        candidates: order.len(),
        confirmed,
        rejected,
        flow_iterations,
        estimate_seconds,
        confirm_seconds: t1.elapsed().as_secs_f64(),
    })
}

/// The error when no candidate converged: the vertices tried, the budgets, the best residual
/// reached and the time spent (`n_ranked` ranked vertices, `seconds`).
fn no_candidate_error(
    rejected: &[RejectedCandidate],
    n_ranked: usize,
    options: &AtlasOptions,
    budget_iterations: usize,
    seconds: f64,
) -> Error {
    let po = &options.placement;
    let best = rejected
        .iter()
        .filter_map(|r| r.best_error.map(|e| (e, r.vertex)))
        .min_by(|a, b| a.0.total_cmp(&b.0));
    let tried: Vec<String> = rejected.iter().map(|r| r.vertex.to_string()).collect();
    Error::numerical(format!(
        "no candidate cone vertex gave a converged flat metric: tried {} of the {} ranked \
         vertices ({}) with the {} scheme, then inversive and tangential packing, on the mesh \
         with the cone's valence raised{}, at most {} Newton iterations per scheme and {} in \
         all{}; {:.1} s — choose the singular vertex (CLI: --singularity V) or the cones \
         yourself",
        rejected.len(),
        n_ranked,
        tried.join(", "),
        options.scheme.name(),
        if po.grade {
            " and then graded around it"
        } else {
            ""
        },
        po.candidate_iterations.max(1),
        budget_iterations,
        match best {
            Some((e, v)) => {
                format!("; the best reached max |K − K̄| = {e:.3e} (vertex {v}, tolerance 1e-9)")
            }
            None => String::new(),
        },
        seconds,
    ))
}

/// The paper's brute force: [`measured_distortion`] of every vertex in `candidates`
/// (`None` where the flow did not converge). Slow: one full flow per candidate.
pub fn brute_force(
    mesh: &Mesh,
    metric: &IntrinsicMetric,
    candidates: &[u32],
    scheme: Scheme,
    progress: &mut dyn Progress,
) -> Vec<(u32, Option<f64>)> {
    let n = candidates.len().max(1);
    candidates
        .iter()
        .enumerate()
        .map(|(i, &v)| {
            progress.report(
                "brute force",
                Some(i as f64 / n as f64),
                &format!("vertex {v}"),
            );
            (v, measured_distortion(mesh, metric, v, scheme, 1e-9).ok())
        })
        .collect()
}
