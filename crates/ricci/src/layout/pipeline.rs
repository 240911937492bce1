//! The whole chain used by `ricci layout` and `ricci spectrum`: a surface with a metric →
//! canonical cut ([`crate::cut`]) → cut mesh with the metric carried over → layout in the
//! model space of its geometry → side pairings and deck generators.
//!
//! The uniformization metric itself comes from [`crate::flow`] ([`uniformization_metric`]:
//! E² for genus 1, H² for genus ≥ 2, S² for closed genus 0; the flat free-boundary metric for
//! disks), or from the caller.
//!
//! **H²: metric polished to double-double before the layout** (on by default in
//! `ricci layout` and `ricci spectrum`): [`polish_uniformization`] refines the flow's `u` by
//! iterative refinement with a double-double curvature residual ([`crate::flow::polish`],
//! from ~5e-15 to ~1e-30), and [`cut_disk_polished`] carries the double-double lengths
//! through the cut: the cut's refinement computes the lengths of split and new edges in
//! double-double too ([`crate::metric::refine::split_side_dd`], Stewart's theorem), so the
//! refined metric is as converged as its input; its double-double curvature is checked
//! ([`crate::flow::polish::max_curvature_dd`]) and only when it is above the polish tolerance
//! (a double-precision input) is it polished in place by vertex scaling
//! (`sinh(l/2) = e^{(ui+uj)/2} sinh(l⁰/2)`, target 0 on every vertex — new vertices are
//! flat). The cut mesh then carries an [`IntrinsicMetric`] with low parts, which
//! [`super::place::layout_dd`] uses. The deck maps computed
//! from different edges of a side then agree to the double-double layout's own accuracy
//! instead of ~κ·sinh r with κ ≈ 5e-15 (BENCHMARKS.md, Layout).

use super::deck::Polygon;
use crate::cut::{canonical_cut, CanonicalCut, Construction, CutOptions};
use crate::error::{Error, Result};
use crate::flow::polish::{max_curvature_dd, polish_metric, PolishSettings, PolishedMetric};
use crate::flow::{flow_with_fallback, FlowResult, UniformizationOptions};
use crate::mesh::Mesh;
use crate::metric::{ConformalStructure, Geometry, IntrinsicMetric, Scheme};
use crate::progress::Progress;

pub use crate::flow::uniformize::uniformization_geometry;

/// Run the uniformization flow (Newton, conformal scheme `scheme` — the papers use Thurston
/// circle packing — tolerance `tolerance`) with the
/// target that suits the topology: `uniform` for closed surfaces, `free-boundary` for disks in
/// E², `geodesic-boundary` for other bordered surfaces in H² ([`crate::flow::uniformize`]).
pub fn uniformization_metric(
    mesh: &Mesh,
    metric: &IntrinsicMetric,
    geometry: Geometry,
    scheme: Scheme,
    tolerance: f64,
    progress: &mut dyn Progress,
) -> Result<FlowResult> {
    metric.require(Geometry::Euclidean, "the uniformization flow")?;
    let opts = UniformizationOptions::single(Some(geometry), scheme, tolerance);
    Ok(flow_with_fallback(mesh, metric, &opts, None, progress)?.result)
}

/// A surface cut open into a disk, with the metric on the cut mesh.
#[derive(Debug, Clone)]
pub struct CutDisk {
    /// The cut mesh (faces keep the ids of the refined mesh).
    pub mesh: Mesh,
    /// The metric on the cut mesh (edge lengths by cut-mesh edge id), with low parts
    /// (double-double) after [`cut_disk_polished`], without after [`cut_disk`].
    pub metric: IntrinsicMetric,
    /// What the polish of the refined metric did ([`cut_disk_polished`]).
    pub refined_polish: Option<PolishReport>,
    /// For every cut-mesh vertex, the vertex of the (refined) surface it is a copy of.
    pub vertex_origin: Vec<u32>,
    /// The fundamental polygon (sides read from the cut mesh).
    pub polygon: Polygon,
    /// What the cut computed (refined mesh and metric, loops, report).
    pub cut: CanonicalCut,
}

