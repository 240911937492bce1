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
//! * [`curves`] — the T-mesh drawn on the surface (paper 003 Fig. 5/7), the torus tessellation;
//! * [`export`] — STEP (AP214 `B_SPLINE_SURFACE_WITH_KNOTS` faces), IGES (entity 128), OBJ;
//! * [`fit`] — paper 003 §3.3: least squares to the data points plus thin-plate fairness
//!   (conjugate gradients), adaptive refinement (1-to-4 where `L∞ > 2ε`, else 1-to-2), and the
//!   genus-1 domain from the flat metric (the flat torus *is* the conformal net for genus 1).
//!
//! What is not here yet: domains of genus 0 and ≥ 2 (they need the holomorphic 1-forms and
//! the conformal net with its zeros, paper 003 §2).

#![allow(clippy::needless_range_loop)]

pub mod basis;
pub mod bezier;
pub mod curves;
pub mod export;
pub mod fit;
pub mod surface;
pub mod tmesh;

pub use bezier::{continuity, extract, BezierPatch, Continuity};
pub use surface::{TBasis, TSpline};
pub use tmesh::{Anchor, Lattice, TMesh};
