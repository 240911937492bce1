//! Discrete conformal equivalence: Newton's method for vertex scaling on the intrinsic Delaunay
//! triangulation of the current metric (Gu–Luo–Sun–Wu 2018 for E², Gu–Guo–Luo–Sun–Wu 2018
//! for H²; Springborn 2020; Bobenko–Pinkall–Springborn 2015 for the convex energy;
//! Gillespie–Springborn–Crane 2021 (CEPS) §4 for the algorithm; docs/DESIGN.md §3 "Our default").
//!
//! The input metric is first made intrinsically Delaunay with *isometric* flips
//! ([`IntrinsicTriangulation::make_delaunay_isometric`]) — its log Penner coordinates on that
//! triangulation define the discrete conformal class. Every evaluation at `u` then scales the
//! coordinates (`λ̃ = λ + u_i + u_j`), flips to the Penner Delaunay triangulation with Ptolemy
//! flips (which preserve the class), and computes corner angles with the stable half-angle
//! cosine law of the background (`l = e^{λ̃/2}` in E², `l = 2 asinh e^{λ̃/2}` in H²), the
//! curvature `K_i = 2π − Σθ` (`π − Σθ` on the boundary; every corner of a Δ-complex counted)
//! and the Hessian `H = ∂K/∂u` per face by the chain rule `∂θ/∂u = (∂θ/∂l)(∂l/∂u)` with
//! `∂l_ij/∂u_i = s(l/2)/c(l/2)` (E²: `l/2`, which makes `H` the cotangent Laplacian
//! `(cot θ_k + cot θ_l)/2` of the current triangulation; H²: `tanh(l/2)`).
//!
//! **Energy.** `E(u) = ∫ Σ (K_i − K̄_i) du_i` is convex and C¹ across flips (its Hessian is
//! the Laplacian of whichever Delaunay triangulation is current; BPS 2015 Thm 4.2, GLSW 2018).
//! The line search accepts `u + tδ` when the convexity bound `E(u+tδ) − E(u) ≤ t g(t)`
//! (`g(t) = (K(u+tδ) − K̄)·δ`) already proves Armijo's condition (`g(t) ≤ c g(0)`, `c = 10⁻⁴`),
//! when Simpson's estimate `t(g(0) + 4g(t/2) + g(t))/6 ≤ c t g(0)` does, or when the largest
//! curvature error at least halves (Newton's quadratic phase).
//!
//! **Linear algebra.** Sparse Cholesky (faer) on a lower-triangular pattern that only grows:
//! the symbolic factorization is redone only when flips create a vertex pair that the pattern
//! lacks (entries of vanished pairs are stored as zeros), beside the Hessian's assembly (two
//! threads). Every edge keeps the slot of its two ends' entry; a flip renews its edge's slot,
//! a grown pattern moves the others.
//!
//! **Targets.** Per-vertex `K̄` from [`super::target`]; fixed vertices (free boundary) keep
//! `u = 0`; round boundaries re-evaluate `K̄` from the current boundary lengths (boundary edges
//! never flip, so the loops' edge ids stay valid) and take exact Newton steps on
//! `K(u) − K̄(u) = 0` with the Jacobian `H − ∂K̄/∂u` (sparse part by Cholesky, one rank-one term
//! per loop by Woodbury; `round_jacobian_step`), accepted when the residual `‖K − K̄‖²`
//! decreases by Armijo's factor at `t = 1` or `½` (or the largest error halves); otherwise
//! that iteration takes a chord step (target frozen, energy line search). Chord steps alone
//! converge linearly (camelhead 26 steps, face.off 28); with exact steps 7 and 9.

#![allow(clippy::needless_range_loop)]

use super::hessian_pattern::GrowingPattern;
use super::newton::max_error;
use super::target::Target;
use super::IterationRecord;
use crate::error::{Error, Result};
use crate::mesh::NONE;
use crate::metric::intrinsic::{length_of_lambda, IntrinsicTriangulation};
use crate::metric::kernel::angle_derivatives;
use crate::metric::{Euclidean, Geometry, Hyperbolic, Spherical};
use crate::progress::Progress;
use std::f64::consts::PI;
use std::time::Instant;

/// Settings of [`solve`].
#[derive(Debug, Clone)]
pub struct ConformalSettings {
    pub geometry: Geometry,
    /// Stop when max |K − K̄| ≤ tolerance.
    pub tolerance: f64,
    pub max_iterations: usize,
    /// Flips allowed in one evaluation.
    pub flip_budget: usize,
    /// Vertices held at `u = 0` besides the target's fixed ones (the E² scale pin).
    pub pinned: Vec<u32>,
}

