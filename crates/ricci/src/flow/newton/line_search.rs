//! The backtracking line search of [`super::newton`] (module doc there): Armijo's condition
//! on the convex energy by Simpson's rule, or on the residual `‖K̄ − K‖²`, or the largest
//! curvature error at least halving.

use super::LineSearch;
use crate::flow::target::Target;
use crate::metric::Evaluator;

/// Work vectors of the line search.
pub(super) struct LineSearchScratch {
    trial: Vec<f64>,
    half: Vec<f64>,
}

impl LineSearchScratch {
    pub(super) fn new(n: usize) -> LineSearchScratch {
        LineSearchScratch {
            trial: vec![0.0; n],
            half: vec![0.0; n],
        }
    }
}

/// One backtracking line search along `delta` from `u` (see the module doc).
pub(super) struct StepSearch<'a> {
    pub(super) u: &'a [f64],
    pub(super) delta: &'a [f64],
    pub(super) held: &'a [bool],
    /// The target the step is measured against when frozen (chord steps); `None`: the
    /// target follows the metric.
    pub(super) frozen: Option<&'a [f64]>,
    pub(super) kind: LineSearch,
    /// `∇E·δ` at `u` (negative).
    pub(super) g0: f64,
    /// `‖K̄ − K‖²` at `u`.
    pub(super) res0: f64,
    /// max |K − K̄| at `u`.
    pub(super) err: f64,
    pub(super) t_start: f64,
}

impl StepSearch<'_> {
    /// The accepted step length `t`, with the energy change estimated by Simpson's rule when
    /// that is what accepted it; `None` when 40 halvings found no acceptable step.
    pub(super) fn run(
        &self,
        ev: &mut Evaluator,
        target: &mut Target,
        scratch: &mut LineSearchScratch,
    ) -> Option<(f64, Option<f64>)> {
        let n = self.u.len();
        let (u, delta, held) = (self.u, self.delta, self.held);
        let use_frozen = self.frozen.is_some();
        let mut t = self.t_start;
        for _ in 0..40 {
            for i in 0..n {
                scratch.trial[i] = u[i] + t * delta[i];
            }
            if !eval(ev, target, &scratch.trial, !use_frozen) {
                t *= 0.5;
                continue;
            }
            let tk: &[f64] = self.frozen.unwrap_or(&target.curvature);
            let err_t = max_error_against(&ev.ws.curvature, tk, &target.fixed);
            let gt: f64 = (0..n)
                .filter(|&i| !held[i])
                .map(|i| (ev.ws.curvature[i] - tk[i]) * delta[i])
                .sum();
            let res_t: f64 = (0..n)
                .filter(|&i| !held[i])
                .map(|i| (ev.ws.curvature[i] - tk[i]).powi(2))
                .sum();
            let halves = err_t <= 0.5 * self.err && err_t.is_finite();
            match self.kind {
                LineSearch::Energy => {
                    if halves {
                        return Some((t, None));
                    }
                    for i in 0..n {
                        scratch.half[i] = u[i] + 0.5 * t * delta[i];
                    }
                    if !eval(ev, target, &scratch.half, !use_frozen) {
                        t *= 0.5;
                        continue;
                    }
                    let tk: &[f64] = self.frozen.unwrap_or(&target.curvature);
                    let gh: f64 = (0..n)
                        .filter(|&i| !held[i])
                        .map(|i| (ev.ws.curvature[i] - tk[i]) * delta[i])
                        .sum();
                    let g0 = self.g0;
                    let de = t / 6.0 * (g0 + 4.0 * gh + gt);
                    if de <= 1e-4 * t * g0 {
                        return Some((t, Some(de)));
                    }
                }
                LineSearch::Residual => {
                    if (res_t <= (1.0 - 2e-4 * t) * self.res0 && err_t <= 2.0 * self.err) || halves
                    {
                        return Some((t, None));
                    }
                }
            }
            t *= 0.5;
        }
        None
    }
}

/// Evaluate at `u` (with targets following the metric unless `frozen`); false outside the
/// domain.
pub(super) fn eval(
    ev: &mut Evaluator,
    target: &mut Target,
    u: &[f64],
    update_targets: bool,
) -> bool {
    if !ev.evaluate(u) {
        return false;
    }
    if update_targets && target.is_dynamic() {
        target.update_round(&ev.ws.lengths, &ev.ws.dlengths, &ev.data.edges);
    }
    true
}

/// Largest |K − target| over the vertices that are not fixed.
fn max_error_against(curvature: &[f64], target: &[f64], fixed: &[bool]) -> f64 {
    curvature
        .iter()
        .zip(target)
        .zip(fixed)
        .filter(|(_, &f)| !f)
        .map(|((k, t), _)| (k - t).abs())
        .fold(0.0, f64::max)
}
