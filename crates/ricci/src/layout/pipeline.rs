//! The whole chain used by `ricci layout` and `ricci spectrum`: a surface with a metric →
//! canonical cut ([`crate::cut`]) → cut mesh with the metric carried over → layout in the
//! model space of its geometry → side pairings and deck generators.
//!
//! The uniformization metric itself comes from [`crate::flow`] ([`uniformization_metric`]:
//! E² for genus 1, H² for genus ≥ 2, S² for closed genus 0; the flat free-boundary metric for
//! disks), or from the caller.

use super::deck::Polygon;
use crate::cut::{canonical_cut, CanonicalCut, CutOptions};
use crate::error::{Error, Result};
use crate::flow::{ricci_flow, FlowOptions, FlowResult, TargetSpec};
use crate::mesh::{topology, Mesh};
use crate::metric::{Geometry, Scheme};
use crate::progress::Progress;

/// The geometry of the uniformization metric of a connected surface: S² for closed genus 0,
/// E² for genus 1 and for disks, H² otherwise.
pub fn uniformization_geometry(mesh: &Mesh) -> Result<Geometry> {
    let t = topology(mesh);
    if t.components.len() != 1 {
        return Err(Error::topology(format!(
            "the surface has {} components; lay out one at a time",
            t.components.len()
        )));
    }
    let c = &t.components[0];
    Ok(match (c.genus, c.boundary_loops) {
        (0, 0) => Geometry::Spherical,
        (0, 1) | (1, 0) => Geometry::Euclidean,
        _ => Geometry::Hyperbolic,
    })
}

/// Run the uniformization flow (Newton, conformal scheme `scheme` — the papers use Thurston
/// circle packing — tolerance `tolerance`) with the
/// target that suits the topology: `uniform` for closed surfaces, `free-boundary` for disks in
/// E², `geodesic-boundary` for other bordered surfaces in H².
pub fn uniformization_metric(
    mesh: &Mesh,
    lengths: &[f64],
    geometry: Geometry,
    scheme: Scheme,
    tolerance: f64,
    progress: &mut dyn Progress,
) -> Result<FlowResult> {
    let bordered = mesh.has_boundary();
    let target = match (geometry, bordered) {
        (_, false) => TargetSpec::Uniform,
        (Geometry::Hyperbolic, true) => TargetSpec::GeodesicBoundary,
        (_, true) => TargetSpec::FreeBoundary,
    };
    let opts = FlowOptions {
        geometry,
        scheme,
        target,
        tolerance,
        ..FlowOptions::default()
    };
    ricci_flow(mesh, lengths, &opts, progress)
}

/// A surface cut open into a disk, with the metric on the cut mesh.
#[derive(Debug, Clone)]
pub struct CutDisk {
    /// The cut mesh (faces keep the ids of the refined mesh).
    pub mesh: Mesh,
    /// Edge lengths of the cut mesh.
    pub lengths: Vec<f64>,
    /// For every cut-mesh vertex, the vertex of the (refined) surface it is a copy of.
    pub vertex_origin: Vec<u32>,
    /// The fundamental polygon (sides read from the cut mesh).
    pub polygon: Polygon,
    /// What the cut computed (refined mesh and metric, loops, report).
    pub cut: CanonicalCut,
}

/// Cut a surface with metric `lengths` (in `geometry`) along a canonical system of loops
/// through `base` (or an automatic base vertex) and carry the metric to the cut mesh.
pub fn cut_disk(
    mesh: &Mesh,
    lengths: &[f64],
    geometry: Geometry,
    positions: Option<&[[f64; 3]]>,
    base: Option<u32>,
    progress: &mut dyn Progress,
) -> Result<CutDisk> {
    let opts = CutOptions {
        base,
        ..CutOptions::default()
    };
    let cut = canonical_cut(mesh, lengths, geometry, positions, &opts, progress)?;
    let refined = &cut.refined;
    let cm = cut.cut_mesh.clone();
    let mut cl = vec![0.0; cm.n_edges()];
    for h in 0..cm.n_corners() as u32 {
        cl[cm.he_edge(h) as usize] = refined.lengths[refined.mesh.he_edge(h) as usize];
    }
    let polygon = Polygon::from_labelled(
        cut.polygon
            .iter()
            .map(|s| (s.label.clone(), s.vertices.clone()))
            .collect(),
    )?;
    Ok(CutDisk {
        mesh: cm,
        lengths: cl,
        vertex_origin: cut.cut_vertex_origin.clone(),
        polygon,
        cut,
    })
}