/// Angles, curvature and per-face angle Jacobians of the current triangulation at some `u`.
#[derive(Debug, Clone, Default)]
pub struct ConformalState {
    /// Corner angles, by corner `3f + i` of the intrinsic triangulation.
    pub angles: Vec<f64>,
    /// `K_i` per vertex.
    pub curvature: Vec<f64>,
    /// `∂θ_m/∂u_{v_n}` per face in local corner indices (`jac[9f + 3m + n]`).
    pub jac: Vec<f64>,
    /// Faces violating a triangle inequality.
    pub degenerate_faces: usize,
    /// Total background area.
    pub area: f64,
    /// Flips made by the evaluation.
    pub flips: usize,
}

/// Evaluate the metric `u` on `tri`: flip to Delaunay (Ptolemy), angles, curvature, Jacobians.
/// Returns false when the flip budget runs out.
pub fn evaluate(
    tri: &mut IntrinsicTriangulation,
    geometry: Geometry,
    u: &[f64],
    flip_budget: usize,
    state: &mut ConformalState,
) -> bool {
    let rep = tri.make_delaunay(u, flip_budget);
    state.flips = rep.flips;
    if !rep.delaunay {
        return false;
    }
    match geometry {
        Geometry::Euclidean => evaluate_angles::<Euclidean>(tri, geometry, u, state),
        Geometry::Hyperbolic => evaluate_angles::<Hyperbolic>(tri, geometry, u, state),
        Geometry::Spherical => evaluate_angles::<Spherical>(tri, geometry, u, state),
    }
    true
}

fn evaluate_angles<B: crate::metric::Background>(
    tri: &IntrinsicTriangulation,
    geometry: Geometry,
    u: &[f64],
    st: &mut ConformalState,
) {
    let nf = tri.n_faces();
    let nv = tri.n_vertices;
    st.angles.resize(3 * nf, 0.0);
    st.jac.resize(9 * nf, 0.0);
    st.curvature.clear();
    st.curvature
        .extend((0..nv).map(|v| if tri.boundary_vertex[v] { PI } else { 2.0 * PI }));
    // Per face in parallel (rayon): angles and their derivatives go to the face's own slots;
    // the curvatures and the area are then summed in face order, as one loop would (the same
    // numbers whatever the number of threads).
    use rayon::prelude::*;
    let per_face: Vec<(bool, f64)> = st
        .angles
        .par_chunks_mut(3)
        .zip(st.jac.par_chunks_mut(9))
        .enumerate()
        .with_min_len(1024)
        .map(|(f, (angles, jac))| {
            let b = 3 * f;
            // Side m is opposite corner m: the edge of half-edge 3f + (m+1)%3.
            let mut l = [0.0; 3];
            let mut ht = [0.0; 3];
            for m in 0..3 {
                let h = (b + (m + 1) % 3) as u32;
                let lam = tri.lambda[tri.edge[h as usize] as usize]
                    + u.get(tri.origin[h as usize] as usize)
                        .copied()
                        .unwrap_or(0.0)
                    + u.get(tri.tip(h) as usize).copied().unwrap_or(0.0);
                l[m] = length_of_lambda(geometry, lam);
                ht[m] = B::half_tangent(l[m]);
            }
            let (th, d, deg) = angle_derivatives::<B>(l);
            for m in 0..3 {
                angles[m] = th[m];
                for n in 0..3 {
                    // ∂θ_m/∂u_n = Σ_{k ≠ n} ∂θ_m/∂l_k · ∂l_k/∂u (edge k has corners k+1, k+2).
                    let mut s = 0.0;
                    for k in 0..3 {
                        if k != n {
                            s += d[m][k] * ht[k];
                        }
                    }
                    jac[3 * m + n] = s;
                }
            }
            let a = match geometry {
                Geometry::Euclidean => B::area(l[0], l[1], l[2]),
                Geometry::Hyperbolic => (PI - th[0] - th[1] - th[2]).max(0.0),
                Geometry::Spherical => (th[0] + th[1] + th[2] - PI).max(0.0),
            };
            (deg, a)
        })
        .collect();
    st.degenerate_faces = 0;
    let mut area = 0.0;
    let mut used = vec![false; nv];
    for (f, &(deg, a)) in per_face.iter().enumerate() {
        if deg {
            st.degenerate_faces += 1;
        }
        for m in 0..3 {
            let v = tri.origin[3 * f + m] as usize;
            used[v] = true;
            st.curvature[v] -= st.angles[3 * f + m];
        }
        area += a;
    }
    for v in 0..nv {
        if !used[v] {
            st.curvature[v] = 0.0;
        }
    }
    st.area = area;
}

