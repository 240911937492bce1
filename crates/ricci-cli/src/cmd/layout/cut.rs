//! The cut stage of `ricci layout`: the canonical cut of the surface into a disk (its refined
//! metric checked, and polished if needed, in double-double when the metric is), and its
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
    let d = if metric.is_double_double() {
        let d = cut_disk_polished(work, metric, work_positions, base, bar)?;
        polish_report["refined"] = json!(d.refined_polish);
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