/// Cut a surface with `metric` along a canonical system of loops
/// through `base` (or an automatic base vertex) and carry the metric to the cut mesh.
pub fn cut_disk(
    mesh: &Mesh,
    metric: &IntrinsicMetric,
    positions: Option<&[[f64; 3]]>,
    base: Option<u32>,
    progress: &mut dyn Progress,
) -> Result<CutDisk> {
    // Short loops keep the hyperbolic fundamental polygon compact (see
    // `Construction::GreedyThenCutAndPaste`).
    let opts = CutOptions {
        base,
        construction: Construction::GreedyThenCutAndPaste,
        ..CutOptions::default()
    };
    let cut = canonical_cut(mesh, metric, positions, &opts, progress)?;
    let refined = &cut.refined;
    let cm = cut.cut_mesh.clone();
    let metric = IntrinsicMetric::new(metric.geometry(), refined.lengths.clone())
        .carried_to(&refined.mesh, &cm);
    let polygon = Polygon::from_labelled(
        cut.polygon
            .iter()
            .map(|s| (s.label.clone(), s.vertices.clone()))
            .collect(),
    )?;
    Ok(CutDisk {
        mesh: cm,
        metric,
        refined_polish: None,
        vertex_origin: cut.cut_vertex_origin.clone(),
        polygon,
        cut,
    })
}

/// What a double-double polish did (for reports).
#[derive(Debug, Clone, Copy, serde::Serialize)]
pub struct PolishReport {
    /// Refinement steps.
    pub steps: usize,
    /// Max |K − K̄| in double-double before and after.
    pub residual_start: f64,
    pub residual_dd: f64,
    pub converged: bool,
}

impl From<&PolishedMetric> for PolishReport {
    fn from(p: &PolishedMetric) -> PolishReport {
        PolishReport {
            steps: p.steps,
            residual_start: p.residual_start,
            residual_dd: p.residual_dd,
            converged: p.converged,
        }
    }
}

/// Polish a hyperbolic uniformization flow (`flow`, run on `mesh` with Euclidean input
/// `lengths`) to double-double ([`crate::flow::polish`]): the conformal structure is rebuilt
/// from the same inputs (it is deterministic), and `u` is refined until the double-double
/// curvature residual is ≤ 1e-26 (at most 4 steps). Errors: not H², a target other than 0
/// (uniform / geodesic boundary), a flow that did not converge.
pub fn polish_uniformization(
    mesh: &Mesh,
    metric: &IntrinsicMetric,
    flow: &FlowResult,
) -> Result<PolishedMetric> {
    metric.require(Geometry::Euclidean, "the polish of a uniformization flow")?;
    if flow.geometry != Geometry::Hyperbolic {
        return Err(Error::input(format!(
            "only hyperbolic metrics are polished, this one is {}",
            flow.geometry
        )));
    }
    if !flow.converged {
        return Err(Error::numerical(format!(
            "the flow did not converge (max curvature error {:.3e}); nothing to polish",
            flow.max_curvature_error
        )));
    }
    if let Some(t) = &flow.triangulation {
        // A conformal flow's metric lives on its intrinsic triangulation: polish it there in
        // place (new vertices of the splits are flat, so the target is 0 everywhere).
        if flow.fixed.iter().any(|&f| f) || flow.target.iter().any(|&k| k != 0.0) {
            return Err(Error::input(
                "the metric has cone points or a fixed boundary; only uniform hyperbolic \
                 metrics are polished",
            ));
        }
        let m = &t.simplicial.mesh;
        return polish_lengths(m, &flow.metric());
    }
    let structure =
        ConformalStructure::new(mesh, metric, flow.geometry, flow.scheme, flow.input_scale)?;
    polish_metric(
        mesh,
        &structure,
        None,
        &flow.u,
        &flow.target,
        &flow.fixed,
        &PolishSettings::default(),
    )
}