/// What [`solve`] produced.
#[derive(Debug, Clone)]
pub struct ConformalOutcome {
    pub u: Vec<f64>,
    pub iterations: usize,
    pub history: Vec<IterationRecord>,
    pub converged: bool,
    pub max_error: f64,
    /// Ptolemy flips made during the solve (the isometric initial flips not included).
    pub flips: usize,
    /// Symbolic factorizations computed (the pattern grew this many times, plus one).
    pub symbolic_factorizations: usize,
    pub state: ConformalState,
    pub notes: Vec<String>,
    /// Why the solve stopped short of the tolerance ([`super::newton::stop_reason`]).
    pub stop_reason: Option<String>,
}

/// Newton's method for the target `target` on `tri` (already Delaunay for its base metric),
/// starting from `u = 0`.
pub fn solve(
    tri: &mut IntrinsicTriangulation,
    target: &mut Target,
    settings: &ConformalSettings,
    progress: &mut dyn Progress,
) -> Result<ConformalOutcome> {
    let t0 = Instant::now();
    let n = tri.n_vertices;
    if target.curvature.len() != n || target.fixed.len() != n {
        return Err(Error::input(format!(
            "target has {} values for {} vertices",
            target.curvature.len(),
            n
        )));
    }
    let mut held = target.fixed.clone();
    for &p in &settings.pinned {
        held[p as usize] = true;
    }
    let dynamic = target.is_dynamic();
    let mut cn = ConformalNewton::new(tri, settings, held);
    let mut exact_steps = 0usize;
    let mut chord_steps = 0usize;
    let mut history = Vec::new();
    let mut notes = Vec::new();
    let mut converged = false;
    let mut err;
    let mut it = 0;
    if !cn.evaluate_at_u() {
        return Err(Error::numerical(format!(
            "the initial metric needed more than {} Delaunay flips",
            settings.flip_budget
        )));
    }
    if dynamic {
        update_round(cn.tri, &cn.u, target);
    }
    loop {
        err = max_error(&cn.st.curvature, target);
        history.push(IterationRecord {
            iteration: it,
            max_curvature_error: err,
            energy: (!dynamic).then_some(cn.energy),
            step: cn.last_step,
            seconds: t0.elapsed().as_secs_f64(),
        });
        progress.report(
            "conformal",
            None,
            &format!("iteration {it}: max |K − K̄| = {err:.3e}"),
        );
        if !err.is_finite() {
            notes.push("the curvature became non-finite".into());
            break;
        }
        if err <= settings.tolerance {
            converged = true;
            break;
        }
        if it >= settings.max_iterations {
            break;
        }
        it += 1;
        cn.assemble()?;
        cn.newton_rhs(target);
        if dynamic {
            // Exact Newton step on K(u) − K̄(u) = 0 with a residual line search; on failure a
            // chord step (target frozen) follows.
            if cn.exact_round_step(target, err) {
                exact_steps += 1;
                continue;
            }
            chord_steps += 1;
            // The triangulation may have moved during the trials: back to Delaunay at u.
            if !cn.evaluate_at_u() {
                notes.push(format!("iteration {it}: flip budget exceeded"));
                break;
            }
            cn.assemble()?;
        }
        if !cn.newton_direction() {
            notes.push(format!(
                "iteration {it}: the Hessian was not numerically positive definite; gradient step"
            ));
        }
        let g0 = cn.slope(&cn.st, target);
        if g0.is_nan() || g0 >= 0.0 {
            notes.push(format!(
                "iteration {it}: the Newton direction is not a descent direction (g = {g0:.3e})"
            ));
            break;
        }
        let Some((t, need_reevaluation)) = cn.line_search(target, err, g0) else {
            notes.push(format!("iteration {it}: the line search found no decrease"));
            break;
        };
        if need_reevaluation {
            // The triangulation may have moved on at t/2: make it Delaunay at the accepted u.
            if !cn.evaluate_at_trial() {
                notes.push(format!("iteration {it}: flip budget exceeded"));
                break;
            }
        } else {
            std::mem::swap(&mut cn.st, &mut cn.trial_st);
        }
        cn.last_step = cn.delta.iter().map(|x| (t * x).abs()).fold(0.0, f64::max);
        std::mem::swap(&mut cn.u, &mut cn.trial);
        if dynamic {
            update_round(cn.tri, &cn.u, target);
        }
    }
    let stop_reason =
        super::newton::stop_reason(converged, it, settings.max_iterations, err, &notes);
    if dynamic {
        notes.push(format!(
            "round boundary: {exact_steps} exact Newton step(s) (Jacobian H − ∂K̄/∂u), \
             {chord_steps} chord step(s) (target frozen) after a rejected exact step"
        ));
    }
    if !converged && it >= settings.max_iterations {
        notes.push(format!(
            "not converged after {it} Newton iterations: max |K − K̄| = {err:.3e}"
        ));
    }
    Ok(ConformalOutcome {
        u: cn.u,
        iterations: it,
        history,
        converged,
        max_error: err,
        flips: cn.flips,
        symbolic_factorizations: cn.pattern.symbolic_count,
        state: cn.st,
        notes,
        stop_reason,
    })
}

