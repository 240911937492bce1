//! Holonomy constraints of seamless parametrizations on closed surfaces of genus ≥ 1
//! (`ricci param --seamless`), after Campen–Shen–Zhou–Zorin 2019, "Seamless parametrization
//! with arbitrary cones for arbitrary genus" (§4–5).
//!
//! A flat metric with cones whose angles are multiples of `π/2` makes every transition across
//! a cut a rotation by a multiple of 90° only if, in addition, the **holonomy** (the rotation
//! of parallel transport) of every homology loop is a multiple of `π/2`. The conformal flow
//! fixes the cone angles but not these `2g` rotations; here the metric of the flow's final
//! triangulation `T` is changed, by the least `ℓ²` change of the log edge lengths, until
//!
//! * every vertex keeps its angle sum `Θ_v` (cones `2π − K̄_v`, `2π` elsewhere), and
//! * the holonomy of each of `2g` dual loops forming a homology basis (tree–cotree: a primal
//!   spanning tree, a dual spanning tree avoiding it, and one loop per remaining edge,
//!   Eppstein 2003) equals its initial value rounded to the nearest multiple of `π/2`.
//!
//! The holonomy of a dual loop `f_0 → f_1 → … → f_0` is, modulo `π`, `Σ_i s_i θ_{f_i}(y_i)`:
//! in each face the loop enters and leaves across two edges sharing the vertex `y_i`, and the
//! direction of the crossed edge turns by the corner angle there, `s_i = +1` when the exit
//! edge follows the entry edge counter-clockwise about `y_i` (otherwise `−1`); reversing an
//! edge's orientation adds `π`. Since `π/2` divides `π`, a loop value that is a multiple of
//! `π/2` is a holonomy that is one too.
//!
//! The constraints `F(x) = 0` (vertex rows but one, which Gauss–Bonnet implies, and the loop
//! rows) are solved by Newton's method with weighted least-norm steps
//! `δ = W Jᵀ (J W Jᵀ + μ d I)⁻¹ (−F)` in the log lengths `x_e = log ℓ_e` (CSZZ §5 solve the
//! same underdetermined system), with `∂θ_i/∂x_i = cot θ_j + cot θ_k`, `∂θ_i/∂x_j = −cot θ_k`
//! in a triangle with corners `i, j, k` and opposite edges `x_i, x_j, x_k`. The weight `W_e`
//! is the least `sin³ θ / q⁴` over the edge's two triangles (`θ` their corners, `q` the
//! distortion `σ_max/σ_min` of the linear map from the triangle's starting shape to its
//! present one): the plain least-norm step (`W = I`) piles the holonomy change onto the strip
//! of triangles along each loop, whose thinnest triangles then degenerate before the targets
//! are met (kitten, eight); weighted, the change moves to well-shaped, little-changed
//! triangles, and no triangle's shape changes by more than [`MAX_FACE_DISTORTION`] (the
//! written map of the common subdivision inherits it: fertility's qc max 1e6 → 64). `μ` (Levenberg–Marquardt, `d` the mean diagonal)
//! is zero unless `J W Jᵀ` is numerically singular or no step along `δ` helps; then it is
//! raised by 100 at a time. The step is halved until every triangle is non-degenerate and
//! `‖F‖` drops. Every transition across the cut graph is then a product of
//! loops around cones and of the basis loops: a rotation by a multiple of 90°.

use crate::error::{Error, Result};
use crate::mesh::{Mesh, NONE};
use crate::metric::{corner_angles, Geometry, IntrinsicMetric};
use faer::sparse::{SparseColMat, Triplet};
use std::f64::consts::PI;

/// A dual loop: per face crossed, the corner whose angle enters the holonomy and its sign.
#[derive(Debug, Clone)]
pub struct DualLoop {
    pub corners: Vec<(u32, f64)>,
}

/// What [`quarter_turn_holonomy`] did.
#[derive(Debug, Clone)]
pub struct HolonomyFix {
    /// The metric of `T` (per edge) with the constraints met.
    pub lengths: Vec<f64>,
    /// Homology loops constrained (`2g`), Newton iterations, and the largest residual of the
    /// vertex angle sums and loop holonomies (radians) at the end.
    pub loops: usize,
    pub iterations: usize,
    pub max_residual: f64,
    /// Largest `|log ℓ_e − log ℓ⁰_e|`: how far the metric left the conformal one.
    pub max_log_length_change: f64,
}

