//! Background geometries, discrete conformal schemes, curvature and Hessian (paper 001 §IV–V).

pub mod geometry;

pub use geometry::{Background, Euclidean, Geometry, Hyperbolic, Spherical};
