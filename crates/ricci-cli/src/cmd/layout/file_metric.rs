//! What a metric read with `--metric` says of itself (issue 15, "fix on the way": a metric
//! whose flow did not converge gave a broken layout with exit 0 and nothing on stderr, and a
//! spectrum that searched for minutes). A file whose flow wrote `"converged": false` is refused
//! when it is read ([`ricci::metric::file::MetricFile::check_usable`]); a file that does not
//! say (hand-made, or its flags removed) is checked here against its own lengths: the
//! curvature `K` at the interior vertices, recomputed from them.

use ricci::mesh::Mesh;
use ricci::metric::Geometry;
use serde_json::Value;

/// Interior curvature above this is not a flat (E²) / hyperbolic (H²) metric at that vertex
/// (a flow that converged wrote it to its tolerance, `1e-10` by default).
pub const CURVED: f64 = 1e-8;

/// The largest `|K|` at an interior vertex of `lengths` on `mesh`, and the vertex.
pub fn interior_curvature(mesh: &Mesh, g: Geometry, lengths: &[f64]) -> (f64, Option<u32>) {
    let k = ricci::metric::curvature(mesh, g, lengths);
    let mut best = (0.0f64, None);
    for (v, &x) in k.iter().enumerate() {
        let v = v as u32;
        if mesh.is_isolated(v) || mesh.is_boundary_vertex(v) {
            continue;
        }
        if x.is_nan() || x.abs() > best.0 {
            best = (x.abs(), Some(v));
        }
    }
    best
}

/// The `metric` report's entries for a file metric: its flow's flag and its own curvature.
pub fn report(report: &mut Value, converged: Option<bool>, k: (f64, Option<u32>)) {
    report["converged"] = serde_json::json!(converged);
    report["max_interior_curvature"] = serde_json::json!(k.0);
    report["max_interior_curvature_vertex"] = serde_json::json!(k.1);
}

/// The interior curvature and its vertex from a `metric` report, when it came from a file and
/// is above [`CURVED`].
fn curved(report: &Value) -> Option<(f64, u64)> {
    let k = report["max_interior_curvature"].as_f64()?;
    let v = report["max_interior_curvature_vertex"].as_u64()?;
    (k.is_nan() || k > CURVED).then_some((k, v))
}

/// `ricci layout`'s warning for a file metric that is curved at an interior vertex and whose
/// file does not say its flow converged (a cone metric a flow wrote says so, and is laid out
/// without a warning).
pub fn layout_warning(report: &Value) -> Option<String> {
    if report["converged"].as_bool() == Some(true) {
        return None;
    }
    let (k, v) = curved(report)?;
    Some(format!(
        "{}: the file does not say that its flow converged, and its metric has curvature \
         |K| = {k:.3e} at interior vertex {v}: unless that vertex is a cone you asked for, the \
         layout will have flipped faces and a deck group that does not close (run `ricci flow` \
         until it reports \"converged\": true)",
        report["source"].as_str().unwrap_or("the metric file")
    ))
}

/// `ricci spectrum`'s refusal of a file metric that is not the uniformization (curved at an
/// interior vertex, whatever its file says): its lengths would not be the surface's.
pub fn spectrum_refusal(report: &Value) -> Option<String> {
    let (k, v) = curved(report)?;
    Some(format!(
        "{}: this metric has curvature |K| = {k:.3e} at interior vertex {v} (a spectrum needs \
         the uniformization, K = 0 at every vertex to {CURVED:e}); run `ricci flow` with the \
         default target until it reports \"converged\": true",
        report["source"].as_str().unwrap_or("the metric file")
    ))
}