/// `2g` dual loops forming a basis of the first homology of the closed surface `mesh`
/// (tree–cotree, see the module docs), each as its corners with signs.
pub fn homology_loops(mesh: &Mesh) -> Vec<DualLoop> {
    let (nv, nf, ne) = (mesh.n_vertices(), mesh.n_faces(), mesh.n_edges());
    // Primal spanning tree (breadth first from vertex 0).
    let mut in_tree = vec![false; ne];
    let mut seen = vec![false; nv];
    let mut queue = std::collections::VecDeque::new();
    if let Some(v0) = (0..nv as u32).find(|&v| !mesh.is_isolated(v)) {
        seen[v0 as usize] = true;
        queue.push_back(v0);
    }
    let mut out_he: Vec<Vec<u32>> = vec![Vec::new(); nv];
    for h in 0..mesh.n_corners() as u32 {
        out_he[mesh.he_origin(h) as usize].push(h);
    }
    while let Some(v) = queue.pop_front() {
        for &h in &out_he[v as usize] {
            let w = mesh.he_tip(h);
            if !seen[w as usize] {
                seen[w as usize] = true;
                in_tree[mesh.he_edge(h) as usize] = true;
                queue.push_back(w);
            }
        }
    }
    // Dual spanning tree over the edges not in the primal tree: parent half-edge per face
    // (the half-edge of the face that leads to its parent), depth.
    let mut parent = vec![NONE; nf];
    let mut depth = vec![usize::MAX; nf];
    let mut in_cotree = vec![false; ne];
    if nf > 0 {
        depth[0] = 0;
        queue.clear();
        queue.push_back(0);
    }
    while let Some(f) = queue.pop_front() {
        for h in mesh.face_halfedges(f) {
            let e = mesh.he_edge(h) as usize;
            let g = mesh.he_twin(h);
            let Some(k) = Some(mesh.he_face(g)).filter(|&k| k != NONE) else {
                continue;
            };
            if in_tree[e] || depth[k as usize] != usize::MAX {
                continue;
            }
            depth[k as usize] = depth[f as usize] + 1;
            parent[k as usize] = g;
            in_cotree[e] = true;
            queue.push_back(k);
        }
    }
    let mut loops = Vec::new();
    for e in 0..ne as u32 {
        if in_tree[e as usize] || in_cotree[e as usize] || mesh.is_boundary_edge(e) {
            continue;
        }
        // Cycle of crossed half-edges: from face a across h to face b, then up the dual tree
        // from b and down to a.
        let h = mesh.edge_halfedge(e);
        let (a, b) = (mesh.he_face(h), mesh.he_face(mesh.he_twin(h)));
        let (mut up_b, mut up_a) = (Vec::new(), Vec::new());
        let (mut x, mut y) = (b, a);
        while depth[x as usize] > depth[y as usize] {
            up_b.push(parent[x as usize]);
            x = mesh.he_face(mesh.he_twin(parent[x as usize]));
        }
        while depth[y as usize] > depth[x as usize] {
            up_a.push(parent[y as usize]);
            y = mesh.he_face(mesh.he_twin(parent[y as usize]));
        }
        while x != y {
            up_b.push(parent[x as usize]);
            x = mesh.he_face(mesh.he_twin(parent[x as usize]));
            up_a.push(parent[y as usize]);
            y = mesh.he_face(mesh.he_twin(parent[y as usize]));
        }
        // Exit half-edges in order: h (a → b), up from b (b's parent half-edges), then down
        // to a (the twins of a's parent half-edges, in reverse).
        let mut exits = vec![h];
        exits.extend(up_b);
        exits.extend(up_a.iter().rev().map(|&g| mesh.he_twin(g)));
        loops.push(DualLoop {
            corners: loop_corners(mesh, &exits),
        });
    }
    loops
}

/// The signed corners of a dual loop given by its exit half-edges (each in the face it
/// leaves; the next one leaves the face the previous one enters).
fn loop_corners(mesh: &Mesh, exits: &[u32]) -> Vec<(u32, f64)> {
    let k = exits.len();
    (0..k)
        .map(|i| {
            let b = exits[i];
            let a = mesh.he_twin(exits[(i + k - 1) % k]); // entry half-edge, in b's face
            if mesh.he_next(a) == b {
                (b, -1.0) // shared vertex: origin of b
            } else {
                (a, 1.0) // a = next(b): shared vertex: origin of a
            }
        })
        .collect()
}

