//! Newton's method and the papers' gradient flow for the Ricci energy (paper 001 §V Step 3,
//! paper 000 §4 Step 3).
//!
//! **Newton.** Solve `H δ = K̄ − K` over the free vertices with `H = ∂K/∂u` (sparse Cholesky,
//! symbolic factorization once), then `u += t δ` with a backtracking line search:
//! * on the convex energy (E², H² with a fixed target): accept `t` when the Simpson estimate of
//!   `E(u + tδ) − E(u) = ∫₀ᵗ (K(u+sδ) − K̄)·δ ds` satisfies Armijo's condition with
//!   `c = 10⁻⁴`, or when the largest curvature error at least halves;
//! * on the residual (S², round boundaries): accept when `‖K̄ − K‖²` decreases by Armijo's
//!   factor `1 − 2ct`, or the largest error at least halves.
//!
//! Steps that leave the domain (a hyperbolic radius variable `u ≥ 0`, a length that does not
//! exist) are halved. The E² scale kernel is removed by holding one vertex fixed (its equation
//! follows from Gauss–Bonnet).
//!
//! **S².** The Hessian is indefinite: near a round metric `H ≈ L − 2M` (cotangent-like
//! Laplacian minus twice the lumped area matrix), with generalized eigenvalues
//! `l(l+1) − 2 = −2, 0, 0, 0, 4, 10, …` — one negative direction (close to the global scale)
//! and a three-dimensional near-kernel (Möbius transformations of the sphere move spherical
//! circle packings and vertex-scaled metrics along the solution set). Steps solve
//! `(H + μM) δ = K̄ − K` by LDLᵀ with `μ = min(½, √max|K − K̄|)`: a Levenberg–Marquardt damping
//! in the metric of `M` that keeps the system regular (μ stays away from 2), bounds the steps
//! along the Möbius near-kernel and vanishes at the solution (superlinear convergence).
//!
//! **Round boundaries.** The target depends on the metric (boundary vertices on a circle,
//! see [`super::target`]). Newton steps solve with the Jacobian `J = H − ∂K̄/∂u` of the full
//! system ([`exact_round_step`]): its sparse part by sparse LU (for circle packings `J` is not
//! symmetric; the symbolic factorization is computed once), its rank-one parts (one per loop:
//! the circle's radius) by Woodbury's identity. An exact step the residual line search rejects
//! is replaced by a chord step: the target frozen, the convex energy minimized. (Chord steps
//! while far from the solution, as before, took 25 of 30 steps on refined face.off and did not
//! converge; exact steps from the start converge in 22.)
//!
//! **Gradient flow** (reference): `u += ε (K̄ − K)`, with `ε` halved whenever a step leaves the
//! domain or increases the largest error tenfold; in E² without fixed vertices the mean of `u`
//! is kept (the papers' normalization `Σ u = const`).

mod line_search;

use super::target::Target;
use super::IterationRecord;
use crate::error::Result;
use crate::metric::{Evaluator, HessianPattern};
use crate::numeric::sparse::{SparseLu, SymmetricSolver};
use crate::progress::Progress;
use line_search::{eval, LineSearchScratch, StepSearch};
use std::time::Instant;

/// How steps are accepted.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum LineSearch {
    Energy,
    Residual,
}

/// Settings of one Newton solve.
#[derive(Debug, Clone)]
pub struct NewtonSettings {
    pub tolerance: f64,
    pub max_iterations: usize,
    pub line_search: LineSearch,
    /// Vertices held fixed in addition to the target's fixed vertices (E² scale pin).
    pub pinned: Vec<u32>,
    /// Use LDLᵀ with Levenberg–Marquardt damping (S²) instead of LLᵀ.
    pub indefinite: bool,
}

/// What a solve produced.
#[derive(Debug, Clone)]
pub struct SolveOutcome {
    pub u: Vec<f64>,
    pub iterations: usize,
    pub history: Vec<IterationRecord>,
    pub converged: bool,
    pub max_error: f64,
    pub notes: Vec<String>,
    /// Why the solve stopped short of the tolerance (see [`stop_reason`]); `None` when it
    /// converged.
    pub stop_reason: Option<String>,
}

