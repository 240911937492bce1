//! The metric stage's errors with their data ([`MetricError`]): a face whose edge lengths
//! violate the triangle inequality, a face too large for a spherical triangle. They convert
//! into [`crate::Error::Stage`] with the same sentence as before; [`crate::Error::stage_error`]
//! gives the enum back, so a caller (e.g. of the flow, which checks its input metric here)
//! can point at the face without parsing the message.

use std::fmt;

use crate::error::{Error, Kind, StageError};

/// An error of the metric stage, with the face and the lengths it is about.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub enum MetricError {
    /// Face `face` (corners `vertices`) has edge lengths (`lengths[i]` opposite corner `i`)
    /// that violate the triangle inequality.
    DegenerateFace {
        face: u32,
        vertices: [u32; 3],
        lengths: [f64; 3],
    },
    /// Face `face` has perimeter ≥ 2π: too large for a triangle on the unit sphere.
    SphericalFaceTooLarge { face: u32, perimeter: f64 },
}

impl MetricError {
    /// The face the error is about.
    pub fn face(&self) -> u32 {
        match self {
            MetricError::DegenerateFace { face, .. }
            | MetricError::SphericalFaceTooLarge { face, .. } => *face,
        }
    }
}

impl fmt::Display for MetricError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            MetricError::DegenerateFace {
                face,
                vertices,
                lengths: l,
            } => write!(
                f,
                "face {face} (vertices {vertices:?}) is degenerate: its edge lengths {:.6e}, \
                 {:.6e}, {:.6e} violate the triangle inequality",
                l[0], l[1], l[2]
            ),
            MetricError::SphericalFaceTooLarge { face, perimeter } => write!(
                f,
                "face {face} is too large for a spherical triangle (perimeter {perimeter:.4} ≥ 2π)"
            ),
        }
    }
}

impl std::error::Error for MetricError {}

impl StageError for MetricError {
    fn kind(&self) -> Kind {
        Kind::InvalidInput
    }
}

impl From<MetricError> for Error {
    fn from(e: MetricError) -> Self {
        Error::stage(e)
    }
}