/// Round boundaries: the target `K̄` re-evaluated from the boundary lengths of the metric `u`.
fn update_round(tri: &IntrinsicTriangulation, u: &[f64], target: &mut Target) {
    let lengths = tri.lengths(Geometry::Euclidean, u);
    target.update_round(&lengths, &[], &[]);
}

/// Armijo's constant of the line searches.
const C_ARMIJO: f64 = 1e-4;

/// The state of one Newton solve of [`solve`]: the triangulation, the iterate `u` and its
/// evaluation `st`, trial points, the growing Hessian pattern and its values, the step.
struct ConformalNewton<'a> {
    tri: &'a mut IntrinsicTriangulation,
    settings: &'a ConformalSettings,
    held: Vec<bool>,
    pattern: GrowingPattern,
    values: Vec<f64>,
    /// `K̄ − K` on the free vertices (with the scale pin's mean removed).
    rhs: Vec<f64>,
    u: Vec<f64>,
    trial: Vec<f64>,
    /// The Newton direction on all vertices.
    delta: Vec<f64>,
    st: ConformalState,
    trial_st: ConformalState,
    mid_st: ConformalState,
    /// Ptolemy flips made so far.
    flips: usize,
    last_step: f64,
    /// `E(u) − E(0)` as estimated by the accepted line searches.
    energy: f64,
}

impl<'a> ConformalNewton<'a> {
    fn new(
        tri: &'a mut IntrinsicTriangulation,
        settings: &'a ConformalSettings,
        held: Vec<bool>,
    ) -> Self {
        let n = tri.n_vertices;
        let pattern = GrowingPattern::new(&held);
        ConformalNewton {
            tri,
            settings,
            rhs: vec![0.0; pattern.n()],
            pattern,
            held,
            values: Vec::new(),
            u: vec![0.0; n],
            trial: vec![0.0; n],
            delta: vec![0.0; n],
            st: ConformalState::default(),
            trial_st: ConformalState::default(),
            mid_st: ConformalState::default(),
            flips: 0,
            last_step: 0.0,
            energy: 0.0,
        }
    }

    /// Delaunay at `u` and its evaluation into `st`; false when the flip budget ran out.
    fn evaluate_at_u(&mut self) -> bool {
        let (geometry, budget) = (self.settings.geometry, self.settings.flip_budget);
        if !evaluate(self.tri, geometry, &self.u, budget, &mut self.st) {
            return false;
        }
        self.flips += self.st.flips;
        true
    }

    /// Delaunay at `trial` and its evaluation into `st`; false when the flip budget ran out.
    fn evaluate_at_trial(&mut self) -> bool {
        let (geometry, budget) = (self.settings.geometry, self.settings.flip_budget);
        if !evaluate(self.tri, geometry, &self.trial, budget, &mut self.st) {
            return false;
        }
        self.flips += self.st.flips;
        true
    }

    /// The Hessian of the current triangulation at `u` into `values`, and the pattern's
    /// symbolic factorization when it grew (the two in parallel: they share only the
    /// pattern).
    fn assemble(&mut self) -> Result<()> {
        if !self.pattern.cover(self.tri) {
            self.pattern.assemble(self.tri, &self.st, &mut self.values);
            return Ok(());
        }
        let (pattern, tri, st, values) = (&self.pattern, &*self.tri, &self.st, &mut self.values);
        let (analysis, ()) =
            rayon::join(|| pattern.analysis(), || pattern.assemble(tri, st, values));
        let (solver, amd_nnz) = analysis?;
        if let Some(nnz) = amd_nnz {
            self.pattern.amd_factor_nnz = nnz;
        }
        self.pattern.solver = Some(solver);
        self.pattern.symbolic_count += 1;
        Ok(())
    }

