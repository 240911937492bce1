//! The bottom layer: numerical building blocks that every stage of the pipeline may use and
//! that use nothing of the pipeline (only [`crate::error`]).
//!
//! * [`dd`] — double-double real and complex arithmetic (~32 digits), the working precision
//!   of hyperbolic layouts, deck groups, the metric polish and spline evaluation.
//! * [`sparse`] — sparse symmetric positive-definite (and indefinite) solves with faer: a
//!   symbolic factorization reused across numeric refactorizations, LU with a reused symbolic
//!   analysis, one-shot Cholesky; each leaves the vector registers clean ([`simd`]).
//! * [`simd`] — `vzeroupper` after faer's AVX kernels (called inside [`sparse`] and after the dense products of the callers).
//! * [`dijkstra`] — single- and multi-source shortest paths on a graph given by a neighbour
//!   closure, with the tie-breaking every caller relies on (smaller distance, then smaller
//!   vertex id, first).
//! * [`vec3`] — small vector helpers in R³ and Kahan's stable Heron formula ([`heron`]).

pub mod dd;
pub(crate) mod dijkstra;
pub mod float_text;
pub(crate) mod simd;
pub(crate) mod sparse;
pub mod vec3;

pub use dd::{Cdd, Dd};
pub use vec3::heron;
