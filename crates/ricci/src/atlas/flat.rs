//! Step 3 of the atlas (paper 000 §4 Step 3): the flat cone metric by Euclidean Ricci flow
//! ([`crate::flow::ricci_flow`], Newton), with a fallback over the conformal schemes when the
//! requested one does not converge, and an iteration budget for the placement's candidates.

use crate::error::{Error, Result};
use crate::flow::{ricci_flow, FlowOptions, TargetSpec};
use crate::mesh::Mesh;
use crate::metric::{Geometry, Scheme};

/// The flat metric of `target` by Newton's method (tolerance `tolerance`, at most 400
/// iterations) with `scheme`; when that does not converge, again with inversive distance
/// and then tangential circle packing (strong cones can break Thurston's clamped packing).
/// Returns the result, the scheme used and notes.
pub fn flat_flow(
    mesh: &Mesh,
    lengths: &[f64],
    target: TargetSpec,
    scheme: Scheme,
    tolerance: f64,
) -> Result<(crate::flow::FlowResult, Scheme, Vec<String>)> {
    let mut unlimited = usize::MAX;
    let f = flat_flow_limited(
        mesh,
        lengths,
        target,
        scheme,
        tolerance,
        400,
        &mut unlimited,
    )?;
    Ok((f.result, f.scheme, f.notes))
}

/// What [`flat_flow_limited`] produced.
#[derive(Debug, Clone)]
pub struct FlatFlow {
    /// The converged flow, or the last one that ran when none converged.
    pub result: crate::flow::FlowResult,
    /// The scheme of `result`.
    pub scheme: Scheme,
    pub notes: Vec<String>,
    /// Newton iterations of all the schemes tried together.
    pub iterations: usize,
    /// The smallest max |K − K̄| any scheme reached.
    pub best_error: f64,
}

/// [`flat_flow`] with at most `max_iterations` Newton iterations per scheme and `budget`
/// iterations in all (the spent ones are subtracted; no further scheme is tried once it is
/// 0). The candidate flows of the automatic placement run with such a budget
/// ([`placement::PlacementOptions`]).
pub fn flat_flow_limited(
    mesh: &Mesh,
    lengths: &[f64],
    target: TargetSpec,
    scheme: Scheme,
    tolerance: f64,
    max_iterations: usize,
    budget: &mut usize,
) -> Result<FlatFlow> {
    let mut notes = Vec::new();
    let mut schemes = vec![scheme];
    for s in [Scheme::Inversive, Scheme::Tangential] {
        if !schemes.contains(&s) {
            schemes.push(s);
        }
    }
    let mut last = None;
    let mut iterations = 0;
    let mut best_error = f64::INFINITY;
    for (k, &s) in schemes.iter().enumerate() {
        if *budget == 0 {
            notes.push(format!(
                "the iteration budget was spent before the {} scheme could run",
                s.name()
            ));
            break;
        }
        let run = ricci_flow(
            mesh,
            lengths,
            &FlowOptions {
                geometry: Geometry::Euclidean,
                scheme: s,
                target: target.clone(),
                tolerance,
                max_iterations: Some(max_iterations.min(*budget).max(1)),
                ..FlowOptions::default()
            },
            &mut crate::progress::NoProgress,
        );
        if let Ok(f) = &run {
            *budget = budget.saturating_sub(f.iterations.max(1));
        }
        match run {
            Ok(f) if f.converged => {
                if k > 0 {
                    notes.push(format!(
                        "the {} flow did not converge; the metric comes from the {} scheme",
                        scheme.name(),
                        s.name()
                    ));
                }
                notes.extend(f.notes.iter().cloned());
                iterations += f.iterations;
                best_error = best_error.min(f.max_curvature_error);
                return Ok(FlatFlow {
                    result: f,
                    scheme: s,
                    notes,
                    iterations,
                    best_error,
                });
            }
            Ok(f) => {
                notes.push(format!(
                    "{} flow: max |K − K̄| = {:.3e} after {} iterations (not converged)",
                    s.name(),
                    f.max_curvature_error,
                    f.iterations
                ));
                iterations += f.iterations;
                if f.max_curvature_error.is_finite() {
                    best_error = best_error.min(f.max_curvature_error);
                }
                last = Some(Ok((f, s)));
            }
            Err(e) => {
                if k == 0 {
                    // A refused target (Gauss–Bonnet, Chow–Luo) is refused by every scheme.
                    if matches!(e, Error::InvalidInput { .. }) {
                        return Err(e);
                    }
                }
                notes.push(format!("{} flow failed: {e}", s.name()));
                if last.is_none() {
                    last = Some(Err(e));
                }
            }
        }
    }
    match last {
        Some(Ok((f, s))) => {
            notes.extend(f.notes.iter().cloned());
            Ok(FlatFlow {
                result: f,
                scheme: s,
                notes,
                iterations,
                best_error,
            })
        }
        Some(Err(e)) => Err(e),
        None => Err(Error::numerical("no flow was run")),
    }
}