/// Why an iteration stopped short of its tolerance, for the non-convergence sentence the
/// caller prints: the iteration budget when it ran out, a non-finite curvature, else the
/// note the loop wrote when it broke off (every other early exit writes one: `loop_notes`
/// are the notes written since the loop started). `None` when it converged.
pub fn stop_reason(
    converged: bool,
    iterations: usize,
    max_iterations: usize,
    err: f64,
    loop_notes: &[String],
) -> Option<String> {
    if converged {
        None
    } else if !err.is_finite() {
        Some("the curvature became non-finite".into())
    } else if iterations >= max_iterations {
        Some(format!("the budget of {max_iterations} iterations ran out"))
    } else {
        Some(
            loop_notes
                .last()
                .cloned()
                .unwrap_or_else(|| "the iteration stopped without a reason".into()),
        )
    }
}

/// Largest |K − K̄| over the vertices with a prescribed curvature.
pub fn max_error(curvature: &[f64], target: &Target) -> f64 {
    curvature
        .iter()
        .zip(&target.curvature)
        .zip(&target.fixed)
        .filter(|(_, &f)| !f)
        .map(|((k, t), _)| (k - t).abs())
        .fold(0.0, f64::max)
}

fn progress_fraction(e0: f64, e: f64, tol: f64) -> f64 {
    if e0 <= tol || e <= tol {
        return 1.0;
    }
    ((e0 / e).ln() / (e0 / tol).ln()).clamp(0.0, 1.0)
}

/// The line search's first step length along `delta`: 1, or for S² and exact round-boundary
/// steps (indefinite systems, `trust_region`) a trust region of 2 in u (radii change by at most
/// e²), against wild steps from a nearly singular system.
fn first_step(delta: &[f64], trust_region: bool) -> f64 {
    let dmax = delta.iter().fold(0.0f64, |m, d| m.max(d.abs()));
    if trust_region && dmax > 2.0 {
        2.0 / dmax
    } else {
        1.0
    }
}

