//! # ricci
//!
//! Discrete surface Ricci flow and the structures and splines built on it, following
//! Gu, Jin, Luo et al. (see `shared/papers` and `docs/DESIGN.md`).
//!
//! The pipeline, one module per stage, each using only the stages before it:
//!
//! ```text
//! numeric < mesh < metric < flow < cut < layout ≈ analysis < atlas < spline
//! ```
//!
//! * [`numeric`] — the bottom layer, used by every stage and using none: double-double
//!   arithmetic, the faer wrappers for sparse solves and dense products (with the
//!   vector-register hygiene of [`numeric::simd`] inside them), one Dijkstra, R³ helpers and
//!   Heron's formula;
//! * [`mesh`] — connectivity (half-edge arrays), positions, validation, topology, formats,
//!   procedural surfaces;
//! * [`metric`] — background geometries, discrete conformal schemes, curvature, Hessian,
//!   intrinsic refinement (edge splits and flips that keep the metric);
//! * [`flow`] — target curvatures and solvers (Newton, gradient flow);
//! * [`cut`] — homotopy bases, canonical fundamental group generators, slicing;
//! * [`layout`] — isometric layouts in the plane, the Poincaré disk and the sphere, deck groups;
//! * [`analysis`] — distortion, geodesic spectrum (beside `layout`: it uses it);
//! * [`atlas`] — affine atlas with one extraordinary point;
//! * [`param`] — conformal UV maps with cones and seams (beside `atlas`);
//! * [`spline`] — triangular B-splines (DMS) and manifold splines.
//!
//! [`error`] and [`progress`] are utilities every module may use. The order is checked by
//! `tests/layers.rs` (every `crate::…` path of every source file). Every item has one path:
//! the compatibility re-exports of the old layout are gone (`Dd`, `Cdd` and `simd` are in
//! [`numeric`], intrinsic refinement in [`metric::refine`], the spline-space interface in
//! [`spline::space`] and the quadrature rules in [`spline::quadrature`]).
//!
//! Connectivity, metric and embedding are separate types: a [`mesh::Mesh`] knows who is next
//! to whom, edge lengths live in plain `Vec<f64>` indexed by edge id, and positions live in a
//! [`mesh::Surface`].

pub mod analysis;
pub mod atlas;
pub mod cut;
pub mod error;
pub mod flow;
pub mod layout;
pub mod mesh;
pub mod metric;
pub mod numeric;
pub mod param;
pub mod progress;
pub mod spline;

pub use error::{Error, Result};
