//! Triangular B-splines (DMS) and manifold splines (paper 000 §5).
//!
//! * [`simplex`] — bivariate simplex splines, their recurrence and derivatives, evaluated for a
//!   family of knot sets at once with a half-open convention that holds everywhere;
//! * [`poly`] — bivariate polynomials and their blossoms;
//! * [`dms`] — the DMS basis over a planar triangulation: knot clouds, admissibility, evaluation
//!   of splines and derivatives, control points of polynomials, B-patch blossoms;
//! * [`fit`] — paper 000's fairing by constrained least squares (fairness parameter `r`) and a
//!   least-squares fit to data with a thin-plate fairness term.

// Negated comparisons are deliberate: they also reject NaN. Index loops mirror the formulas.
#![allow(clippy::neg_cmp_op_on_partial_ord, clippy::needless_range_loop)]

pub mod dms;
pub mod fit;
pub mod poly;
pub mod simplex;
