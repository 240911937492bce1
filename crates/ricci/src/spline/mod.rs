//! Triangular B-splines (DMS) and manifold splines (paper 000 §5).
//!
//! * [`simplex`] — bivariate simplex splines, their recurrence and derivatives, evaluated for a
//!   family of knot sets at once with a half-open convention that holds everywhere;
//! * [`poly`] — bivariate polynomials and their blossoms;
//! * [`dms`] — the DMS basis over a planar triangulation: knot clouds, admissibility, evaluation
//!   of splines and derivatives, control points of polynomials, B-patch blossoms;
//! * [`space`] — [`space::SplineSpace`], what the fairing and the fit need from a spline space
//!   (implemented by [`dms::DmsSpace`] and [`manifold::ManifoldSpace`]), and evaluation of
//!   `Σ c N` on any of them;
//! * [`quadrature`] — the graded quadrature rules of the thin-plate energy;
//! * [`fit`] — paper 000's fairing by constrained least squares (fairness parameter `r`) and a
//!   least-squares fit to data with a thin-plate fairness term, generic over
//!   [`space::SplineSpace`];
//! * [`manifold`] — the same basis over a flat cone metric and its charts (paper 000 §5): knots
//!   in vertex frames, bases in home charts, chart-independent evaluation, the independent chart
//!   provider [`manifold::LocalCharts`];
//! * [`hole`] — the seam around the extraordinary point and the G¹ fill patch;
//! * [`pou`] — partition-of-unity surfaces over the hyperbolic atlas (paper 004), C∞ without
//!   extraordinary points;
//! * [`surface`] — the whole construction (subdivision, fairing, fit, fill), tessellation,
//!   errors against the input mesh and continuity measurements.
//! * [`error`] — [`SplineError`], the errors that name a parameter, vertex or face.

// Negated comparisons are deliberate: they also reject NaN. Index loops mirror the formulas.
#![allow(clippy::neg_cmp_op_on_partial_ord, clippy::needless_range_loop)]

pub mod dms;
pub(crate) mod error;
pub mod fit;
pub mod hole;
pub mod manifold;
pub mod poly;
pub mod pou;
pub mod quadrature;
pub mod simplex;
pub mod space;
pub mod surface;
pub mod tspline;

pub use error::SplineError;
