//! The spline stage's errors with their data ([`SplineError`]): a degree, knot spread or
//! fairness parameter out of range, a singular vertex that does not exist, a face of the
//! spline's hole, a boundary that folds back at a vertex, a T-mesh that stays not
//! analysis-suitable within its budget. They convert into [`crate::Error::Stage`] with the
//! same sentence as before; [`crate::Error::stage_error`] gives the enum back.

use std::fmt;

use crate::error::{Error, Kind, StageError};

/// An error of the spline stage, with the parameter, vertex or face it is about.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub enum SplineError {
    /// The `spline` ("DMS" or "manifold") spline does not support `degree`; it supports
    /// `min..=max`.
    DegreeUnsupported {
        spline: &'static str,
        degree: usize,
        min: usize,
        max: usize,
    },
    /// The knot spread `spread` is outside (0, 0.45].
    KnotSpread { spread: f64 },
    /// The fairness parameter `r` is not below the degree `degree` (`0 ≤ r ≤ n − 1`).
    FairnessOutOfRange { r: usize, degree: usize },
    /// The singular vertex `vertex` of the charts is not below `n_vertices`.
    SingularVertexMissing { vertex: u32, n_vertices: usize },
    /// Face `face` is incident to a singular vertex: the spline is not defined there.
    FaceInHole { face: u32 },
    /// The boundary of the spline domain folds back on itself at vertex `vertex`.
    BoundaryFolds { vertex: u32 },
    /// After `budget` extensions the T-mesh still has `remaining` intersecting T-junction
    /// extensions.
    NotAnalysisSuitable { budget: usize, remaining: usize },
}

impl fmt::Display for SplineError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            SplineError::DegreeUnsupported {
                spline,
                degree,
                min,
                max,
            } => write!(
                f,
                "{spline} spline degree {degree} is not supported ({min}..={max})"
            ),
            SplineError::KnotSpread { spread } => {
                write!(f, "knot spread {spread} is outside (0, 0.45]")
            }
            SplineError::FairnessOutOfRange { r, degree } => write!(
                f,
                "fairness parameter r = {r} must be between 0 and n − 1 = {}",
                *degree as i64 - 1
            ),
            SplineError::SingularVertexMissing { vertex, .. } => {
                write!(
                    f,
                    "manifold spline: singular vertex {vertex} does not exist"
                )
            }
            SplineError::FaceInHole { face } => write!(
                f,
                "manifold spline evaluation in face {face}: the face is incident to a singular \
                 vertex (the hole of the spline)"
            ),
            SplineError::BoundaryFolds { vertex } => write!(
                f,
                "manifold spline: the boundary of the spline domain folds back on itself at \
                 vertex {vertex}"
            ),
            SplineError::NotAnalysisSuitable { budget, remaining } => write!(
                f,
                "the T-mesh is not analysis-suitable after {budget} extensions ({remaining} \
                 intersecting T-junction extensions remain)"
            ),
        }
    }
}

impl std::error::Error for SplineError {}

impl StageError for SplineError {
    fn kind(&self) -> Kind {
        match self {
            SplineError::NotAnalysisSuitable { .. } => Kind::Numerical,
            _ => Kind::InvalidInput,
        }
    }
}

impl From<SplineError> for Error {
    fn from(e: SplineError) -> Self {
        Error::stage(e)
    }
}
