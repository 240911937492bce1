//! Fitting a T-spline over the flat torus to mesh points (paper 003 §3.3) and the genus-1
//! domain (paper 003 §2 for genus one: the flat metric's fundamental domain is the conformal
//! net).
//!
//! **Fit.** Minimise `E(P) = Σ_k |S(u_k) − p_k|² + λ ∫ (|S_uu|² + 2|S_uv|² + |S_vv|²) du dv`
//! over the control points `P` (paper 003 eq. (3), thin-plate fairness). `E` is quadratic:
//! `(AᵀA + λF) P = Aᵀp` with `A_ki = B̃_i(u_k)` and `F` the thin-plate Gram matrix, integrated
//! exactly by 4×4 Gauss points on every Bézier element (the integrand is a polynomial of
//! degree ≤ 6 per variable there). `λ = smoothing · tr(AᵀA)/tr(F)` keeps the parameter
//! free of the scale of the domain. The system is solved by conjugate gradients (faer),
//! symmetrically Jacobi-scaled, warm-started from the previous surface; `F` and the sparsity
//! pattern are built once per T-mesh and the rounds of parameter correction refill only `AᵀA`
//! ([`super::system`]).
//!
//! **Start**: a uniform tensor grid whose faces holding more than
//! [`FitOptions::max_points_per_face`] data points are split 1-to-4 (repeatedly): for an evenly
//! sampled mesh the knot spacing then follows the inverse of the conformal factor `e^u`, which
//! the conformal map makes vary by orders of magnitude (ears, tails).
//!
//! **Refinement** (§3.3): a T-mesh face `I` whose points have `L∞ᴵ > 2ε` is split 1-to-4,
//! one with `ε < L∞ᴵ ≤ 2ε` 1-to-2 across its longer side — of the faces with
//! `L∞ᴵ > max(ε, θ L∞)` only ([`FitOptions::mark_fraction`] `θ`; paper 003 refines every face
//! above `ε`, `θ = 0`, which spends control points where one more refit would do); then T-junctions are extended until
//! the T-mesh is analysis-suitable, and the fit is repeated, until `L∞ ≤ ε` or the budget of
//! iterations / control points is spent (reported, not hidden).

use super::correction::correct_parameters;
use super::half::Half;
use super::surface::{TBasis, TSpline};
use super::system::FitSystem;
use super::tmesh::{Lattice, TMesh};
use crate::error::{Error, Result};
use crate::mesh::Surface;
use crate::progress::Progress;
use rayon::prelude::*;

/// Options of [`fit`].
#[derive(Debug, Clone)]
pub struct FitOptions {
    /// `ε` as a fraction of the longest side of the bounding box (0.005 = 0.5 %).
    pub tolerance: f64,
    /// Thin-plate weight relative to the data term (scale-free).
    pub smoothing: f64,
    /// Faces of the initial tensor-product T-mesh (about; the aspect ratio follows the domain).
    pub initial_faces: usize,
    pub max_iterations: usize,
    pub max_control_points: usize,
    /// Marking: a face is refined when its `L∞ᴵ > max(ε, mark_fraction · L∞)`. `0` is paper
    /// 003's rule (every face above `ε`); larger values refine only the worst faces per step.
    pub mark_fraction: f64,
    /// Before the first fit, faces holding more than this many data points are split 1-to-4
    /// (repeatedly): the initial knot spacing follows the point density, i.e. the inverse of
    /// the conformal factor `e^u` for a mesh of even sampling. `0` = uniform start.
    pub max_points_per_face: usize,
    /// Relative residual of the conjugate gradients and their iteration budget.
    pub cg_tolerance: f64,
    pub cg_max_iterations: usize,
    /// Parameter correction after every fit ([`super::correction`]): this many rounds of
    /// (move each parameter to the foot of its perpendicular, refit). `0` keeps the
    /// parameters of the domain (paper 003 §3.3 as written).
    pub parameter_correction: usize,
    /// Newton steps per data point in each round of parameter correction.
    pub correction_steps: usize,
    /// The correction rounds of a fit stop early once a round lowers the (weighted) rms by
    /// less than this fraction of it (`0` = always all [`FitOptions::parameter_correction`]
    /// rounds).
    pub correction_gain: f64,
    /// Target rms error as a fraction of the longest bounding-box side (`0` = none). While the
    /// rms is above it (and `L∞ ≤ ε`), the faces with the largest sums of squared errors (their
    /// share of the rms) are refined: those above `mark_fraction ×` the largest sum. The rms is
    /// weighted by [`FitOptions::weights`] when they are given.
    pub rms_tolerance: f64,
    /// The thin-plate weight is multiplied by this factor after every refinement (`1` =
    /// constant): finer T-meshes need less fairing to stay well posed.
    pub smoothing_decay: f64,
    /// Refinement steps of the rms phase (`L∞ ≤ ε`, rms above [`FitOptions::rms_tolerance`]):
    /// `0` splits every face whose sum of squared errors exceeds `mark_fraction ×` the largest;
    /// `k > 0` splits the `k` faces with the largest sums (greedy spending of the control-point
    /// budget, at the cost of more refits).
    pub rms_marks: usize,
    /// Weight of each data point in the data term, the rms and the marking (empty = 1 each).
    /// [`vertex_areas`] makes `Σ_k w_k |S(u_k) − p_k|²` the integral of the squared error over
    /// the surface rather than a sum dominated by where the mesh is dense.
    pub weights: Vec<f64>,
    /// Count only the control points whose blending function meets this strip against
    /// [`FitOptions::max_control_points`] (the genus-0 domain: the surface's half of the
    /// torus, [`super::genus0::Genus0Domain::half`]); `None`: all of them.
    pub budget_half: Option<Half>,
}

