//! Cubic T-splines over the flat torus and their export to CAD (paper 003 §3; Sederberg,
//! Zheng, Bakenov, Nasri 2003 and Sederberg et al. 2004 for knot intervals and local knot
//! vectors; Li, Zheng, Sederberg, Hughes, Scott 2012 for analysis suitability).
//!
//! * [`tmesh`] — periodic T-meshes (faces, T-junctions, inferred local knot vectors, T-junction
//!   extensions, analysis-suitability check and closure, local refinement);
//! * [`basis`] — the cubic B-spline of five knots with derivatives;
//! * [`surface`] — blending functions `B_i = N[u⃗_i](u) N[v⃗_i](v)` summed over lattice
//!   translates, T-spline surfaces with derivatives up to order two;
//! * [`bezier`] — Bézier extraction to bicubic patches, continuity across patch sides;
//! * [`bezier_elements`] — the Bézier elements (maximal rectangles on which the spline is one
//!   polynomial) from a finer grid of patches, for every genus's export;
//! * [`correction`] — parameter correction (feet of perpendiculars) between fits;
//! * [`cylinders`] — genus ≥ 2: the cylinders cut out by the critical horizontal trajectories
//!   of a holomorphic 1-form with integer imaginary periods (paper 003 §2, Fig. 2);
//! * [`charts`] — chart independence: the spline in the charts `p + λ` of the universal cover;
//! * [`curves`] — the T-mesh drawn on the surface (paper 003 Fig. 5/7), the torus tessellation;
//! * [`export`] — STEP (AP214 `B_SPLINE_SURFACE_WITH_KNOTS` faces), IGES (entity 128), OBJ;
//! * [`fit`] — paper 003 §3.3: least squares to the data points plus thin-plate fairness
//!   (conjugate gradients), adaptive refinement (1-to-4 where `L∞ > 2ε`, else 1-to-2), and the
//!   genus-1 domain from the flat metric (the flat torus *is* the conformal net for genus 1).
//!
//! * [`genus0`] — genus 0, closed or with boundary loops: the flat torus of the double of an
//!   annulus (loops filled, one face cut at each of two poles), the data on half of it;
//! * [`half`] — that half (the strip between the seams): the control points that influence
//!   the surface, the Bézier patches clipped to it for export.
//!
//! * [`domain_mesh`] — genus ≥ 2: one conforming quad mesh of knot intervals over all the
//!   strips glued by translations (the zeros its only irregular vertices) and its spline,
//!   C² on every cell side not incident to a zero and G¹ at the zeros for the nets that keep
//!   its linear conditions there, graded towards the zeros for local refinement, the graded
//!   lines ending in T-junctions past the zeros' corner blocks (`domain_mesh::TJunctions`:
//!   an analysis-suitable T-mesh whose blending functions are folded into the reduction);
//!   [`domain_fit`] fits on it (`ricci tspline`'s default for genus ≥ 2; the per-cylinder
//!   [`cylinder_fit`] is the `--per-cylinder` option); [`domain_continuity`] measures its
//!   derivative jumps and the normals' angle at the zeros across every cell side.
//!
//! Surfaces with boundary loops of genus ≥ 1 use the domain of the surface with its loops
//! filled by fans ([`genus0::fill_boundary_loops`]; the fills carry no data). What is not here
//! yet: for genus ≥ 2, refinement away from the zeros by local blocks (it refines the whole
//! mesh there); T-junctions are only where the grading towards the zeros ends.

#![allow(clippy::needless_range_loop)]

pub(crate) mod basis;
pub(crate) mod bezier;
pub mod bezier_elements;
pub(crate) mod charts;
pub(crate) mod correction;
pub mod curves;
pub mod cylinder_fit;
pub mod cylinder_jumps;
pub mod cylinders;
pub mod domain_continuity;
pub mod domain_fit;
pub mod domain_mesh;
pub mod export;
pub mod fit;
pub mod genus0;
pub mod genus_domain;
pub mod glue;
pub mod half;
pub(crate) mod surface;
pub(crate) mod system;
pub(crate) mod tmesh;

pub use bezier::{continuity, extract, extract_elements, BezierPatch, Continuity};
pub use bezier_elements::MergeStats;
pub use charts::{chart_independence, ChartIndependence};
pub use surface::{TBasis, TSpline};
pub use tmesh::{Anchor, Lattice, TMesh};
