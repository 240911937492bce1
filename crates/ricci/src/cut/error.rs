//! The cut stage's errors with their data ([`CutError`]): a base vertex that does not exist
//! or lies on the boundary, a base vertex through which no canonical system was found, a
//! path that is not simple or not on the surface. They convert into
//! [`crate::Error::Stage`] with the same sentence as before; [`crate::Error::stage_error`]
//! gives the enum back, so a caller can point at the vertex without parsing the message.

use std::fmt;

use crate::error::{Error, Kind, StageError};

/// An error of the cut stage, with the vertex it is about.
#[derive(Debug, Clone, PartialEq, Eq)]
#[non_exhaustive]
pub enum CutError {
    /// The base vertex `vertex` is not below `n_vertices`.
    BaseVertexMissing { vertex: u32, n_vertices: usize },
    /// The base vertex `vertex` is on the boundary (the loops need an interior vertex).
    BaseVertexOnBoundary { vertex: u32 },
    /// No canonical system of loops through `vertex` was found after `attempts` attempts;
    /// `reason` is why the last one failed.
    NoCanonicalSystem {
        vertex: u32,
        attempts: usize,
        reason: String,
    },
    /// A path names vertex `vertex`, which is not below `n_vertices`.
    PathVertexMissing { vertex: u32, n_vertices: usize },
    /// Consecutive path vertices `from` and `to` are not joined by an edge.
    PathNotAnEdge { from: u32, to: u32 },
    /// The path passes vertex `vertex` twice (its next edge does not leave `vertex`).
    PathNotSimple { vertex: u32 },
}

impl CutError {
    /// The vertex the error is about.
    pub fn vertex(&self) -> u32 {
        match self {
            CutError::BaseVertexMissing { vertex, .. }
            | CutError::BaseVertexOnBoundary { vertex }
            | CutError::NoCanonicalSystem { vertex, .. }
            | CutError::PathVertexMissing { vertex, .. }
            | CutError::PathNotSimple { vertex } => *vertex,
            CutError::PathNotAnEdge { from, .. } => *from,
        }
    }
}

impl fmt::Display for CutError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            CutError::BaseVertexMissing { vertex, n_vertices } => write!(
                f,
                "base vertex {vertex} does not exist (the mesh has {n_vertices} vertices)"
            ),
            CutError::BaseVertexOnBoundary { vertex } => write!(
                f,
                "base vertex {vertex} lies on the boundary; choose an interior vertex"
            ),
            CutError::NoCanonicalSystem {
                vertex,
                attempts,
                reason,
            } => write!(
                f,
                "no canonical system through vertex {vertex} was found after {attempts} \
                 attempts ({reason}); try another base vertex or a larger --min-valence"
            ),
            CutError::PathVertexMissing { vertex, n_vertices } => write!(
                f,
                "path vertex {vertex} does not exist (the mesh has {n_vertices} vertices)"
            ),
            CutError::PathNotAnEdge { from, to } => {
                write!(f, "path vertices {from} and {to} are not joined by an edge")
            }
            CutError::PathNotSimple { vertex } => write!(
                f,
                "the path is not simple at vertex {vertex} (its next edge does not leave \
                 {vertex})"
            ),
        }
    }
}

impl std::error::Error for CutError {}

impl StageError for CutError {
    fn kind(&self) -> Kind {
        match self {
            CutError::NoCanonicalSystem { .. } => Kind::Numerical,
            _ => Kind::InvalidInput,
        }
    }
}

impl From<CutError> for Error {
    fn from(e: CutError) -> Self {
        Error::stage(e)
    }
}