    /// r = K̄ − K on the free vertices; with a scale pin the mean is removed (Gauss–Bonnet
    /// makes it vanish up to rounding, which would otherwise pile up at the pin).
    fn newton_rhs(&mut self, target: &Target) {
        let n = self.u.len();
        let st = &self.st;
        let shift = if self.settings.pinned.is_empty() {
            0.0
        } else {
            let (s, c) = (0..n)
                .filter(|&i| !target.fixed[i])
                .fold((0.0, 0usize), |(s, c), i| {
                    (s + target.curvature[i] - st.curvature[i], c + 1)
                });
            s / c.max(1) as f64
        };
        for (c, &v) in self.pattern.free_vertex.iter().enumerate() {
            self.rhs[c] = target.curvature[v as usize] - st.curvature[v as usize] - shift;
        }
    }

    /// Round boundaries: the exact Newton step on `K(u) − K̄(u) = 0`, tried at `t = 1` and
    /// `½` with the residual test. When accepted, `u`, `st` and `target` move to it (true).
    fn exact_round_step(&mut self, target: &mut Target, err: f64) -> bool {
        let (geometry, budget) = (self.settings.geometry, self.settings.flip_budget);
        let rhs = &self.rhs;
        let Some(d) = round_jacobian_step(
            &mut self.pattern,
            &self.values,
            self.tri,
            &self.u,
            target,
            rhs,
        ) else {
            return false;
        };
        let r0 = residual_norm2(&self.st.curvature, target, &self.held);
        let mut t = 1.0;
        let mut trial_target = target.clone();
        // Full and half steps only: a damped exact step makes little progress where the
        // chord step does better.
        for _ in 0..2 {
            for i in 0..self.u.len() {
                self.trial[i] = self.u[i] + t * d[i];
            }
            let ok = evaluate(self.tri, geometry, &self.trial, budget, &mut self.trial_st);
            self.flips += self.trial_st.flips;
            if ok && self.trial_st.degenerate_faces == 0 {
                update_round(self.tri, &self.trial, &mut trial_target);
                let r1 = residual_norm2(&self.trial_st.curvature, &trial_target, &self.held);
                let e1 = max_error(&self.trial_st.curvature, &trial_target);
                if r1 <= (1.0 - 2e-4 * t) * r0 || e1 <= 0.5 * err {
                    self.last_step = d.iter().map(|x| (t * x).abs()).fold(0.0, f64::max);
                    std::mem::swap(&mut self.st, &mut self.trial_st);
                    std::mem::swap(&mut self.u, &mut self.trial);
                    *target = trial_target;
                    return true;
                }
            }
            t *= 0.5;
        }
        false
    }

    /// The Newton direction `H δ = r` into `delta` (sparse Cholesky); when `H` does not
    /// factorize, the gradient direction `δ = r` (false).
    fn newton_direction(&mut self) -> bool {
        let solver = self.pattern.solver.as_mut().expect("pattern covered");
        let mut step = self.rhs.clone();
        let factored = solver.factor_llt(&self.values);
        if factored {
            solver.solve(&mut step);
        }
        self.delta.iter_mut().for_each(|x| *x = 0.0);
        for (c, &v) in self.pattern.free_vertex.iter().enumerate() {
            self.delta[v as usize] = step[c];
        }
        factored
    }

    /// g(t) = (K(u + tδ) − K̄)·δ for the evaluation `s` at `u + tδ`.
    fn slope(&self, s: &ConformalState, target: &Target) -> f64 {
        let mut g = 0.0;
        for i in 0..self.u.len() {
            if !self.held[i] {
                g += (s.curvature[i] - target.curvature[i]) * self.delta[i];
            }
        }
        g
    }

