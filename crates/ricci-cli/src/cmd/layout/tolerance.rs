//! The flow tolerance of `ricci layout`: the conformal flow's hyperbolic uniformization is
//! polished to double-double before the cut, so the flow needs to come only within the
//! polish's reach (`ricci::flow::uniformize::polished_layout_tolerance`, 1e-10 instead of
//! `layout_tolerance`'s 1e-12).

use super::Args;
use ricci::layout::pipeline::uniformization_geometry;
use ricci::mesh::Mesh;
use ricci::metric::{Geometry, Scheme};

/// The tolerance to give the flow of `mesh` (`None`: the layout's own, `layout_tolerance`): the
/// polished tolerance for the default (conformal) flow to the topology's hyperbolic target
/// when the polish runs (no `--no-polish`, `--metric`, `--target`).
pub fn flow_tolerance(a: &Args, mesh: &Mesh, geometry: Option<Geometry>) -> Option<f64> {
    let polished = !a.no_polish
        && a.metric.is_none()
        && a.target.is_none()
        && matches!(a.scheme, None | Some(Scheme::Conformal));
    let g = match geometry {
        Some(g) => g,
        None => uniformization_geometry(mesh).ok()?,
    };
    (polished && g == Geometry::Hyperbolic)
        .then(|| ricci::flow::uniformize::polished_layout_tolerance(g))
}