/// The loop's value `Σ s θ` (module docs) for corner angles `theta`.
pub fn loop_value(l: &DualLoop, theta: &[f64]) -> f64 {
    l.corners.iter().map(|&(c, s)| s * theta[c as usize]).sum()
}

/// Per corner `c` and corner `d` of the same face: `∂θ_c/∂x_{e(d)}`, `e(d)` the edge
/// opposite `d` (module docs).
fn angle_derivatives(theta: &[f64], f: usize) -> [[f64; 3]; 3] {
    let cot = |i: usize| 1.0 / theta[3 * f + i].tan();
    let mut d = [[0.0; 3]; 3];
    for (i, row) in d.iter_mut().enumerate() {
        let (j, k) = ((i + 1) % 3, (i + 2) % 3);
        row[i] = cot(j) + cot(k);
        row[j] = -cot(k);
        row[k] = -cot(j);
    }
    d
}

fn residuals(
    mesh: &Mesh,
    theta: &[f64],
    angle_sum: &[f64],
    loops: &[DualLoop],
    targets: &[f64],
) -> Vec<f64> {
    let mut r = angle_sum.iter().map(|&t| -t).collect::<Vec<_>>();
    for (c, &t) in theta.iter().enumerate() {
        r[mesh.corner_vertex(c as u32) as usize] += t;
    }
    r.remove(0);
    r.extend(
        loops
            .iter()
            .zip(targets)
            .map(|(l, &t)| loop_value(l, theta) - t),
    );
    r
}

/// The Jacobian of [`residuals`] as rows of `(edge, value)`.
fn jacobian(mesh: &Mesh, theta: &[f64], loops: &[DualLoop]) -> Vec<Vec<(u32, f64)>> {
    let nv = mesh.n_vertices();
    let mut rows: Vec<Vec<(u32, f64)>> = vec![Vec::new(); nv - 1 + loops.len()];
    let edges = |f: usize| mesh.face_edges_opposite(f as u32);
    for f in 0..mesh.n_faces() {
        let d = angle_derivatives(theta, f);
        let e = edges(f);
        for (i, di) in d.iter().enumerate() {
            let v = mesh.corner_vertex((3 * f + i) as u32) as usize;
            if v > 0 {
                rows[v - 1].extend(e.iter().zip(di).map(|(&ej, &x)| (ej, x)));
            }
        }
    }
    for (k, l) in loops.iter().enumerate() {
        for &(c, s) in &l.corners {
            let (f, i) = (c as usize / 3, c as usize % 3);
            let d = angle_derivatives(theta, f);
            let e = edges(f);
            rows[nv - 1 + k].extend(e.iter().zip(&d[i]).map(|(&ej, &x)| (ej, s * x)));
        }
    }
    rows
}

/// Per edge, the weight of its log length in the step (module docs): the least
/// `sin³θ / q⁴` over its two triangles (`θ` their corner angles, `q` their distortion from the
/// starting metric, [`face_distortion`]), so that edges of nearly degenerate or already much
/// distorted triangles move least.
fn edge_weights(mesh: &Mesh, theta: &[f64], l0: &[f64], l: &[f64]) -> Vec<f64> {
    let mut w = vec![1.0f64; mesh.n_edges()];
    for f in 0..mesh.n_faces() {
        let edges = mesh.face_edges_opposite(f as u32);
        let q = face_distortion(edges.map(|e| l0[e as usize]), edges.map(|e| l[e as usize]));
        let s = (0..3).fold(1.0f64, |m, i| m.min(theta[3 * f + i].sin().powi(3))) / q.powi(4);
        for e in edges {
            w[e as usize] = w[e as usize].min(s);
        }
    }
    w
}