    /// Backtracking along `delta` (module doc): `Some((t, whether st must be re-evaluated at
    /// trial))` with `trial = u + tδ` evaluated in `trial_st`, or `None` after 40 halvings.
    ///
    /// Every evaluation is used once: when Simpson's test at `t` needed the midpoint `t/2`,
    /// the triangulation is Delaunay there, so the midpoint is accepted instead of `t` when
    /// the quadratic model of `g` through `0, t/2, t` gives it the lower energy (and Armijo's
    /// condition), and it is the next trial without a new evaluation when `t` is rejected.
    fn line_search(&mut self, target: &Target, err: f64, g0: f64) -> Option<(f64, bool)> {
        let (geometry, budget) = (self.settings.geometry, self.settings.flip_budget);
        let n = self.u.len();
        let mut t = 1.0;
        // `trial_st` already holds the evaluation at `u + tδ` (the last midpoint).
        let mut evaluated = false;
        for _ in 0..40 {
            let ok = evaluated || {
                for i in 0..n {
                    self.trial[i] = self.u[i] + t * self.delta[i];
                }
                let ok = evaluate(self.tri, geometry, &self.trial, budget, &mut self.trial_st);
                self.flips += self.trial_st.flips;
                ok
            };
            evaluated = false;
            // Faces violating the triangle inequality (angles extended by 0, 0, π; the energy
            // stays convex and C¹) are accepted only if the start had as many: a start outside
            // the domain can come back, a valid iterate never leaves it.
            if ok && self.trial_st.degenerate_faces <= self.st.degenerate_faces {
                let gt = self.slope(&self.trial_st, target);
                let et = max_error(&self.trial_st.curvature, target);
                if gt <= C_ARMIJO * g0 || et <= 0.5 * err {
                    self.energy += (t * gt).min(0.0);
                    return Some((t, false));
                }
                for i in 0..n {
                    self.trial[i] = self.u[i] + 0.5 * t * self.delta[i];
                }
                if evaluate(self.tri, geometry, &self.trial, budget, &mut self.mid_st) {
                    self.flips += self.mid_st.flips;
                    let gh = self.slope(&self.mid_st, target);
                    let de = t * (g0 + 4.0 * gh + gt) / 6.0;
                    let de_half = 0.5 * t * (5.0 * g0 + 8.0 * gh - gt) / 12.0;
                    let mid_valid = self.mid_st.degenerate_faces <= self.st.degenerate_faces;
                    if mid_valid && de_half <= de && de_half <= C_ARMIJO * 0.5 * t * g0 {
                        std::mem::swap(&mut self.trial_st, &mut self.mid_st);
                        self.energy += de_half.min(0.0);
                        return Some((0.5 * t, false));
                    }
                    if de <= C_ARMIJO * t * g0 {
                        for i in 0..n {
                            self.trial[i] = self.u[i] + t * self.delta[i];
                        }
                        self.energy += de.min(0.0);
                        return Some((t, true));
                    }
                    // `t` rejected: the midpoint, evaluated and Delaunay, is the next trial.
                    std::mem::swap(&mut self.trial_st, &mut self.mid_st);
                    evaluated = true;
                }
            }
            t *= 0.5;
        }
        None
    }
}

/// `Σ (K_i − K̄_i)²` over the vertices that are not held.
fn residual_norm2(k: &[f64], target: &Target, held: &[bool]) -> f64 {
    let mut s = 0.0;
    for i in 0..k.len() {
        if !held[i] {
            let d = k[i] - target.curvature[i];
            s += d * d;
        }
    }
    s
}