impl Default for FitOptions {
    fn default() -> Self {
        FitOptions {
            tolerance: 0.005,
            smoothing: 1e-5,
            initial_faces: 64,
            max_iterations: 30,
            max_control_points: 20_000,
            mark_fraction: 0.5,
            max_points_per_face: 80,
            cg_tolerance: 1e-10,
            cg_max_iterations: 5000,
            parameter_correction: 0,
            correction_steps: 3,
            correction_gain: 0.0,
            rms_tolerance: 0.0,
            smoothing_decay: 1.0,
            rms_marks: 0,
            weights: Vec::new(),
            budget_half: None,
        }
    }
}

/// One fit of the refinement loop.
#[derive(Debug, Clone, serde::Serialize)]
pub struct FitStep {
    pub control_points: usize,
    pub faces: usize,
    pub t_junctions: usize,
    /// The rms of the errors, weighted by [`FitOptions::weights`] when they are given.
    pub rms_error_percent: f64,
    pub max_error_percent: f64,
    /// Conjugate-gradient iterations; `FitOptions::cg_max_iterations` when they did not reach
    /// the tolerance and the system was solved by sparse Cholesky instead, 0 when it was
    /// solved by sparse Cholesky at once (the gradients failed on an earlier step).
    pub cg_iterations: usize,
    /// Relative residual of the solution (of the Cholesky solve, measured, in that case).
    pub cg_relative_residual: f64,
}

/// What [`fit`] reached.
#[derive(Debug, Clone)]
pub struct FitResult {
    pub spline: TSpline,
    pub steps: Vec<FitStep>,
    /// Longest side of the bounding box of the data (the 100 % of the error percentages).
    pub scale: f64,
    /// Per data point: `|S(u_k) − p_k|`.
    pub errors: Vec<f64>,
    /// The parameters the errors are measured at (canonical; corrected when
    /// [`FitOptions::parameter_correction`] > 0).
    pub params: Vec<[f64; 2]>,
    pub converged: bool,
    /// The fit stopped above the tolerance because the faces marked for refinement could not
    /// be split (narrower than the T-mesh's tolerance, 1e-10 of the lattice: the conformal
    /// parameters of their points are that crowded), not at the budget.
    pub stalled: bool,
}

