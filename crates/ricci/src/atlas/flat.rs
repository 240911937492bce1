//! Step 3 of the atlas (paper 000 §4 Step 3): the flat cone metric by Euclidean Ricci flow
//! ([`crate::flow::ricci_flow`], Newton), with a fallback over the conformal schemes when the
//! requested one does not converge ([`crate::flow::flow_with_fallback`] with
//! [`UniformizationOptions::flat`]), and an iteration budget for the placement's candidates.

use crate::error::Result;
use crate::flow::{flow_with_fallback, FallbackFlow, TargetSpec, UniformizationOptions};
use crate::mesh::Mesh;
use crate::metric::{Geometry, IntrinsicMetric, Scheme};
use crate::progress::NoProgress;

/// The flat metric of `target` by Newton's method (tolerance `tolerance`, at most 400
/// iterations) with `scheme`; when that does not converge, again with inversive distance
/// and then tangential circle packing (strong cones can break Thurston's clamped packing).
/// Returns the result, the scheme used and notes.
pub fn flat_flow(
    mesh: &Mesh,
    metric: &IntrinsicMetric,
    target: TargetSpec,
    scheme: Scheme,
    tolerance: f64,
) -> Result<(crate::flow::FlowResult, Scheme, Vec<String>)> {
    let mut unlimited = usize::MAX;
    let f = flat_flow_limited(mesh, metric, target, scheme, tolerance, 400, &mut unlimited)?;
    Ok((f.result, f.scheme, f.notes))
}

/// What [`flat_flow_limited`] produced: the flow with the scheme fallback of
/// [`crate::flow::flow_with_fallback`].
pub type FlatFlow = FallbackFlow;

/// [`flat_flow`] with at most `max_iterations` Newton iterations per scheme and `budget`
/// iterations in all (the spent ones are subtracted; no further scheme is tried once it is
/// 0). The candidate flows of the automatic placement run with such a budget
/// ([`placement::PlacementOptions`]).
pub fn flat_flow_limited(
    mesh: &Mesh,
    metric: &IntrinsicMetric,
    target: TargetSpec,
    scheme: Scheme,
    tolerance: f64,
    max_iterations: usize,
    budget: &mut usize,
) -> Result<FlatFlow> {
    metric.require(Geometry::Euclidean, "the flat flow of the atlas")?;
    let opts = UniformizationOptions::flat(target, scheme, tolerance, max_iterations);
    flow_with_fallback(mesh, metric, &opts, Some(budget), &mut NoProgress)
}