/// The exact Newton step of a round-boundary target (E²): solve `J δ = r` on the free
/// vertices with `J = H − ∂K̄/∂u`. For a loop with total `T`, edge lengths `l_k`,
/// `α_k = 2 asin(l_k/2R)`, `c_k = ∂α_k/∂l_k = 1/(R cos(α_k/2))`, `S = Σ l_k c_k` and
/// `∂l_k/∂u_a = l_k/2` at both ends, the constraint `Σ α_k = |T|` gives
/// `dα_k = c_k dl_k − l_k c_k (Σ_j c_j dl_j)/S`, hence with `K̄_v = sign(T)(α_{k−1} + α_k)/2`
/// and `ρ_v = (l_{k−1}c_{k−1} + l_k c_k)/2`:
/// `∂K̄/∂u = sign(T) (A − ρρᵀ/S)`, `A` the sparse symmetric matrix with `w_k = c_k l_k/4` on
/// both ends and the off-diagonal of every boundary edge. So `J = (H − sign A) + sign ρρᵀ/S`:
/// the sparse part by Cholesky (LLᵀ, else LDLᵀ), one rank-one term per loop by Woodbury.
/// `None` when a factorization fails.
fn round_jacobian_step(
    pattern: &mut GrowingPattern,
    h_values: &[f64],
    tri: &IntrinsicTriangulation,
    u: &[f64],
    target: &Target,
    rhs: &[f64],
) -> Option<Vec<f64>> {
    let nf = pattern.n();
    let mut values = h_values.to_vec();
    let mut terms: Vec<(Vec<f64>, f64)> = Vec::new();
    let fi = |v: u32| pattern.free_index[v as usize];
    for lp in &target.round_loops {
        let m = lp.vertices.len();
        let l: Vec<f64> = lp
            .edges
            .iter()
            .map(|&e| length_of_lambda(Geometry::Euclidean, tri.scaled_lambda(e, u)))
            .collect();
        let c = super::target::CircleLoop::new(&l, lp.total);
        if c.sign == 0.0 || !c.radius.is_finite() {
            continue;
        }
        let mut rho = vec![0.0; nf];
        for k in 0..m {
            let (a, b) = (lp.vertices[k], lp.vertices[(k + 1) % m]);
            let w = c.sign * c.dalpha[k] * l[k] / 4.0;
            let (ia, ib) = (fi(a), fi(b));
            if ia != NONE {
                values[pattern.slot(ia, ia)?] -= w;
                rho[ia as usize] += 0.5 * l[k] * c.dalpha[k];
            }
            if ib != NONE {
                values[pattern.slot(ib, ib)?] -= w;
                rho[ib as usize] += 0.5 * l[k] * c.dalpha[k];
            }
            if ia != NONE && ib != NONE && ia != ib {
                values[pattern.slot(ia.min(ib), ia.max(ib))?] -= w;
            }
        }
        terms.push((rho, c.sign / c.s));
    }
    let solver = pattern.solver.as_mut()?;
    if !solver.factor_llt(&values) && !solver.factor_ldlt(&values) {
        return None;
    }
    let mut x = rhs.to_vec();
    solver.solve(&mut x);
    if !terms.is_empty() {
        // Woodbury: (M + R Σ Rᵀ)⁻¹ b = M⁻¹b − Z (Σ⁻¹ + RᵀZ)⁻¹ Rᵀ M⁻¹ b with Z = M⁻¹R.
        let k = terms.len();
        let mut z: Vec<Vec<f64>> = Vec::with_capacity(k);
        for (rho, _) in &terms {
            let mut y = rho.clone();
            solver.solve(&mut y);
            z.push(y);
        }
        let dot = |a: &[f64], b: &[f64]| a.iter().zip(b).map(|(p, q)| p * q).sum::<f64>();
        let mut cm = vec![vec![0.0; k]; k];
        let mut rb = vec![0.0; k];
        for i in 0..k {
            for j in 0..k {
                cm[i][j] = dot(&terms[i].0, &z[j]);
            }
            cm[i][i] += 1.0 / terms[i].1;
            rb[i] = dot(&terms[i].0, &x);
        }
        let y = solve_dense(cm, rb)?;
        for j in 0..k {
            for i in 0..nf {
                x[i] -= z[j][i] * y[j];
            }
        }
    }
    let mut d = vec![0.0; u.len()];
    for (c, &v) in pattern.free_vertex.iter().enumerate() {
        d[v as usize] = x[c];
    }
    d.iter().all(|x| x.is_finite()).then_some(d)
}

/// Gaussian elimination with partial pivoting for the small Woodbury systems.
fn solve_dense(mut a: Vec<Vec<f64>>, mut b: Vec<f64>) -> Option<Vec<f64>> {
    let n = b.len();
    for c in 0..n {
        let p = (c..n).max_by(|&i, &j| a[i][c].abs().total_cmp(&a[j][c].abs()))?;
        if a[p][c].abs() < 1e-300 {
            return None;
        }
        a.swap(c, p);
        b.swap(c, p);
        for r in c + 1..n {
            let f = a[r][c] / a[c][c];
            for k in c..n {
                a[r][k] -= f * a[c][k];
            }
            b[r] -= f * b[c];
        }
    }
    let mut x = vec![0.0; n];
    for r in (0..n).rev() {
        let mut s = b[r];
        for k in r + 1..n {
            s -= a[r][k] * x[k];
        }
        x[r] = s / a[r][r];
    }
    Some(x)
}