/// Least squares with thin-plate fairness over a fixed T-mesh (one step of §3.3).
/// `guess`: initial control points for the conjugate gradients; `weights`: per data point
/// (empty = 1 each).
#[allow(clippy::too_many_arguments)]
pub fn fit_fixed(
    basis: TBasis,
    points: &[[f64; 3]],
    params: &[[f64; 2]],
    weights: &[f64],
    smoothing: f64,
    guess: Option<&[[f64; 3]]>,
    cg_tolerance: f64,
    cg_max_iterations: usize,
) -> Result<(TSpline, usize, f64)> {
    let mut system = FitSystem::new(basis)?;
    let (control, iters, resid) = system.solve(
        points,
        params,
        weights,
        smoothing,
        guess,
        cg_tolerance,
        cg_max_iterations,
    )?;
    let basis = system.basis;
    Ok((TSpline { basis, control }, iters, resid))
}

fn errors_of(ts: &TSpline, points: &[[f64; 3]], params: &[[f64; 2]]) -> Vec<f64> {
    points
        .par_iter()
        .zip(params)
        .map(|(p, uv)| {
            let q = ts.point(uv[0], uv[1]);
            ((q[0] - p[0]).powi(2) + (q[1] - p[1]).powi(2) + (q[2] - p[2]).powi(2)).sqrt()
        })
        .collect()
}

/// The rms of per-vertex `errors` weighted by vertex area (a third of the incident faces'
/// areas): the rms over points spread evenly on the surface, which a decimated mesh's vertices
/// (dense where the detail is) are not. `None` when the sizes differ or the area is zero.
pub fn area_weighted_rms(surface: &Surface, errors: &[f64]) -> Option<f64> {
    if errors.len() != surface.positions.len() {
        return None;
    }
    let w = vertex_areas(surface);
    let total: f64 = w.iter().sum();
    if !(total > 0.0) {
        return None;
    }
    Some(weighted_rms(errors, &w))
}

/// Per vertex a third of the incident faces' areas, scaled to mean 1 (all zero when the
/// surface has no area): the weights of [`FitOptions::weights`] for an area-weighted fit.
pub fn vertex_areas(surface: &Surface) -> Vec<f64> {
    use crate::numeric::vec3::{cross, norm, sub};
    let mut w = vec![0.0; surface.positions.len()];
    for t in surface.mesh.faces() {
        let [a, b, c] = t.map(|v| surface.positions[v as usize]);
        let third = norm(cross(sub(b, a), sub(c, a))) / 6.0;
        for &v in t {
            w[v as usize] += third;
        }
    }
    let mean = w.iter().sum::<f64>() / w.len().max(1) as f64;
    if mean > 0.0 {
        w.iter_mut().for_each(|x| *x /= mean);
    }
    w
}

/// `sqrt(Σ w_k e_k² / Σ w_k)` (`w` empty: the plain rms).
fn weighted_rms(errors: &[f64], w: &[f64]) -> f64 {
    let (mut sse, mut total) = (0.0, 0.0);
    for (k, e) in errors.iter().enumerate() {
        let w = w.get(k).copied().unwrap_or(1.0);
        sse += w * e * e;
        total += w;
    }
    if total > 0.0 {
        (sse / total).sqrt()
    } else {
        0.0
    }
}

/// Longest side of the bounding box.
pub fn bbox_scale(points: &[[f64; 3]]) -> f64 {
    let mut lo = [f64::INFINITY; 3];
    let mut hi = [f64::NEG_INFINITY; 3];
    for p in points {
        for d in 0..3 {
            lo[d] = lo[d].min(p[d]);
            hi[d] = hi[d].max(p[d]);
        }
    }
    (0..3).map(|d| hi[d] - lo[d]).fold(0.0, f64::max)
}

