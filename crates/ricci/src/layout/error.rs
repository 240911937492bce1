//! The layout stage's errors with their data ([`LayoutError`]): an edge length that is not a
//! length of the geometry, a low part that is not finite, a seed face that does not exist, a
//! mesh that is not simply connected. They convert into [`crate::Error::Stage`] with the same
//! sentence as before; [`crate::Error::stage_error`] gives the enum back, so a caller can
//! point at the edge or face without parsing the message.

use std::fmt;

use crate::error::{Error, Kind, StageError};
use crate::metric::Geometry;

/// An error of the layout stage, with the edge, face or topology it is about.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub enum LayoutError {
    /// Edge `edge` (between `vertices`) has `length`, which is not a valid length in
    /// `geometry` (not finite and positive, or not below π on the unit sphere).
    InvalidLength {
        edge: u32,
        vertices: [u32; 2],
        length: f64,
        geometry: Geometry,
    },
    /// The low (double-double) part of edge `edge`'s length is `value`, not a finite number.
    InvalidLowPart { edge: u32, value: f64 },
    /// The seed face `face` is not below `n_faces`.
    SeedFaceMissing { face: u32, n_faces: usize },
    /// A layout needs a disk or a closed genus-0 surface; this one has `genus` and
    /// `boundary_loops`.
    NotSimplyConnected { genus: i64, boundary_loops: usize },
}

impl fmt::Display for LayoutError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            LayoutError::InvalidLength {
                edge,
                vertices: [a, b],
                length,
                geometry,
            } => write!(
                f,
                "edge {edge} (vertices {a}–{b}) has length {length}, which is not a valid {} \
                 length",
                geometry.name()
            ),
            LayoutError::InvalidLowPart { edge, value } => {
                write!(f, "edge {edge}: the low part of its length is {value}")
            }
            LayoutError::SeedFaceMissing { face, n_faces } => write!(
                f,
                "seed face {face} does not exist (the mesh has {n_faces} faces)"
            ),
            LayoutError::NotSimplyConnected {
                genus,
                boundary_loops,
            } => write!(
                f,
                "a layout needs a disk or a closed genus-0 surface, this mesh has genus {genus} \
                 and {boundary_loops} boundary loops (cut it to a disk first)"
            ),
        }
    }
}

impl std::error::Error for LayoutError {}

impl StageError for LayoutError {
    fn kind(&self) -> Kind {
        match self {
            LayoutError::NotSimplyConnected { .. } => Kind::Topology,
            _ => Kind::InvalidInput,
        }
    }
}

impl From<LayoutError> for Error {
    fn from(e: LayoutError) -> Self {
        Error::stage(e)
    }
}