/// The full symmetric `H = ∂K/∂u` of the state as `(i, j, value)` triplets over all vertices
/// (duplicates to be summed), from the state's per-face Jacobians on `tri` (for tests and
/// diagnostics).
pub fn hessian_triplets(tri: &IntrinsicTriangulation, st: &ConformalState) -> Vec<(u32, u32, f64)> {
    let mut out = Vec::with_capacity(9 * tri.n_faces());
    for f in 0..tri.n_faces() {
        let vs = tri.face(f as u32);
        for m in 0..3 {
            for n in 0..3 {
                out.push((vs[m], vs[n], -st.jac[9 * f + 3 * m + n]));
            }
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::Mesh;
    use std::collections::HashMap;

    /// The growing pattern's slots (kept across flips and growth) against the Hessian summed
    /// here from [`hessian_triplets`] by vertex pair: every entry, after every evaluation of
    /// a sequence of scale factors that flips edges and grows the pattern.
    #[test]
    fn growing_pattern_assembles_the_hessian_of_every_triangulation() {
        // A jittered 12 × 12 grid of the unit square, split along one diagonal.
        let k = 12usize;
        let mut state = 0x2545_F491_4F6C_DD1Du64;
        let mut rand = move || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state >> 11) as f64 / (1u64 << 53) as f64
        };
        let mut pts = Vec::new();
        for j in 0..=k {
            for i in 0..=k {
                let inner = i > 0 && i < k && j > 0 && j < k;
                let jitter = if inner { 0.3 / k as f64 } else { 0.0 };
                pts.push([
                    i as f64 / k as f64 + jitter * (2.0 * rand() - 1.0),
                    j as f64 / k as f64 + jitter * (2.0 * rand() - 1.0),
                ]);
            }
        }
        let id = |i: usize, j: usize| (j * (k + 1) + i) as u32;
        let mut faces = Vec::new();
        for j in 0..k {
            for i in 0..k {
                faces.push([id(i, j), id(i + 1, j), id(i + 1, j + 1)]);
                faces.push([id(i, j), id(i + 1, j + 1), id(i, j + 1)]);
            }
        }
        let mesh = Mesh::from_triangles(pts.len(), faces).unwrap();
        let lengths: Vec<f64> = (0..mesh.n_edges() as u32)
            .map(|e| {
                let [a, b] = mesh.edge_vertices(e).map(|v| pts[v as usize]);
                ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2)).sqrt()
            })
            .collect();
        let mut tri =
            IntrinsicTriangulation::from_mesh(&mesh, Geometry::Euclidean, &lengths).unwrap();
        tri.make_delaunay_isometric(Geometry::Euclidean, 100_000);
        // Boundary vertices held, as the free boundary of `ricci param`.
        let held: Vec<bool> = (0..pts.len())
            .map(|v| {
                let p = pts[v];
                p[0] <= 0.0 || p[0] >= 1.0 || p[1] <= 0.0 || p[1] >= 1.0
            })
            .collect();
        let mut pattern = GrowingPattern::new(&held);
        let mut st = ConformalState::default();
        let mut values = Vec::new();
        let (mut grown, mut flips) = (0, 0);
        for step in 0..6 {
            let amplitude = 0.4 * step as f64;
            let u: Vec<f64> = (0..pts.len())
                .map(|v| {
                    let p = pts[v];
                    amplitude * (3.0 * p[0] + 5.0 * p[1] * p[1]).sin()
                })
                .collect();
            assert!(evaluate(
                &mut tri,
                Geometry::Euclidean,
                &u,
                100_000,
                &mut st
            ));
            flips += st.flips;
            if pattern.cover(&tri) {
                grown += 1;
                pattern.solver = Some(pattern.analysis().unwrap().0);
            }
            pattern.assemble(&tri, &st, &mut values);
            let mut want: HashMap<(u32, u32), f64> = HashMap::new();
            for (a, b, x) in hessian_triplets(&tri, &st) {
                let (r, c) = (
                    pattern.free_index[a as usize],
                    pattern.free_index[b as usize],
                );
                if r != NONE && c != NONE && c <= r {
                    *want.entry((c, r)).or_default() += x;
                }
            }
            for c in 0..pattern.n() as u32 {
                for s in
                    pattern.col_ptr[c as usize] as usize..pattern.col_ptr[c as usize + 1] as usize
                {
                    let r = pattern.row_idx[s];
                    let w = want.remove(&(c, r)).unwrap_or(0.0);
                    assert!(
                        (values[s] - w).abs() <= 1e-12 * w.abs().max(1.0),
                        "step {step}: entry ({c}, {r}) is {} instead of {w}",
                        values[s]
                    );
                }
            }
            assert!(
                want.is_empty(),
                "step {step}: pairs missing from the pattern: {want:?}"
            );
        }
        assert!(
            flips > 0 && grown > 1,
            "flips {flips}, pattern grew {grown} times"
        );
    }
}