/// Adaptive fit over the flat torus `lattice` (points with parameters in any representative).
pub fn fit(
    points: &[[f64; 3]],
    params: &[[f64; 2]],
    lattice: Lattice,
    opts: &FitOptions,
    progress: &mut dyn Progress,
) -> Result<FitResult> {
    if points.len() != params.len() || points.is_empty() {
        return Err(Error::input(format!(
            "the fit needs one parameter per point ({} points, {} parameters)",
            points.len(),
            params.len()
        )));
    }
    if let Some(k) = points
        .iter()
        .zip(params)
        .position(|(p, q)| p.iter().chain(q.iter()).any(|x| !x.is_finite()))
    {
        return Err(Error::input(format!(
            "data point {k} or its parameter is not finite"
        )));
    }
    check_options(opts)?;
    check_weights(&opts.weights, points.len())?;
    let scale = bbox_scale(points);
    if !(scale > 0.0) {
        return Err(Error::input("the data points have an empty bounding box"));
    }
    let eps = opts.tolerance * scale;
    let aspect = lattice.width / lattice.height;
    let nv = ((opts.initial_faces as f64 / aspect).sqrt().round() as usize).max(4);
    let nu = ((opts.initial_faces as f64 / nv as f64).round() as usize).max(4);
    let mut mesh = TMesh::uniform(lattice, nu, nv)?;
    mesh.make_analysis_suitable(10_000)?;
    let mut params: Vec<[f64; 2]> = params
        .iter()
        .map(|p| {
            let (u, v) = lattice.canonical(p[0], p[1]);
            [u, v]
        })
        .collect();
    if opts.max_points_per_face > 0 {
        for _ in 0..16 {
            let mut count = vec![0usize; mesh.faces().len()];
            let grid = mesh.face_grid();
            for uv in &params {
                if let Some(f) = grid.locate(uv[0], uv[1]) {
                    count[f] += 1;
                }
            }
            let marks: Vec<(usize, bool)> = count
                .iter()
                .enumerate()
                .filter(|(_, &c)| c > opts.max_points_per_face)
                .map(|(f, _)| (f, true))
                .collect();
            if marks.is_empty() {
                break;
            }
            mesh.refine_faces(&marks);
            mesh.make_analysis_suitable(50_000)?;
        }
    }
    let mut steps = Vec::new();
    let mut prev: Option<TSpline> = None;
    let mut iteration = 0;
    let rms_target = opts.rms_tolerance.max(0.0) * scale;
    let mut smoothing = opts.smoothing;
    // once the conjugate gradients fail on one T-mesh, the later (larger) ones go direct
    let mut direct = false;
    loop {
        iteration += 1;
        progress.report("tspline", None, &format!("T-spline fit {iteration}"));
        let tj = mesh.t_junctions().len();
        let faces = mesh.faces().len();
        let basis = TBasis::new(mesh.clone())?;
        let guess: Option<Vec<[f64; 3]>> = prev
            .as_ref()
            .map(|p| basis.anchors.iter().map(|a| p.point(a.u, a.v)).collect());
        let (ts, cg_it, cg_res) = fit_corrected(
            basis,
            points,
            &mut params,
            opts,
            smoothing,
            guess,
            &mut direct,
        )?;
        let errors = errors_of(&ts, points, &params);
        let max = errors.iter().cloned().fold(0.0, f64::max);
        let rms = weighted_rms(&errors, &opts.weights);
        steps.push(FitStep {
            control_points: ts.control.len(),
            faces,
            t_junctions: tj,
            rms_error_percent: 100.0 * rms / scale,
            max_error_percent: 100.0 * max / scale,
            cg_iterations: cg_it,
            cg_relative_residual: cg_res,
        });
        let converged = max <= eps && (rms_target == 0.0 || rms <= rms_target);
        let marks = if converged
            || iteration >= opts.max_iterations
            || counted(&ts.basis.anchors, opts.budget_half) >= opts.max_control_points
        {
            Vec::new()
        } else {
            let m = Marking {
                eps,
                rms_target,
                theta: opts.mark_fraction,
                rms_marks: opts.rms_marks,
                weights: &opts.weights,
            };
            refinement_marks(&mesh, &params, &errors, &m)
        };
        let refined =
            refine_within_budget(&mesh, &marks, opts.max_control_points, opts.budget_half)?;
        // marked faces narrower than the T-mesh's tolerance are not split: the same T-mesh
        // again would give the same fit (camel's legs: 15 identical steps to the budget)
        let stalled = refined
            .as_ref()
            .is_some_and(|r| r.faces().len() == mesh.faces().len());
        let Some(refined) = refined.filter(|_| !stalled) else {
            return Ok(FitResult {
                spline: ts,
                steps,
                scale,
                errors,
                params,
                converged,
                stalled,
            });
        };
        mesh = refined;
        smoothing *= opts.smoothing_decay;
        prev = Some(ts);
    }
}