/// Polish a hyperbolic metric with zero target curvature (to double-double, or double
/// precision: missing low parts are 0) in place by vertex scaling (see the module docs);
/// returns the polished metric.
pub fn polish_lengths(mesh: &Mesh, metric: &IntrinsicMetric) -> Result<PolishedMetric> {
    use crate::numeric::dd::Dd;
    if metric.geometry() != Geometry::Hyperbolic {
        return Err(Error::input(format!(
            "only hyperbolic metrics are polished, this one is {}",
            metric.geometry()
        )));
    }
    let ne = mesh.n_edges();
    if metric.len() != ne {
        return Err(Error::input(format!(
            "{} lengths and {} low parts for a mesh with {ne} edges",
            metric.len(),
            metric.lengths_lo().map_or(0, <[f64]>::len)
        )));
    }
    let mut eta = Vec::with_capacity(ne);
    let mut eta_lo = Vec::with_capacity(ne);
    for e in 0..ne {
        let x = (metric.length_dd(e) * Dd::new(0.5)).sinh();
        eta.push(x.hi);
        eta_lo.push(x.lo);
    }
    let nv = mesh.n_vertices();
    let structure = ConformalStructure {
        geometry: Geometry::Hyperbolic,
        scheme: Scheme::Yamabe,
        eta,
        u0: vec![0.0; nv],
        input_scale: 1.0,
        clamped_edges: 0,
        initial_length_error: 0.0,
    };
    polish_metric(
        mesh,
        &structure,
        Some(&eta_lo),
        &vec![0.0; nv],
        &vec![0.0; nv],
        &vec![false; nv],
        &PolishSettings::default(),
    )
}

/// [`cut_disk`] for a double-double H² metric with zero target curvature (e.g. the `metric`
/// of [`polish_uniformization`]; missing low parts are 0): the cut runs on the leading parts
/// and computes the refined lengths in double-double from the input's; when the cut refined
/// the mesh, the refined metric's double-double curvature is checked and, if above the
/// polish tolerance (or the metric has no low parts: a double-precision uniform metric,
/// polished here once), it is polished in place ([`polish_lengths`]) before it is carried to
/// the cut mesh. [`CutDisk::refined_polish`] reports either (0 steps when only checked).
pub fn cut_disk_polished(
    mesh: &Mesh,
    metric: &IntrinsicMetric,
    positions: Option<&[[f64; 3]]>,
    base: Option<u32>,
    progress: &mut dyn Progress,
) -> Result<CutDisk> {
    if metric.geometry() != Geometry::Hyperbolic {
        return Err(Error::input(format!(
            "only hyperbolic metrics are cut in double-double, this one is {}",
            metric.geometry()
        )));
    }
    if metric.len() != mesh.n_edges() {
        return Err(Error::input(format!(
            "{} low parts of lengths for a mesh with {} edges",
            metric.len(),
            mesh.n_edges()
        )));
    }
    let mut disk = cut_disk(mesh, metric, positions, base, progress)?;
    let refined = &disk.cut.refined;
    let rm = &refined.mesh;
    let rlo = match &refined.lengths_lo {
        Some(lo) => lo.clone(),
        None => vec![0.0; rm.n_edges()],
    };
    let refined_metric =
        IntrinsicMetric::with_low_parts(Geometry::Hyperbolic, refined.lengths.clone(), rlo)?;
    let tolerance = PolishSettings::default().tolerance;
    let refined_metric = if refined.splits() == 0 && metric.is_double_double() {
        refined_metric
    } else {
        // Split in double-double from a polished metric, the refined metric is as converged
        // as its input: check, and polish only when it is not.
        let start = if refined.lengths_lo.is_some() {
            Some(max_curvature_dd(rm, &refined_metric)?)
        } else {
            None
        };
        match start {
            Some(r) if r <= tolerance => {
                disk.refined_polish = Some(PolishReport {
                    steps: 0,
                    residual_start: r,
                    residual_dd: r,
                    converged: true,
                });
                refined_metric
            }
            _ => {
                progress.report(
                    "polish",
                    None,
                    "polishing the refined metric in double-double",
                );
                let p = polish_lengths(rm, &refined_metric)?;
                disk.refined_polish = Some(PolishReport::from(&p));
                p.metric
            }
        }
    };
    disk.metric = refined_metric.carried_to(rm, &disk.mesh);
    Ok(disk)
}
