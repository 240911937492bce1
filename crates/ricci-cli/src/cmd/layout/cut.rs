//! The cut stage of `ricci layout`: the canonical cut of the surface into a disk (polished to
//! double-double when the metric is, or when its polish was deferred to after the cut), and its
//! report (boundary word, base vertex, refinement splits, attempts, loop lengths).

use super::Bar;
use ricci::layout::pipeline::{cut_disk, cut_disk_polished, CutDisk};
use ricci::mesh::Mesh;
use ricci::metric::IntrinsicMetric;
use serde_json::{json, Value};

/// Cut `work` (metric `metric`, input positions when it is the input) into a disk; the cut's
/// numbers go into `out`, the refined mesh's polish into `polish_report`.
pub fn cut_stage(
    work: &Mesh,
    metric: &IntrinsicMetric,
    work_positions: Option<&[[f64; 3]]>,
    base: Option<u32>,
    polish_report: &mut Value,
    out: &mut Value,
    bar: &mut Bar,
) -> anyhow::Result<CutDisk> {
    bar.0.set_message("cutting along canonical loops");
    let deferred = polish_report["deferred"] == json!(true);
    let d = if metric.is_double_double() || deferred {
        let d = cut_disk_polished(work, metric, work_positions, base, bar)?;
        polish_report["refined"] = json!(d.refined_polish);
        if let (true, Some(p)) = (deferred, &d.refined_polish) {
            polish_report["steps"] = json!(p.steps);
            polish_report["residual_start"] = json!(p.residual_start);
            polish_report["residual_dd"] = json!(p.residual_dd);
            polish_report["converged"] = json!(p.converged);
        }
        d
    } else {
        cut_disk(work, metric, work_positions, base, bar)?
    };
    out["boundary_word"] = json!(d.polygon.word());
    out["base_vertex"] = json!(d.cut.base);
    out["refinement_splits"] = json!(d.cut.report.refinement_splits);
    out["cut_attempts"] = json!(d.cut.report.attempts);
    out["cut_failed_attempts"] = json!(d.cut.report.failed_attempts);
    out["loop_lengths"] = json!(d
        .cut
        .loops
        .iter()
        .map(|l| json!({"label": l.label, "length": l.length}))
        .collect::<Vec<_>>());
    Ok(d)
}