/// The ranges of the marking fraction, rms tolerance, smoothing decay and correction gain.
fn check_options(opts: &FitOptions) -> Result<()> {
    if !(0.0..1.0).contains(&opts.mark_fraction) {
        return Err(Error::input(format!(
            "the marking fraction {} of the T-spline fit must be in [0, 1)",
            opts.mark_fraction
        )));
    }
    if !(opts.rms_tolerance >= 0.0 && opts.rms_tolerance < 1.0) {
        return Err(Error::input(format!(
            "the rms tolerance {} of the T-spline fit must be in [0, 1)",
            opts.rms_tolerance
        )));
    }
    let decay_ok = opts.smoothing_decay > 0.0 && opts.smoothing_decay <= 1.0;
    if !(decay_ok && (0.0..1.0).contains(&opts.correction_gain)) {
        return Err(Error::input(format!(
            "the smoothing decay {} and the correction gain {} of the T-spline fit must be in (0, 1] and [0, 1)",
            opts.smoothing_decay, opts.correction_gain
        )));
    }
    Ok(())
}

/// `weights` empty, or one finite non-negative weight per point with a positive sum.
fn check_weights(weights: &[f64], n: usize) -> Result<()> {
    if weights.is_empty() {
        return Ok(());
    }
    if weights.len() != n {
        return Err(Error::input(format!(
            "the fit has {n} data points but {} weights",
            weights.len()
        )));
    }
    if let Some(k) = weights.iter().position(|w| !(w.is_finite() && *w >= 0.0)) {
        return Err(Error::input(format!(
            "the weight {} of data point {k} is not a finite non-negative number",
            weights[k]
        )));
    }
    if !(weights.iter().sum::<f64>() > 0.0) {
        return Err(Error::input("the weights of the data points are all zero"));
    }
    Ok(())
}

/// The control points counted against the budget: those meeting `half`, or all.
pub fn counted(anchors: &[super::tmesh::Anchor], half: Option<Half>) -> usize {
    half.map_or(anchors.len(), |h| h.anchors_on(anchors))
}

/// The refinement rule's parameters (see [`refinement_marks`]).
struct Marking<'a> {
    eps: f64,
    rms_target: f64,
    theta: f64,
    rms_marks: usize,
    weights: &'a [f64],
}

/// The T-mesh refined by `marks` (most important first) and made analysis-suitable, with at
/// most `budget` control points: when all marks exceed it, the first half of them is tried,
/// and so on; `None` when even the first mark alone exceeds it.
fn refine_within_budget(
    mesh: &TMesh,
    marks: &[(usize, bool)],
    budget: usize,
    half: Option<Half>,
) -> Result<Option<TMesh>> {
    let mut k = marks.len();
    while k > 0 {
        let mut m = mesh.clone();
        m.refine_faces(&marks[..k]);
        m.make_analysis_suitable(50_000)?;
        let n = match half {
            Some(h) => h.anchors_on(&m.anchors()?),
            None => m.vertices().len(),
        };
        if n <= budget {
            return Ok(Some(m));
        }
        k /= 2;
    }
    Ok(None)
}

