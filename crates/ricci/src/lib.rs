//! # ricci
//!
//! Discrete surface Ricci flow and the structures and splines built on it, following
//! Gu, Jin, Luo et al. (see `shared/papers` and `DESIGN.md`).
//!
//! The pipeline, one module per stage:
//!
//! * [`mesh`] — connectivity (half-edge arrays), positions, validation, topology, formats,
//!   procedural surfaces;
//! * [`metric`] — background geometries, discrete conformal schemes, curvature, Hessian;
//! * [`flow`] — target curvatures and solvers (Newton, gradient flow);
//! * [`cut`] — homotopy bases, canonical fundamental group generators, slicing;
//! * [`layout`] — isometric layouts in the plane, the Poincaré disk and the sphere, deck groups;
//! * [`atlas`] — affine atlas with one extraordinary point;
//! * [`analysis`] — distortion, geodesic spectrum;
//! * [`spline`] — triangular B-splines (DMS) and manifold splines.
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
pub mod progress;
pub mod spline;

/// Compatibility re-export: `simd` moved to [`numeric::simd`]; the path `crate::simd` keeps
/// working.
pub use numeric::simd;

pub use error::{Error, Result};
