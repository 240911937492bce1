//! Compatibility re-export: the sparse symmetric solver of Newton's method moved to
//! [`crate::numeric::sparse`] (the bottom layer, shared with the atlas); the path
//! `crate::flow::linear::SymmetricSolver` keeps working. `SymmetricSolver::new(&pattern)`
//! accepts a [`crate::metric::HessianPattern`] as before.

pub use crate::numeric::sparse::SymmetricSolver;