/// The faces to refine after a fit (`(face, split 1-to-4)`, the worst first). While `L∞ > ε`:
/// the faces with `L∞ᴵ > max(ε, θ L∞)`, 1-to-4 above `2ε`, else 1-to-2 (paper 003 §3.3 with
/// the worst-face fraction `θ`). Then, while the rms is above `rms_target`: the faces whose sum
/// of squared errors exceeds `θ ×` the largest (or the `rms_marks` largest), 1-to-2 across the
/// longer side.
fn refinement_marks(
    mesh: &TMesh,
    params: &[[f64; 2]],
    errors: &[f64],
    m: &Marking<'_>,
) -> Vec<(usize, bool)> {
    let (eps, rms_target, theta) = (m.eps, m.rms_target, m.theta);
    let max = errors.iter().cloned().fold(0.0, f64::max);
    let mut face_max = vec![0.0f64; mesh.faces().len()];
    let mut face_sse = vec![0.0f64; mesh.faces().len()];
    let grid = mesh.face_grid();
    for (k, (uv, &e)) in params.iter().zip(errors).enumerate() {
        if let Some(f) = grid.locate(uv[0], uv[1]) {
            face_max[f] = face_max[f].max(e);
            face_sse[f] += m.weights.get(k).copied().unwrap_or(1.0) * e * e;
        }
    }
    if max > eps {
        let threshold = eps.max(theta * max);
        let mut marks: Vec<(usize, f64)> = face_max
            .iter()
            .enumerate()
            .filter(|(_, &e)| e > threshold)
            .map(|(f, &e)| (f, e))
            .collect();
        marks.sort_by(|a, b| b.1.total_cmp(&a.1));
        return marks.into_iter().map(|(f, e)| (f, e > 2.0 * eps)).collect();
    }
    let rms = weighted_rms(errors, m.weights);
    if rms_target > 0.0 && rms > rms_target {
        let top = face_sse.iter().cloned().fold(0.0, f64::max);
        let mut marks: Vec<(usize, f64)> = face_sse
            .iter()
            .enumerate()
            .filter(|(_, &e)| e > 0.0 && (m.rms_marks > 0 || e > theta * top))
            .map(|(f, &e)| (f, e))
            .collect();
        marks.sort_by(|a, b| b.1.total_cmp(&a.1));
        if m.rms_marks > 0 {
            marks.truncate(m.rms_marks);
        }
        return marks.into_iter().map(|(f, _)| (f, false)).collect();
    }
    Vec::new()
}

/// [`fit_fixed`], then `opts.parameter_correction` rounds of parameter correction and refit.
fn fit_corrected(
    basis: TBasis,
    points: &[[f64; 3]],
    params: &mut Vec<[f64; 2]>,
    opts: &FitOptions,
    smoothing: f64,
    guess: Option<Vec<[f64; 3]>>,
    direct: &mut bool,
) -> Result<(TSpline, usize, f64)> {
    // the fairness matrix and the pattern once per T-mesh; the rounds refill the data term
    let mut system = FitSystem::new(basis)?;
    system.direct = *direct;
    let solve = |system: &mut FitSystem, params: &[[f64; 2]], guess: Option<&[[f64; 3]]>| {
        system.solve(
            points,
            params,
            &opts.weights,
            smoothing,
            guess,
            opts.cg_tolerance,
            opts.cg_max_iterations,
        )
    };
    let (control, mut cg_it, mut cg_res) = solve(&mut system, params, guess.as_deref())?;
    let mut ts = TSpline {
        basis: system.basis.clone(),
        control,
    };
    let rms_of = |ts: &TSpline, params: &[[f64; 2]]| {
        weighted_rms(&errors_of(ts, points, params), &opts.weights)
    };
    let mut rms = if opts.correction_gain > 0.0 {
        rms_of(&ts, params)
    } else {
        0.0
    };
    for _ in 0..opts.parameter_correction {
        let (corrected, moved) = correct_parameters(&ts, points, params, opts.correction_steps);
        if moved == 0 {
            break;
        }
        *params = corrected;
        let control;
        (control, cg_it, cg_res) = solve(&mut system, params, Some(&ts.control))?;
        ts.control = control;
        if opts.correction_gain > 0.0 {
            let now = rms_of(&ts, params);
            if now > (1.0 - opts.correction_gain) * rms {
                break;
            }
            rms = now;
        }
    }
    *direct = system.direct;
    Ok((ts, cg_it, cg_res))
}