/// The weighted, damped least-norm Newton step `δ = W Jᵀ (J W Jᵀ + μ d I)⁻¹ (−r)`, `d` the
/// mean diagonal of `J W Jᵀ`; `None` when that matrix is not numerically positive definite.
fn least_norm_step(
    rows: &[Vec<(u32, f64)>],
    r: &[f64],
    w: &[f64],
    mu: f64,
) -> Result<Option<Vec<f64>>> {
    let (m, ne) = (rows.len(), w.len());
    let mut cols: Vec<Vec<(u32, f64)>> = vec![Vec::new(); ne];
    for (i, row) in rows.iter().enumerate() {
        for &(e, x) in row {
            cols[e as usize].push((i as u32, x));
        }
    }
    let mut trip = Vec::new();
    let mut diag = vec![0.0; m];
    for (col, &we) in cols.iter().zip(w) {
        for &(i, a) in col {
            for &(j, b) in col {
                if j <= i {
                    trip.push(Triplet::new(i as usize, j as usize, we * a * b));
                }
                if j == i {
                    diag[i as usize] += we * a * b;
                }
            }
        }
    }
    if mu > 0.0 {
        let d = mu * diag.iter().sum::<f64>() / m as f64;
        trip.extend((0..m).map(|i| Triplet::new(i, i, d)));
    }
    let a = SparseColMat::<usize, f64>::try_new_from_triplets(m, m, &trip)
        .map_err(|_| Error::numerical("seamless: the constraint matrix could not be assembled"))?;
    let Ok(chol) = crate::numeric::sparse::Cholesky::factor(a.as_ref()) else {
        return Ok(None);
    };
    let mut y: Vec<f64> = r.iter().map(|x| -x).collect();
    chol.solve_in_place(faer::MatMut::from_column_major_slice_mut(&mut y, m, 1));
    let mut delta = vec![0.0; ne];
    for (i, row) in rows.iter().enumerate() {
        for &(e, x) in row {
            delta[e as usize] += w[e as usize] * x * y[i];
        }
    }
    if delta.iter().all(|d| d.is_finite()) {
        Ok(Some(delta))
    } else {
        Ok(None)
    }
}

fn max_abs(r: &[f64]) -> f64 {
    r.iter().fold(0.0f64, |m, x| m.max(x.abs()))
}

/// The metric of the closed flat triangulation `mesh` (`lengths` per edge) changed so that
/// the vertex angle sums are `angle_sum` and the `2g` homology loops have holonomy a multiple
/// of `π/2` (module docs), to `tolerance` (radians).
pub fn quarter_turn_holonomy(
    mesh: &Mesh,
    metric: &IntrinsicMetric,
    angle_sum: &[f64],
    tolerance: f64,
) -> Result<HolonomyFix> {
    let lengths = metric.lengths();
    if mesh.has_boundary() || angle_sum.len() != mesh.n_vertices() || mesh.n_vertices() < 2 {
        return Err(Error::input(
            "seamless holonomy constraints need a closed surface and one angle sum per vertex",
        ));
    }
    let loops = homology_loops(mesh);
    const BUDGET: usize = 200;
    let mut l = lengths.to_vec();
    let mut theta = corner_angles(mesh, Geometry::Euclidean, &l);
    let q = PI / 2.0;
    let targets: Vec<f64> = loops
        .iter()
        .map(|lp| (loop_value(lp, &theta) / q).round() * q)
        .collect();
    // Continuation: the loop targets move from their start values to the rounded ones in
    // stages (the increment halved when a stage fails), Newton to the tolerance at each.
    let start: Vec<f64> = loops.iter().map(|lp| loop_value(lp, &theta)).collect();
    let mut iterations = 0;
    let (mut s, mut ds) = (0.0f64, 0.25f64);
    let mut r = residuals(mesh, &theta, angle_sum, &loops, &start);
    let mut history = Vec::new();
    let problem = Problem {
        mesh,
        start: lengths,
        angle_sum,
        loops: &loops,
    };
    while iterations < BUDGET {
        let s_next = (s + ds).min(1.0);
        let stage: Vec<f64> = start
            .iter()
            .zip(&targets)
            .map(|(a, b)| a + s_next * (b - a))
            .collect();
        // Intermediate stages to 1e-8, the last one to the tolerance.
        let tol = if s_next >= 1.0 {
            tolerance
        } else {
            tolerance.max(1e-8)
        };
        let (nl, th, rt, its) = newton(&problem, &l, &stage, tol, 25)?;
        iterations += its;
        if max_abs(&rt) <= tol {
            (l, theta, r, s) = (nl, th, rt, s_next);
            history.push(format!("{s:.3}"));
            if s >= 1.0 {
                break;
            }
            ds = (2.0 * ds).min(1.0 - s);
        } else {
            history.push(format!("{s_next:.3}: {:.1e}", max_abs(&rt)));
            ds *= 0.5;
            if ds < 1e-3 {
                break;
            }
        }
    }
    if s < 1.0 {
        r = residuals(mesh, &theta, angle_sum, &loops, &targets);
    }
    let max_residual = max_abs(&r);
    if max_residual > tolerance {
        return Err(Error::numerical(format!(
            "seamless: the holonomy constraints were not met (max residual {max_residual:.2e} \
             rad after {iterations} Newton steps; continuation stages {})",
            history.join(", ")
        )));
    }
    let max_log_length_change = l
        .iter()
        .zip(lengths)
        .fold(0.0f64, |m, (a, b)| m.max((a / b).ln().abs()));
    Ok(HolonomyFix {
        lengths: l,
        loops: loops.len(),
        iterations,
        max_residual,
        max_log_length_change,
    })
}