/// Newton's method from `u_start`.
pub fn newton(
    ev: &mut Evaluator,
    target: &mut Target,
    u_start: Vec<f64>,
    settings: &NewtonSettings,
    progress: &mut dyn Progress,
) -> Result<SolveOutcome> {
    let t0 = Instant::now();
    let n = ev.data.n_vertices();
    let mut held = target.fixed.clone();
    for &p in &settings.pinned {
        held[p as usize] = true;
    }
    let mut sys = NewtonSystem::new(HessianPattern::new(&ev.data, &held), n)?;
    let mut delta = vec![0.0; n];
    let mut scratch = LineSearchScratch::new(n);
    let mut frozen = target.curvature.clone();
    let mut u = u_start;
    let mut history = Vec::new();
    let mut notes = Vec::new();
    let mut energy = 0.0;
    let mut last_step = 0.0;
    let mut converged = false;
    let mut err = f64::INFINITY;
    let mut e0 = f64::NAN;
    let mut it = 0;
    let mut counts = StepCounts::default();
    let mut exact_failed = false;
    let dynamic = target.is_dynamic();
    let notes_before_loop = notes.len();
    loop {
        if !ev.evaluate_with_hessian(&u, &sys.pattern, &mut sys.values) {
            notes.push("the metric left the domain of the scheme".into());
            break;
        }
        if dynamic {
            target.update_round(&ev.ws.lengths, &ev.ws.dlengths, &ev.data.edges);
        }
        err = max_error(&ev.ws.curvature, target);
        if e0.is_nan() {
            e0 = err;
        }
        history.push(IterationRecord {
            iteration: it,
            max_curvature_error: err,
            energy: (settings.line_search == LineSearch::Energy).then_some(energy),
            step: last_step,
            seconds: t0.elapsed().as_secs_f64(),
        });
        progress.report(
            "newton",
            Some(progress_fraction(e0, err, settings.tolerance)),
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
        // Round boundaries: exact Newton steps on the full Jacobian; a frozen-target (chord)
        // step on the convex energy after an exact step was rejected.
        let exact = !dynamic || !exact_failed;
        exact_failed = false;
        let chord = dynamic && !exact;
        if chord {
            counts.chord += 1;
            frozen.copy_from_slice(&target.curvature);
        }
        let exact_round = dynamic && exact;
        let r0 = match sys.direction(ev, target, settings, exact_round, err, &mut delta) {
            Direction::Step(r0) => r0,
            Direction::Rejected => {
                exact_failed = true;
                counts.rejected_exact += 1;
                continue;
            }
            Direction::Failed(why) => {
                notes.push(format!("iteration {it}: {why}"));
                break;
            }
        };
        // Line search, against the frozen target for chord steps.
        let g0: f64 = -r0.iter().zip(&sys.rhs).map(|(r, d)| r * d).sum::<f64>(); // ∇E·δ < 0
        let res0: f64 = r0.iter().map(|r| r * r).sum();
        let t_start = first_step(&delta, settings.indefinite || exact_round);
        let search = StepSearch {
            u: &u,
            delta: &delta,
            held: &held,
            frozen: chord.then_some(&frozen[..]),
            kind: if chord {
                LineSearch::Energy
            } else {
                settings.line_search
            },
            g0,
            res0,
            err,
            t_start,
        };
        let Some((t, de)) = search.run(ev, target, &mut scratch) else {
            if dynamic && exact {
                // Take a frozen-target step instead.
                exact_failed = true;
                counts.rejected_exact += 1;
                continue;
            }
            notes.push(format!(
                "iteration {it}: the line search found no acceptable step (stagnation at max \
                 |K − K̄| = {err:.3e})"
            ));
            break;
        };
        if let Some(de) = de {
            energy += de;
        }
        for i in 0..n {
            u[i] += t * delta[i];
        }
        last_step = t * delta.iter().fold(0.0f64, |m, d| m.max(d.abs()));
    }
    let stop_reason = stop_reason(
        converged,
        it,
        settings.max_iterations,
        err,
        &notes[notes_before_loop..],
    );
    counts.shifted = sys.shifted_steps;
    counts.push_notes(settings.indefinite && it > 0, &mut notes);
    Ok(SolveOutcome {
        u,
        iterations: it,
        history,
        converged,
        max_error: err,
        notes,
        stop_reason,
    })
}

/// The linear algebra of the Newton steps: the Hessian's pattern and values, its sparse
/// Cholesky/LDLᵀ solver, the sparse LU of the round-boundary Jacobian, and work vectors.
struct NewtonSystem {
    pattern: HessianPattern,
    solver: SymmetricSolver,
    lu: SparseLu,
    values: Vec<f64>,
    shifted: Vec<f64>,
    /// `K̄ − K` on the free vertices, then the step on them.
    rhs: Vec<f64>,
    mass: Vec<f64>,
    /// Factorizations that needed a diagonal shift.
    shifted_steps: usize,
}

/// What [`NewtonSystem::direction`] found.
enum Direction {
    /// A step (in the caller's `delta`), with the right-hand side it solved for.
    Step(Vec<f64>),
    /// The exact round-boundary Jacobian could not be solved: take a chord step next.
    Rejected,
    /// No step (the reason, for the notes).
    Failed(String),
}

impl NewtonSystem {
    fn new(pattern: HessianPattern, n: usize) -> Result<NewtonSystem> {
        Ok(NewtonSystem {
            solver: SymmetricSolver::new(&pattern)?,
            lu: SparseLu::new(),
            values: vec![0.0; pattern.nnz()],
            shifted: vec![0.0; pattern.nnz()],
            rhs: vec![0.0; pattern.n()],
            mass: vec![0.0; n],
            shifted_steps: 0,
            pattern,
        })
    }

    /// The Newton direction at the evaluated metric (Hessian in `values`) into `delta`:
    /// the exact round-boundary step when `exact_round`, else `H δ = K̄ − K` (damped on S²).
    fn direction(
        &mut self,
        ev: &Evaluator,
        target: &Target,
        settings: &NewtonSettings,
        exact_round: bool,
        err: f64,
        delta: &mut [f64],
    ) -> Direction {
        let pattern = &self.pattern;
        newton_rhs(
            ev,
            target,
            pattern,
            !settings.pinned.is_empty(),
            &mut self.rhs,
        );
        let r0 = self.rhs.clone();
        // Round boundaries, exact steps: solve J δ = K̄ − K with the full Jacobian by sparse
        // LU ([`exact_round_step`]); if that fails, take a chord step instead.
        let mut exact_delta = None;
        if exact_round {
            match exact_round_step(ev, target, pattern, &self.values, &r0, &mut self.lu) {
                Some(d) => exact_delta = Some(d),
                None => return Direction::Rejected,
            }
        }
        let indefinite = settings.indefinite;
        if indefinite {
            add_spherical_damping(ev, pattern, &mut self.values, &mut self.mass, err);
        }
        if let Some(d) = exact_delta {
            self.rhs.copy_from_slice(&d);
        } else {
            let (solver, values, shifted) = (&mut self.solver, &self.values, &mut self.shifted);
            match factor_with_shift(solver, pattern, values, shifted, indefinite) {
                Some(shift_used) => self.shifted_steps += usize::from(shift_used),
                None => {
                    return Direction::Failed(
                        "the Hessian could not be factorized (singular or indefinite)".into(),
                    )
                }
            }
            self.solver.solve(&mut self.rhs);
        }
        delta.iter_mut().for_each(|d| *d = 0.0);
        for (c, &v) in pattern.free_vertex.iter().enumerate() {
            delta[v as usize] = self.rhs[c];
        }
        if delta.iter().any(|d| !d.is_finite()) {
            return Direction::Failed("the Newton step is not finite".into());
        }
        Direction::Step(r0)
    }
}

/// How many Newton steps needed special treatment (reported in the notes).
#[derive(Debug, Default)]
struct StepCounts {
    /// Factorizations that needed a diagonal shift.
    shifted: usize,
    /// Steps with the round-boundary target frozen.
    chord: usize,
    /// Exact round-boundary steps the line search (or the LU solve) rejected.
    rejected_exact: usize,
}

impl StepCounts {
    fn push_notes(&self, damped: bool, notes: &mut Vec<String>) {
        let shifted_steps = self.shifted;
        if shifted_steps > 0 {
            notes.push(format!(
                "{shifted_steps} Newton step(s) needed a diagonal shift to factorize the Hessian"
            ));
        }
        if damped {
            notes.push(
                "spherical steps were damped: (H + μM)δ = K̄ − K with M the lumped area matrix \
                 and μ = min(½, √max|K − K̄|), LDLᵀ factorization"
                    .into(),
            );
        }
        let rejected_exact = self.rejected_exact;
        if rejected_exact > 0 {
            notes.push(format!(
                "{rejected_exact} exact round-boundary Newton step(s) were rejected by the line \
                 search and replaced by frozen-target steps"
            ));
        }
        let chord_steps = self.chord;
        if chord_steps > 0 {
            notes.push(format!(
                "{chord_steps} step(s) with the round-boundary target frozen (convex chord steps)"
            ));
        }
    }
}

/// Right-hand side `r = K̄ − K` on the free vertices. With a scale pin (E²), Gauss–Bonnet
/// makes `Σ r` vanish over the prescribed vertices up to rounding; the rounding would
/// accumulate at the pinned vertex (≈ 1e-10 on a million faces), so its mean is removed and
/// spread evenly instead.
fn newton_rhs(
    ev: &Evaluator,
    target: &Target,
    pattern: &HessianPattern,
    pinned: bool,
    rhs: &mut [f64],
) {
    let n = ev.data.n_vertices();
    let shift = if !pinned {
        0.0
    } else {
        let (sum, count) = (0..n)
            .filter(|&i| !target.fixed[i])
            .fold((0.0, 0usize), |(s, c), i| {
                (s + target.curvature[i] - ev.ws.curvature[i], c + 1)
            });
        sum / count.max(1) as f64
    };
    for (c, &v) in pattern.free_vertex.iter().enumerate() {
        rhs[c] = target.curvature[v as usize] - ev.ws.curvature[v as usize] - shift;
    }
}

/// S²: Levenberg–Marquardt damping with the lumped spherical mass matrix, (H + μM)δ = K̄ − K.
/// On a round sphere H ≈ L − 2M has generalized eigenvalues l(l+1) − 2 = −2, 0 (×3, Möbius),
/// 4, 10, …: μ < 1 keeps the system regular and bounds the steps along the Möbius
/// near-kernel. Adds `μ M` to the diagonal of `values` (`mass` is scratch).
fn add_spherical_damping(
    ev: &Evaluator,
    pattern: &HessianPattern,
    values: &mut [f64],
    mass: &mut [f64],
    err: f64,
) {
    let mu = err.sqrt().min(0.5);
    mass.iter_mut().for_each(|m| *m = 0.0);
    for (f, t) in ev.data.faces.iter().enumerate() {
        let a = (ev.ws.angles[3 * f] + ev.ws.angles[3 * f + 1] + ev.ws.angles[3 * f + 2]
            - std::f64::consts::PI)
            .max(0.0)
            / 3.0;
        for &w in t {
            mass[w as usize] += a;
        }
    }
    for &w in &pattern.free_vertex {
        values[pattern.diag_slot[w as usize] as usize] += mu * mass[w as usize];
    }
}

/// Factorize `values` (LDLᵀ when `indefinite`, else LLᵀ); if that fails, retry up to six
/// times with a diagonal shift `μ = 10⁻¹² max|H_ii|`, growing ×100. `Some(shift used)`, or
/// `None` when no factorization succeeded.
fn factor_with_shift(
    solver: &mut SymmetricSolver,
    pattern: &HessianPattern,
    values: &[f64],
    shifted: &mut [f64],
    indefinite: bool,
) -> Option<bool> {
    let factor = |solver: &mut SymmetricSolver, v: &[f64]| {
        if indefinite {
            solver.factor_ldlt(v)
        } else {
            solver.factor_llt(v)
        }
    };
    if factor(solver, values) {
        return Some(false);
    }
    let dmax = pattern
        .free_vertex
        .iter()
        .map(|&v| values[pattern.diag_slot[v as usize] as usize].abs())
        .fold(0.0, f64::max);
    let mut mu = 1e-12 * dmax.max(1e-300);
    for _ in 0..6 {
        shifted.copy_from_slice(values);
        for &v in &pattern.free_vertex {
            shifted[pattern.diag_slot[v as usize] as usize] += mu;
        }
        if factor(solver, shifted) {
            return Some(true);
        }
        mu *= 100.0;
    }
    None
}

/// The exact Newton step of a round-boundary target: solve `J δ = r` (free vertices) with
/// `J = H − ∂K̄/∂u` (see [`Target::update_round`]),
/// `∂K̄_i/∂u_j = s/2 [Σ_{k at i} c_k ∂l_k/∂u_j − p_i q_j / S]`, `p_i = l_a c_a + l_b c_b`,
/// `q_j = Σ_k c_k ∂l_k/∂u_j`, `s = sign(T)`. The sparse part `H − s/2 Σ c_k ∂l_k/∂u` is
/// factorized by sparse LU (faer; for circle packings `J` is not symmetric, since
/// `∂l_k/∂u_a ≠ ∂l_k/∂u_b`), the rank-one parts (one per loop: the circle's radius) are applied
/// with Woodbury's identity. `values` holds `H` on `pattern` (lower triangle). `None` if the
/// factorization fails or the step is not finite.
fn exact_round_step(
    ev: &Evaluator,
    target: &Target,
    pattern: &HessianPattern,
    values: &[f64],
    r: &[f64],
    lu: &mut SparseLu,
) -> Option<Vec<f64>> {
    use faer::sparse::Triplet;
    let nf = pattern.n();
    let mut trip: Vec<Triplet<u32, u32, f64>> = Vec::with_capacity(2 * values.len());
    for c in 0..nf {
        for k in pattern.col_ptr[c] as usize..pattern.col_ptr[c + 1] as usize {
            let row = pattern.row_idx[k];
            trip.push(Triplet::new(row, c as u32, values[k]));
            if row as usize != c {
                trip.push(Triplet::new(c as u32, row, values[k]));
            }
        }
    }
    let none = crate::mesh::NONE;
    let mut terms: Vec<(Vec<f64>, Vec<f64>, f64)> = Vec::new();
    for lp in &target.round_loops {
        let l: Vec<f64> = lp
            .edges
            .iter()
            .map(|&e| ev.ws.lengths[e as usize])
            .collect();
        let c = super::target::CircleLoop::new(&l, lp.total);
        if c.sign == 0.0 {
            continue;
        }
        let mut p = vec![0.0; nf];
        let mut q = vec![0.0; nf];
        for (k, &e) in lp.edges.iter().enumerate() {
            let [a, b] = ev.data.edges[e as usize];
            let d = ev.ws.dlengths[e as usize];
            let ck = c.dalpha[k];
            let ends = [
                (pattern.free_index[a as usize], d[0]),
                (pattern.free_index[b as usize], d[1]),
            ];
            for &(fi, _) in &ends {
                if fi == none {
                    continue;
                }
                p[fi as usize] += l[k] * ck;
                for &(fj, dj) in &ends {
                    if fj != none {
                        trip.push(Triplet::new(fi, fj, -0.5 * c.sign * ck * dj));
                    }
                }
            }
            for &(fj, dj) in &ends {
                if fj != none {
                    q[fj as usize] += ck * dj;
                }
            }
        }
        terms.push((p, q, 0.5 * c.sign / c.s));
    }
    // The triplets come in the same order with the same pattern at every step, so the
    // symbolic factorization (ordering, elimination structure) is computed once.
    if !lu.factor(nf, &trip) {
        return None;
    }
    let lu = &*lu;
    let mut solve = |x: &mut [f64]| lu.solve(x);
    let mut x = r.to_vec();
    solve(&mut x);
    woodbury(&mut solve, &terms, &mut x);
    x.iter().all(|v| v.is_finite()).then_some(x)
}

/// Given `y = A⁻¹ r` in `x`, overwrite it with `(A + Σ_k c_k p_k q_kᵀ)⁻¹ r` (Woodbury), with
/// `solve` applying `A⁻¹` in place.
fn woodbury(solve: &mut dyn FnMut(&mut [f64]), terms: &[(Vec<f64>, Vec<f64>, f64)], x: &mut [f64]) {
    let b = terms.len();
    if b == 0 {
        return;
    }
    let z: Vec<Vec<f64>> = terms
        .iter()
        .map(|(p, _, _)| {
            let mut z = p.clone();
            solve(&mut z);
            z
        })
        .collect();
    // M = C⁻¹ + Qᵀ Z, rhs = Qᵀ y.
    let mut m = vec![0.0; b * b];
    let mut q = vec![0.0; b];
    for i in 0..b {
        for j in 0..b {
            m[i * b + j] = dot(&terms[i].1, &z[j]);
        }
        m[i * b + i] += 1.0 / terms[i].2;
        q[i] = dot(&terms[i].1, x);
    }
    // Solve M s = q by Gaussian elimination with partial pivoting (b is the number of loops).
    for c in 0..b {
        let p = (c..b)
            .max_by(|&i, &j| m[i * b + c].abs().total_cmp(&m[j * b + c].abs()))
            .unwrap_or(c);
        if p != c {
            for j in 0..b {
                m.swap(c * b + j, p * b + j);
            }
            q.swap(c, p);
        }
        let d = m[c * b + c];
        if d == 0.0 {
            return;
        }
        for i in c + 1..b {
            let f = m[i * b + c] / d;
            for j in c..b {
                m[i * b + j] -= f * m[c * b + j];
            }
            q[i] -= f * q[c];
        }
    }
    let mut s = vec![0.0; b];
    for i in (0..b).rev() {
        let mut acc = q[i];
        for j in i + 1..b {
            acc -= m[i * b + j] * s[j];
        }
        s[i] = acc / m[i * b + i];
    }
    for (k, zk) in z.iter().enumerate() {
        for (xi, zi) in x.iter_mut().zip(zk) {
            *xi -= s[k] * zi;
        }
    }
}

fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

/// Settings of the gradient flow.
#[derive(Debug, Clone)]
pub struct GradientSettings {
    pub tolerance: f64,
    pub max_iterations: usize,
    pub step: f64,
    /// Keep the mean of `u` (E² without fixed vertices).
    pub keep_mean: bool,
}

/// The papers' discrete Ricci flow `u += ε (K̄ − K)` from `u_start`.
pub fn gradient_flow(
    ev: &mut Evaluator,
    target: &mut Target,
    u_start: Vec<f64>,
    settings: &GradientSettings,
    progress: &mut dyn Progress,
) -> Result<SolveOutcome> {
    let t0 = Instant::now();
    let n = ev.data.n_vertices();
    let free: Vec<usize> = (0..n).filter(|&i| !target.fixed[i]).collect();
    let mut u = u_start;
    let mut notes = Vec::new();
    let mut history = Vec::new();
    let mut eps = settings.step;
    let mut trial = u.clone();
    let mean = |u: &[f64]| free.iter().map(|&i| u[i]).sum::<f64>() / free.len().max(1) as f64;
    let m0 = mean(&u);
    if !eval(ev, target, &u, true) {
        return Err(crate::error::Error::numerical(
            "the initial metric lies outside the domain of the scheme",
        ));
    }
    let mut err = max_error(&ev.ws.curvature, target);
    let e0 = err;
    let mut r: Vec<f64> = (0..n)
        .map(|i| target.curvature[i] - ev.ws.curvature[i])
        .collect();
    let mut energy = 0.0;
    let mut converged = false;
    let mut it = 0;
    let mut next_record = 0usize;
    let mut last_step = 0.0;
    let record_every = (settings.max_iterations / 2000).max(1);
    loop {
        if it >= next_record || err <= settings.tolerance || it >= settings.max_iterations {
            history.push(IterationRecord {
                iteration: it,
                max_curvature_error: err,
                energy: Some(energy),
                step: last_step,
                seconds: t0.elapsed().as_secs_f64(),
            });
            next_record = it + record_every;
            progress.report(
                "gradient",
                Some(progress_fraction(e0, err, settings.tolerance)),
                &format!("iteration {it}: max |K − K̄| = {err:.3e}"),
            );
        }
        if err <= settings.tolerance {
            converged = true;
            break;
        }
        if it >= settings.max_iterations || !err.is_finite() {
            break;
        }
        it += 1;
        let mut accepted = false;
        for _ in 0..30 {
            trial.copy_from_slice(&u);
            for &i in &free {
                trial[i] += eps * r[i];
            }
            if settings.keep_mean {
                let d = mean(&trial) - m0;
                for &i in &free {
                    trial[i] -= d;
                }
            }
            if eval(ev, target, &trial, true) {
                let e = max_error(&ev.ws.curvature, target);
                if e.is_finite() && e <= 10.0 * err {
                    // Trapezoid estimate of the energy change along the step.
                    let mut de = 0.0;
                    for &i in &free {
                        let k1 = ev.ws.curvature[i] - target.curvature[i];
                        de += 0.5 * (-r[i] + k1) * (trial[i] - u[i]);
                    }
                    energy += de;
                    err = e;
                    accepted = true;
                    break;
                }
            }
            eps *= 0.5;
        }
        if !accepted {
            notes.push(format!("iteration {it}: no admissible gradient step"));
            break;
        }
        last_step = free
            .iter()
            .map(|&i| (trial[i] - u[i]).abs())
            .fold(0.0, f64::max);
        std::mem::swap(&mut u, &mut trial);
        for i in 0..n {
            r[i] = target.curvature[i] - ev.ws.curvature[i];
        }
    }
    let stop_reason = stop_reason(converged, it, settings.max_iterations, err, &notes);
    if eps < settings.step {
        notes.push(format!("step length reduced to ε = {eps:.3e}"));
    }
    Ok(SolveOutcome {
        u,
        iterations: it,
        history,
        converged,
        max_error: err,
        notes,
        stop_reason,
    })
}

#[cfg(test)]
mod round_jacobian_tests {
    use super::*;
    use crate::metric::{ConformalStructure, Geometry, Scheme};

    /// The exact round-boundary step solves `J δ = r` with the true Jacobian of
    /// `F(u) = K(u) − K̄(u)` on the free vertices: the central difference of `F` along `δ`
    /// reproduces `r` (every scheme; a disk and an annulus, whose hole has `T = −2π`).
    #[test]
    fn exact_round_step_inverts_the_jacobian() {
        let disk = crate::mesh::generate::disk(40).unwrap();
        let annulus = crate::mesh::generate::annulus(0.5, 1.0, 40).unwrap();
        for s in [disk, annulus] {
            let lengths = s.edge_lengths();
            for scheme in [
                Scheme::Thurston,
                Scheme::Tangential,
                Scheme::Inversive,
                Scheme::Yamabe,
            ] {
                let st =
                    ConformalStructure::new(&s.mesh, &lengths, Geometry::Euclidean, scheme, 1.0)
                        .unwrap();
                let mut ev = Evaluator::new(&s.mesh, st);
                let mut target = crate::flow::target::resolve(
                    &s.mesh,
                    Geometry::Euclidean,
                    &crate::flow::TargetSpec::RoundBoundary,
                )
                .unwrap();
                let n = s.mesh.n_vertices();
                // A generic point: u0 plus a smooth perturbation.
                let u: Vec<f64> = (0..n)
                    .map(|i| ev.structure.u0[i] + 0.05 * ((i as f64) * 0.7).sin())
                    .collect();
                assert!(ev.evaluate(&u));
                crate::flow::target::set_round_totals(
                    &mut target,
                    &ev.ws.lengths,
                    &ev.ws.dlengths,
                    &ev.data.edges,
                );
                let mut held = target.fixed.clone();
                let pin = (0..n as u32)
                    .find(|&v| !s.mesh.is_boundary_vertex(v))
                    .unwrap();
                held[pin as usize] = true;
                let pattern = HessianPattern::new(&ev.data, &held);
                let mut values = vec![0.0; pattern.nnz()];
                assert!(ev.evaluate_with_hessian(&u, &pattern, &mut values));
                target.update_round(&ev.ws.lengths, &ev.ws.dlengths, &ev.data.edges);
                let nf = pattern.n();
                let r: Vec<f64> = (0..nf).map(|c| ((c as f64) * 1.3).cos()).collect();
                let d = exact_round_step(&ev, &target, &pattern, &values, &r, &mut SparseLu::new())
                    .unwrap_or_else(|| panic!("{scheme} {n}"));
                let dmax = d.iter().fold(0.0f64, |m, x| m.max(x.abs()));
                let h = 1e-5 / dmax;
                let mut f = |sign: f64| -> Vec<f64> {
                    let mut uu = u.clone();
                    for (c, &v) in pattern.free_vertex.iter().enumerate() {
                        uu[v as usize] += sign * h * d[c];
                    }
                    assert!(ev.evaluate(&uu));
                    target.update_round(&ev.ws.lengths, &ev.ws.dlengths, &ev.data.edges);
                    pattern
                        .free_vertex
                        .iter()
                        .map(|&v| ev.ws.curvature[v as usize] - target.curvature[v as usize])
                        .collect()
                };
                let (fp, fm) = (f(1.0), f(-1.0));
                let rmax = r.iter().fold(0.0f64, |m, x| m.max(x.abs()));
                let worst = (0..nf)
                    .map(|c| ((fp[c] - fm[c]) / (2.0 * h) - r[c]).abs())
                    .fold(0.0, f64::max);
                assert!(
                    worst <= 1e-6 * rmax,
                    "{scheme}, {} vertices: J δ differs from r by {worst:e}",
                    n
                );
            }
        }
    }
}