/// The genus-1 domain: flat metric (default conformal flow to max |K| ≤ 1e-11, accepted up to
/// 1e-10 when rounding stalls it there), cut along a canonical basis, flat layout; the deck translations span the lattice, reduced (Gauss) and rotated so that
/// `ω₁ = (W, 0)`, `ω₂ = (s, H)`. Returns one parameter per input vertex and the lattice.
pub fn flat_torus_domain(
    surface: &Surface,
    progress: &mut dyn Progress,
) -> Result<(Vec<[f64; 2]>, Lattice)> {
    use crate::layout::deck::deck_group;
    use crate::layout::pipeline::cut_disk;
    use crate::layout::place::layout;
    use crate::metric::{Euclidean, Geometry};
    let t = crate::mesh::topology(&surface.mesh);
    let c = t.components.first();
    if t.components.len() != 1 || c.map(|c| (c.genus, c.boundary_loops)) != Some((1, 0)) {
        return Err(Error::topology(format!(
            "the flat-torus domain needs one closed surface of genus 1; this mesh has {} component(s), genus {} and {} boundary loop(s)",
            t.components.len(),
            c.map_or(0, |c| c.genus),
            c.map_or(0, |c| c.boundary_loops)
        )));
    }
    let opts = crate::flow::UniformizationOptions::single(
        Some(Geometry::Euclidean),
        crate::flow::default_scheme(Geometry::Euclidean),
        1e-11,
    )
    .with_target(crate::flow::TargetSpec::Uniform);
    let r = crate::flow::flow_with_fallback(
        &surface.mesh,
        &surface.edge_lengths(),
        &opts,
        None,
        progress,
    )?
    .result;
    // Newton can stall a little above 1e-11 by rounding (camel, with angles down to 0.003°:
    // 3.9e-11 after 50 iterations): accepted up to the tolerance of the layout's flat flow.
    let accept = crate::flow::uniformize::layout_tolerance(Geometry::Euclidean);
    if !(r.converged || r.max_curvature_error <= accept) {
        return Err(Error::numerical(format!(
            "the flat-metric flow did not converge (max curvature error {:.3e} after {} iterations, above {accept:.0e})",
            r.max_curvature_error, r.iterations
        )));
    }
    let work = r
        .triangulation
        .as_ref()
        .map(|t| t.simplicial.mesh.clone())
        .unwrap_or_else(|| surface.mesh.clone());
    let disk = cut_disk(
        &work,
        &crate::metric::IntrinsicMetric::new(Geometry::Euclidean, r.lengths.clone()),
        None,
        None,
        progress,
    )?;
    let l = layout::<Euclidean>(&disk.mesh, &disk.metric, None)?;
    let g = deck_group::<Euclidean>(&l, &disk.polygon)?;
    let gens = g.named_generators();
    if gens.len() != 2 {
        return Err(Error::numerical(format!(
            "expected two deck translations of the flat torus, found {}",
            gens.len()
        )));
    }
    let (mut w1, mut w2) = (gens[0].1.t, gens[1].1.t);
    // Gauss reduction
    for _ in 0..100 {
        if w2.norm() < w1.norm() {
            std::mem::swap(&mut w1, &mut w2);
        }
        let m = ((w2 * w1.conj()).re / w1.norm_sqr()).round();
        if m == 0.0 {
            break;
        }
        w2 -= w1 * m;
    }
    let rot = w1.conj() / w1.norm();
    let mut b = w2 * rot;
    if b.im < 0.0 {
        b = -b;
    }
    // A shift below 1e-7 W is the flow's rounding on a rectangular lattice (a symmetric torus):
    // kept, it would cut 1e-10-wide sliver elements along every column.
    let shift = if b.re.abs() < 1e-7 * w1.norm() {
        0.0
    } else {
        b.re
    };
    let lattice = Lattice {
        width: w1.norm(),
        height: b.im,
        shift,
    };
    if !(lattice.height > 1e-12 * lattice.width) {
        return Err(Error::numerical(
            "the deck translations of the flat torus are parallel",
        ));
    }
    let n = surface.mesh.n_vertices();
    let mut uv = vec![[f64::NAN; 2]; n];
    for (cv, &orig) in disk.vertex_origin.iter().enumerate() {
        let o = orig as usize;
        if o < n && uv[o][0].is_nan() {
            let z = l.positions[cv] * rot;
            let (u, v) = lattice.canonical(z.re, z.im);
            uv[o] = [u, v];
        }
    }
    if let Some(v) = uv.iter().position(|p| p[0].is_nan()) {
        return Err(Error::numerical(format!(
            "vertex {v} got no position in the flat layout"
        )));
    }
    Ok((uv, lattice))
}