/// The constraints of one solve: the triangulation, its starting (conformal) metric, the
/// vertex angle sums and the homology loops.
struct Problem<'a> {
    mesh: &'a Mesh,
    start: &'a [f64],
    angle_sum: &'a [f64],
    loops: &'a [DualLoop],
}

/// Newton with least-norm steps from `l` to the constraints with loop targets `targets`
/// (at most `budget` steps): the lengths, angles, residuals and steps taken.
type NewtonEnd = (Vec<f64>, Vec<f64>, Vec<f64>, usize);
fn newton(
    problem: &Problem,
    l: &[f64],
    targets: &[f64],
    tolerance: f64,
    budget: usize,
) -> Result<NewtonEnd> {
    let (mesh, angle_sum, loops) = (problem.mesh, problem.angle_sum, problem.loops);
    let mut l = l.to_vec();
    let mut theta = corner_angles(mesh, Geometry::Euclidean, &l);
    let mut r = residuals(mesh, &theta, angle_sum, loops, targets);
    let mut iterations = 0;
    // Levenberg–Marquardt damping `μ`: raised when no step along the direction lowers `‖r‖`
    // (or `J W Jᵀ` is singular), lowered after every accepted step.
    let mut mu = 0.0f64;
    while max_abs(&r) > tolerance && iterations < budget {
        iterations += 1;
        let rows = jacobian(mesh, &theta, loops);
        let w = edge_weights(mesh, &theta, problem.start, &l);
        let norm0 = r.iter().map(|x| x * x).sum::<f64>();
        let mut accepted = None;
        for _ in 0..MU_TRIES {
            if let Some(delta) = least_norm_step(&rows, &r, &w, mu)? {
                accepted = line_search(problem, &l, &delta, targets, norm0);
            }
            if accepted.is_some() {
                break;
            }
            mu = if mu == 0.0 { 1e-10 } else { mu * 100.0 };
        }
        let Some((nl, th, rt)) = accepted else {
            break;
        };
        (l, theta, r) = (nl, th, rt);
        mu = if mu < 1e-9 { 0.0 } else { mu / 10.0 };
    }
    Ok((l, theta, r, iterations))
}

/// Raising `μ` this many times (by 100 from 1e-10) at one Newton step at most.
const MU_TRIES: usize = 10;

/// Backtracking along `delta` (log lengths): the first of the steps `1, 1/2, …, 2⁻²⁰` that
/// keeps every triangle within [`MAX_FACE_DISTORTION`] of its starting shape and lowers
/// `‖r‖²` below `norm0`.
fn line_search(
    problem: &Problem,
    l: &[f64],
    delta: &[f64],
    targets: &[f64],
    norm0: f64,
) -> Option<(Vec<f64>, Vec<f64>, Vec<f64>)> {
    let (mesh, angle_sum, loops) = (problem.mesh, problem.angle_sum, problem.loops);
    let mut step = 1.0;
    while step >= 1e-6 {
        let trial: Vec<f64> = l
            .iter()
            .zip(delta)
            .map(|(&x, &d)| x * (step * d).exp())
            .collect();
        if valid(mesh, problem.start, &trial) {
            let th = corner_angles(mesh, Geometry::Euclidean, &trial);
            let rt = residuals(mesh, &th, angle_sum, loops, targets);
            if rt.iter().map(|x| x * x).sum::<f64>() < norm0 {
                return Some((trial, th, rt));
            }
        }
        step *= 0.5;
    }
    None
}

/// Largest quasi-conformal distortion `σ_max/σ_min` of the linear map from a triangle of the
/// starting (conformal) metric to the same triangle of the seamless one (a step that exceeds
/// it is shortened; the weights keep the solve well inside: fertility ≤ 3.8, eight ≤ 2.8).
/// The layouts of `T` in both metrics share the map from the input to `T`'s faces (the common
/// subdivision's projective interpolation, [`super::transfer`]), so the written map's
/// distortion is at most this times the conformal one's. Without the bound and the `q⁴` of
/// [`edge_weights`], fertility (`--cones 12`) ended with a triangle of lengths 6.14, 3.74,
/// 9.88 (flat to 1e-5; conformal 6.60, 4.64, 7.96) and subdivision triangles of qc 1e6.
const MAX_FACE_DISTORTION: f64 = 8.0;

/// Every face satisfies the strict triangle inequality and its linear map from the starting
/// metric `l0` has distortion at most [`MAX_FACE_DISTORTION`].
fn valid(mesh: &Mesh, l0: &[f64], l: &[f64]) -> bool {
    (0..mesh.n_faces() as u32).all(|f| {
        let edges = mesh.face_edges_opposite(f);
        let e = edges.map(|e| l[e as usize]);
        e[0] < e[1] + e[2]
            && e[1] < e[0] + e[2]
            && e[2] < e[0] + e[1]
            && face_distortion(edges.map(|e| l0[e as usize]), e) <= MAX_FACE_DISTORTION
    })
}

/// `σ_max/σ_min` of the linear map between the triangles with side lengths `a` and `b`
/// (same order; infinite when `b` is degenerate).
pub(crate) fn face_distortion(a: [f64; 3], b: [f64; 3]) -> f64 {
    // Each triangle laid out with its first side on the x axis: columns (side 0, side 2
    // reversed) of the triangle with corners 0 = (0, 0), 1 = (l₀, 0), 2 from l₂ = |02|.
    let frame = |l: [f64; 3]| {
        let x = (l[0] * l[0] + l[2] * l[2] - l[1] * l[1]) / (2.0 * l[0]);
        (l[0], x, (l[2] * l[2] - x * x).max(0.0).sqrt())
    };
    let ((pa, px, py), (qa, qx, qy)) = (frame(a), frame(b));
    // J = Q P⁻¹ with P = [[pa, px], [0, py]], Q = [[qa, qx], [0, qy]] (upper triangular).
    let (j00, j01, j11) = (qa / pa, (qx - qa * px / pa) / py, qy / py);
    // Singular values of [[j00, j01], [0, j11]]: σ₁ ± σ₂ = |J ± J'| with the conformal and
    // anti-conformal parts.
    let s = (j00 + j11).hypot(j01);
    let d = (j00 - j11).hypot(j01);
    (s + d) / (s - d).abs()
}

/// [`quarter_turn_holonomy`] on a chart's flat triangulation `t_mesh` (the flow's simplicial
/// mesh: the chart's `n` vertices first, split vertices flat), cones `(vertex, K̄)`, to 1e-11 rad.
pub fn chart_holonomy(
    t_mesh: &Mesh,
    metric: &IntrinsicMetric,
    n: usize,
    cones: &[(u32, f64)],
    progress: &mut dyn crate::progress::Progress,
) -> Result<Vec<f64>> {
    progress.report(
        "seamless",
        None,
        "holonomy of the homology loops to quarter turns",
    );
    let mut angle_sum = vec![2.0 * PI; t_mesh.n_vertices()];
    for &(v, k) in cones {
        if (v as usize) < n {
            angle_sum[v as usize] = 2.0 * PI - k;
        }
    }
    Ok(quarter_turn_holonomy(t_mesh, metric, &angle_sum, 1e-11)?.lengths)
}

#[cfg(test)]
mod tests {
    use super::face_distortion;

    /// Closed forms: a similarity has distortion 1; the right isosceles triangle with legs
    /// 1, 1 stretched by 2 along one leg (legs 2, 1, hypotenuse √5) has distortion 2; a
    /// degenerate image has infinite distortion.
    #[test]
    fn face_distortion_closed_forms() {
        let a = [3.0, 4.0, 5.0];
        assert!((face_distortion(a, a.map(|x| 2.5 * x)) - 1.0).abs() < 1e-12);
        let s2 = 2f64.sqrt();
        for (p, q) in [
            ([1.0, s2, 1.0], [2.0, 5f64.sqrt(), 1.0]),
            ([s2, 1.0, 1.0], [5f64.sqrt(), 1.0, 2.0]),
        ] {
            let d = face_distortion(p, q);
            assert!((d - 2.0).abs() < 1e-12, "{d}");
        }
        assert!(face_distortion(a, [1.0, 2.0, 3.0]) > 1e12);
    }
}
